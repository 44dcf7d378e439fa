// SPDX-License-Identifier: BSD-3-Clause
#include "core/actuators.hpp"

#include <cmath>
#include <numbers>
#include <tuple>

#include "core/yaml_fields.hpp"

namespace mcopt {

ActuatorSet defaultActuators(const RobotModel& robot) {
  ActuatorSet set;
  set.joints.resize(robot.joints.size());
  set.sources.resize(robot.joints.size());
  for (std::size_t j = 0; j < robot.joints.size(); ++j) {
    const Joint& joint = robot.joints[j];
    ActuatorParameters& a = set.joints[j];
    ActuatorSources& from = set.sources[j];
    a.torqueLimit = joint.limits.effort;
    a.velocityLimit = joint.limits.velocity;
    a.viscousFriction = joint.damping;
    a.dryFriction = joint.friction;
    if (std::isfinite(joint.limits.effort)) from.torqueLimit = "URDF <limit effort>";
    if (std::isfinite(joint.limits.velocity)) from.velocityLimit = "URDF <limit velocity>";
    if (joint.damping != 0.0) from.viscousFriction = "URDF <dynamics damping>";
    if (joint.friction != 0.0) from.dryFriction = "URDF <dynamics friction>";
  }
  return set;
}

std::vector<std::string> urdfFrictionNotes(const ActuatorSet& actuators, const RobotModel& robot) {
  std::vector<std::string> notes;
  for (const auto& [member, tag, meaning] :
       {std::tuple{&ActuatorSources::viscousFriction, "URDF <dynamics damping>", "viscous friction"},
        std::tuple{&ActuatorSources::dryFriction, "URDF <dynamics friction>", "dry friction"}}) {
    std::vector<std::string> joints;
    for (std::size_t j = 0; j < actuators.sources.size(); ++j)
      if (actuators.sources[j].*member == tag) joints.push_back(robot.joints[j].name);
    if (joints.empty()) continue;
    std::string list;
    for (std::size_t k = 0; k < joints.size() && k < 6; ++k) list += (k == 0 ? "" : ", ") + joints[k];
    if (joints.size() > 6) list += " and " + std::to_string(joints.size() - 6) + " more";
    notes.push_back(std::to_string(joints.size()) + " joint" + (joints.size() == 1 ? "" : "s") + " (" + list + ") take " +
                    meaning + " from the " + tag + ": a joint-side value, used as motor-side " + meaning +
                    " (the same only where the gear ratio is 1); set it in the actuator file to override");
  }
  return notes;
}

namespace {

void readJoint(const std::filesystem::path& file, const YAML::Node& node, const std::string& field,
               ActuatorParameters& a, ActuatorSources& from) {
  const std::string source = "actuator file " + field;
  for (const auto& [key, member] :
       {std::pair{"gear_ratio", &ActuatorSources::gearRatio}, std::pair{"torque_constant", &ActuatorSources::torqueConstant},
        std::pair{"resistance", &ActuatorSources::resistance}, std::pair{"rotor_inertia", &ActuatorSources::rotorInertia},
        std::pair{"viscous_friction", &ActuatorSources::viscousFriction},
        std::pair{"dry_friction", &ActuatorSources::dryFriction}, std::pair{"torque_limit", &ActuatorSources::torqueLimit},
        std::pair{"velocity_limit", &ActuatorSources::velocityLimit}})
    if (node[key]) from.*member = source;
  yaml::rejectUnknownKeys(file, node, field,
                          {"gear_ratio", "torque_constant", "resistance", "rotor_inertia", "viscous_friction",
                           "dry_friction", "torque_limit", "velocity_limit"});
  if (node["gear_ratio"]) a.gearRatio = yaml::positive(file, node["gear_ratio"], field + ".gear_ratio");
  if (node["torque_constant"])
    a.torqueConstant = yaml::positive(file, node["torque_constant"], field + ".torque_constant");
  if (node["resistance"]) a.resistance = yaml::nonNegative(file, node["resistance"], field + ".resistance");
  if (node["rotor_inertia"]) a.rotorInertia = yaml::nonNegative(file, node["rotor_inertia"], field + ".rotor_inertia");
  if (node["viscous_friction"])
    a.viscousFriction = yaml::nonNegative(file, node["viscous_friction"], field + ".viscous_friction");
  if (node["dry_friction"]) a.dryFriction = yaml::nonNegative(file, node["dry_friction"], field + ".dry_friction");
  if (node["torque_limit"]) a.torqueLimit = yaml::positive(file, node["torque_limit"], field + ".torque_limit");
  if (node["velocity_limit"])
    a.velocityLimit = yaml::positive(file, node["velocity_limit"], field + ".velocity_limit");
}

ActuatorSet readActuators(const std::filesystem::path& path, const RobotModel& robot) {
  const YAML::Node root = yaml::loadFile(path);
  yaml::rejectUnknownKeys(path, root, "", {"friction_sharpness", "defaults", "joints", "sources"});
  ActuatorSet set = defaultActuators(robot);
  if (root["friction_sharpness"])
    set.frictionSharpness = yaml::positive(path, root["friction_sharpness"], "friction_sharpness");
  if (root["defaults"])
    for (std::size_t j = 0; j < set.joints.size(); ++j) readJoint(path, root["defaults"], "defaults", set.joints[j], set.sources[j]);
  const YAML::Node joints = yaml::required(path, root, "joints", "");
  if (!joints.IsMap()) throw InputError(yaml::where(path, joints, "joints") + "expected a mapping joint name → values");
  for (const auto& entry : joints) {
    const std::string name = entry.first.as<std::string>();
    const int index = robot.findJoint(name);
    if (index < 0)
      throw InputError(yaml::where(path, entry.first, "joints." + name) + "unknown joint (not an actuated joint of " +
                       robot.source + ")");
    readJoint(path, entry.second, "joints." + name, set.joints[index], set.sources[index]);
  }
  return set;
}

}  // namespace

double frictionTorque(const ActuatorParameters& actuator, double motorSpeed, double sharpness) {
  return actuator.viscousFriction * motorSpeed +
         actuator.dryFriction * (2.0 / std::numbers::pi) * std::atan(sharpness * motorSpeed);
}

double frictionTorqueSlope(const ActuatorParameters& actuator, double motorSpeed, double sharpness) {
  const double x = sharpness * motorSpeed;
  return actuator.viscousFriction + actuator.dryFriction * (2.0 / std::numbers::pi) * sharpness / (1.0 + x * x);
}

double frictionTorqueCurvature(const ActuatorParameters& actuator, double motorSpeed, double sharpness) {
  const double x = sharpness * motorSpeed, denominator = 1.0 + x * x;
  return -actuator.dryFriction * (2.0 / std::numbers::pi) * 2.0 * sharpness * sharpness * x / (denominator * denominator);
}

MotorPower motorPower(const ActuatorParameters& actuator, double sharpness, double torque, double velocity,
                      double acceleration) {
  const double n = actuator.gearRatio;
  const double motorSpeed = n * velocity;
  MotorPower out;
  out.motorTorque =
      torque / n + actuator.rotorInertia * n * acceleration + frictionTorque(actuator, motorSpeed, sharpness);
  const double k = actuator.torqueConstant;
  out.power = out.motorTorque * motorSpeed + (actuator.resistance / (k * k)) * out.motorTorque * out.motorTorque;
  return out;
}

MotorPowerDerivatives motorPowerDerivatives(const ActuatorParameters& actuator, double sharpness, double torque,
                                            double velocity, double acceleration) {
  const MotorPower p = motorPower(actuator, sharpness, torque, velocity, acceleration);
  const double n = actuator.gearRatio, k = actuator.torqueConstant;
  const double motorSpeed = n * velocity;
  const double frictionSlope = frictionTorqueSlope(actuator, motorSpeed, sharpness);
  const double dPdMotorTorque = motorSpeed + 2.0 * (actuator.resistance / (k * k)) * p.motorTorque;
  MotorPowerDerivatives d;
  d.power = p.power;
  d.dTorque = dPdMotorTorque / n;
  d.dVelocity = n * p.motorTorque + dPdMotorTorque * n * frictionSlope;
  d.dAcceleration = dPdMotorTorque * actuator.rotorInertia * n;
  return d;
}

Eigen::Matrix3d motorPowerHessian(const ActuatorParameters& actuator, double sharpness, double torque, double velocity,
                                  double acceleration) {
  const MotorPower p = motorPower(actuator, sharpness, torque, velocity, acceleration);
  const double n = actuator.gearRatio, k = actuator.torqueConstant, r = actuator.resistance / (k * k);
  const double motorSpeed = n * velocity;
  const double dPdMotorTorque = motorSpeed + 2.0 * r * p.motorTorque;
  const Eigen::Vector3d g(1.0 / n, n * frictionTorqueSlope(actuator, motorSpeed, sharpness), actuator.rotorInertia * n);
  // g eΩᵀ + eΩ gᵀ + 2 (R/K²) g gᵀ entry by entry (eΩ = (0, N, 0)), so that it is symmetric to the bit.
  Eigen::Matrix3d h = 2.0 * r * g * g.transpose();
  for (int i = 0; i < 3; ++i) h(i, 1) += g[i] * n, h(1, i) += g[i] * n;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < i; ++j) h(j, i) = h(i, j);
  h(1, 1) += dPdMotorTorque * n * n * frictionTorqueCurvature(actuator, motorSpeed, sharpness);
  return h;
}

ActuatorSet loadActuators(const std::filesystem::path& path, const RobotModel& robot) {
  return yaml::reading(path, [&] { return readActuators(path, robot); });
}

}  // namespace mcopt
