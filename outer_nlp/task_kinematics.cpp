#include "outer_nlp/task_kinematics.hpp"

#include "core/spatial.hpp"

namespace mcopt {

namespace {

/// va(M) = ½ vee(M − Mᵀ).
Vector3 antisymmetricPart(const Matrix3& m) {
  return 0.5 * Vector3(m(2, 1) - m(1, 2), m(0, 2) - m(2, 0), m(1, 0) - m(0, 1));
}

}  // namespace

TaskWorkspace::TaskWorkspace(const DynamicsModel& model)
    : jacobian(6, model.jointCount()),
      dTwistDq(6, model.jointCount()),
      dTwistDv(6, model.jointCount()),
      dAccelerationDq(6, model.jointCount()),
      dAccelerationDv(6, model.jointCount()),
      dAccelerationDa(6, model.jointCount()),
      comJacobian(3, model.jointCount()) {}

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
  switch (task.kind) {
    case TaskKind::Position: value = point; break;
    case TaskKind::Orientation: value = antisymmetricPart(task.targetRotation.transpose() * pose.rotation); break;
    case TaskKind::LinearVelocity:
      value = data.linearVelocity[static_cast<std::size_t>(position)] + omega.cross(point);
      break;
    case TaskKind::AngularVelocity: value = omega; break;
    case TaskKind::CenterOfMass: break;
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
    case TaskKind::CenterOfMass: break;
  }
}

}  // namespace mcopt
