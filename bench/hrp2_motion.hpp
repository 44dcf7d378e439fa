// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The HRP-2 motion whose samples give the inner solvers' benchmark its problems (Inner/*).
#include <filesystem>
#include <random>
#include <vector>

#include "core/bspline.hpp"
#include "core/dynamics_model.hpp"
#include "core/robot_files.hpp"

namespace mcopt::bench {

inline const std::filesystem::path kHrp2 = std::filesystem::path(MCOPT_SOURCE_DIR) / "robots/hrp2";

/// HRP-2 in half-sitting on both soles, the right hand (and, for four contacts, the left
/// hand) against the environment where the posture puts them; the head swings and every
/// joint moves a little, so consecutive samples differ as in a real motion.
struct Hrp2Motion {
  RobotModel robot = loadUrdfFile(kHrp2 / "hrp2.urdf");
  DynamicsModel model{robot, "l_sole"};
  MotionParametrization parametrization{robot.jointCount()};
  Eigen::VectorXd parameters;

  Hrp2Motion() {
    const Eigen::VectorXd halfSitting = loadPostures(kHrp2 / "postures.yaml", robot).at("half_sitting");
    parameters = parametrization.constantMotion(halfSitting);
    std::mt19937 rng(42);
    std::uniform_real_distribution<double> small(-0.02, 0.02), large(-0.3, 0.3);
    for (int j = 0; j < robot.jointCount(); ++j)
      for (int k = 0; k < parametrization.parametersPerJoint(); ++k)
        parameters[j * parametrization.parametersPerJoint() + k] +=
            robot.joints[j].name.rfind("HEAD", 0) == 0 ? large(rng) : small(rng);
  }
  std::vector<ContactSurface> contacts(int count) const {
    const auto all = loadContactSurfaces(kHrp2 / "contacts.yaml", robot);  // r_sole, l_sole, r_hand, l_hand
    std::vector<ContactSurface> chosen;
    for (const char* name : {"l_sole", "r_sole", "r_hand", "l_hand"})
      for (const ContactSurface& s : all)
        if (s.name == name && static_cast<int>(chosen.size()) < count) chosen.push_back(s);
    return chosen;
  }
};

}  // namespace mcopt::bench
