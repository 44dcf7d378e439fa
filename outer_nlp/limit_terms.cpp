// SPDX-License-Identifier: BSD-3-Clause
// The joints' limits as constraint terms (constraint_term.hpp; formulation.md §3, §10):
//   velocity_limit       on the velocity spline's control points 3 (p_{k+1} − p_k) / (T Δu),
//                        which bound the whole continuous motion (position limits are variable
//                        bounds: every control point is a free parameter);
//   torque_limit         Γ_js ∈ [−L_j, L_j] at each sample (rows screened out are left out);
//   closing_joint_limit  the position and velocity limits of a joint that closes a contact, at
//                        the samples where it follows the closure instead of its spline.
#include <cmath>
#include <ostream>

#include "core/bspline.hpp"
#include "outer_nlp/constraint_term.hpp"
#include "outer_nlp/scenario.hpp"

namespace mcopt {

namespace {

constexpr ConstraintKindInfo kVelocityLimit{"velocity_limit", "rad/s"};
constexpr ConstraintKindInfo kTorqueLimit{"torque_limit", "N m"};
constexpr ConstraintKindInfo kClosingJointLimit{"closing_joint_limit", "rad, rad/s"};

const std::string& jointName(const Scenario& scenario, int joint) {
  return scenario.robot.joints[static_cast<std::size_t>(joint)].name;
}

class VelocityLimitTerm final : public ConstraintTerm {
 public:
  explicit VelocityLimitTerm(const TermContext& c) : scenario_(c.scenario) {
    const MotionParametrization& p = c.parametrization;
    const auto& knots = p.basis().knots();
    const int m = p.parametersPerJoint();
    for (int j = 0; j < scenario_.robot.jointCount() && scenario_.velocityLimits; ++j) {
      if (!std::isfinite(scenario_.actuators.joints[static_cast<std::size_t>(j)].velocityLimit)) continue;
      // A whole-motion contact's closing joint: its limit is a row at every sample (a window's
      // keeps its spline's rows for the instants outside it, and rows at the samples inside).
      if (c.closure && c.closure->closes(j) && c.closure->wholeMotion(c.closure->contactOf(j))) continue;
      for (int k = 0; k + 1 < p.controlPointCount(); ++k) {
        const int first = p.parameterOfControlPoint(k), second = p.parameterOfControlPoint(k + 1);
        if (first == second) continue;  // the clamped ends: identically zero
        rows_.push_back({j, j * m + first, j * m + second,
                         3.0 / (knots[static_cast<std::size_t>(k) + 4] - knots[static_cast<std::size_t>(k) + 1])});
      }
    }
  }
  RowPlace place() const override { return RowPlace::ControlPoints; }
  std::vector<ConstraintKindInfo> kinds() const override { return {kVelocityLimit}; }
  const ConstraintKindInfo& kind(int, int) const override { return kVelocityLimit; }
  void appendRows(RowSink& sink) const override {
    for (std::size_t v = 0; v < rows_.size(); ++v) sink.directRow(static_cast<int>(v), rows_[v].first, rows_[v].second);
  }
  void bounds(int detail, int, double& lower, double& upper) const override {
    const double limit = scenario_.actuators.joints[static_cast<std::size_t>(row(detail).joint)].velocityLimit;
    lower = -limit, upper = limit;
  }
  void subject(int detail, int, std::ostream& name) const override {
    name << "velocity limit of " << jointName(scenario_, row(detail).joint);
  }
  double directValue(int detail, const Eigen::VectorXd& x, double T) const override {
    const Row& v = row(detail);
    return v.scale * (x[v.second] - x[v.first]) / T;
  }
  double directDerivative(int detail, int k, const Eigen::VectorXd& x, double T) const override {
    const Row& v = row(detail);
    switch (k) {
      case 0: return -v.scale / T;
      case 1: return v.scale / T;
      default: return -v.scale * (x[v.second] - x[v.first]) / (T * T);
    }
  }
  // λ scale (x_second − x_first) / T adds ∓λ scale / T² and 2 λ scale (x_second − x_first) / T³.
  void addDirectHessian(int detail, double multiplier, const Eigen::VectorXd& x, double T, int column,
                        Eigen::MatrixXd& hessian) const override {
    const Row& v = row(detail);
    const double lambda = multiplier * v.scale;
    for (const auto& [variable, sign] : {std::pair{v.second, -1.0}, std::pair{v.first, 1.0}}) {
      hessian(column, variable) += sign * lambda / (T * T);
      hessian(variable, column) += sign * lambda / (T * T);
    }
    hessian(column, column) += 2.0 * lambda * (x[v.second] - x[v.first]) / (T * T * T);
  }

 private:
  /// 3 (x_second − x_first) / (T Δu): scale = 3 / Δu.
  struct Row {
    int joint, first, second;
    double scale;
  };
  const Row& row(int detail) const { return rows_[static_cast<std::size_t>(detail)]; }
  const Scenario& scenario_;
  std::vector<Row> rows_;
};

class TorqueLimitTerm final : public SampleTermOfOneKind {
 public:
  explicit TorqueLimitTerm(const TermContext& c) : SampleTermOfOneKind(kTorqueLimit), c_(c) {}
  void appendRows(RowSink& sink) const override {
    const int n = c_.outputs.joints, s = sink.block();
    for (const int j : c_.torqueJoints)
      if (c_.omittedTorqueRows.empty() || !c_.omittedTorqueRows[static_cast<std::size_t>(s * n + j)])
        sink.outputRow(j, c_.outputs.torque(j), c_.relatedJoints[static_cast<std::size_t>(j)], true);
  }
  void bounds(int joint, int, double& lower, double& upper) const override {
    const double limit = c_.scenario.actuators.joints[static_cast<std::size_t>(joint)].torqueLimit;
    lower = -limit, upper = limit;
  }
  void subject(int joint, int, std::ostream& name) const override {
    name << "torque limit of " << jointName(c_.scenario, joint);
  }

 private:
  TermContext c_;
};

/// detail k < closing: closing joint k's position; closing + k: its velocity.
class ClosingJointLimitTerm final : public SampleTermOfOneKind {
 public:
  explicit ClosingJointLimitTerm(const TermContext& c) : SampleTermOfOneKind(kClosingJointLimit), c_(c) {}
  void appendRows(RowSink& sink) const override {
    const int closing = c_.outputs.closing;
    const auto omitted = [&](int detail) {
      return !c_.omittedClosingRows.empty() &&
             c_.omittedClosingRows[static_cast<std::size_t>(sink.block() * 2 * closing + detail)];
    };
    for (int k = 0; k < closing; ++k) {
      const int joint = c_.closure->closingJoints()[static_cast<std::size_t>(k)];
      if (!c_.closure->closesIn(joint, sink.closed())) continue;  // a spline here: its control points' bounds
      if (c_.scenario.positionLimits && !omitted(k)) sink.outputRow(k, c_.outputs.closingPosition(k), c_.allJoints, false);
      if (c_.scenario.velocityLimits && std::isfinite(c_.scenario.actuators.joints[static_cast<std::size_t>(joint)].velocityLimit) &&
          !omitted(closing + k))
        sink.outputRow(closing + k, c_.outputs.closingVelocity(k), c_.allJoints, false);
    }
  }
  void bounds(int detail, int, double& lower, double& upper) const override {
    const int joint = jointOf(detail);
    if (detail < c_.outputs.closing) {
      const JointLimits& limit = c_.scenario.robot.joints[static_cast<std::size_t>(joint)].limits;
      lower = limit.lower, upper = limit.upper;
    } else {
      const double limit = c_.scenario.actuators.joints[static_cast<std::size_t>(joint)].velocityLimit;
      lower = -limit, upper = limit;
    }
  }
  void subject(int detail, int, std::ostream& name) const override {
    const int joint = jointOf(detail);
    name << (detail < c_.outputs.closing ? "position" : "velocity") << " limit of " << jointName(c_.scenario, joint)
         << " (closing " << c_.closure->contacts()[static_cast<std::size_t>(c_.closure->contactOf(joint))].name << ")";
  }

 private:
  int jointOf(int detail) const { return c_.closure->closingJoints()[static_cast<std::size_t>(detail % c_.outputs.closing)]; }
  TermContext c_;
};

}  // namespace

std::unique_ptr<const ConstraintTerm> makeVelocityLimitTerm(const TermContext& context) {
  return std::make_unique<VelocityLimitTerm>(context);
}
std::unique_ptr<const ConstraintTerm> makeTorqueLimitTerm(const TermContext& context) {
  return std::make_unique<TorqueLimitTerm>(context);
}
std::unique_ptr<const ConstraintTerm> makeClosingJointLimitTerm(const TermContext& context) {
  return std::make_unique<ClosingJointLimitTerm>(context);
}

}  // namespace mcopt
