// SPDX-License-Identifier: BSD-3-Clause
#include "outer_nlp/standing_posture.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "core/dynamics_data.hpp"
#include "core/dynamics_model.hpp"
#include "core/errors.hpp"
#include "core/inverse_dynamics.hpp"
#include "core/kinematics.hpp"
#include "outer_nlp/nlp_problem.hpp"

namespace mcopt {

namespace {

constexpr int kRows = 11;
constexpr const char* kRowNames[kRows] = {
    "second sole x", "second sole y", "second sole z", "second sole normal x", "second sole normal y",
    "second sole yaw", "centre of mass x", "centre of mass y", "root height", "root upright x", "root upright y"};

/// The rows, in the first sole's frame (the model's world): the second sole's origin against
/// its zero-posture place beside the first, its normal against the vertical, its x axis against
/// the first's; the centre of mass against the soles' middle; the root's height and its up
/// direction against the vertical.
class StandingProblem final : public NlpProblem {
 public:
  StandingProblem(const DynamicsModel& model, const ContactSurface& second, const Vector3& secondTarget,
                  const Eigen::Vector2d& comTarget, double rootHeight, const Vector3& rootUp, Eigen::VectorXd q0)
      : model_(model),
        second_(second),
        secondTarget_(secondTarget),
        comTarget_(comTarget),
        rootHeight_(rootHeight),
        rootUp_(rootUp),
        q0_(std::move(q0)),
        n_(model.jointCount()),
        data_(model),
        jacobian_(6, model.jointCount()),
        comJacobian_(3, model.jointCount()) {
    jacobianRows_.resize(kRows * n_);
    jacobianColumns_.resize(kRows * n_);
    for (int r = 0; r < kRows; ++r)
      for (int j = 0; j < n_; ++j) jacobianRows_[r * n_ + j] = r, jacobianColumns_[r * n_ + j] = j;
    const RobotModel& robot = model.robot();
    rootFrame_ = robot.findFrame(robot.bodies.front().name);
  }

  int variableCount() const override { return n_; }
  int constraintCount() const override { return kRows; }
  const Eigen::VectorXi& jacobianRows() const override { return jacobianRows_; }
  const Eigen::VectorXi& jacobianColumns() const override { return jacobianColumns_; }
  void variableBounds(Eigen::VectorXd& lower, Eigen::VectorXd& upper) const override {
    lower.resize(n_), upper.resize(n_);
    for (int j = 0; j < n_; ++j) {
      const Joint& joint = model_.robot().joints[static_cast<std::size_t>(j)];
      lower[j] = std::isfinite(joint.limits.lower) ? joint.limits.lower : -std::numbers::pi;
      upper[j] = std::isfinite(joint.limits.upper) ? joint.limits.upper : std::numbers::pi;
    }
  }
  void constraintBounds(Eigen::VectorXd& lower, Eigen::VectorXd& upper) const override {
    lower.setZero(kRows), upper.setZero(kRows);
  }
  double objective(const Eigen::VectorXd& q) override { return 0.5 * (q - q0_).squaredNorm(); }
  void objectiveGradient(const Eigen::VectorXd& q, Eigen::VectorXd& gradient) override { gradient = q - q0_; }
  void constraints(const Eigen::VectorXd& q, Eigen::VectorXd& values) override {
    evaluate(q, false);
    values = rows_;
  }
  void jacobianValues(const Eigen::VectorXd& q, Eigen::VectorXd& values) override {
    evaluate(q, true);
    values.resize(kRows * n_);
    for (int r = 0; r < kRows; ++r) values.segment(r * n_, n_) = rowsByQ_.row(r).transpose();
  }
  std::string rowName(int row) const override { return kRowNames[row]; }

  /// Rows at q (and their derivatives when `derivatives`).
  void evaluate(const Eigen::VectorXd& q, bool derivatives) {
    forwardKinematics(model_, data_, q);
    rows_.resize(kRows);
    const RigidTransform sole = framePose(model_, data_, second_.frame) * second_.placement;
    const RigidTransform root = framePose(model_, data_, rootFrame_);
    const Vector3 com = centerOfMass(model_, data_);
    const Vector3 normal = sole.rotation.col(2), axis = sole.rotation.col(0), up = root.rotation * rootUp_;
    rows_.head<3>() = sole.translation - secondTarget_;
    rows_[3] = normal.x(), rows_[4] = normal.y(), rows_[5] = axis.y();
    rows_.segment<2>(6) = com.head<2>() - comTarget_;
    rows_[8] = root.translation.z() - rootHeight_;
    rows_[9] = up.x(), rows_[10] = up.y();
    if (!derivatives) return;
    rowsByQ_.setZero(kRows, n_);
    // d(R v)/dq = ω × (R v): component i is (R v × e_i) · J_ω.
    frameJacobian(model_, data_, model_.framePosition(second_.frame), sole.translation, jacobian_);
    rowsByQ_.topRows<3>() = jacobian_.topRows<3>();
    const auto angular = jacobian_.bottomRows<3>();
    rowsByQ_.row(3) = normal.cross(Vector3::UnitX()).transpose() * angular;
    rowsByQ_.row(4) = normal.cross(Vector3::UnitY()).transpose() * angular;
    rowsByQ_.row(5) = axis.cross(Vector3::UnitY()).transpose() * angular;
    centerOfMassJacobian(model_, data_, comJacobian_);
    rowsByQ_.middleRows<2>(6) = comJacobian_.topRows<2>();
    frameJacobian(model_, data_, model_.framePosition(rootFrame_), root.translation, jacobian_);
    rowsByQ_.row(8) = jacobian_.row(2);
    rowsByQ_.row(9) = up.cross(Vector3::UnitX()).transpose() * jacobian_.bottomRows<3>();
    rowsByQ_.row(10) = up.cross(Vector3::UnitY()).transpose() * jacobian_.bottomRows<3>();
  }

  const Eigen::VectorXd& rows() const { return rows_; }
  Vector3 centerOfMassAt() const { return centerOfMass(model_, data_); }
  Vector3 secondSoleAt() const { return (framePose(model_, data_, second_.frame) * second_.placement).translation; }
  double rootHeightAt() const { return framePose(model_, data_, rootFrame_).translation.z(); }

 private:
  const DynamicsModel& model_;
  ContactSurface second_;
  Vector3 secondTarget_;
  Eigen::Vector2d comTarget_;
  double rootHeight_;
  Vector3 rootUp_;
  Eigen::VectorXd q0_;
  int n_;
  int rootFrame_ = 0;
  DynamicsData data_;
  FrameJacobian jacobian_;
  Eigen::Matrix3Xd comJacobian_;
  Eigen::VectorXd rows_;
  Eigen::MatrixXd rowsByQ_;
  Eigen::VectorXi jacobianRows_, jacobianColumns_;
};

std::string centimetres(double metres) {
  std::ostringstream s;
  s.precision(3);
  s << 100.0 * metres << " cm";
  return s.str();
}

}  // namespace

StandingPosture findStandingPosture(const RobotModel& robot, const ContactSurface& first, const ContactSurface& second,
                                    const StandingPostureSettings& settings) {
  // The model rooted at the first sole: its contact frame at the world origin.
  const DynamicsModel model(robot, robot.frames[static_cast<std::size_t>(first.frame)].name, first.placement.inverse());
  const int n = model.jointCount();

  // The zero posture, inside the limits.
  Eigen::VectorXd q0 = Eigen::VectorXd::Zero(n);
  for (int j = 0; j < n; ++j) {
    const JointLimits& l = robot.joints[static_cast<std::size_t>(j)].limits;
    q0[j] = std::clamp(0.0, std::isfinite(l.lower) ? l.lower : -1e9, std::isfinite(l.upper) ? l.upper : 1e9);
  }
  DynamicsData data(model);
  forwardKinematics(model, data, q0);
  const RigidTransform sole = framePose(model, data, second.frame) * second.placement;
  const std::string names = "'" + first.name + "' and '" + second.name + "'";
  if (sole.rotation(2, 2) < std::cos(0.05))
    throw InputError(robot.source + ": the soles " + names + " are not parallel at the zero posture (tilted " +
                     std::to_string(std::acos(std::clamp(sole.rotation(2, 2), -1.0, 1.0))) + " rad): cannot stand on both");
  if (std::abs(sole.translation.z()) > 0.02)
    throw InputError(robot.source + ": the sole " + second.name + " is " + centimetres(sole.translation.z()) + " above " +
                     first.name + " at the zero posture: not on one ground");
  const int rootFrame = robot.findFrame(robot.bodies.front().name);
  const RigidTransform root = framePose(model, data, rootFrame);
  if (root.translation.z() < 0.1)
    throw InputError(robot.source + ": the root body " + robot.bodies.front().name + " is " +
                     centimetres(root.translation.z()) + " above the sole " + first.name +
                     " at the zero posture: the soles are not under the robot");

  // Side by side as at the zero posture, no yaw; the centre of mass above the rectangles' middle.
  const Vector3 secondTarget(0.0, sole.translation.y(), 0.0);
  const Eigen::Vector2d firstCentre(0.5 * (first.xMin + first.xMax), 0.5 * (first.yMin + first.yMax));
  const Eigen::Vector2d secondCentre =
      secondTarget.head<2>() + Eigen::Vector2d(0.5 * (second.xMin + second.xMax), 0.5 * (second.yMin + second.yMax));
  const Eigen::Vector2d comTarget = 0.5 * (firstCentre + secondCentre);
  const Vector3 rootUp = root.rotation.transpose() * Vector3::UnitZ();
  const double rootHeight = (1.0 - settings.rootLowering) * root.translation.z();

  StandingProblem problem(model, second, secondTarget, comTarget, rootHeight, rootUp, q0);
  // Start off the limits' edges and off a straight knee (no slope there): a joint whose range
  // reaches at least twice as far on one side of zero as on the other (a knee: flexion against
  // hyperextension) starts 0.2 rad to that side, the way it bends.
  Eigen::VectorXd lower, upper;
  problem.variableBounds(lower, upper);
  Eigen::VectorXd start = q0;
  for (int j = 0; j < n; ++j) {
    const double below = q0[j] - lower[j], above = upper[j] - q0[j];
    if (above >= 2.0 * below) start[j] += 0.2;
    else if (below >= 2.0 * above) start[j] -= 0.2;
    const double margin = std::min(0.2, 0.25 * (upper[j] - lower[j]));
    start[j] = std::clamp(start[j], lower[j] + margin, upper[j] - margin);
  }
  OuterSolverSettings solver;
  solver.problemHessian = true;
  solver.maxIterations = settings.maxIterations;
  solver.tolerance = 1e-8;
  solver.constraintTolerance = settings.tolerance;
  const OuterOutcome outcome = solveOuter(problem, start, solver, [](const IterationReport&) { return true; });

  StandingPosture result;
  result.status = outcome.status;
  result.iterations = outcome.iterations;
  result.q = outcome.x.size() == n && outcome.x.allFinite() ? outcome.x : start;
  problem.evaluate(result.q, false);
  Eigen::Index worst = 0;
  result.violation = problem.rows().cwiseAbs().maxCoeff(&worst);
  result.violatedRow = problem.rowName(static_cast<int>(worst));
  result.centerOfMass = problem.centerOfMassAt();
  result.secondSole = problem.secondSoleAt();
  result.rootHeight = problem.rootHeightAt();
  return result;
}

}  // namespace mcopt
