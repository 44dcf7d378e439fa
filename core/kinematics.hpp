// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Kinematic quantities read from a DynamicsData filled by forwardKinematics or
// inverseDynamics (formulation.md §4–§5). No allocation when outputs are pre-sized.

#include <Eigen/Core>

#include "core/dynamics_data.hpp"

namespace mcopt {

using FrameJacobian = Eigen::Matrix<double, 6, Eigen::Dynamic>;

/// World pose of a RobotModel frame.
RigidTransform framePose(const DynamicsModel& model, const DynamicsData& data, int frame);

/// Whole-body centre of mass [m], world frame.
Vector3 centerOfMass(const DynamicsModel& model, const DynamicsData& data);

/// Kinetic energy of the bodies [J]: Σ ½ m |v_c|² + ½ ωᵀ I_c ω from the twists that
/// inverseDynamics leaves in `data` (the reference body's own twist included).
double kineticEnergy(const DynamicsModel& model, const DynamicsData& data);

/// Potential energy of the bodies in the model's gravity g [J]: −Σ m gᵀ c, zero at the world
/// origin (poses from forwardKinematics or inverseDynamics).
double potentialEnergy(const DynamicsModel& model, const DynamicsData& data);

/// Twist (linear velocity of `pointInWorld`, angular velocity; world axes) of the body at
/// `bodyPosition`, from the twists inverseDynamics leaves in `data`.
Vector6 pointTwist(const DynamicsData& data, int bodyPosition, const Vector3& pointInWorld);

/// Twist Jacobian of a frame fixed to a body at `placementInBody`: rows (linear velocity of
/// the frame origin, angular velocity), world axes; columns: joints in URDF order.
/// Only joints between the reference body and the frame's body have non-zero columns.
/// jacobian: 6 × jointCount, written.
void frameJacobian(const DynamicsModel& model, const DynamicsData& data, int bodyPosition,
                   const Vector3& pointInWorld, FrameJacobian& jacobian);

/// Jacobian of the whole-body centre of mass: 3 × jointCount, written.
void centerOfMassJacobian(const DynamicsModel& model, const DynamicsData& data, Eigen::Matrix3Xd& jacobian);

}  // namespace mcopt
