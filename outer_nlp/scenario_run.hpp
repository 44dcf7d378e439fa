// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A scenario's whole run (docs/reference/scenario-file.md): the optional configuration optimisation of its
// end postures (report §3.5), then the motion solve with its continuation stages and
// torque-limit screening (motion_solve.hpp), gathered into one RunRecord. The command line
// (`mcopt run`) and the Python module both run scenarios through here and only differ in
// how they show progress, how a stop is asked for and what they do with the record.
#include <Eigen/Core>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "outer_nlp/outer_solver.hpp"
#include "outer_nlp/motion_problem.hpp"
#include "outer_nlp/motion_solve.hpp"
#include "outer_nlp/motion_verification.hpp"
#include "outer_nlp/posture_check.hpp"
#include "outer_nlp/timing_check.hpp"
#include "outer_nlp/scenario.hpp"

namespace mcopt {

/// Run-time changes to a scenario (`mcopt run` options, keyword arguments in Python), typed:
/// the command line and Python parse their text; an unset field leaves the scenario's.
struct ScenarioOverrides {
  std::optional<bool> configurationOptimisation;
  std::optional<std::string> contactForces;  ///< formulation.md §9
  std::optional<ForceUnits> forceUnits;      ///< `force_units`
  std::optional<int> maxIterations;            ///< Ipopt's max_iter for the motion and the cap of every stage, ≥ 0
  std::optional<std::string> innerSolver;      ///< a registered inner solver (bilevel, formulation.md §7)
  /// The motion's and every continuation stage's Hessian. A stage left differing from the
  /// scenario in nothing but its iteration limit (a Hessian hand-over, as the bundled
  /// gauss-newton first stages are) is dropped.
  std::optional<HessianOption> hessian;
  std::optional<int> refineRounds;  ///< `--refine [ROUNDS]`, ≥ 0
};

/// Applies the overrides; throws InputError for an unregistered inner solver, a negative count,
/// and "--hessian: exact: …" where the exact Hessian's stencils do not hold (exactHessianRefusal).
void applyOverrides(Scenario& scenario, const ScenarioOverrides& overrides);

/// Starts the scenario's motion optimisation from a given motion (a result's: `mcopt run
/// --start-from`): its spline parameters by joint name, each the scenario's control points − 4
/// values, and its duration. The start and end postures become the motion's first and last
/// control points (fixed if the scenario fixes them) and configuration optimisation is off.
/// Throws InputError "<origin>: parameters.<joint>: …" or "<origin>: duration: …" for a motion
/// that does not fit the scenario.
void startFromMotion(Scenario& scenario, const std::map<std::string, std::vector<double>>& parametersByJoint,
                     double duration, const std::string& origin);

/// One static posture found by configuration optimisation (report §3.5).
struct PostureOutcome {
  bool optimised = false;
  OuterStatus status = OuterStatus::InternalError;
  double staticPowerBefore = 0.0, staticPowerAfter = 0.0;  ///< [W]
  int iterations = 0;
  double seconds = 0.0;
};

/// One Ipopt iteration of the motion solve, with the bilevel inner problems of the last
/// evaluation before it (result.json `history`).
struct IterationRecord {
  int stage = 0;  ///< continuation stage (0 without continuation)
  int iteration = 0;
  double objective = 0.0, violation = 0.0, dualInfeasibility = 0.0, elapsedSeconds = 0.0;
  double stepSize = 0.0, regularisation = 0.0, barrier = 0.0;  ///< Ipopt's α_pr, δ_w and μ
  SolveTimings timings;  ///< cumulative up to this iteration
  MotionProblem::InnerStatistics inner;
  /// With a throw: the iterate's miss distance (formulation.md §10); none where Ipopt gives
  /// no iterate (its restoration phase).
  std::optional<double> missDistance;
};

/// One round of a refined run: the grid it ran on, how it ended, what verify found of its motion.
struct RefinementRound {
  int round = 0;    ///< 0: the scenario's own run
  int samples = 0;  ///< the scenario's samples in that round
  OuterStatus status = OuterStatus::InternalError;
  int iterations = 0;    ///< Ipopt iterations of the round, every stage
  double seconds = 0.0;  ///< the run's total time at the end of the round
  bool verified = false;  ///< false too when the round did not end optimal (not verified)
  std::vector<VerificationCheck> failed;  ///< the checks that failed on its motion
};

struct RunRecord {
  OuterStatus status = OuterStatus::InternalError;
  std::string message, reason;  ///< reason: why a run that is not optimal ended
  Eigen::VectorXd x;            ///< the outer problem's variables (the last usable iterate)
  PostureOutcome start, end;
  /// Per contact with a window inside the motion: the posture the initial motion holds over
  /// it, the one nearest the start–end path that meets the tasks at the window's middle, its
  /// closure among them (ConfigurationProblem's reach; motion_problem.hpp).
  struct ContactPosture {
    std::string contact;
    double time = 0.0;         ///< the window's middle [s]
    PostureOutcome outcome;    ///< static power before: of the path's posture there
    double distance = 0.0;     ///< ‖q − path‖ [rad]
  };
  std::vector<ContactPosture> contactPostures;
  OuterOutcome solver;
  std::vector<IterationRecord> history;
  std::vector<StageOutcome> stages;  ///< one per continuation stage, the scenario's own problem last
  double configurationSeconds = 0.0, optimisationSeconds = 0.0, totalSeconds = 0.0;
  /// The fixed postures, checked at rest before anything else (posture_check.hpp).
  std::vector<PostureCheck> postureChecks;
  /// The centre-of-mass tasks' timings against the linear inverted pendulum's least times
  /// (timing_check.hpp), checked before anything is optimised.
  std::vector<TimingCheck> timingChecks;
  /// What the run should not pass over in silence (result.json `warnings`): a fixed posture the
  /// robot cannot hold, a posture whose configuration optimisation did not end optimal, …
  std::vector<std::string> warnings;
  /// With refinement (refineRun): every round, the run's own first; the record's motion is the last's.
  std::vector<RefinementRound> refinement;
};

struct ScenarioRunEvents {
  /// The fixed postures have been checked (before anything is optimised); may throw to stop
  /// the run there (`mcopt run --strict` throws InputError when one cannot be held).
  std::function<void(const std::vector<PostureCheck>&)> onPostureChecks;
  /// The centre-of-mass timings have been checked (after the postures); may throw to stop the
  /// run (`--strict`, one too short).
  std::function<void(const std::vector<TimingCheck>&)> onTimingChecks;
  /// A start or end posture has been optimised ("start" or "end").
  std::function<void(const std::string& which, const PostureOutcome&)> onPosture;
  std::function<void(const RunRecord::ContactPosture&)> onContactPosture;
  std::function<void(const SolveStart&)> onSolve;
  /// After each motion iteration, once its record has joined `sofar.history`; false stops.
  std::function<bool(const RunRecord& sofar, const MotionProblem& current, const IterationReport&)> onIteration;
  /// Asked at every Ipopt iteration of every solve (postures included); false stops, and
  /// the run ends with status `interrupted` and its last iterate.
  std::function<bool()> keepRunning;
  /// A refinement round has ended and been verified (refineRun).
  std::function<void(const RefinementRound&)> onRefinementRound;
};

/// The outcome of refineRun: the last round's record, and its scenario and problem when that is
/// not the run's own (null otherwise; MotionProblem keeps a reference to its scenario, so both
/// live here).
struct RefinedRun {
  std::unique_ptr<Scenario> scenario;
  std::unique_ptr<MotionProblem> problem;
  RunRecord record;
};

/// The initial point of a run between the boundary postures `start` and `end`: through the
/// posture reaching each contact whose window lies inside the motion (RunRecord::ContactPosture;
/// appended to `reaches` when given), the motion problem's initialPoint otherwise.
Eigen::VectorXd initialPointThroughContacts(MotionProblem& problem, const Eigen::VectorXd& start, const Eigen::VectorXd& end,
                                            std::vector<RunRecord::ContactPosture>* reaches = nullptr,
                                            const ScenarioRunEvents& events = {});

/// Runs `scenario` on its own motion problem `problem` (built from it). Never throws for a
/// numerical outcome (that is the record's status); throws InputError for what Ipopt refuses.
RunRecord runScenario(const Scenario& scenario, MotionProblem& problem, const ScenarioRunEvents& events);

/// runScenario's motion solve (its continuation stages and screening rounds) from x0, into
/// `record` (its solver outcome, stages, history, status and x; totalSeconds added to).
void solveScenarioFrom(const Scenario& scenario, MotionProblem& problem, const Eigen::VectorXd& x0,
                       const ScenarioRunEvents& events, RunRecord& record);

/// The scenario on twice its sample intervals (every sample kept; a throw's release where the
/// coarser grid had it), started from the motion (parameters, T), without continuation stages
/// or configuration optimisation: a refinement round's problem.
Scenario refinedScenario(const Scenario& scenario, const Eigen::VectorXd& parameters, double duration);

/// A run refined until its motion holds between its samples (`mcopt run --refine`, scenario
/// `refine`; docs/reference/verify.md, "Refine"): the run's optimum is verified
/// (motion_verification.hpp); while a check fails and rounds remain, the scenario is solved again
/// on twice the sample intervals from the motion reached (refinedScenario; the force splines
/// copied, the `variables` wrenches interpolated) and verified again. A round that does not end
/// optimal ends the refinement. `record` is the run's own (round 0).
RefinedRun refineRun(const Scenario& scenario, MotionProblem& problem, RunRecord record, int rounds,
                     const VerificationSettings& settings, const ScenarioRunEvents& events);

}  // namespace mcopt
