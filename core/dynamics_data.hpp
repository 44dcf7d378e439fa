// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// DynamicsData: every per-sample buffer of the Newton–Euler recursion, sized once
// from a DynamicsModel (style.md: Model / Data). Hot functions write into it and
// never allocate. Arrays indexed "by position" follow DynamicsModel's tree positions.

#include <Eigen/Core>
#include <vector>

#include "core/dynamics_model.hpp"

namespace mcopt {

struct DynamicsData {
  explicit DynamicsData(const DynamicsModel& model);

  // Forward recursion, world frame (formulation.md §4, (3.2)–(3.5)), by position.
  std::vector<Matrix3> rotation;        ///< body frame orientation R_j
  std::vector<Vector3> position;        ///< body frame origin P_j [m]
  std::vector<Vector3> jointAxis;       ///< sw: world joint axis of the incoming joint
  std::vector<Vector3> jointMoment;     ///< sv = P × sw (revolute) or sw (prismatic): linear part of the motion subspace at the world origin
  std::vector<Vector3> linearVelocity;  ///< v_O: velocity of the body point at the world origin
  std::vector<Vector3> angularVelocity;
  std::vector<Vector3> linearAcceleration;   ///< spatial, gravity folded in as −g at the root
  std::vector<Vector3> angularAcceleration;
  std::vector<Vector3> comPosition;     ///< world centre of mass of each body

  // Backward recursion: wrench carried by each body's incoming joint (world axes, about the world origin).
  std::vector<Vector3> force;
  std::vector<Vector3> moment;

  Eigen::VectorXd tau;                  ///< Γ0, URDF joint order and sign, friction excluded [N m or N]
  Vector6 referenceWrench;              ///< W0: environment → reference body, world axes, about the world origin

  Vector6 rootTwist = Vector6::Zero();          ///< (v_O, ω) of the reference body; zero when it is fixed
  Vector6 rootAcceleration = Vector6::Zero();   ///< its spatial acceleration, gravity excluded
};

}  // namespace mcopt
