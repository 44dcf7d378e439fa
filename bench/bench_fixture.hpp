// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Shared set-up for mcopt-bench: the robots (ours and, when present, ../shared's),
// seeded inputs, and the context printed with the numbers.
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "core/robot_model.hpp"

namespace mcopt::bench {

struct BenchRobot {
  std::string name;                  ///< folder name: hrp2, talos, romeo, icub, jvrc1
  std::filesystem::path urdf;
  std::string sole;                  ///< reference body used in the benchmarks
};

inline std::vector<BenchRobot> benchRobots() {
  std::vector<BenchRobot> robots{{"hrp2", std::filesystem::path(MCOPT_SOURCE_DIR) / "robots/hrp2/hrp2.urdf", "l_sole"}};
#ifdef MCOPT_SHARED_DIR
  const std::filesystem::path r = std::filesystem::path(MCOPT_SHARED_DIR) / "robots";
  robots.push_back({"talos", r / "talos/talos_reduced.urdf", "left_sole_link"});
  robots.push_back({"romeo", r / "romeo/romeo.urdf", "l_sole"});
  robots.push_back({"icub", r / "icub/icub_reduced.urdf", "l_sole"});
  robots.push_back({"jvrc1", r / "jvrc1/jvrc1.urdf", "L_ANKLE_P_S"});
#endif
  return robots;
}

/// Romeo's published inertias are not physical; the benchmarks load it anyway.
inline RobotModel loadBenchRobot(const BenchRobot& robot) { return loadUrdfFile(robot.urdf, {true}); }

}  // namespace mcopt::bench
