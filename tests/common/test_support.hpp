// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Shared helpers for the test suite: data locations, seeded random states,
// relative-error comparisons.

#include <Eigen/Core>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "core/robot_model.hpp"

namespace mcopt::test {

/// Under AddressSanitizer the executables run ~10× slower: tests run lighter variants there.
#ifdef MCOPT_UNDER_SANITIZERS
inline constexpr bool kUnderSanitizers = true;
#else
inline constexpr bool kUnderSanitizers = false;
#endif

inline std::filesystem::path sourceDir() { return MCOPT_SOURCE_DIR; }
#ifdef MCOPT_SHARED_DIR
inline std::filesystem::path sharedDir() { return MCOPT_SHARED_DIR; }
#endif

/// max_i |a_i − b_i| / (1 + |b_i|)
inline double scaledError(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return ((a - b).array().abs() / (1.0 + b.array().abs())).maxCoeff();
}

inline Eigen::VectorXd randomVector(std::mt19937& rng, int n, double scale) {
  std::uniform_real_distribution<double> uniform(-scale, scale);
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) v[i] = uniform(rng);
  return v;
}

struct NamedRobot {
  std::string name;               ///< folder name, used in benchmark names
  std::filesystem::path urdf;
  std::vector<std::string> soles; ///< sole frames (left, right)
};

/// The third-party robots of ../shared/robots (empty when shared data is absent).
inline std::vector<NamedRobot> sharedRobots() {
#ifdef MCOPT_SHARED_DIR
  const auto r = sharedDir() / "robots";
  return {{"talos", r / "talos/talos_reduced.urdf", {"left_sole_link", "right_sole_link"}},
          {"talos_full", r / "talos/talos_full_v2.urdf", {"left_sole_link", "right_sole_link"}},
          {"romeo", r / "romeo/romeo.urdf", {"l_sole", "r_sole"}},
          {"icub", r / "icub/icub_reduced.urdf", {"l_sole", "r_sole"}},
          {"icub_full", r / "icub/icub.urdf", {"l_sole", "r_sole"}},
          {"jvrc1", r / "jvrc1/jvrc1.urdf", {"L_ANKLE_P_S", "R_ANKLE_P_S"}}};
#else
  return {};
#endif
}

/// Our own HRP-2 model, always available.
inline NamedRobot hrp2() {
  const auto dir = sourceDir() / "robots/hrp2";
  return {"hrp2", dir / "hrp2.urdf", {"l_sole", "r_sole"}};
}

}  // namespace mcopt::test
