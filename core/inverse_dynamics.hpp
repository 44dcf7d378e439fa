// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Recursive Newton–Euler inverse dynamics in the world frame, rooted at the
// reference body (formulation.md §4). One call is O(number of bodies) and
// allocates nothing.

#include <Eigen/Core>

#include "core/dynamics_data.hpp"

namespace mcopt {

using ConstVectorRef = Eigen::Ref<const Eigen::VectorXd>;

/// Body poses only (positions rotation, position, jointAxis, jointMoment, comPosition).
/// q: jointCount() values in URDF joint order.
void forwardKinematics(const DynamicsModel& model, DynamicsData& data, const ConstVectorRef& q);

/// Joint torques Γ0 (data.tau) and the reference-body wrench W0 (data.referenceWrench),
/// plus every pose, twist, acceleration and joint wrench in `data`.
/// q, v, a: jointCount() values each, URDF joint order. The reference body moves with
/// data.rootTwist / data.rootAcceleration (zero: fixed, the normal case).
void inverseDynamics(const DynamicsModel& model, DynamicsData& data, const ConstVectorRef& q,
                     const ConstVectorRef& v, const ConstVectorRef& a);

/// W0 moved to the origin of the reference frame (what `mcopt dynamics` reports): world axes.
Vector6 referenceWrenchAtReferenceFrame(const DynamicsModel& model, const DynamicsData& data);

}  // namespace mcopt
