// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The ball's flight after release (formulation.md §10, "throw to target"): from the release
// position p and velocity v under gravity g (along −z), p(τ) = p + v τ + ½ g τ². The flight
// time to the target's height z_t is eliminated analytically: the descending root
//   τ = (v_z + √D) / g,   D = v_z² + 2 g (p_z − z_t),
// and the landing point at that height is L = p_xy + v_xy τ. D / (2 g) = p_z − z_t + v_z²/(2 g)
// is the apex's height above the target: where it is negative the ball never reaches that
// height (τ and L are then taken at the apex, D clipped to 0, and a row holds the apex ≥ 0).
// Every quantity comes with its exact gradient and Hessian in (p, v) (the Hessians for the
// exact outer Hessian, docs/theory/outer-problem.md, "The exact Hessian").

#include <Eigen/Core>
#include <array>

#include "core/spatial.hpp"
#include "core/spatial_algebra.hpp"

namespace mcopt {

struct BallisticFlight {
  double flightTime = 0.0;                       ///< τ [s]
  Eigen::Vector2d landing = Eigen::Vector2d::Zero();  ///< L, at the target's height [m]
  double apexAboveTarget = 0.0;                  ///< D / (2 g) [m]
  double speed = 0.0;                            ///< |v| [m/s]
  double elevation = 0.0;                        ///< atan2(v_z, |v_xy|) [rad]
  /// Gradients in (p, v), columns p_x p_y p_z v_x v_y v_z.
  Eigen::Matrix<double, 1, 6> flightTimeGradient, apexGradient, speedGradient, elevationGradient;
  Eigen::Matrix<double, 2, 6> landingGradient;
  /// Hessians in (p, v), the same columns. Where D ≤ 0 (τ at the apex) τ is v_z / g.
  Matrix6 flightTimeHessian, apexHessian, speedHessian, elevationHessian;
  std::array<Matrix6, 2> landingHessian;
};

/// The flight from release (p, v) to the height `targetHeight`; g > 0 is gravity's magnitude.
BallisticFlight ballisticFlight(const Vector3& position, const Vector3& velocity, double targetHeight, double g);

}  // namespace mcopt
