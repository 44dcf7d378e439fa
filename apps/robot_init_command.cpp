// SPDX-License-Identifier: BSD-3-Clause
// `mcopt robot init URDF --out DIR`: a robot folder from a URDF (apps/robot_init.hpp), and what
// was found, estimated and left out, said once.
#include <iomanip>
#include <iostream>

#include "apps/commands.hpp"
#include "apps/robot_init.hpp"

namespace mcopt::cli {

namespace {

int runRobotInit(const RobotInitSettings& settings) {
  const RobotInitResult r = initRobotFolder(settings);
  for (const std::string& w : r.robot.warnings) std::cerr << "mcopt: warning: " << w << "\n";
  std::cout << "robot " << r.robot.name << " (" << settings.urdf.string() << "): " << r.robot.jointCount() << " joints, "
            << std::fixed << std::setprecision(1) << r.dimensions.mass << " kg\n\ncontact surfaces (estimated):\n";
  for (const ContactEstimate& c : r.contacts)
    std::cout << "  " << std::left << std::setw(12) << c.surface.name << std::right << " on " << c.link << ": "
              << std::setprecision(1) << 100.0 * (c.surface.xMax - c.surface.xMin) << " × "
              << 100.0 * (c.surface.yMax - c.surface.yMin) << " cm; " << c.source << "\n";
  std::cout << std::setprecision(3) << "\nstanding posture: both soles flat " << 100.0 * r.dimensions.stanceWidth
            << " cm apart, centre of mass " << 100.0 * r.dimensions.centerOfMassHeight
            << " cm high above their middle (Ipopt: " << toString(r.standing.status) << ", " << r.standing.iterations
            << " iterations, largest row " << std::scientific << std::setprecision(1) << r.standing.violation << ")\n"
            << std::fixed << std::setprecision(3) << "dimensions: leg " << r.dimensions.legLength << " m, right arm "
            << r.dimensions.armLength << " m, its hand " << std::setprecision(2) << r.dimensions.handSpeed
            << " m/s with its arm's and trunk's joints at their velocity limits\n";
  if (!r.notes.empty()) {
    std::cout << "\nnotes:\n";
    for (const std::string& n : r.notes) std::cout << "  - " << n << "\n";
  }
  std::cout << "\nwritten to " << settings.out.string() << ":";
  for (const std::string& f : r.files) std::cout << " " << f;
  std::cout << "\nnext: mcopt robot check " << settings.out.string() << "; then mcopt run " << (settings.out / "scenarios" / "kick.yaml").string()
            << "\n";
  return 0;
}

}  // namespace

Runner addRobotInit(CLI::App& command) {
  auto o = std::make_shared<RobotInitSettings>();
  command.add_option("urdf", o->urdf, "the robot's URDF")->required()->check(CLI::ExistingFile);
  command.add_option("--out", o->out, "the robot folder to write (absent or empty)")->required();
  command.add_option("--root-lowering", o->standing.rootLowering,
                     "the standing posture's root body lowered by this fraction of its zero-posture height (bent knees)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 0.5));
  command.add_flag("--allow-nonphysical-inertia", o->allowNonPhysicalInertia,
                   "load a URDF whose inertias a real body cannot have (not positive definite, or breaking the "
                   "triangle inequality), with a warning for each");
  return [o] { return runRobotInit(*o); };
}

}  // namespace mcopt::cli
