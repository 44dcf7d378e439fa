// SPDX-License-Identifier: BSD-3-Clause
// `center_of_mass`: the robot's centre of mass c, world frame; ∂c/∂q = J_com.
#include "outer_nlp/task.hpp"

namespace mcopt {

namespace {

class CenterOfMassTask final : public Task {
 public:
  std::string kind() const override { return "center_of_mass"; }
  TaskQuantity reads() const override { return TaskQuantity::CenterOfMass; }

  void calc(const DynamicsModel& model, const DynamicsData& data, TaskWorkspace&,
            Eigen::Ref<Eigen::VectorXd> value) const override {
    value = centerOfMass(model, data);
  }
  void calcDiff(const DynamicsModel& model, const DynamicsData& data, TaskWorkspace& w, Eigen::Ref<Eigen::VectorXd> value,
                Eigen::Ref<Eigen::MatrixXd> dq, Eigen::Ref<Eigen::MatrixXd> dv) const override {
    value = centerOfMass(model, data);
    centerOfMassJacobian(model, data, w.comJacobian);
    dq = w.comJacobian;
    dv.setZero();
  }
};

}  // namespace

std::shared_ptr<const Task> makeCenterOfMassTask() { return std::make_shared<CenterOfMassTask>(); }

ReadTask readCenterOfMassTask(const TaskFields& fields) {
  ReadTask out;
  out.task = makeCenterOfMassTask();
  readTargetOrBounds(fields, 3, out);
  return out;
}

}  // namespace mcopt
