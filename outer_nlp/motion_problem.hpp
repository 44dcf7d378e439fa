// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The outer motion problem of one scenario as a plain NLP (formulation.md §10), independent
// of Ipopt so that tests can probe it: variables, bounds, objective, constraints, their
// exact gradient and sparse Jacobian.
//
// Variables x = [free spline parameters (joint-major), T when free, contact-force variables z
// (splines / variables formulations), epigraph slacks s_js].
//
// Contacts (formulation.md §5, §9): the reference body's surface carries the robot at every
// instant; every other contact (scenario `contacts`) is fixed in the world over its window.
// Its wrench comes from the scenario's contact-force formulation (contact_force_formulation.hpp):
//   bilevel    an inner problem per sample over the contacts active there picks them
//              (sensitivity/bilevel_sample.hpp); exact gradients through its KKT system;
//   splines / variables   they are linear in z (contact_force_parametrization.hpp) and the
//              reference contact's wrench follows from the balance,
//              W_ref = W0 − Σ_i wrenchToWorld_i F_i, so the balance holds exactly.
// With the reference contact alone, the three are the one-contact problem: W_ref = W0.
//
// Constraint rows, each described once in the row registry (kind, sample or task instant,
// which output of that sample's evaluation) from which bounds, values, the Jacobian's
// pattern and its values are all read:
//   1. velocity limits on the velocity control points 3 (p_{k+1} − p_k) / (T Δu) (§3:
//      they bound the whole continuous motion); position limits are variable bounds,
//      since every control point is a free parameter;
//   2. per sample s: torque limits Γ_js ∈ [−L_j, L_j] with Γ = Γ0 − Σ J1_i F_i; per contact
//      in contact there (splines, variables; the reference one always): f_z ≥ f_min,
//      (μ² f_z² − f_x² − f_y²)/(m g)² ≥ 0, the centre of pressure in the rectangle written
//      linearly; bilevel: the inner problem's infeasibility φ = ‖slack‖²/(m g)² ≤ 0 (the
//      inner problem holds the contacts' own rows); with the epigraph form s_js − P_js ≥ 0;
//   3. task rows: per task, per instant, per bounded component; at each end of a contact's
//      window inside the motion, its frame at its world pose and at rest (position,
//      orientation, linear and angular velocity: twelve equality rows), where the splines of its
//      closing joints meet the closure (each end is sampled twice, out of contact and in);
//   4. per sample, the position and velocity limits of the joints that close a contact active
//      there (closed_chains.hpp): those joints follow the closure, not splines.
// Every environment contact holds by construction: at every instant of its window (the whole
// motion, or its own) its loop's six closing joints are the closure's (closed_chains.hpp), and
// every output's derivative goes through them (the chain rule by the implicit function
// theorem); the spline parameters that reach no instant outside the window are fixed at the
// start posture and unused.
// Sample rows depend only on the ≤ 4 local parameters of the joints that move them (+ T,
// + the sample's force variables, + a slack), which is the declared sparsity.
//
// Objective: E = Σ_s c_s Δt Σ_j P⁺_js, Δt = T/(N − 1), trapezoid weights c_s, with P⁺
// the smooth maximum (P + sqrt(P² + ε²))/2 or the epigraph slack (formulation.md §6), plus
// the scenario's regularisation w Σ_s c_s Δt Σ_j q̈_js² (formulation.md §10; 0 by default).

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/bspline.hpp"
#include "core/dynamics_derivatives.hpp"
#include "core/dynamics_model.hpp"
#include "outer_nlp/closed_chains.hpp"
#include "outer_nlp/contact_force_parametrization.hpp"
#include "outer_nlp/derivative_stencil.hpp"
#include "outer_nlp/nlp_problem.hpp"
#include "outer_nlp/scenario.hpp"
#include "outer_nlp/constraint_term.hpp"
#include "outer_nlp/contact_admissibility.hpp"
#include "outer_nlp/cost_term.hpp"
#include "outer_nlp/sample_outputs.hpp"
#include "outer_nlp/task.hpp"

namespace mcopt {

class ContactForceFormulation;  // outer_nlp/contact_force_formulation.hpp
struct MotionWorkspace;  // outer_nlp/motion_workspace.hpp

/// A thrown ball at its release (formulation.md §10), from the motion's q, q̇ at t_r by
/// forward kinematics, and its flight to the target's height (ballistic_flight.hpp).
struct ReleaseState {
  double time = 0.0;                    ///< t_r [s]
  Vector3 position = Vector3::Zero(), velocity = Vector3::Zero();  ///< of the ball, world frame
  double flightTime = 0.0;              ///< τ [s] to the target's height
  Vector3 landing = Vector3::Zero();    ///< where the flight crosses the target's height
  double apexAboveTarget = 0.0;         ///< [m]; negative: the ball never reaches that height
  double speed = 0.0, elevation = 0.0;  ///< [m/s], [rad]
  Vector3 target = Vector3::Zero();     ///< the throw's target, world frame
  Eigen::Vector2d targetHalfWidths = Eigen::Vector2d::Zero();  ///< its box at its height (0: a point)
  double missDistance = 0.0;            ///< |landing − target| [m]
  double missOutsideBox = 0.0;          ///< distance from the landing point to the target's box [m] (0 inside)
  double elevationDegrees() const { return elevation * 180.0 / 3.14159265358979323846; }
};

/// Everything a motion's samples say, for results (apps serialise it; nothing is re-evaluated there).
struct SampledPhysics {
  Eigen::VectorXd time;                        ///< N [s]
  Eigen::MatrixXd q, v, a, tau, tau0, power;   ///< n × N; tau = Γ with the contact wrenches, tau0 = Γ0
  Eigen::MatrixXd referenceWrench;             ///< 6 × N, W0 at the reference frame origin, world axes
  /// Per contact (the reference one first, then the scenario's order): 6 × N wrenches in the
  /// contact frame, zero where the contact is not active; whether it is active; centre of
  /// pressure (NaN without load); friction-cone margin μ f_z − ‖f_t‖ [N].
  std::vector<std::string> contactNames;
  std::vector<Eigen::MatrixXd> wrenches;
  std::vector<std::vector<bool>> active;
  std::vector<Eigen::MatrixXd> centerOfPressure;  ///< 2 × N each
  std::vector<Eigen::VectorXd> frictionMargin;
  /// Per environment contact, on a fine grid (the output samples or 10 instants per sample
  /// interval, the finer) within its window: the worst distance [m] and angle [rad] of its frame
  /// from its world pose, and the fastest its frame slides [m/s] and turns [rad/s]. Zeros when
  /// sampledPhysics was asked to skip them (MotionProblem::ClosureDrift::Skipped).
  std::vector<double> closureDrift;
  std::vector<double> closureRotationDrift;
  std::vector<double> closureSpeed, closureAngularSpeed;
  std::vector<std::string> innerStatus;         ///< bilevel: per sample
  int infeasibleSamples = 0, failedSamples = 0;
  double energy = 0.0;                          ///< ∫ Σ max(P, 0) dt at the samples (trapezoid)
  /// The scenario's output samples: power per joint and energy. With the reference contact
  /// alone (Γ = Γ0 there); with more contacts the wrenches exist at the samples only, and
  /// these stay empty.
  Eigen::VectorXd fineTime;
  Eigen::MatrixXd finePower;
  double fineEnergy = std::numeric_limits<double>::quiet_NaN();
  /// With a throw: the release. The samples then hold t_r twice, loaded and released.
  std::optional<ReleaseState> release;
};

/// What a motion problem is built with besides the problem the scenario poses: the run's
/// choices (scenario_run.hpp, motion_solve.hpp), not the scenario's.
struct MotionProblemOptions {
  /// The Hessian model lagrangianHessian assembles (docs/theory/outer-problem.md, "Hessian
  /// options"); `exact` is refused where its stencils do not hold (exactHessianRefusal).
  HessianOption hessian = HessianOption::SampleDifferences;
  /// Empty, or one flag per joint and sample (index s · n + j): those torque-limit rows are
  /// left out of the NLP — torque-limit screening (formulation.md §10;
  /// docs/reference/scenario-file.md), where rows far from their bound are checked after the
  /// solve instead of weighing on every KKT factorisation.
  std::vector<bool> omittedTorqueRows{};
  /// Empty, or one flag per sample and closing_joint_limit detail (index s · 2c + k: closing
  /// joint k's position row for k < c, its velocity row for c ≤ k < 2c, c the closing joints):
  /// those rows are left out (`limits.closing_screening`).
  std::vector<bool> omittedClosingRows{};
  /// Whether the problem lays out its Jacobian (and can evaluate derivatives). Without it, only
  /// values: the objective, the rows, sampledPhysics, violations; a derivative asked for throws
  /// std::logic_error. For the fine grids of the energy balance and of `mcopt verify`
  /// (thousands of samples), whose Jacobian would take gigabytes and most of their time.
  bool derivatives = true;
};

class MotionProblem final : public NlpProblem {
 public:
  MotionProblem(const Scenario& scenario, MotionProblemOptions options);
  /// The problem with the scenario's own Hessian model (scenario.solve.hessian) and every
  /// torque-limit row.
  explicit MotionProblem(const Scenario& scenario);
  /// The problem keeps a reference to its scenario (rows, names and terms read it): a
  /// temporary would leave it dangling, so one does not compile.
  MotionProblem(Scenario&&, MotionProblemOptions) = delete;
  explicit MotionProblem(Scenario&&) = delete;
  /// The Hessian model it was built with.
  HessianOption hessianOption() const { return hessian_; }
  /// Per joint and sample (index s · n + j): whether |Γ_js| < fraction · its limit at x
  /// (joints without a finite limit: true). For torque-limit screening.
  std::vector<bool> torquesBelow(const Eigen::VectorXd& x, double fraction);
  int omittedTorqueRowCount() const;
  /// Per sample and closing_joint_limit detail (the index of omittedClosingRows): whether the
  /// closing joint's position is within fraction · its half-range of the range's middle, and
  /// its velocity below fraction · its limit, at x (true where the sample has no such row).
  std::vector<bool> closingLimitsBelow(const Eigen::VectorXd& x, double fraction);
  int omittedClosingRowCount() const;
  ~MotionProblem() override;
  const ContactAdmissibilityRows& support() const { return support_; }

  const Scenario& scenario() const { return scenario_; }
  const DynamicsModel& model() const { return model_; }
  const MotionParametrization& parametrization() const { return parametrization_; }
  const SampledTrajectory& samples() const { return samples_; }
  bool durationIsFree() const { return scenario_.duration.free(); }
  /// The formulation in use: with the reference contact alone there are no contact forces to choose.
  bool bilevel() const;
  int forceVariableCount() const;
  int forceVariableStart() const { return forceStart_; }
  /// Bilevel: the inner problems of the last evaluation (all zero otherwise).
  struct InnerStatistics {
    int optimal = 0, infeasible = 0, failed = 0;
    int polished = 0;             ///< answers polished on their active sets (inner.polish)
    double meanIterations = 0.0;  ///< inner solver iterations per sample
    double solveSeconds = 0.0;    ///< summed over the samples (threads overlap)
  };
  InnerStatistics innerStatistics() const;
  int infeasibleSamples() const { return innerStatistics().infeasible; }
  /// Whether environment contact i (scenario.contacts order) is in contact at sample s.
  bool contactActive(int contact, int sample) const;
  /// The contacts held over the whole motion by construction, and their closing joints (null:
  /// none, every contact has a window).
  const ClosedChains* closedChains() const { return closure_.get(); }

  int variableCount() const override { return variableCount_; }
  int nonlinearVariableCount() const override { return slackStart_; }
  int constraintCount() const override { return static_cast<int>(rows_.size()); }
  int jacobianNonZeros() const { return static_cast<int>(jacobianRows_.size()); }
  const Eigen::VectorXi& jacobianRows() const override { return jacobianRows_; }
  const Eigen::VectorXi& jacobianColumns() const override { return jacobianColumns_; }
  /// The constraint terms (constraint_term.hpp), in the registry's order, and every kind of row
  /// they can lay out (result.json's `violation_by_kind` keys), rows or not in this problem.
  const ConstraintTerms& terms() const { return terms_; }
  /// The objective's terms (cost_term.hpp), in the order a sample's integrand sums them.
  const CostTerms& costs() const { return costs_; }
  std::vector<ConstraintKindInfo> rowKinds() const;
  /// A row's kind ("torque_limit", …: rowKinds()) and the term that laid it out.
  const ConstraintKindInfo& rowKindInfo(int row) const {
    const Row& r = rows_[static_cast<std::size_t>(row)];
    return terms_[static_cast<std::size_t>(r.term)]->kind(r.detail, r.block);
  }
  std::string_view rowKind(int row) const { return rowKindInfo(row).name; }
  /// e.g. "torque limit of LLEG_JOINT3 at sample 12": rowSubject and where it is evaluated.
  std::string rowName(int row) const override;
  /// What a row bounds, without its instant: "torque limit of LLEG_JOINT3", "r_hand friction
  /// cone", "task 'toe' component x".
  std::string rowSubject(int row) const;
  /// The instant a row is evaluated at [s] for the duration T: its sample's or its task
  /// instant's; NaN for the rows on control points (velocity limits), which bound the whole motion.
  double rowTime(int row, double T) const;

  void variableBounds(Eigen::VectorXd& lower, Eigen::VectorXd& upper) const override;
  void constraintBounds(Eigen::VectorXd& lower, Eigen::VectorXd& upper) const override;
  /// Ones, except the formulation's force variables (ContactForceFormulation::variableUnits).
  void variableUnits(Eigen::VectorXd& units) const override;

  /// The motion from `start` to `end` (inner control points spaced linearly), the initial
  /// duration, force variables fitted to the inner problem's wrenches along that motion
  /// (splines, variables), and epigraph slacks at max(P, 0) of that motion.
  Eigen::VectorXd initialPoint(const Eigen::VectorXd& start, const Eigen::VectorXd& end);
  /// A posture held over [begin, end] (fractions of T) by the initial motion.
  struct HeldPosture {
    double begin = 0.0, end = 1.0;
    Eigen::VectorXd posture;
  };
  /// The same through postures held over parts of the motion (a window's contact posture,
  /// where its closing joints can reach it): the splines fitted, least squares on a fine grid,
  /// to the path from `start` through each held posture to `end` (linear between them), their
  /// end parameters at `start` and `end`.
  Eigen::VectorXd initialPoint(const Eigen::VectorXd& start, const Eigen::VectorXd& end, const std::vector<HeldPosture>& held);
  /// The same from a given motion (spline parameters, duration T): a result's motion as the
  /// start of another formulation — the bilevel optimum's forces are then a feasible point of
  /// the single-level ones (formulation.md §9).
  Eigen::VectorXd pointFromMotion(const Eigen::VectorXd& motionParameters, double T);
  /// The same with given force variables (a result's z: splines, variables; forceVariableCount()
  /// of them, throws std::invalid_argument otherwise), the epigraph's slacks at max(P, 0).
  Eigen::VectorXd pointFromMotion(const Eigen::VectorXd& motionParameters, double T, const Eigen::VectorXd& forceVariables);
  /// The same from `other`'s point x (another continuation stage's problem, whose energy form
  /// or formulation may lay out other variables after the shared spline parameters and T).
  Eigen::VectorXd pointFrom(const MotionProblem& other, const Eigen::VectorXd& x) {
    startClosureAt(other.closureAngles());
    return pointFromMotion(other.motionParameters(x), other.duration(x));
  }
  /// The closing joints' angles the closure reached last at each sample (closing joints × samples;
  /// empty without closed chains), and a start for the closure's Newton at each sample from such
  /// angles (another stage or round of the same scenario: the same grid and closing joints;
  /// anything else is ignored). Newton then stays on the branch of the motion it continues.
  Eigen::MatrixXd closureAngles() const;
  void startClosureAt(const Eigen::MatrixXd& angles);
  /// `other`'s point x (the same scenario on another grid of samples: energy_balance.hpp) as a
  /// point of this problem with the same motion and the same contact wrenches: the force
  /// splines copied (their windows and control points do not depend on the grid); the
  /// `variables` formulation's wrenches, defined at other's samples only, interpolated linearly
  /// in time (within the ball's carried and released parts apart); slacks at max(P, 0).
  Eigen::VectorXd pointWithWrenchesFrom(MotionProblem& other, const Eigen::VectorXd& x);
  /// The motion (spline parameters, duration T) with its force variables fitted to given
  /// environment-contact wrenches (6 × samples each, in the contact's frame; formulation's fit),
  /// slacks at max(P, 0). Throws std::invalid_argument without force variables.
  Eigen::VectorXd pointWithWrenches(const Eigen::VectorXd& motionParameters, double T, const std::vector<Eigen::MatrixXd>& wrenches);
  Eigen::VectorXd motionParameters(const Eigen::VectorXd& x) const { return x.head(parameterCount_); }
  /// x's spline parameters, with each closing joint's (unused: closed_chains.hpp) replaced by a
  /// least-squares fit of its motion at the samples — what a result reports, so that its
  /// parameters describe every joint and can start a problem rooted elsewhere (--start-from).
  Eigen::VectorXd reportedMotionParameters(const Eigen::VectorXd& x);
  double duration(const Eigen::VectorXd& x) const {
    return durationIsFree() ? x[parameterCount_] : scenario_.duration.initial;
  }

  double objective(const Eigen::VectorXd& x) override;
  void objectiveGradient(const Eigen::VectorXd& x, Eigen::VectorXd& gradient) override;
  void constraints(const Eigen::VectorXd& x, Eigen::VectorXd& values) override;
  void jacobianValues(const Eigen::VectorXd& x, Eigen::VectorXd& values) override;
  /// Its Hessian model (MotionProblemOptions::hessian): `sample-differences` assembles Σ_s B_sᵀ H_s B_s from
  /// each sample's and task instant's state-space Hessian (motion_hessian.cpp); otherwise
  /// the generic differences of whole gradients (NlpProblem).
  void lagrangianHessian(const Eigen::VectorXd& x, double objectiveFactor,
                         const Eigen::Ref<const Eigen::VectorXd>& multipliers, Eigen::VectorXd& values) override;
  /// The assembled options' pattern: the motion's block (spline parameters, a free duration)
  /// dense, and each force variable against the local parameters and force columns of the
  /// samples it enters and a free duration; the generic differences keep the dense triangle.
  void hessianPattern(std::vector<int>& rows, std::vector<int>& columns) const override;

  /// Largest violation of constraint rows and variable bounds, overall and per kind
  /// (variable bounds count as "position limit").
  struct Violations {
    double overall = 0.0, positionLimit = 0.0;
    /// Per kind of row (rowKinds(), in its order; 0 where the problem has none of that kind).
    std::vector<std::pair<std::string, double>> byKind;
    int worstRow = -1;  ///< -1 when a variable bound is the worst
    /// The largest violation of one kind; throws std::out_of_range for a kind no term lays out.
    double of(std::string_view kind) const;
  };
  Violations violations(const Eigen::VectorXd& x);

  /// With a throw: the ball at its release at x (forward kinematics at t_r, no cached state).
  std::optional<ReleaseState> release(const Eigen::VectorXd& x) const;
  /// The NLP's samples: the scenario's N, and with a ball the release sample twice (loaded,
  /// then released). Normalised times and trapezoid weights (fractions of T).
  int sampleCount() const { return samples_.sampleCount(); }
  /// Sample s's instant [s] in a motion of duration T.
  double sampleTime(int s, double T) const { return sampleTimes_[static_cast<std::size_t>(s)] * T; }
  /// Sample s's trapezoid weight, a fraction of T: (u_{s+1} − u_{s−1}) / 2.
  double sampleWeight(int s) const { return sampleWeights_[static_cast<std::size_t>(s)]; }
  bool sampleCarriesBall(int s) const { return loaded_[static_cast<std::size_t>(s)]; }

  /// Whether sampledPhysics also resamples the closure between the samples (closureDrift and
  /// speeds). The fine grids of the energy balance and of `mcopt verify` read only their own
  /// samples: their drift grid would be ten times finer again (75,843 closures on the lean
  /// reach's energy grid, 0.75 s of a 10 s run) for figures nobody reads.
  enum class ClosureDrift { Measured, Skipped };
  /// The motion's physics at the samples (and, unless skipped, the closure drift on a grid ten
  /// times finer or the scenario's output samples).
  SampledPhysics sampledPhysics(const Eigen::VectorXd& x, ClosureDrift drift = ClosureDrift::Measured);


 private:
  struct SampleBlock {
    Eigen::VectorXd y;             ///< outputs, SampleOutputs order (sample_outputs.hpp)
    Eigen::VectorXd velocity;      ///< q̇ (n), for the gauss-newton Hessian's ∇²P
    Eigen::VectorXd acceleration;  ///< q̈ (n), for the regularisation
    Eigen::VectorXd wrenches;      ///< 6 (1 + contacts): each contact's wrench in its frame (zero when inactive)
    Eigen::MatrixXd dyDx;          ///< rows × local parameters
    Eigen::VectorXd dyDT;
    Eigen::VectorXi parameters;
    Eigen::MatrixXd dyDq, dyDv, dyDa;
    Eigen::MatrixXd dyDz;          ///< rows × local force columns
    std::vector<int> forceColumns; ///< global variable of each local force column
    /// The force terms behind the local force columns, in their order: the contact, the
    /// term's weight, its first local column (six each). Laid out once, with forceColumns.
    std::vector<LocalForceTerm> forceTerms;
    /// With closed chains: ∂(q_C, q̇_C, q̈_C)/∂(q, q̇, q̈) at this instant (closed_chains.hpp),
    /// and the closing joints' angles reached last (the next Newton start; NaN: none yet).
    Eigen::MatrixXd closureMap;
    Eigen::VectorXd closedAngles;
    ClosureSet closed = 0;  ///< the contacts closed at this instant (closed_chains.hpp)
    /// A window end's twin in contact: its Newton starts from the splines' angles, which the
    /// window end's rows make the closure's (the branch the splines hand over).
    bool startFromSplines = false;
  };
  using ThreadWorkspace = MotionWorkspace;
  /// The admissibility rows of the reference contact, then of each environment contact.
  std::vector<int> contactRowCounts() const {
    std::vector<int> counts;
    for (int c = 0; c <= outputs_.contacts; ++c) counts.push_back(outputs_.contactRowCount(c));
    return counts;
  }
  /// A row of the registry: the term that laid it out (terms_), what `detail` says to that
  /// term (joint, contact row, task component…), the sample or task instant it belongs to (−1:
  /// the control points), the output it reads and its own slack variable (−1: none); the
  /// term's place and sign, kept here so that evaluations ask the term nothing per row.
  struct Row {
    int term, detail, block, output, slack;
    RowPlace place;
    double sign;
  };
  /// Where a Jacobian entry's value comes from (Direct: the term's directDerivative along local column `local`).
  struct JacobianEntry {
    enum class Source : unsigned char { Parameter, Duration, Force, Slack, Direct };
    Source source;
    bool task;  ///< a task block rather than a sample block
    int block, output, local;
    double sign;
  };
  /// pointFromMotion's point: the force variables given, or (null) fitted to the inner problem's wrenches.
  Eigen::VectorXd motionPoint(const Eigen::VectorXd& motionParameters, double T, const Eigen::VectorXd* forceVariables);
  void evaluate(const Eigen::VectorXd& x, bool derivatives);
  void evaluateSample(int s, const Eigen::VectorXd& x, double duration, bool derivatives, ThreadWorkspace& w);
  void evaluateTaskInstant(int i, double duration, bool derivatives, ThreadWorkspace& w);
  /// A sample's outputs (and their derivatives in its state and force columns) at the state
  /// in w.q, w.v, w.a and the force variables of x, into `b`.
  void sampleOutputs(int s, const Eigen::VectorXd& x, bool derivatives, ThreadWorkspace& w, SampleBlock& b);
  /// A task instant's outputs at the state in w.q, w.v (w.a for the dynamics' forward pass).
  void taskOutputs(int i, bool derivatives, ThreadWorkspace& w, SampleBlock& b);
  void buildStructure();
  /// The closing joints' state in w.q, w.v, w.a from the others' (Newton from b's last angles),
  /// with the map into `map` when given, up to `order` (ClosedChains::close). False when the
  /// loop cannot close there.
  bool closeState(const SampleBlock& b, ThreadWorkspace& w, Eigen::MatrixXd* map,
                  ClosureOrder order = ClosureOrder::Accelerations) const;
  /// Without angles to start from (a new problem, not started from another's: startClosureAt),
  /// the closure at every sample in time order, Newton from the sample before's angles (from the
  /// splines' where a window starts), and at each task instant from the nearest sample's: the
  /// branch of the motion the splines start it on, followed through time — a Newton start from
  /// splines that are unused inside a window (fixed at the start posture) may find another.
  void startClosureAlongTheMotion(const Eigen::MatrixXd& controlPoints, double duration);
  /// Each task instant's Newton start: the nearest sample's angles.
  void startTaskClosures();
  /// closure_reach_margin: every loop has a longest reach, and a fixed start or end posture
  /// where its contact is closed keeps its loop within 1 − margin of it (InputError otherwise).
  void checkLoopReaches() const;
  /// The same at an evaluation's own state: the map into b (with derivatives) and the angles
  /// reached kept in b for the next Newton start.
  void closeAndRemember(SampleBlock& b, ThreadWorkspace& w, bool derivatives,
                        ClosureOrder order = ClosureOrder::Accelerations);
  /// Chain rule through the closure: (dyDq, dyDv, dyDa) of b, the closing joints' columns
  /// folded into the others' through b.closureMap, into dq, dv, da.
  /// (All four of b's output rows: a task instant passes its workspace's top rows.)
  void foldClosure(const SampleBlock& b, Eigen::Ref<Eigen::MatrixXd> gather, Eigen::Ref<Eigen::MatrixXd> dq,
                   Eigen::Ref<Eigen::MatrixXd> dv, Eigen::Ref<Eigen::MatrixXd> da) const;
  /// A gradient in the full state's first `stateBlocks` blocks (q; q, q̇; or q, q̇, q̈), brought
  /// to the spline joints' through the closure's map: g_F += Mᵀ g_C, g_C = 0.
  void foldGradient(const Eigen::MatrixXd& map, ClosureSet closed, int stateBlocks, Eigen::Ref<Eigen::VectorXd> gradient) const;
  /// Per-thread buffers of the sample-differences Hessian (motion_hessian.cpp).
  struct HessianWorkspace {
    Eigen::VectorXd probeX, weights, base, gradient;
    Eigen::VectorXd costSlopes, costCurvatures;  ///< the cost terms' slopes and curvatures in the outputs
    Eigen::MatrixXd stateHessian, spread;
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen;
    // The exact option: outputs' weights held at the sample's point, a column being summed,
    // the held-weight gradient at the point itself (the one-sided stencils' f(0)), zero
    // multipliers (the objective's own gradient), and the duration's row in the state
    // (dz/dT, ∂²L/∂z∂T) with its diagonal entry ∂²L/∂T².
    Eigen::VectorXd fixedWeights, zeroWeights, column, centreGradient, objectiveGradient, stateByDuration, durationRow;
    double durationCurvature = 0.0;
    // The rows quadratic in the wrench enter through W_ref: its held weights ω, its Jacobian in
    // the state and force columns at the sample's point, and C J_W for the rows' curvature.
    Vector6 wrenchWeights = Vector6::Zero();
    Eigen::Matrix<double, 6, Eigen::Dynamic> wrenchJacobian, curvedWrenchJacobian;
    // A throw's task instant: the weights its flight puts on the ball's state (ball_flight_task.hpp).
    Vector6 ballWeights = Vector6::Zero();
    // Closed chains: the closing joints' columns and rows of H set aside while the state Hessian
    // is brought to the spline joints' (motion_hessian.cpp).
    Eigen::MatrixXd foldColumns, foldRows;
    // Closed chains, sample differences: the closure's map at a probe, and the closed state the
    // probes start from.
    Eigen::MatrixXd probeMap;
    Eigen::VectorXd closedState;
  };
  /// The exact option's stencils (derivative_stencil.hpp): along a joint angle, a velocity, an
  /// acceleration, a force variable of a sample, and a task instant's angle and velocity.
  struct ExactStencils {
    DerivativeStencil angle, velocity, acceleration, force, taskAngle, taskVelocity;
  };
  ExactStencils exactStencils_;
  /// One sample's (or task instant's) Bᵀ H B over its own columns: kept apart and summed in
  /// sample order afterwards, so that the Hessian does not depend on the thread count.
  struct LocalHessian {
    Eigen::MatrixXd values;    ///< leading size × size block used
    std::vector<int> columns;  ///< the NLP variable of each row and column
    int size = 0;
  };
  void sampleDifferencesHessian(const Eigen::VectorXd& x, double objectiveFactor,
                                const Eigen::Ref<const Eigen::VectorXd>& multipliers, Eigen::VectorXd& values);
  /// ∇ of one sample's Lagrangian terms in its state (q, q̇, q̈) and force columns, from the
  /// outputs' derivatives in `b` and each output's multiplier (+ the objective's share).
  void sampleLagrangianGradient(int s, const SampleBlock& b, const Eigen::Ref<const Eigen::VectorXd>& multipliers,
                                double objectiveWeight, HessianWorkspace& h, Eigen::Ref<Eigen::VectorXd> gradient) const;
  /// The gauss-newton option's H_s (HessianOption::GaussNewton) into h.stateHessian, from the
  /// sample's state, outputs and derivatives in `b`.
  void sampleGaussNewtonHessian(int s, const SampleBlock& b, const Eigen::Ref<const Eigen::VectorXd>& multipliers,
                                double objectiveWeight, HessianWorkspace& h) const;
  /// Sample s as the cost terms see it, from block b (its own, or a Hessian probe at its state).
  CostSample costSample(int s, const SampleBlock& b) const {
    return CostSample{s, b.y, b.acceleration, b.closed, b.dyDx, b.dyDT, b.dyDz, b.parameters, b.forceColumns};
  }
  /// The cost terms' slopes and curvatures in sample s's outputs at b, times objectiveWeight,
  /// into h.costSlopes and h.costCurvatures.
  void costOutputWeights(int s, const SampleBlock& b, double objectiveWeight, HessianWorkspace& h) const;
  /// Σ_o weights_o ∇y_o in the state (q, q̇, q̈) and force columns of `b`, weights held fixed.
  void outputGradient(const SampleBlock& b, const Eigen::VectorXd& weights, Eigen::Ref<Eigen::VectorXd> gradient) const;
  /// ∂W_ref/∂(state, force columns) at the point sampleOutputs last evaluated in `w`, 6 × d.
  void referenceWrenchJacobian(int s, const ThreadWorkspace& w, Eigen::Ref<Eigen::Matrix<double, 6, Eigen::Dynamic>> jacobian) const;
  /// The exact option's H_s (HessianOption::Exact) into h.stateHessian (full, not yet
  /// symmetrised): the gauss-newton terms plus the outputs' own curvature by the stencils.
  void sampleExactHessian(int s, const SampleBlock& b, const Eigen::Ref<const Eigen::VectorXd>& multipliers,
                          double objectiveWeight, double duration, ThreadWorkspace& w, HessianWorkspace& h, SampleBlock& probe);
  double rowValue(const Row& row, const Eigen::VectorXd& x, double duration) const;
  /// The reference surface, then the environment contacts in contact at the sample (their order).
  std::vector<ContactSurface> surfacesInContact(int sample) const;
  /// The epigraph's slack of a joint at a sample, for its rows (energy_epigraph_term.cpp): the
  /// epigraph energy's variables, the first cost term's (cost_term.cpp).
  int slackIndex(int sample, int joint) const { return slackStart_ + sample * jointCount_ + joint; }
  /// The cost terms' own variables of x started from x's motion (CostTerm::startSampleVariables:
  /// the epigraph's slacks at max(P, 0)); nothing to do when no term has any.
  void startCostVariables(Eigen::VectorXd& x);
  /// Each cost term's own variables at each sample, in x's order (makeCostTerms's layout, after
  /// every other variable): f(term, sample, first index in x, count).
  template <class F>
  void forEachCostVariableBlock(F&& f) const {
    int first = slackStart_;
    for (const auto& cost : costs_)
      for (int s = 0, size = cost->variablesPerSample(); size > 0 && s < samples_.sampleCount(); ++s, first += size)
        f(*cost, s, first, size);
  }
  /// The robot's dynamics at sample s: with the ball while it is carried.
  const DynamicsModel& modelOf(int s) const { return loaded_[static_cast<std::size_t>(s)] ? *loadedModel_ : model_; }

  const Scenario& scenario_;
  DynamicsModel model_;
  MotionParametrization parametrization_;
  SampledTrajectory samples_;
  std::vector<double> sampleTimes_;       ///< normalised, per NLP sample
  std::vector<int> sampleSides_;          ///< −1, +1: the twin before, after an instant sampled twice; 0 otherwise
  std::vector<std::vector<bool>> active_; ///< per environment contact and sample: in contact there
  std::vector<double> sampleWeights_;     ///< trapezoid weights, fractions of T
  std::vector<bool> loaded_;              ///< per sample: the ball still in the hand
  std::unique_ptr<DynamicsModel> loadedModel_;  ///< the robot with the ball (a throw)
  int releaseSample_ = -1;                ///< the loaded twin of the release sample; releaseSample_ + 1 is released
  std::vector<int> taskOfInstant_;        ///< task index of each task instant
  SampledTrajectory taskSamples_;         ///< the task instants, as normalised times
  int jointCount_ = 0, parameterCount_ = 0, variableCount_ = 0, slackStart_ = 0, forceStart_ = 0;
  SampleOutputs outputs_;
  std::vector<std::array<double, 2>> windows_;   ///< per environment contact, normalised
  /// How the environment contacts' wrenches are chosen (contact_force_formulation.hpp).
  std::unique_ptr<ContactForceFormulation> formulation_;
  std::unique_ptr<ClosedChains> closure_;  ///< null without environment contacts
  /// Per spline parameter: fixed and unused, every sample and task instant it reaches closing
  /// its joint (a whole-motion contact's closing joints: all theirs; a window's: those inside it).
  std::vector<bool> unusedParameter_;
  std::vector<ContactAdmissibilityRows> contactRows_;  ///< per environment contact, on its own wrench
  std::vector<int> torqueJoints_;         ///< joints with a finite torque limit (when limited)
  HessianOption hessian_;
  bool derivativesLaidOut_ = true;  ///< MotionProblemOptions::derivatives
  std::vector<bool> omittedTorqueRows_;   ///< per sample and joint, rows left out (screening)
  std::vector<bool> omittedClosingRows_;  ///< per sample and closing detail, rows left out (screening)
  std::vector<int> allJoints_;
  std::vector<std::vector<int>> relatedJoints_;  ///< joints whose motion changes Γ_i: i's ancestors and descendants
  std::vector<std::vector<int>> taskJoints_;     ///< per task instant: joints that move the task's body
  ContactAdmissibilityRows support_;
  double weight_ = 0.0;                   ///< m g [N]
  Eigen::VectorXd units_;                 ///< variableUnits(): the outer solver's and the difference steps'

  ConstraintTerms terms_;  ///< the row families (constraint_term.hpp), made once the layout above is known
  CostTerms costs_;        ///< the objective's terms (cost_term.hpp)
  std::vector<Row> rows_;
  std::vector<JacobianEntry> entries_;
  Eigen::VectorXi jacobianRows_, jacobianColumns_;

  std::vector<SampleBlock> blocks_, taskBlocks_;
  std::vector<ThreadWorkspace> workspaces_;
  std::vector<HessianWorkspace> hessianWorkspaces_;
  std::vector<LocalHessian> localHessians_;  ///< samples, then task instants
  Eigen::MatrixXd hessianSum_;
  std::vector<SampleBlock> probes_, taskProbes_;  ///< per thread: outputs at a perturbed state
  Eigen::MatrixXd sampleMultipliers_, taskMultipliers_;  ///< per output × sample / task instant
  int taskRows_ = 1;  ///< the largest task dimension: rows of the task multipliers, probes and fold buffers
  Eigen::MatrixXd controlPoints_;
  Eigen::VectorXd cachedX_;
  bool cachedDerivatives_ = false, cacheValid_ = false;
  bool closureStarted_ = false;  ///< every sample has closure angles to start Newton from
  bool sizedValues_ = false, sizedWithDerivatives_ = false;  ///< an evaluation of that kind has run (NoMallocScope)
};

}  // namespace mcopt
