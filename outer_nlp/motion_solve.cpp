// SPDX-License-Identifier: BSD-3-Clause
#include "outer_nlp/motion_solve.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>

#include "core/errors.hpp"

namespace mcopt {

StageStallWatch::StageStallWatch(Settings settings) : settings_(settings) {
  if (settings_.window < 2) throw InputError("stage stall watch: the window needs at least 2 iterations");
  if (!(settings_.dualFall > 1.0)) throw InputError("stage stall watch: the dual infeasibility's fall needs a factor above 1");
  objectives_.assign(static_cast<std::size_t>(settings_.window), 0.0);
  duals_.assign(static_cast<std::size_t>(settings_.window), 0.0);
}

bool StageStallWatch::stalled(const IterationReport& r) {
  if (r.iterate == nullptr || !(r.violation <= settings_.violation) || !std::isfinite(r.objective)) {
    recorded_ = 0;
    return false;
  }
  const auto slot = static_cast<std::size_t>(recorded_ % settings_.window);
  objectives_[slot] = r.objective;
  duals_[slot] = r.dualInfeasibility;
  ++recorded_;
  if (recorded_ < settings_.window) return false;
  const auto [low, high] = std::minmax_element(objectives_.begin(), objectives_.end());
  if (*high - *low > settings_.relativeChange * std::max(1.0, std::abs(r.objective))) return false;
  // The ring's oldest entry is the one the next iteration overwrites.
  const double first = duals_[static_cast<std::size_t>(recorded_ % settings_.window)];
  const bool converging = std::isfinite(r.dualInfeasibility) && r.dualInfeasibility * settings_.dualFall <= first;
  return !converging;
}

MotionSolveOutcome solveMotion(const Scenario& given, MotionProblem& problem, const Eigen::VectorXd& x0,
                               const OuterSolverSettings& settings, const MotionSolveEvents& events) {
  // Stages meant for another contact-force formulation are not run (and not counted).
  const Scenario scenario = withStagesForItsFormulation(given);
  MotionSolveOutcome result;
  Eigen::VectorXd x = x0;
  const int stages = static_cast<int>(scenario.solve.continuation.size()) + 1;
  std::optional<Scenario> solved;  // the problem of the last stage that ended optimal
  Eigen::MatrixXd closureAngles;  // the closing joints' angles at each sample, handed from solve to solve
  // The start of the last stage if it ended neither optimal nor stalled (stageEndDominated).
  int unfinished = -1;
  Eigen::VectorXd unfinishedStart;
  Eigen::MatrixXd unfinishedAngles;
  // The formulation x and unfinishedStart are points of (a stage's contact_forces can differ).
  std::string xForces = scenario.contactForces, unfinishedForces;
  for (int k = 0; k < stages; ++k) {
    const bool last = k + 1 == stages;
    const Scenario stageScenario = continuationStage(scenario, static_cast<std::size_t>(k));
    // A stage whose problem an earlier stage has solved (the same ν, ε, samples and energy
    // form: it differs in its Hessian or its limit) is not run: Ipopt's optimality test reads
    // the exact first derivatives, whatever Hessian shaped the steps, and a restart from the
    // optimum only wanders (the bundled kick's sample-differences stage after an optimal
    // Gauss–Newton stage: 48 iterations, 7.6 s, the same optimum; docs/reference/scenario-file.md).
    if (!last && solved && posesScenarioProblem(stageScenario, *solved)) continue;
    const std::unique_ptr<MotionProblem> stageProblem = last ? nullptr : std::make_unique<MotionProblem>(stageScenario);
    MotionProblem& full = last ? problem : *stageProblem;
    // A stage of another energy form lays out other variables after the shared spline
    // parameters and T (the epigraph's slacks): it starts from the motion reached, its own
    // variables set from it (MotionProblem::pointFrom; the smooth maximum's optimum, then the
    // exact epigraph form: docs/theory/outer-problem.md, "Continuation").
    full.startClosureAt(closureAngles);
    // Another formulation's point (a stage's contact_forces) hands on its motion, the force
    // variables fitted to the inner problem's wrenches along it.
    if (x.size() != full.variableCount() || xForces != stageScenario.contactForces) x = full.pointFrom(problem, x);
    xForces = stageScenario.contactForces;
    // A stage that ended worse than it began hands on its start instead, judged in this
    // stage's problem (each point on its own closure branch).
    int restartedFrom = -1;
    StagePoint handed, restart;
    if (unfinished >= 0) {
      Eigen::VectorXd start = unfinishedStart;
      if (start.size() != full.variableCount() || unfinishedForces != stageScenario.contactForces)
        start = full.pointFrom(problem, start);
      handed = {full.violations(x).overall, full.objective(x)};
      full.startClosureAt(unfinishedAngles);
      restart = {full.violations(start).overall, full.objective(start)};
      const bool endBroken = !std::isfinite(handed.objective) || !std::isfinite(handed.violation);
      if (std::isfinite(restart.objective) && (endBroken || stageEndDominated(restart, handed))) {
        x = start, closureAngles = unfinishedAngles, restartedFrom = unfinished;
      }
      full.startClosureAt(closureAngles);
      unfinished = -1;
    }
    const Eigen::VectorXd stageStart = x;
    const Eigen::MatrixXd stageStartAngles = closureAngles;
    std::vector<bool> omitted;
    const double screening = scenario.solve.torqueScreening;
    if (scenario.torqueLimits && screening > 0.0) omitted = full.torquesBelow(x, screening);
    std::vector<bool> omittedClosing;
    const double closingScreening = scenario.solve.closingScreening;
    if ((scenario.positionLimits || scenario.velocityLimits) && closingScreening > 0.0 && !scenario.contacts.empty())
      omittedClosing = full.closingLimitsBelow(x, closingScreening);
    StageOutcome stage;
    stage.restartedFrom = restartedFrom;
    stage.frictionSharpness = stageScenario.actuators.frictionSharpness;
    stage.smoothing = stageScenario.smoothing;
    stage.samples = stageScenario.samples;
    stage.hessian = stageScenario.solve.hessian;
    stage.energyForm = stageScenario.energyForm;
    if (!stageScenario.contacts.empty()) stage.contactForces = stageScenario.contactForces;
    if (full.bilevel()) {
      stage.innerSolver = stageScenario.inner.solverName;
      stage.feasibility = toString(stageScenario.inner.feasibility);
    }
    OuterOutcome outcome;
    int joined = 0, joinedClosing = 0;
    for (;;) {
      MotionProblemOptions options{stageScenario.solve.hessian, omitted};
      options.omittedClosingRows = omittedClosing;
      MotionProblem current(stageScenario, std::move(options));
      current.startClosureAt(closureAngles);  // the closure continues the motion's branch
      stage.omittedTorqueRows = current.omittedTorqueRowCount();
      stage.omittedClosingRows = current.omittedClosingRowCount();
      if (events.onSolve)
        events.onSolve(SolveStart{k, stages, stageScenario, current, joined, stage.rounds == 0 ? restartedFrom : -1,
                                  handed, restart, joinedClosing});
      OuterSolverSettings roundSettings = settings;
      roundSettings.problemHessian = stageScenario.solve.hessian != HessianOption::LimitedMemory;
      // After the scenario's options: the stage's own limit wins.
      if (!last && scenario.solve.continuation[static_cast<std::size_t>(k)].maxIterations >= 0)
        roundSettings.maxIterations = scenario.solve.continuation[static_cast<std::size_t>(k)].maxIterations;
      // A later stage, and a screening round, starts at the iterate the last solve ended on, to
      // be kept: a small barrier parameter keeps Ipopt near it instead of re-centring it
      // (measured on the bilevel weight shift: from the Gauss–Newton stage's iterate,
      // sample-differences ended optimal after 79 iterations with it, and not in 1000 without
      // it; docs/reference/scenario-file.md). So does the first solve from a given motion
      // (--start-from: another run's optimum). The epigraph form starts lower still: its slacks
      // start at max(P, 0), on their bounds, and a barrier μ lifts each by about 2μ/c (c the
      // sample's weight in the criterion, the smooth maximum's offset with ε = 2μ/c): at 1e-4
      // the kick's 3000 slacks rose to a criterion of 0.6 J before coming back, 161 iterations
      // with the exact Hessian and none in 400 with gauss-newton; at 1e-6, 47 and 55 to the
      // same optimum (docs/reference/scenario-file.md, "Continuation"). The scenario's `solver`
      // options still override it.
      // Such a start is not pushed off its bounds either (the solver's default pushes would
      // move a feasible start off its own point — the bilevel optimum that --start-from gives
      // another formulation, formulation.md §9, or a smooth-maximum stage's optimum with the
      // epigraph's slacks at max(P, 0), many at 0): measured, the second stage after 500
      // Gauss–Newton iterations then took 59 instead of 86 iterations on the weight shift, 49
      // instead of 63 on the one-foot throw, 48 instead of 59 on the kick without configuration
      // optimisation (docs/reference/scenario-file.md).
      if (k > 0 || stage.rounds > 0 || scenario.initialMotion) {
        const bool epigraph = stageScenario.energyForm == EnergyForm::Epigraph;
        roundSettings.warmStart = OuterSolverSettings::WarmStart{
            epigraph ? 1e-6 : 1e-4,
            stage.rounds > 0 ? "torque-limit screening: " : k > 0 ? "continuation stage: " : "--start-from: "};
      }
      // A stage before the scenario's own problem hands on once it stalls (StageStallWatch).
      StageStallWatch watch;
      bool stalled = false;
      outcome = solveOuter(current, x, roundSettings, [&](const IterationReport& r) {
        if (!last && watch.stalled(r)) {
          stalled = true;
          return false;
        }
        return !events.onIteration || events.onIteration(k, current, r);
      });
      if (stalled && outcome.status == OuterStatus::Interrupted) {
        outcome.status = OuterStatus::Stalled;
        outcome.message = "the stage's criterion stopped moving; its iterate is handed on";
      }
      closureAngles = current.closureAngles();
      ++stage.rounds;
      stage.iterations += outcome.iterations;
      stage.seconds += outcome.seconds;
      stage.timings += outcome.timings;
      if (outcome.x.size() != x.size() || !outcome.x.allFinite() || !outcome.optimal() ||
          (omitted.empty() && omittedClosing.empty()))
        break;
      // Optimal for the rows in the problem, and for all of them when every omitted row is
      // still below its fraction (then strictly inside its bound: multiplier 0).
      const auto join = [](std::vector<bool>& out, const std::vector<bool>& below) {
        int count = 0;
        for (std::size_t i = 0; i < out.size(); ++i)
          if (out[i] && !below[i]) out[i] = false, ++count;
        return count;
      };
      joined = omitted.empty() ? 0 : join(omitted, full.torquesBelow(outcome.x, scenario.solve.torqueScreening));
      joinedClosing = omittedClosing.empty() ? 0 : join(omittedClosing, full.closingLimitsBelow(outcome.x, closingScreening));
      if (joined == 0 && joinedClosing == 0) break;
      x = outcome.x;
    }
    const bool usable = outcome.x.size() == x.size() && outcome.x.allFinite();
    if (usable) x = outcome.x;
    stage.status = outcome.status, stage.objective = outcome.objective;
    result.stages.push_back(stage);
    // A stage that differs from the scenario's own problem only in its Hessian option (or
    // iteration limit) and ends optimal has solved that problem: Ipopt's optimality test reads
    // the exact first derivatives, whatever Hessian shaped the steps. The later stages would
    // only restart from its optimum (measured: a restart with sample-differences wandered off
    // the lean reach's optimum; docs/reference/scenario-file.md).
    const bool scenarioProblem = posesScenarioProblem(stageScenario, scenario);
    if (!last && scenarioProblem && usable && outcome.optimal()) {
      result.solver = outcome;
      break;
    }
    if (usable && outcome.optimal()) solved = stageScenario;
    if (usable && !outcome.optimal() && outcome.status != OuterStatus::Stalled)
      unfinished = k, unfinishedStart = stageStart, unfinishedAngles = stageStartAngles, unfinishedForces = xForces;
    if (last || outcome.status == OuterStatus::Interrupted || !usable) {
      result.solver = outcome;
      if (!last) {
        // The last usable iterate, of an earlier stage, as a point of the scenario's problem.
        result.solver.x = x.size() != problem.variableCount() || xForces != scenario.contactForces ? problem.pointFrom(problem, x) : x;
        result.reason = "stopped in continuation stage " + std::to_string(k + 1) + " of " + std::to_string(stages) +
                        " (" + toString(outcome.status) + ")";
      }
      break;
    }
  }
  problem.startClosureAt(closureAngles);  // the results' closure on the run's branch
  // The run's iterate in the scenario's own layout, also when an earlier stage's is the last usable one.
  if (result.solver.x.size() > 0 && result.solver.x.size() != problem.variableCount())
    result.solver.x = problem.pointFrom(problem, result.solver.x);
  return result;
}

}  // namespace mcopt
