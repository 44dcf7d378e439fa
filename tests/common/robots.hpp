// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Loading the test robots: ours (always) and the third-party ones of ../shared.
#include <catch2/catch.hpp>

#include "common/test_support.hpp"

namespace mcopt::test {

/// Every robot the physics tests run on. Romeo's URDF has non-physical inertias
/// (RShoulderYawLink breaks the triangle inequality by 80 %), so test loads allow them.
/// Says at run time which robots a test covers: without ../shared it is HRP-2 alone.
inline std::vector<NamedRobot> allRobots() {
  std::vector<NamedRobot> robots = sharedRobots();
  robots.insert(robots.begin(), hrp2());
  std::string names;
  for (const NamedRobot& r : robots) names += (names.empty() ? "" : ", ") + r.name;
  WARN("on " << robots.size() << " robots: " << names
             << (robots.size() == 1 ? " (no ../shared: the third-party robots are not covered)" : ""));
  return robots;
}

inline RobotModel load(const NamedRobot& robot) { return loadUrdfFile(robot.urdf, {true}); }

/// A state inside the joint ranges (± 1 rad where a range is unbounded), velocities and
/// accelerations of a few rad/s and rad/s².
inline void randomState(std::mt19937& rng, const RobotModel& model, Eigen::VectorXd& q, Eigen::VectorXd& v,
                        Eigen::VectorXd& a) {
  const int n = model.jointCount();
  q.resize(n);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int j = 0; j < n; ++j) {
    double lo = model.joints[j].limits.lower, hi = model.joints[j].limits.upper;
    if (!std::isfinite(lo) || !std::isfinite(hi)) lo = -1.0, hi = 1.0;
    q[j] = lo + (hi - lo) * unit(rng);
  }
  v = randomVector(rng, n, 2.0);
  a = randomVector(rng, n, 5.0);
}

}  // namespace mcopt::test
