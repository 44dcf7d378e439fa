// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A standing posture for a robot we know only from its URDF and its two sole frames (`mcopt
// robot init`, docs/tutorials/own-robot.md): the posture closest to the robot's zero posture
// (½ Σ (q − q₀)², q₀ the zero posture inside the limits) with
//   - both soles flat on one ground, the second where the zero posture puts it beside the first
//     (same lateral distance, side by side, no yaw);
//   - the centre of mass above the middle of the two soles' rectangles;
//   - the root body (the pelvis) upright and lowered by a fraction of its zero-posture height
//     above the soles: bent knees, as a humanoid stands (a straight knee is singular for the
//     closure of the two feet, and at the edge of its range);
// subject to the joint limits. Solved with Ipopt (exact first derivatives). Whether the robot
// can hold it, with which torques and power, is `mcopt robot check`'s question
// (posture_check.hpp).

#include <Eigen/Core>
#include <string>

#include "core/robot_files.hpp"
#include "core/robot_model.hpp"
#include "outer_nlp/outer_solver.hpp"

namespace mcopt {

struct StandingPostureSettings {
  /// The root body's height above the soles, lowered by this fraction of its zero-posture value.
  double rootLowering = 0.08;
  int maxIterations = 300;
  double tolerance = 1e-10;  ///< on the constraint rows [m, and unit-vector components]
};

struct StandingPosture {
  OuterStatus status = OuterStatus::InternalError;
  int iterations = 0;
  Eigen::VectorXd q;             ///< URDF joint order [rad, m]
  double violation = 0.0;        ///< largest constraint row at q
  std::string violatedRow;       ///< its name ("centre of mass x", …)
  Vector3 centerOfMass = Vector3::Zero();  ///< in the first sole's frame [m]
  Vector3 secondSole = Vector3::Zero();    ///< the second sole's origin in the first's frame [m]
  double rootHeight = 0.0;       ///< the root body's origin above the first sole at q [m]
  bool found() const { return status == OuterStatus::Optimal && violation < 1e-6; }
};

/// `first` and `second`: the two soles (contact frames, z the normal into the robot). Throws
/// InputError when the zero posture does not put them on one ground side by side (tilted, or
/// one above the other) or the root body is not above them.
StandingPosture findStandingPosture(const RobotModel& robot, const ContactSurface& first, const ContactSurface& second,
                                    const StandingPostureSettings& settings = {});

}  // namespace mcopt
