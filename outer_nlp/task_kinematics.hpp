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

}  // namespace mcopt
