#pragma once
// The outer motion problem of one scenario as a plain NLP (formulation.md §10), independent
// of Ipopt so that tests can probe it: variables, bounds, objective, constraints, their
// exact gradient and sparse Jacobian.
//
// Variables x = [free spline parameters (joint-major), T when free, epigraph slacks s_js].
// Constraint rows, in this order:
//   1. velocity limits on the velocity control points 3 (p_{k+1} − p_k) / (T Δu) (§3:
//      they bound the whole continuous motion); position limits are variable bounds,
//      since every control point is a free parameter;
//   2. per sample s: torque limits Γ0_js ∈ [−L_j, L_j]; the reference sole's wrench W0 in
//      its contact frame: f_z ≥ f_min, (μ² f_z² − f_x² − f_y²)/(m g)² ≥ 0, centre of
//      pressure in the rectangle written linearly (x_min f_z ≤ −m_y ≤ x_max f_z,
//      y_min f_z ≤ m_x ≤ y_max f_z); with the epigraph form s_js − P_js ≥ 0;
//   3. task rows: per task, per instant, per bounded component.
// Sample rows depend only on the ≤ 4 local parameters of every joint (+ T, + a slack),
// which is the declared sparsity (B-spline local support).
//
// Objective: E = Σ_s c_s Δt Σ_j P⁺_js, Δt = T/(N − 1), trapezoid weights c_s, with P⁺
// the smooth maximum (P + sqrt(P² + ε²))/2 or the epigraph slack (formulation.md §6), plus
// the scenario's regularisation w Σ_s c_s Δt Σ_j q̈_js² (formulation.md §10; 0 by default).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/bspline.hpp"
#include "core/dynamics_derivatives.hpp"
#include "core/dynamics_model.hpp"
#include "outer_nlp/nlp_problem.hpp"
#include "outer_nlp/scenario.hpp"
#include "outer_nlp/support_contact.hpp"
#include "outer_nlp/task_kinematics.hpp"

namespace mcopt {

enum class ConstraintKind { VelocityLimit, TorqueLimit, ContactUnilateral, ContactFriction, ContactCop, Task, Epigraph };
inline constexpr int kConstraintKindCount = 7;
const char* constraintKindName(ConstraintKind kind);

class MotionProblem final : public NlpProblem {
 public:
  explicit MotionProblem(const Scenario& scenario);
  const SupportContactRows& support() const { return support_; }

  const Scenario& scenario() const { return scenario_; }
  const DynamicsModel& model() const { return model_; }
  const MotionParametrization& parametrization() const { return parametrization_; }
  const SampledTrajectory& samples() const { return samples_; }
  bool durationIsFree() const { return scenario_.duration.free(); }

  int variableCount() const override { return variableCount_; }
  int nonlinearVariableCount() const override { return slackStart_; }
  int constraintCount() const override { return static_cast<int>(rowKind_.size()); }
  int jacobianNonZeros() const { return static_cast<int>(jacobianRows_.size()); }
  const Eigen::VectorXi& jacobianRows() const override { return jacobianRows_; }
  const Eigen::VectorXi& jacobianColumns() const override { return jacobianColumns_; }
  ConstraintKind rowKind(int row) const { return rowKind_[static_cast<std::size_t>(row)]; }
  /// e.g. "torque limit LLEG_JOINT3 at t = 0.512 s".
  std::string rowName(int row) const override;

  void variableBounds(Eigen::VectorXd& lower, Eigen::VectorXd& upper) const override;
  void constraintBounds(Eigen::VectorXd& lower, Eigen::VectorXd& upper) const override;

  /// The motion from `start` to `end` (inner control points spaced linearly), the initial
  /// duration, and epigraph slacks at max(P, 0) of that motion.
  Eigen::VectorXd initialPoint(const Eigen::VectorXd& start, const Eigen::VectorXd& end);
  Eigen::VectorXd motionParameters(const Eigen::VectorXd& x) const { return x.head(parameterCount_); }
  double duration(const Eigen::VectorXd& x) const {
    return durationIsFree() ? x[parameterCount_] : scenario_.duration.initial;
  }

  double objective(const Eigen::VectorXd& x) override;
  void objectiveGradient(const Eigen::VectorXd& x, Eigen::VectorXd& gradient) override;
  void constraints(const Eigen::VectorXd& x, Eigen::VectorXd& values) override;
  void jacobianValues(const Eigen::VectorXd& x, Eigen::VectorXd& values) override;

  /// Largest violation of constraint rows and variable bounds, overall and per kind
  /// (variable bounds count as "position limit").
  struct Violations {
    double overall = 0.0, positionLimit = 0.0;
    std::array<double, kConstraintKindCount> byKind{};
    int worstRow = -1;  ///< -1 when a variable bound is the worst
  };
  Violations violations(const Eigen::VectorXd& x);

 private:
  struct SampleBlock {
    Eigen::VectorXd y;        ///< [Γ0 (n), contact rows (6), power (n)]
    Eigen::VectorXd acceleration;  ///< q̈ (n), for the regularisation
    Eigen::MatrixXd dyDx;     ///< rows × local parameters
    Eigen::VectorXd dyDT;
    Eigen::VectorXi parameters;
    Eigen::MatrixXd dyDq, dyDv, dyDa;
  };
  struct ThreadWorkspace {
    explicit ThreadWorkspace(const DynamicsModel& model) : data(model), derivatives(model), task(model) {}
    DynamicsData data;
    DynamicsDerivatives derivatives;
    TaskWorkspace task;
    Eigen::VectorXd q, v, a;
  };
  void evaluate(const Eigen::VectorXd& x, bool derivatives);
  void evaluateSample(int s, double duration, bool derivatives, ThreadWorkspace& w);
  void evaluateTaskInstant(int i, double duration, bool derivatives, ThreadWorkspace& w);
  void buildStructure();

  const Scenario& scenario_;
  DynamicsModel model_;
  MotionParametrization parametrization_;
  SampledTrajectory samples_;
  std::vector<int> taskOfInstant_;        ///< task index of each task instant
  SampledTrajectory taskSamples_;         ///< the task instants, as normalised times
  int jointCount_ = 0, parameterCount_ = 0, variableCount_ = 0, slackStart_ = 0;
  std::vector<int> torqueJoints_;         ///< joints with a finite torque limit
  std::vector<int> allJoints_;
  std::vector<std::vector<int>> relatedJoints_;  ///< joints whose motion changes Γ_i: i's ancestors and descendants
  std::vector<std::vector<int>> taskJoints_;     ///< per task instant: joints that move the task's body
  struct VelocityRow { int joint, first, second; double scale; };  ///< 3 (x_second − x_first)/(T Δu) → scale = 3/Δu
  std::vector<VelocityRow> velocityRows_;
  SupportContactRows support_;

  std::vector<ConstraintKind> rowKind_;
  std::vector<int> rowDetail_;            ///< joint, task component or contact row index
  std::vector<int> rowSample_;            ///< sample or task instant (−1 for velocity rows)
  Eigen::VectorXi jacobianRows_, jacobianColumns_;
  int contactRowCount_ = 0;

  std::vector<SampleBlock> blocks_, taskBlocks_;
  std::vector<ThreadWorkspace> workspaces_;
  Eigen::MatrixXd controlPoints_;
  Eigen::VectorXd cachedX_;
  bool cachedDerivatives_ = false, cacheValid_ = false;
};

}  // namespace mcopt
