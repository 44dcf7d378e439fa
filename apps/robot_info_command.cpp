// SPDX-License-Identifier: BSD-3-Clause
// `mcopt robot info`: what a robot description contains, in text or JSON.
#include <iomanip>
#include <iostream>
#include <map>

#include "apps/commands.hpp"
#include "apps/json_io.hpp"
#include "apps/robot_info_json.hpp"
#include "core/actuators.hpp"

namespace mcopt::cli {

namespace {

struct RobotInfoOptions {
  std::string robot, actuators;
  bool json = false, allowNonPhysicalInertia = false;
};

int runRobotInfo(const RobotInfoOptions& o) {
  const RobotModel robot = loadUrdfFile(o.robot, {o.allowNonPhysicalInertia});
  for (const std::string& w : robot.warnings) std::cerr << "mcopt: warning: " << w << "\n";
  const ActuatorSet actuators = o.actuators.empty() ? defaultActuators(robot) : loadActuators(o.actuators, robot);
  const json_io::Json info = robotInfoJson(robot, actuators);
  if (o.json) {
    std::cout << info.dump(2) << "\n";
    return 0;
  }
  const auto& com = info["com"];
  std::cout << "robot " << robot.name << " (" << robot.source << ")\n"
            << "  " << robot.bodyCount() << " bodies (fixed joints merged), " << robot.frames.size()
            << " frames, " << robot.jointCount() << " actuated joints\n"
            << std::fixed << std::setprecision(3) << "  total mass " << robot.totalMass() << " kg, centre of mass at"
            << " the zero posture (root frame) [" << com[0].get<double>() << " " << com[1].get<double>() << " "
            << com[2].get<double>() << "] m\n\n"
            << "  #   joint                       lower     upper    vel.max  effort.max\n";
  for (int j = 0; j < robot.jointCount(); ++j) {
    const Joint& joint = robot.joints[j];
    std::cout << "  " << std::setw(3) << std::left << j << " " << std::setw(24) << joint.name << std::right
              << std::setw(10) << joint.limits.lower << std::setw(10) << joint.limits.upper << std::setw(10)
              // Limits: the actuator file over the URDF (formulation.md §2).
              << actuators.joints[j].velocityLimit << std::setw(11) << actuators.joints[j].torqueLimit << "\n";
  }
  // Where the values in use came from, field by field: joints counted by source.
  std::cout << "\n  where the actuator values come from (joints):\n";
  for (const auto& [field, member] :
       {std::pair{"velocity limit", &ActuatorSources::velocityLimit}, std::pair{"torque limit", &ActuatorSources::torqueLimit},
        std::pair{"gear ratio", &ActuatorSources::gearRatio}, std::pair{"torque constant", &ActuatorSources::torqueConstant},
        std::pair{"resistance", &ActuatorSources::resistance}, std::pair{"rotor inertia", &ActuatorSources::rotorInertia},
        std::pair{"viscous friction", &ActuatorSources::viscousFriction},
        std::pair{"dry friction", &ActuatorSources::dryFriction}}) {
    std::map<std::string, int> counts;  // "actuator file joints.X" counted as "actuator file joints"
    for (const ActuatorSources& from : actuators.sources) {
      const std::string source = from.*member;
      ++counts[source.rfind("actuator file joints.", 0) == 0 ? "actuator file joints" : source];
    }
    std::cout << "    " << std::left << std::setw(18) << field << std::right;
    bool first = true;
    for (const auto& [source, count] : counts) std::cout << (first ? "" : ", ") << source << " (" << count << ")", first = false;
    std::cout << "\n";
  }
  for (const std::string& n : urdfFrictionNotes(actuators, robot)) std::cerr << "mcopt: note: " << n << "\n";
  return 0;
}

}  // namespace

Runner addRobotInfo(CLI::App& command) {
  auto o = std::make_shared<RobotInfoOptions>();
  command.add_option("--robot", o->robot, "URDF file")->required()->check(CLI::ExistingFile);
  command.add_option("--actuators", o->actuators, "actuator YAML file (formulation.md §2)")->check(CLI::ExistingFile);
  command.add_flag("--json", o->json, "print JSON instead of text");
  command.add_flag("--allow-nonphysical-inertia", o->allowNonPhysicalInertia,
                   "load inertias that break positivity or the triangle inequality, with a warning");
  return [o] { return runRobotInfo(*o); };
}

}  // namespace mcopt::cli
