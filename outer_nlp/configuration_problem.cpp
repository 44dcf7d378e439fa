// SPDX-License-Identifier: BSD-3-Clause
#include "outer_nlp/configuration_problem.hpp"

#include <cmath>

namespace mcopt {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace

ConfigurationProblem::ConfigurationProblem(const Scenario& scenario, const DynamicsModel& model,
                                           const ContactAdmissibilityRows& support, double instant,
                                           std::optional<Eigen::VectorXd> near)
    : scenario_(scenario),
      model_(model),
      support_(support),
      near_(std::move(near)),
      jointCount_(model.jointCount()),
      data_(model),
      derivatives_(model),
      taskWorkspace_(model),
      zero_(Eigen::VectorXd::Zero(model.jointCount())),
      taskValue_(kMaxTaskDimension),
      taskDq_(kMaxTaskDimension, model.jointCount()),
      taskDv_(kMaxTaskDimension, model.jointCount()) {
  if (scenario.contactConstraints && !near_) {
    supportRows_ = support.rowCount();
    for (int c = 0; c < support.rowCount(); ++c) rowTask_.push_back(-1), rowComponent_.push_back(c);
  }
  for (std::size_t t = 0; t < scenario.tasks.size(); ++t) {
    const TaskSpec& task = scenario.tasks[t];
    if (task.task->readsVelocity()) continue;
    if (instant < task.start - 1e-9 || instant > task.end + 1e-9) continue;
    tasks_.push_back(static_cast<int>(t));
    for (int c = 0; c < task.dimension(); ++c)
      if (std::isfinite(task.lower[c]) || std::isfinite(task.upper[c]))
        rowTask_.push_back(static_cast<int>(t)), rowComponent_.push_back(c);
  }
  const int rows = constraintCount();
  jacobianRows_.resize(rows * jointCount_);
  jacobianColumns_.resize(rows * jointCount_);
  for (int r = 0; r < rows; ++r)
    for (int j = 0; j < jointCount_; ++j) jacobianRows_[r * jointCount_ + j] = r, jacobianColumns_[r * jointCount_ + j] = j;
  rows_.setZero(rows);
  rowsByQ_.setZero(rows, jointCount_);
  rowsByWrench_.setZero(support.rowCount(), 6);
}

void ConfigurationProblem::variableBounds(Eigen::VectorXd& lower, Eigen::VectorXd& upper) const {
  lower.setConstant(jointCount_, -kInf);
  upper.setConstant(jointCount_, kInf);
  if (!scenario_.positionLimits) return;
  for (int j = 0; j < jointCount_; ++j) {
    lower[j] = scenario_.robot.joints[static_cast<std::size_t>(j)].limits.lower;
    upper[j] = scenario_.robot.joints[static_cast<std::size_t>(j)].limits.upper;
  }
}

void ConfigurationProblem::constraintBounds(Eigen::VectorXd& lower, Eigen::VectorXd& upper) const {
  lower.resize(constraintCount());
  upper.resize(constraintCount());
  for (int r = 0; r < constraintCount(); ++r) {
    const int t = rowTask_[static_cast<std::size_t>(r)], c = rowComponent_[static_cast<std::size_t>(r)];
    if (t < 0) {
      lower[r] = c == 0 ? scenario_.minimumNormalForce : 0.0;
      upper[r] = kInf;
    } else {
      lower[r] = scenario_.tasks[static_cast<std::size_t>(t)].lower[c];
      upper[r] = scenario_.tasks[static_cast<std::size_t>(t)].upper[c];
    }
  }
}

void ConfigurationProblem::evaluate(const Eigen::VectorXd& q) {
  if (cacheValid_ && q == cachedQ_) return;
  inverseDynamicsDerivatives(model_, data_, derivatives_, q, zero_, zero_);
  int row = 0;
  if (supportRows_ > 0) {
    row = supportRows_;
    support_.evaluate(data_.referenceWrench, rows_.head(row), rowsByWrench_);
    rowsByQ_.topRows(row).noalias() = rowsByWrench_ * derivatives_.dwrenchDq;
  }
  for (const int t : tasks_) {
    const TaskSpec& task = scenario_.tasks[static_cast<std::size_t>(t)];
    const int d = task.dimension();
    task.task->calcDiff(model_, data_, taskWorkspace_, taskValue_.head(d), taskDq_.topRows(d), taskDv_.topRows(d));
    for (int c = 0; c < d; ++c)
      if (std::isfinite(task.lower[c]) || std::isfinite(task.upper[c])) {
        rows_[row] = taskValue_[c];
        rowsByQ_.row(row) = taskDq_.row(c);
        ++row;
      }
  }
  cachedQ_ = q;
  cacheValid_ = true;
}

double ConfigurationProblem::objective(const Eigen::VectorXd& q) {
  if (near_) return 0.5 * (q - *near_).squaredNorm();
  return staticPower(q);
}

double ConfigurationProblem::staticPower(const Eigen::VectorXd& q) {
  evaluate(q);
  double power = 0.0;
  for (int j = 0; j < jointCount_; ++j) {
    const ActuatorParameters& a = scenario_.actuators.joints[static_cast<std::size_t>(j)];
    const double winding = std::max(std::abs(data_.tau[j] / a.gearRatio) - a.dryFriction, 0.0);
    power += a.resistance / (a.torqueConstant * a.torqueConstant) * winding * winding;
  }
  return power;
}

void ConfigurationProblem::objectiveGradient(const Eigen::VectorXd& q, Eigen::VectorXd& gradient) {
  if (near_) {
    gradient = q - *near_;
    return;
  }
  evaluate(q);
  Eigen::VectorXd byTorque(jointCount_);
  for (int j = 0; j < jointCount_; ++j) {
    const ActuatorParameters& a = scenario_.actuators.joints[static_cast<std::size_t>(j)];
    const double motor = data_.tau[j] / a.gearRatio;
    const double winding = std::max(std::abs(motor) - a.dryFriction, 0.0);
    byTorque[j] = 2.0 * a.resistance / (a.torqueConstant * a.torqueConstant) * winding * (motor < 0 ? -1.0 : 1.0) /
                  a.gearRatio;
  }
  gradient.noalias() = derivatives_.dtauDq.transpose() * byTorque;
}

void ConfigurationProblem::constraints(const Eigen::VectorXd& q, Eigen::VectorXd& values) {
  evaluate(q);
  values = rows_;
}

void ConfigurationProblem::jacobianValues(const Eigen::VectorXd& q, Eigen::VectorXd& values) {
  evaluate(q);
  values.resize(constraintCount() * jointCount_);
  for (int r = 0; r < constraintCount(); ++r) values.segment(r * jointCount_, jointCount_) = rowsByQ_.row(r).transpose();
}

std::string ConfigurationProblem::rowName(int row) const {
  const int t = rowTask_[static_cast<std::size_t>(row)], c = rowComponent_[static_cast<std::size_t>(row)];
  if (t < 0) return scenario_.support.name + " " + support_.rowName(c);
  const TaskSpec& task = scenario_.tasks[static_cast<std::size_t>(t)];
  return "task '" + task.name + "' component " + task.task->componentName(c);
}

}  // namespace mcopt
