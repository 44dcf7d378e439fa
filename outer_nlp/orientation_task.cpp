// SPDX-License-Identifier: BSD-3-Clause
// `orientation`: the error e = ½ vee(Rtᵀ R − Rᵀ Rt) of a body's world orientation R from a
// target Rt, sin θ times the axis, each component within ± the tolerance. A change
// δθ = J_ang δq of R gives δe = va(Rtᵀ [δθ]× R).
#include "core/spatial.hpp"
#include "outer_nlp/task.hpp"

namespace mcopt {

namespace {

class OrientationTask final : public Task {
 public:
  OrientationTask(int frame, const Matrix3& target) : frame_(frame), target_(target) {}
  std::string kind() const override { return "orientation"; }
  TaskQuantity reads() const override { return TaskQuantity::Orientation; }
  int frame() const override { return frame_; }

  void calc(const DynamicsModel& model, const DynamicsData& data, TaskWorkspace&,
            Eigen::Ref<Eigen::VectorXd> value) const override {
    value = antisymmetricPart(target_.transpose() * framePose(model, data, frame_).rotation);
  }
  void calcDiff(const DynamicsModel& model, const DynamicsData& data, TaskWorkspace& w, Eigen::Ref<Eigen::VectorXd> value,
                Eigen::Ref<Eigen::MatrixXd> dq, Eigen::Ref<Eigen::MatrixXd> dv) const override {
    const RigidTransform pose = framePose(model, data, frame_);
    value = antisymmetricPart(target_.transpose() * pose.rotation);
    frameJacobian(model, data, model.framePosition(frame_), pose.translation, w.jacobian);
    Matrix3 g;
    for (int i = 0; i < 3; ++i) g.col(i) = antisymmetricPart(target_.transpose() * skew(Vector3::Unit(i)) * pose.rotation);
    threeRows(dq).noalias() = g * w.jacobian.bottomRows<3>();
    dv.setZero();
  }

 private:
  int frame_;
  Matrix3 target_;
};

}  // namespace

std::shared_ptr<const Task> makeOrientationTask(int frame, const Matrix3& target) {
  return std::make_shared<OrientationTask>(frame, target);
}

ReadTask readOrientationTask(const TaskFields& fields) {
  const Matrix3 target = readTargetRotation(fields);
  double tolerance = 0.0;
  if (fields.has("tolerance")) {
    tolerance = fields.number("tolerance");
    if (!(tolerance >= 0.0)) fields.fail("tolerance", "expected a number ≥ 0");
  }
  ReadTask out;
  out.task = makeOrientationTask(fields.body("body"), target);
  out.lower.setConstant(3, -tolerance);
  out.upper.setConstant(3, tolerance);
  return out;
}

}  // namespace mcopt
