// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The quantities a task bounds (formulation.md §10) and their exact derivatives with
// respect to q and q̇, read from a DynamicsData filled by inverseDynamics at (q, q̇, q̈):
//   position of a point of a body            p = R_b c + P_b            ∂p/∂q = J_lin
//   orientation error from a target Rt       e = ½ vee(Rtᵀ R − Rᵀ Rt)   (sin θ times the axis)
//   linear velocity of the point             v_p = v_O + ω × p
//   angular velocity of the body             ω
//   centre of mass                           c,  ∂c/∂q = J_com
//   throw (landing, release)                 functions of the point's p and v_p
//                                            (outer_nlp/ballistic_flight.hpp), chained
// A change δθ = J_ang δq of the body's world orientation gives δe = va(Rtᵀ [δθ]× R) with
// va(M) = ½ vee(M − Mᵀ); ∂v_p/∂q = ∂v_O/∂q − [p]× ∂ω/∂q + [ω]× J_lin (twist derivatives:
// core/motion_derivatives.hpp).

#include <Eigen/Core>

#include "core/dynamics_data.hpp"
#include "core/kinematics.hpp"
#include "core/motion_derivatives.hpp"
#include "outer_nlp/scenario.hpp"

namespace mcopt {

/// Buffers for one thread, sized once.
struct TaskWorkspace {
  explicit TaskWorkspace(const DynamicsModel& model);
  FrameJacobian jacobian;
  MotionDerivative dTwistDq, dTwistDv, dAccelerationDq, dAccelerationDv, dAccelerationDa;
  Eigen::Matrix3Xd comJacobian;
  Eigen::Matrix3Xd velocityDq;  ///< ∂v_p/∂q of a throw's ball
  /// A throw's exact Hessian: ∂k/∂(q, q̇) of the ball's state k = (p, v_p), and W times it.
  Eigen::Matrix<double, 6, Eigen::Dynamic> ballJacobian, weightedBallJacobian;
};

/// Whether the task's quantity depends on q̇ (else on q alone).
inline bool taskReadsVelocity(TaskKind kind) {
  return kind == TaskKind::LinearVelocity || kind == TaskKind::AngularVelocity || kind == TaskKind::ThrowLanding ||
         kind == TaskKind::ThrowRelease;
}

/// value: the task quantity; dq, dv: 3 × jointCount, written when `derivatives` is set.
void evaluateTask(const DynamicsModel& model, const DynamicsData& data, const TaskSpec& task, bool derivatives,
                  TaskWorkspace& workspace, Vector3& value, Eigen::Ref<Eigen::Matrix3Xd> dq,
                  Eigen::Ref<Eigen::Matrix3Xd> dv);

/// A throw task's rows weighted by their multipliers λ, Σ_i λ_i f_i(k) with k = (p, v_p) the
/// ball's state, split for the exact Hessian in (q, q̇) (docs/theory/outer-problem.md, "The exact
/// Hessian"): ∇² = J_kᵀ (Σ λ_i ∇²f_i) J_k + Σ_m w_m ∇²k_m, w = Σ λ_i ∇f_i. The flight's own
/// curvature, the first term, goes to `flightCurvature` (2n × 2n); the weights w on the ball's
/// state go to `ballWeights`, held at the point while a stencil differentiates
/// ballStateGradient for the second (p and v_p have a position's and a linear velocity's degrees).
void throwFlightCurvature(const DynamicsModel& model, const DynamicsData& data, const TaskSpec& task,
                          const Vector3& multipliers, TaskWorkspace& workspace, Vector6& ballWeights,
                          Eigen::Ref<Eigen::MatrixXd> flightCurvature);

/// wᵀ ∂k/∂q and wᵀ ∂k/∂q̇ of a throw's ball state k = (p, v_p), n entries each.
void ballStateGradient(const DynamicsModel& model, const DynamicsData& data, const TaskSpec& task,
                       const Vector6& ballWeights, TaskWorkspace& workspace, Eigen::Ref<Eigen::VectorXd> dq,
                       Eigen::Ref<Eigen::VectorXd> dv);

}  // namespace mcopt
