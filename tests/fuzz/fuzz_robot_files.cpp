// SPDX-License-Identifier: BSD-3-Clause
// A URDF with its side files (docs/reference/robot-files.md) as `mcopt robot info` and the scenario
// loader read them. The input is the URDF, then optionally the actuator, contact-surface and
// posture files, each after a line "--- actuators", "--- contacts", "--- postures".
#include "core/actuators.hpp"
#include "core/errors.hpp"
#include "core/robot_files.hpp"
#include "tests/fuzz/fuzz_support.hpp"

namespace {

/// The part of `text` after the line "--- NAME" up to the next such line, or "" when absent.
std::string section(const std::string& text, const std::string& name, bool& present) {
  const std::string head = "\n--- " + name + "\n";
  const std::size_t at = text.find(head);
  present = at != std::string::npos;
  if (!present) return "";
  const std::size_t begin = at + head.size();
  const std::size_t end = text.find("\n--- ", begin);
  return text.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace fuzz = mcopt::fuzz;
  const std::string text(reinterpret_cast<const char*>(data), size);
  const std::filesystem::path dir = fuzz::workDir();
  const std::size_t firstSection = text.find("\n--- ");
  fuzz::writeFile(dir / "robot.urdf", text.substr(0, firstSection));
  bool actuators = false, contacts = false, postures = false;
  fuzz::writeFile(dir / "actuators.yaml", section(text, "actuators", actuators));
  fuzz::writeFile(dir / "contacts.yaml", section(text, "contacts", contacts));
  fuzz::writeFile(dir / "postures.yaml", section(text, "postures", postures));

  std::vector<std::string> info = {"info", "--robot", (dir / "robot.urdf").string(), "--json"};
  if (actuators) info.insert(info.end(), {"--actuators", (dir / "actuators.yaml").string()});
  fuzz::runCommand(mcopt::cli::addRobotInfo, info);
  try {
    const mcopt::RobotModel robot = mcopt::loadUrdfFile(dir / "robot.urdf");
    if (contacts) mcopt::loadContactSurfaces(dir / "contacts.yaml", robot);
    if (postures) mcopt::loadPostures(dir / "postures.yaml", robot);
  } catch (const mcopt::InputError& e) {
    mcopt::fuzz::refused(e);
  }
  return 0;
}
