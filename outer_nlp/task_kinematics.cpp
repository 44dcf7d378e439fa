// SPDX-License-Identifier: BSD-3-Clause
#include "outer_nlp/task_kinematics.hpp"

#include "core/spatial.hpp"
#include "outer_nlp/ballistic_flight.hpp"

namespace mcopt {

namespace {

/// va(M) = ½ vee(M − Mᵀ).
Vector3 antisymmetricPart(const Matrix3& m) {
  return 0.5 * Vector3(m(2, 1) - m(1, 2), m(0, 2) - m(2, 0), m(1, 0) - m(0, 1));
}

/// The ball's position p and velocity v_p = v_O + ω × p; with derivatives, ∂p/∂q = J_lin
/// (w.jacobian's top rows), ∂v_p/∂q = ∂v_O/∂q − [p]× ∂ω/∂q + [ω]× J_lin (w.velocityDq, as for a
/// linear velocity task) and ∂v_p/∂q̇ = J_lin.
struct BallState {
  Vector3 position, velocity;
};
BallState ballState(const DynamicsModel& model, const DynamicsData& data, const TaskSpec& task, bool derivatives,
                    TaskWorkspace& w) {
  const int position = model.framePosition(task.frame);
  const RigidTransform pose = framePose(model, data, task.frame);
  const Vector3 point = pose.rotation * task.point + pose.translation;
  const Vector3& omega = data.angularVelocity[static_cast<std::size_t>(position)];
  const BallState ball{point, data.linearVelocity[static_cast<std::size_t>(position)] + omega.cross(point)};
  if (!derivatives) return ball;
  frameJacobian(model, data, position, point, w.jacobian);
  bodyMotionDerivatives(model, data, position, w.dTwistDq, w.dTwistDv, w.dAccelerationDq, w.dAccelerationDv,
                        w.dAccelerationDa);
  w.velocityDq = w.dTwistDq.topRows<3>();
  w.velocityDq.noalias() -= skew(point) * w.dTwistDq.bottomRows<3>();
  w.velocityDq.noalias() += skew(omega) * w.jacobian.topRows<3>();
  return ball;
}

/// The flight's three quantities of the task's kind, and their gradients (3 × 6) in (p, v).
Vector3 flightQuantities(const BallisticFlight& f, const TaskSpec& task, Eigen::Matrix<double, 3, 6>& gradient) {
  if (task.kind == TaskKind::ThrowLanding) {
    gradient << f.landingGradient, f.flightTimeGradient;
    return Vector3(f.landing.x() - task.target.x(), f.landing.y() - task.target.y(), f.flightTime);
  }
  gradient << f.speedGradient, f.elevationGradient, f.apexGradient;
  return Vector3(f.speed, f.elevation, f.apexAboveTarget);
}
/// Σ λ_i ∇²f_i (6 × 6) of the task's three quantities in (p, v).
Matrix6 flightCurvature(const BallisticFlight& f, const TaskSpec& task, const Vector3& lambda) {
  if (task.kind == TaskKind::ThrowLanding)
    return lambda[0] * f.landingHessian[0] + lambda[1] * f.landingHessian[1] + lambda[2] * f.flightTimeHessian;
  return lambda[0] * f.speedHessian + lambda[1] * f.elevationHessian + lambda[2] * f.apexHessian;
}

/// The ball's flight from the point's position and velocity (formulation.md §10): the
/// quantities of ballistic_flight.hpp, chained through the ball state's derivatives.
void evaluateThrow(const DynamicsModel& model, const DynamicsData& data, const TaskSpec& task, bool derivatives,
                   TaskWorkspace& w, Vector3& value, Eigen::Ref<Eigen::Matrix3Xd> dq, Eigen::Ref<Eigen::Matrix3Xd> dv) {
  const BallState ball = ballState(model, data, task, derivatives, w);
  const BallisticFlight f = ballisticFlight(ball.position, ball.velocity, task.target.z(), task.gravity);
  Eigen::Matrix<double, 3, 6> gradient;  // of the three components in (p, v)
  value = flightQuantities(f, task, gradient);
  if (!derivatives) return;
  dq.noalias() = gradient.leftCols<3>() * w.jacobian.topRows<3>();
  dq.noalias() += gradient.rightCols<3>() * w.velocityDq;
  dv.noalias() = gradient.rightCols<3>() * w.jacobian.topRows<3>();
}

}  // namespace

TaskWorkspace::TaskWorkspace(const DynamicsModel& model)
    : jacobian(6, model.jointCount()),
      dTwistDq(6, model.jointCount()),
      dTwistDv(6, model.jointCount()),
      dAccelerationDq(6, model.jointCount()),
      dAccelerationDv(6, model.jointCount()),
      dAccelerationDa(6, model.jointCount()),
      comJacobian(3, model.jointCount()),
      velocityDq(3, model.jointCount()),
      ballJacobian(6, 2 * model.jointCount()),
      weightedBallJacobian(6, 2 * model.jointCount()) {}

void evaluateTask(const DynamicsModel& model, const DynamicsData& data, const TaskSpec& task, bool derivatives,
                  TaskWorkspace& w, Vector3& value, Eigen::Ref<Eigen::Matrix3Xd> dq, Eigen::Ref<Eigen::Matrix3Xd> dv) {
  if (task.kind == TaskKind::CenterOfMass) {
    value = centerOfMass(model, data);
    if (derivatives) {
      centerOfMassJacobian(model, data, w.comJacobian);
      dq = w.comJacobian;
      dv.setZero();
    }
    return;
  }
  if (task.kind == TaskKind::ThrowLanding || task.kind == TaskKind::ThrowRelease) {
    evaluateThrow(model, data, task, derivatives, w, value, dq, dv);
    return;
  }
  const int position = model.framePosition(task.frame);
  const RigidTransform pose = framePose(model, data, task.frame);
  const Vector3 point = pose.rotation * task.point + pose.translation;
  const Vector3& omega = data.angularVelocity[static_cast<std::size_t>(position)];
  switch (task.kind) {
    case TaskKind::Position: value = point; break;
    case TaskKind::Orientation: value = antisymmetricPart(task.targetRotation.transpose() * pose.rotation); break;
    case TaskKind::LinearVelocity:
      value = data.linearVelocity[static_cast<std::size_t>(position)] + omega.cross(point);
      break;
    case TaskKind::AngularVelocity: value = omega; break;
    default: break;
  }
  if (!derivatives) return;
  frameJacobian(model, data, position, point, w.jacobian);
  switch (task.kind) {
    case TaskKind::Position:
      dq = w.jacobian.topRows<3>();
      dv.setZero();
      break;
    case TaskKind::Orientation: {
      Matrix3 g;
      for (int i = 0; i < 3; ++i)
        g.col(i) = antisymmetricPart(task.targetRotation.transpose() * skew(Vector3::Unit(i)) * pose.rotation);
      dq.noalias() = g * w.jacobian.bottomRows<3>();
      dv.setZero();
      break;
    }
    case TaskKind::LinearVelocity:
      bodyMotionDerivatives(model, data, position, w.dTwistDq, w.dTwistDv, w.dAccelerationDq, w.dAccelerationDv,
                            w.dAccelerationDa);
      dq = w.dTwistDq.topRows<3>();
      dq.noalias() -= skew(point) * w.dTwistDq.bottomRows<3>();
      dq.noalias() += skew(omega) * w.jacobian.topRows<3>();
      dv = w.jacobian.topRows<3>();
      break;
    case TaskKind::AngularVelocity:
      bodyMotionDerivatives(model, data, position, w.dTwistDq, w.dTwistDv, w.dAccelerationDq, w.dAccelerationDv,
                            w.dAccelerationDa);
      dq = w.dTwistDq.bottomRows<3>();
      dv = w.jacobian.bottomRows<3>();
      break;
    default: break;
  }
}

void throwFlightCurvature(const DynamicsModel& model, const DynamicsData& data, const TaskSpec& task,
                          const Vector3& multipliers, TaskWorkspace& w, Vector6& ballWeights,
                          Eigen::Ref<Eigen::MatrixXd> curvature) {
  const int n = model.jointCount();
  const BallState ball = ballState(model, data, task, true, w);
  const BallisticFlight f = ballisticFlight(ball.position, ball.velocity, task.target.z(), task.gravity);
  Eigen::Matrix<double, 3, 6> gradient;
  flightQuantities(f, task, gradient);
  ballWeights.noalias() = gradient.transpose() * multipliers;
  // J_k = [J_lin 0; ∂v_p/∂q J_lin] in (q, q̇).
  w.ballJacobian.setZero();
  w.ballJacobian.topLeftCorner(3, n) = w.jacobian.topRows<3>();
  w.ballJacobian.bottomLeftCorner(3, n) = w.velocityDq;
  w.ballJacobian.bottomRightCorner(3, n) = w.jacobian.topRows<3>();
  w.weightedBallJacobian.noalias() = flightCurvature(f, task, multipliers) * w.ballJacobian;
  curvature.noalias() = w.ballJacobian.transpose() * w.weightedBallJacobian;
}

void ballStateGradient(const DynamicsModel& model, const DynamicsData& data, const TaskSpec& task,
                       const Vector6& ballWeights, TaskWorkspace& w, Eigen::Ref<Eigen::VectorXd> dq,
                       Eigen::Ref<Eigen::VectorXd> dv) {
  ballState(model, data, task, true, w);
  dq.noalias() = w.jacobian.topRows<3>().transpose() * ballWeights.head<3>();
  dq.noalias() += w.velocityDq.transpose() * ballWeights.tail<3>();
  dv.noalias() = w.jacobian.topRows<3>().transpose() * ballWeights.tail<3>();
}

}  // namespace mcopt
