// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Side files that complete a URDF: contact surfaces and named postures
// (formulation.md §2; formats in docs/reference/robot-files.md).

#include <Eigen/Core>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "core/robot_model.hpp"

namespace mcopt {

/// A rectangular contact surface on a body: frame C (z = surface normal pointing into
/// the robot, origin on the surface), rectangle [xMin, xMax] × [yMin, yMax] in C, friction μ.
struct ContactSurface {
  std::string name;
  int frame = -1;               ///< RobotModel frame (URDF link) the surface is attached to
  RigidTransform placement;     ///< contact frame in that link's frame
  double xMin = 0, xMax = 0, yMin = 0, yMax = 0;
  double friction = 0.7;
};

/// Throws InputError naming file, line and field (unknown link, empty rectangle, μ ≤ 0, …).
std::vector<ContactSurface> loadContactSurfaces(const std::filesystem::path& path, const RobotModel& robot);

/// Named postures: joint values in URDF order, joints not listed at zero.
std::map<std::string, Eigen::VectorXd> loadPostures(const std::filesystem::path& path, const RobotModel& robot);

}  // namespace mcopt
