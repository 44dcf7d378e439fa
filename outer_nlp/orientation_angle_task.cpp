// SPDX-License-Identifier: BSD-3-Clause
// `orientation_angle`: a body's world orientation R within an angle of a target Rt, one row
//   g = 1 − cos θ = (3 − tr(Rtᵀ R)) / 2 ≤ 1 − cos(tolerance),
// θ the angle of the rotation Rtᵀ R. Unlike θ itself, g is smooth at θ = 0. A change
// δφ = J_ang δq of R (δR = [δφ]× R) gives δg = −½ tr(Rtᵀ [δφ]× R) = va(R Rtᵀ) · δφ, with
// va(M) = ½ vee(M − Mᵀ) (tr([a]× M) = −a · vee(M − Mᵀ)).
#include <cmath>
#include <limits>

#include "core/spatial.hpp"
#include "outer_nlp/task.hpp"

namespace mcopt {

namespace {

constexpr double kPi = 3.14159265358979323846;

class OrientationAngleTask final : public Task {
 public:
  OrientationAngleTask(int frame, const Matrix3& target) : frame_(frame), target_(target) {}
  std::string kind() const override { return "orientation_angle"; }
  TaskQuantity reads() const override { return TaskQuantity::Orientation; }
  int dimension() const override { return 1; }
  std::string componentName(int) const override { return "1 − cos(angle)"; }
  int frame() const override { return frame_; }

  void calc(const DynamicsModel& model, const DynamicsData& data, TaskWorkspace&,
            Eigen::Ref<Eigen::VectorXd> value) const override {
    value[0] = oneMinusCosine(framePose(model, data, frame_).rotation);
  }
  void calcDiff(const DynamicsModel& model, const DynamicsData& data, TaskWorkspace& w, Eigen::Ref<Eigen::VectorXd> value,
                Eigen::Ref<Eigen::MatrixXd> dq, Eigen::Ref<Eigen::MatrixXd> dv) const override {
    const RigidTransform pose = framePose(model, data, frame_);
    value[0] = oneMinusCosine(pose.rotation);
    frameJacobian(model, data, model.framePosition(frame_), pose.translation, w.jacobian);
    const Vector3 g = antisymmetricPart(pose.rotation * target_.transpose());
    dq.noalias() = g.transpose() * w.jacobian.bottomRows<3>();
    dv.setZero();
  }

 private:
  double oneMinusCosine(const Matrix3& rotation) const {
    return 0.5 * (3.0 - (target_.transpose() * rotation).trace());
  }
  int frame_;
  Matrix3 target_;
};

}  // namespace

std::shared_ptr<const Task> makeOrientationAngleTask(int frame, const Matrix3& target) {
  return std::make_shared<OrientationAngleTask>(frame, target);
}

ReadTask readOrientationAngleTask(const TaskFields& fields) {
  const Matrix3 target = readTargetRotation(fields);
  if (!fields.has("tolerance")) fields.fail("tolerance", "missing required field (the angle [rad])");
  const double tolerance = fields.number("tolerance");
  // At 0 the row's bound would sit at its minimum, where its gradient vanishes; from π on it
  // bounds nothing.
  if (!(tolerance > 0.0 && tolerance < kPi))
    fields.fail("tolerance", "expected an angle in (0, π) rad");
  ReadTask out;
  out.task = makeOrientationAngleTask(fields.body("body"), target);
  out.lower.setConstant(1, -std::numeric_limits<double>::infinity());
  out.upper.setConstant(1, 1.0 - std::cos(tolerance));
  return out;
}

}  // namespace mcopt
