// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Derivatives of a body's spatial twist V and acceleration A (world frame, at the world
// origin; A includes the fictitious −g of the reference body) with respect to q, q̇, q̈
// (issue 4). For a joint j between the reference body and the body (formulation.md §4):
//   ∂V/∂q_j = S_j × (V − V_j),   ∂V/∂q̇_j = S_j
//   ∂A/∂q_j = S_j × (A − A_j) + (V − V_j) × (S_j × V_j)
//   ∂A/∂q̇_j = S_j × (V − V_j − V_λ(j)),   ∂A/∂q̈_j = S_j
// where V_j, A_j belong to the body joint j moves and V_λ(j) to its parent. Pose
// derivatives are the frame Jacobian (kinematics.hpp).

#include <Eigen/Core>

#include "core/dynamics_data.hpp"

namespace mcopt {

using MotionDerivative = Eigen::Matrix<double, 6, Eigen::Dynamic>;

/// All outputs 6 × jointCount, written (zero off the path). `data` from inverseDynamics.
void bodyMotionDerivatives(const DynamicsModel& model, const DynamicsData& data, int bodyPosition,
                           MotionDerivative& dTwistDq, MotionDerivative& dTwistDv, MotionDerivative& dAccelerationDq,
                           MotionDerivative& dAccelerationDv, MotionDerivative& dAccelerationDa);

}  // namespace mcopt
