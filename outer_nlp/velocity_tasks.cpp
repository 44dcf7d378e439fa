// SPDX-License-Identifier: BSD-3-Clause
// `linear_velocity`: the velocity v_p = v_O + ω × p of a point of a body, world frame;
// `angular_velocity`: the body's angular velocity ω. Both at an instant. Twist derivatives:
// core/motion_derivatives.hpp; ∂v_p/∂q = ∂v_O/∂q − [p]× ∂ω/∂q + [ω]× J_lin, ∂v_p/∂q̇ = J_lin.
#include "core/spatial.hpp"
#include "outer_nlp/task.hpp"

namespace mcopt {

namespace {

class LinearVelocityTask final : public Task {
 public:
  LinearVelocityTask(int frame, const Vector3& point) : frame_(frame), point_(point) {}
  std::string kind() const override { return "linear_velocity"; }
  TaskQuantity reads() const override { return TaskQuantity::LinearVelocity; }
  int frame() const override { return frame_; }

  void calc(const DynamicsModel& model, const DynamicsData& data, TaskWorkspace&,
            Eigen::Ref<Eigen::VectorXd> value) const override {
    const auto position = static_cast<std::size_t>(model.framePosition(frame_));
    const RigidTransform pose = framePose(model, data, frame_);
    value = data.linearVelocity[position] + data.angularVelocity[position].cross(pose.rotation * point_ + pose.translation);
  }
  void calcDiff(const DynamicsModel& model, const DynamicsData& data, TaskWorkspace& w, Eigen::Ref<Eigen::VectorXd> value,
                Eigen::Ref<Eigen::MatrixXd> dq, Eigen::Ref<Eigen::MatrixXd> dv) const override {
    const int position = model.framePosition(frame_);
    const RigidTransform pose = framePose(model, data, frame_);
    const Vector3 point = pose.rotation * point_ + pose.translation;
    const Vector3& omega = data.angularVelocity[static_cast<std::size_t>(position)];
    value = data.linearVelocity[static_cast<std::size_t>(position)] + omega.cross(point);
    frameJacobian(model, data, position, point, w.jacobian);
    bodyMotionDerivatives(model, data, position, w.dTwistDq, w.dTwistDv, w.dAccelerationDq, w.dAccelerationDv,
                          w.dAccelerationDa);
    ThreeRows q3 = threeRows(dq);
    q3 = w.dTwistDq.topRows<3>();
    q3.noalias() -= skew(point) * w.dTwistDq.bottomRows<3>();
    q3.noalias() += skew(omega) * w.jacobian.topRows<3>();
    threeRows(dv) = w.jacobian.topRows<3>();
  }

 private:
  int frame_;
  Vector3 point_;
};

class AngularVelocityTask final : public Task {
 public:
  explicit AngularVelocityTask(int frame) : frame_(frame) {}
  std::string kind() const override { return "angular_velocity"; }
  TaskQuantity reads() const override { return TaskQuantity::AngularVelocity; }
  int frame() const override { return frame_; }

  void calc(const DynamicsModel& model, const DynamicsData& data, TaskWorkspace&,
            Eigen::Ref<Eigen::VectorXd> value) const override {
    value = data.angularVelocity[static_cast<std::size_t>(model.framePosition(frame_))];
  }
  void calcDiff(const DynamicsModel& model, const DynamicsData& data, TaskWorkspace& w, Eigen::Ref<Eigen::VectorXd> value,
                Eigen::Ref<Eigen::MatrixXd> dq, Eigen::Ref<Eigen::MatrixXd> dv) const override {
    const int position = model.framePosition(frame_);
    value = data.angularVelocity[static_cast<std::size_t>(position)];
    frameJacobian(model, data, position, framePose(model, data, frame_).translation, w.jacobian);
    bodyMotionDerivatives(model, data, position, w.dTwistDq, w.dTwistDv, w.dAccelerationDq, w.dAccelerationDv,
                          w.dAccelerationDa);
    threeRows(dq) = w.dTwistDq.bottomRows<3>();
    threeRows(dv) = w.jacobian.bottomRows<3>();
  }

 private:
  int frame_;
};

/// Velocity tasks hold at an instant: a window would bound a velocity over an interval of
/// samples, which the motion's task instants do not give.
void requireInstant(const TaskFields& fields) {
  if (fields.window()) fields.fail("window", "velocity tasks hold at an instant (use time)");
}

}  // namespace

std::shared_ptr<const Task> makeLinearVelocityTask(int frame, const Vector3& point) {
  return std::make_shared<LinearVelocityTask>(frame, point);
}
std::shared_ptr<const Task> makeAngularVelocityTask(int frame) { return std::make_shared<AngularVelocityTask>(frame); }

ReadTask readLinearVelocityTask(const TaskFields& fields) {
  requireInstant(fields);
  Vector3 point = Vector3::Zero();
  if (fields.has("point")) {
    const std::vector<double> p = fields.numbers("point", 3);
    point = Vector3(p[0], p[1], p[2]);
  }
  ReadTask out;
  out.task = makeLinearVelocityTask(fields.body("body"), point);
  readTargetOrBounds(fields, 3, out);
  return out;
}

ReadTask readAngularVelocityTask(const TaskFields& fields) {
  requireInstant(fields);
  ReadTask out;
  out.task = makeAngularVelocityTask(fields.body("body"));
  readTargetOrBounds(fields, 3, out);
  return out;
}

}  // namespace mcopt
