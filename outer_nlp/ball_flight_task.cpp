// SPDX-License-Identifier: BSD-3-Clause
#include "outer_nlp/ball_flight_task.hpp"

#include "core/spatial.hpp"
#include "outer_nlp/ballistic_flight.hpp"

namespace mcopt {

namespace {

/// The flight's three quantities of the part, and their gradients (3 × 6) in (p, v).
Vector3 flightQuantities(const BallisticFlight& f, BallFlightTask::Part part, const Vector3& target,
                         Eigen::Matrix<double, 3, 6>& gradient) {
  if (part == BallFlightTask::Part::Landing) {
    gradient << f.landingGradient, f.flightTimeGradient;
    return Vector3(f.landing.x() - target.x(), f.landing.y() - target.y(), f.flightTime);
  }
  gradient << f.speedGradient, f.elevationGradient, f.apexGradient;
  return Vector3(f.speed, f.elevation, f.apexAboveTarget);
}

/// Σ λ_i ∇²f_i (6 × 6) of the part's three quantities in (p, v).
Matrix6 flightCurvatureOf(const BallisticFlight& f, BallFlightTask::Part part, const Vector3& lambda) {
  if (part == BallFlightTask::Part::Landing)
    return lambda[0] * f.landingHessian[0] + lambda[1] * f.landingHessian[1] + lambda[2] * f.flightTimeHessian;
  return lambda[0] * f.speedHessian + lambda[1] * f.elevationHessian + lambda[2] * f.apexHessian;
}

}  // namespace

BallFlightTask::BallFlightTask(Part part, int frame, const Vector3& point, const Vector3& target, double gravity)
    : part_(part), frame_(frame), point_(point), target_(target), gravity_(gravity) {}

std::string BallFlightTask::componentName(int i) const {
  static const char* const landing[] = {"landing x", "landing y", "flight time"};
  static const char* const release[] = {"speed", "elevation", "apex above the target"};
  if (i < 0 || i > 2) return Task::componentName(i);
  return part_ == Part::Landing ? landing[i] : release[i];
}

/// The ball's position p and velocity v_p = v_O + ω × p; with derivatives, ∂p/∂q = J_lin
/// (w.jacobian's top rows), ∂v_p/∂q = ∂v_O/∂q − [p]× ∂ω/∂q + [ω]× J_lin (w.velocityDq, as for a
/// linear velocity task) and ∂v_p/∂q̇ = J_lin.
BallFlightTask::BallState BallFlightTask::ballState(const DynamicsModel& model, const DynamicsData& data, bool derivatives,
                                                    TaskWorkspace& w) const {
  const int position = model.framePosition(frame_);
  const RigidTransform pose = framePose(model, data, frame_);
  const Vector3 point = pose.rotation * point_ + pose.translation;
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

void BallFlightTask::calc(const DynamicsModel& model, const DynamicsData& data, TaskWorkspace& w,
                          Eigen::Ref<Eigen::VectorXd> value) const {
  const BallState ball = ballState(model, data, false, w);
  const BallisticFlight f = ballisticFlight(ball.position, ball.velocity, target_.z(), gravity_);
  Eigen::Matrix<double, 3, 6> gradient;
  value = flightQuantities(f, part_, target_, gradient);
}

void BallFlightTask::calcDiff(const DynamicsModel& model, const DynamicsData& data, TaskWorkspace& w,
                              Eigen::Ref<Eigen::VectorXd> value, Eigen::Ref<Eigen::MatrixXd> dq,
                              Eigen::Ref<Eigen::MatrixXd> dv) const {
  const BallState ball = ballState(model, data, true, w);
  const BallisticFlight f = ballisticFlight(ball.position, ball.velocity, target_.z(), gravity_);
  Eigen::Matrix<double, 3, 6> gradient;  // of the three components in (p, v)
  value = flightQuantities(f, part_, target_, gradient);
  ThreeRows q3 = threeRows(dq);
  q3.noalias() = gradient.leftCols<3>() * w.jacobian.topRows<3>();
  q3.noalias() += gradient.rightCols<3>() * w.velocityDq;
  threeRows(dv).noalias() = gradient.rightCols<3>() * w.jacobian.topRows<3>();
}

void BallFlightTask::flightCurvature(const DynamicsModel& model, const DynamicsData& data, const Vector3& multipliers,
                                     TaskWorkspace& w, Vector6& ballWeights, Eigen::Ref<Eigen::MatrixXd> curvature) const {
  const int n = model.jointCount();
  const BallState ball = ballState(model, data, true, w);
  const BallisticFlight f = ballisticFlight(ball.position, ball.velocity, target_.z(), gravity_);
  Eigen::Matrix<double, 3, 6> gradient;
  flightQuantities(f, part_, target_, gradient);
  ballWeights.noalias() = gradient.transpose() * multipliers;
  // J_k = [J_lin 0; ∂v_p/∂q J_lin] in (q, q̇).
  w.ballJacobian.setZero();
  w.ballJacobian.topLeftCorner(3, n) = w.jacobian.topRows<3>();
  w.ballJacobian.bottomLeftCorner(3, n) = w.velocityDq;
  w.ballJacobian.bottomRightCorner(3, n) = w.jacobian.topRows<3>();
  w.weightedBallJacobian.noalias() = flightCurvatureOf(f, part_, multipliers) * w.ballJacobian;
  curvature.noalias() = w.ballJacobian.transpose() * w.weightedBallJacobian;
}

void BallFlightTask::ballStateGradient(const DynamicsModel& model, const DynamicsData& data, const Vector6& ballWeights,
                                       TaskWorkspace& w, Eigen::Ref<Eigen::VectorXd> dq,
                                       Eigen::Ref<Eigen::VectorXd> dv) const {
  ballState(model, data, true, w);
  dq.noalias() = w.jacobian.topRows<3>().transpose() * ballWeights.head<3>();
  dq.noalias() += w.velocityDq.transpose() * ballWeights.tail<3>();
  dv.noalias() = w.jacobian.topRows<3>().transpose() * ballWeights.tail<3>();
}

}  // namespace mcopt
