// SPDX-License-Identifier: BSD-3-Clause
#include "apps/robot_info_json.hpp"

#include "core/inverse_dynamics.hpp"
#include "core/kinematics.hpp"

namespace mcopt::cli {

namespace {

json_io::Json finiteOrNull(double value) { return std::isfinite(value) ? json_io::Json(value) : json_io::Json(); }

const char* typeName(JointType type) {
  switch (type) {
    case JointType::Revolute: return "revolute";
    case JointType::Continuous: return "continuous";
    case JointType::Prismatic: return "prismatic";
  }
  return "?";
}

json_io::Json sourcesJson(const ActuatorSources& from) {
  return {{"velocity", from.velocityLimit},       {"effort", from.torqueLimit},
          {"gear_ratio", from.gearRatio},         {"torque_constant", from.torqueConstant},
          {"resistance", from.resistance},        {"rotor_inertia", from.rotorInertia},
          {"viscous_friction", from.viscousFriction}, {"dry_friction", from.dryFriction}};
}

}  // namespace

json_io::Json robotInfoJson(const RobotModel& robot, const ActuatorSet& actuators) {
  const DynamicsModel model(robot, robot.frames[0].name);
  DynamicsData data(model);
  forwardKinematics(model, data, Eigen::VectorXd::Zero(robot.jointCount()));
  const Vector3 com = centerOfMass(model, data);
  // Limits: actuator file over URDF (formulation.md §2).
  auto effort = [&](int j) { return actuators.joints[j].torqueLimit; };
  auto velocity = [&](int j) { return actuators.joints[j].velocityLimit; };
  json_io::Json out;
  out["name"] = robot.name;
  out["source"] = robot.source;
  out["total_mass"] = robot.totalMass();
  out["com"] = json_io::toJson(Eigen::VectorXd(com));
  out["root"] = robot.frames[0].name;
  out["joints"] = json_io::Json::array();
  for (int j = 0; j < robot.jointCount(); ++j) {
    const Joint& joint = robot.joints[j];
    const ActuatorParameters& a = actuators.joints[j];
    out["joints"].push_back({{"name", joint.name},
                             {"type", typeName(joint.type)},
                             {"parent", robot.bodies[joint.parentBody].name},
                             {"child", robot.bodies[joint.childBody].name},
                             {"lower", finiteOrNull(joint.limits.lower)},
                             {"upper", finiteOrNull(joint.limits.upper)},
                             {"velocity", finiteOrNull(velocity(j))},
                             {"effort", finiteOrNull(effort(j))},
                             {"gear_ratio", a.gearRatio},
                             {"torque_constant", a.torqueConstant},
                             {"resistance", a.resistance},
                             {"rotor_inertia", a.rotorInertia},
                             {"viscous_friction", a.viscousFriction},
                             {"dry_friction", a.dryFriction},
                             {"sources", static_cast<std::size_t>(j) < actuators.sources.size()
                                             ? sourcesJson(actuators.sources[static_cast<std::size_t>(j)])
                                             : json_io::Json()}});
  }
  out["bodies"] = json_io::Json::array();
  for (const Body& body : robot.bodies)
    out["bodies"].push_back({{"name", body.name}, {"mass", body.inertia.mass}});
  out["frames"] = json_io::Json::array();
  for (const Frame& frame : robot.frames) out["frames"].push_back(frame.name);
  out["warnings"] = robot.warnings;
  out["notes"] = urdfFrictionNotes(actuators, robot);
  return out;
}

}  // namespace mcopt::cli
