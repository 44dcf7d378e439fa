// SPDX-License-Identifier: BSD-3-Clause
// `position`: a point p = R_b c + P_b of a body, world frame; ∂p/∂q = J_lin.
#include "outer_nlp/task.hpp"

namespace mcopt {

namespace {

class PositionTask final : public Task {
 public:
  PositionTask(int frame, const Vector3& point) : frame_(frame), point_(point) {}
  std::string kind() const override { return "position"; }
  TaskQuantity reads() const override { return TaskQuantity::Position; }
  int frame() const override { return frame_; }

  void calc(const DynamicsModel& model, const DynamicsData& data, TaskWorkspace&,
            Eigen::Ref<Eigen::VectorXd> value) const override {
    const RigidTransform pose = framePose(model, data, frame_);
    value = pose.rotation * point_ + pose.translation;
  }
  void calcDiff(const DynamicsModel& model, const DynamicsData& data, TaskWorkspace& w, Eigen::Ref<Eigen::VectorXd> value,
                Eigen::Ref<Eigen::MatrixXd> dq, Eigen::Ref<Eigen::MatrixXd> dv) const override {
    const RigidTransform pose = framePose(model, data, frame_);
    const Vector3 point = pose.rotation * point_ + pose.translation;
    value = point;
    frameJacobian(model, data, model.framePosition(frame_), point, w.jacobian);
    dq = w.jacobian.topRows<3>();
    dv.setZero();
  }

 private:
  int frame_;
  Vector3 point_;
};

}  // namespace

std::shared_ptr<const Task> makePositionTask(int frame, const Vector3& point) {
  return std::make_shared<PositionTask>(frame, point);
}

ReadTask readPositionTask(const TaskFields& fields) {
  Vector3 point = Vector3::Zero();
  if (fields.has("point")) {
    const std::vector<double> p = fields.numbers("point", 3);
    point = Vector3(p[0], p[1], p[2]);
  }
  ReadTask out;
  out.task = makePositionTask(fields.body("body"), point);
  readTargetOrBounds(fields, 3, out);
  return out;
}

}  // namespace mcopt
