// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A scenario's whole motion solve (docs/theory/outer-problem.md, "Continuation" and "Torque-limit
// screening"): its continuation stages, each from the previous one's iterate, then its own
// problem; every solve with the torque-limit rows below `limits.torque_screening` of their
// limit left out and checked on its result, those that reached it joining for another solve.
// The caller sees every solve start and every Ipopt iteration (progress, checkpoints, stop).
#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "outer_nlp/outer_solver.hpp"
#include "outer_nlp/motion_problem.hpp"
#include "outer_nlp/scenario.hpp"

namespace mcopt {

/// One continuation stage (the scenario's own problem last), over its screening rounds.
struct StageOutcome {
  double frictionSharpness = 0.0, smoothing = 0.0;
  int samples = 0;
  HessianOption hessian = HessianOption::SampleDifferences;
  EnergyForm energyForm = EnergyForm::SmoothMaximum;
  std::string innerSolver;  ///< bilevel: the stage's inner solver; empty otherwise
  std::string feasibility;  ///< bilevel: the stage's inner-feasibility row (slack, margin); empty otherwise
  std::string contactForces;  ///< with environment contacts: the formulation the stage ran in; empty otherwise
  OuterStatus status = OuterStatus::InternalError;  ///< of its last solve
  double objective = 0.0;                           ///< of its last solve
  int iterations = 0;                               ///< over its rounds
  double seconds = 0.0;
  SolveTimings timings;
  int rounds = 0;             ///< solves: 1 + the times torque-limit rows joined
  int omittedTorqueRows = 0;  ///< torque-limit rows out of the last solve, checked at its result
  int omittedClosingRows = 0;  ///< closing joints' limit rows out of the last solve, checked at its result
  /// ≥ 0: this stage started from the point stage `restartedFrom` (0-based) had started from,
  /// because that stage ended worse than it began (StagePoint, stageEndDominated); −1: from the
  /// previous stage's iterate (or the run's start).
  int restartedFrom = -1;
};

/// A point as the next stage's problem sees it: its largest row or bound violation and its
/// criterion.
struct StagePoint {
  double violation = 0.0, objective = 0.0;
};

/// Whether a stage that ended neither optimal nor stalled made its point worse: its start is
/// no worse than its end in both violation and criterion, both measured in the next stage's
/// problem (the filter's order; docs/theory/outer-problem.md, "Continuation"). The next stage
/// then starts from that start instead (measured: the throw's margin-row stage that fell into
/// restoration, docs/developers/lab-notes/admissibility-margin.md).
inline bool stageEndDominated(const StagePoint& start, const StagePoint& end) {
  return start.violation <= end.violation && start.objective <= end.objective;
}

/// One Ipopt solve about to start.
struct SolveStart {
  int stage = 0, stages = 1;
  const Scenario& scenario;      ///< the stage's scenario
  const MotionProblem& problem;  ///< what Ipopt solves (the screened problem)
  int joinedTorqueRows = 0;      ///< rows that joined since the previous round (0 on a stage's first)
  /// ≥ 0 on a stage's first round: it starts from where stage `restartedFrom` started, whose end
  /// (`handed`) that start (`restart`) dominated, both in this stage's problem.
  int restartedFrom = -1;
  StagePoint handed, restart;
  int joinedClosingRows = 0;  ///< closing joints' limit rows that joined since the previous round
};

struct MotionSolveEvents {
  std::function<void(const SolveStart&)> onSolve;
  /// Returns false to stop (Ipopt reports "interrupted").
  std::function<bool(int stage, const MotionProblem& problem, const IterationReport&)> onIteration;
};

struct MotionSolveOutcome {
  OuterOutcome solver;              ///< the last solve's, with x the last usable iterate
  std::vector<StageOutcome> stages;
  std::string reason;               ///< why the solve ended before the scenario's own problem, if it did
};

/// Whether a stage before the scenario's own problem has stopped making progress
/// (docs/theory/outer-problem.md, "Continuation"): over the last `window` regular iterations
/// its criterion moved by at most `relativeChange` × max(1, |f|) while every iterate held its
/// rows to `violation`, and its dual infeasibility did not fall by `dualFall` from the
/// window's first iterate to its last. Such a stage hands its iterate on (status `stalled`)
/// instead of running to its iteration limit: a stage whose Hessian model lacks a curvature
/// the optimum needs can circle there for hundreds of iterations (measured on the throw with
/// the margin row, docs/developers/lab-notes/admissibility-margin.md), or creep, its dual
/// infeasibility falling by a few per cent an iteration (the weight shift's Gauss–Newton
/// stage). A stage converging to its own optimum has a flat criterion too, its dual
/// infeasibility falling by orders of magnitude (the lean reach's last ten iterations), and
/// is left to end optimal. Restoration iterates (another problem's) restart the window.
class StageStallWatch {
 public:
  struct Settings {
    int window = 10;
    double relativeChange = 1e-6;
    double violation = 1e-6;
    double dualFall = 10.0;
  };
  StageStallWatch() : StageStallWatch(Settings{}) {}
  explicit StageStallWatch(Settings settings);
  /// Records one iteration; true once the stage has stalled.
  bool stalled(const IterationReport& report);

 private:
  Settings settings_;
  std::vector<double> objectives_, duals_;  ///< the window, rings
  int recorded_ = 0;                ///< regular iterations in a row, with the violation held
};

/// `problem` is the scenario's own (full) motion problem; x0 its starting point. Continuation
/// stages for other contact-force formulations than the scenario's are left out.
MotionSolveOutcome solveMotion(const Scenario& scenario, MotionProblem& problem, const Eigen::VectorXd& x0,
                               const OuterSolverSettings& settings, const MotionSolveEvents& events);

}  // namespace mcopt
