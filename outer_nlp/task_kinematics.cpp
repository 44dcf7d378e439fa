#include "outer_nlp/task_kinematics.hpp"

#include "core/spatial.hpp"
#include "outer_nlp/ballistic_flight.hpp"

namespace mcopt {

namespace {

/// va(M) = ½ vee(M − Mᵀ).
Vector3 antisymmetricPart(const Matrix3& m) {
  return 0.5 * Vector3(m(2, 1) - m(1, 2), m(0, 2) - m(2, 0), m(1, 0) - m(0, 1));
}

/// The ball's flight from the point's position and velocity (formulation.md §10): the
/// quantities of ballistic_flight.hpp, chained through ∂p/∂q = J_lin, ∂v_p/∂q (as for a linear
/// velocity task) and ∂v_p/∂q̇ = J_lin.
void evaluateThrow(const DynamicsModel& model, const DynamicsData& data, const TaskSpec& task, int position,
                   const Vector3& point, const Vector3& omega, bool derivatives, TaskWorkspace& w, Vector3& value,
                   Eigen::Ref<Eigen::Matrix3Xd> dq, Eigen::Ref<Eigen::Matrix3Xd> dv) {
  const Vector3 velocity = data.linearVelocity[static_cast<std::size_t>(position)] + omega.cross(point);
  const BallisticFlight f = ballisticFlight(point, velocity, task.target.z(), task.gravity);
  Eigen::Matrix<double, 3, 6> gradient;  // of the three components in (p, v)
  if (task.kind == TaskKind::ThrowLanding) {
    value << f.landing.x() - task.target.x(), f.landing.y() - task.target.y(), f.flightTime;
    gradient << f.landingGradient, f.flightTimeGradient;
  } else {
    value << f.speed, f.elevation, f.apexAboveTarget;
    gradient << f.speedGradient, f.elevationGradient, f.apexGradient;
  }
  if (!derivatives) return;
  frameJacobian(model, data, position, point, w.jacobian);
  bodyMotionDerivatives(model, data, position, w.dTwistDq, w.dTwistDv, w.dAccelerationDq, w.dAccelerationDv,
                        w.dAccelerationDa);
  w.velocityDq = w.dTwistDq.topRows<3>();
  w.velocityDq.noalias() -= skew(point) * w.dTwistDq.bottomRows<3>();
  w.velocityDq.noalias() += skew(omega) * w.jacobian.topRows<3>();
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
      velocityDq(3, model.jointCount()) {}

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
  const int position = model.framePosition(task.frame);
  const RigidTransform pose = framePose(model, data, task.frame);
  const Vector3 point = pose.rotation * task.point + pose.translation;
  const Vector3& omega = data.angularVelocity[static_cast<std::size_t>(position)];
  if (task.kind == TaskKind::ThrowLanding || task.kind == TaskKind::ThrowRelease) {
    evaluateThrow(model, data, task, position, point, omega, derivatives, w, value, dq, dv);
    return;
  }
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

}  // namespace mcopt
