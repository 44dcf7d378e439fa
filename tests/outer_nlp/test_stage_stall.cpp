// SPDX-License-Identifier: BSD-3-Clause
// The hand-over of a stalled continuation stage (outer_nlp/motion_solve.hpp, StageStallWatch;
// docs/theory/outer-problem.md, "Continuation"): a window of regular iterations whose criterion
// moves by at most its relative change, every one of them feasible, its dual infeasibility not
// falling by the factor that says converging; restoration iterates, infeasible ones, steady
// progress and convergence restart or withhold it. And which stages pose the
// scenario's own problem (continuationStage, posesScenarioProblem), and when a stage that
// ended worse than it began hands on its start (stageEndDominated).
#include <catch2/catch.hpp>

#include <limits>

#include "common/test_support.hpp"
#include "outer_nlp/motion_solve.hpp"
#include "outer_nlp/scenario.hpp"

using namespace mcopt;

namespace {

IterationReport report(double objective, double violation, bool regular = true, double dual = 1e-2) {
  static const Eigen::VectorXd iterate = Eigen::VectorXd::Zero(1);
  IterationReport r;
  r.objective = objective, r.violation = violation, r.dualInfeasibility = dual;
  r.iterate = regular ? &iterate : nullptr;
  return r;
}

/// The iteration (1-based) at which the watch says stalled, or 0.
int stalledAt(StageStallWatch& watch, const std::vector<IterationReport>& reports) {
  for (std::size_t k = 0; k < reports.size(); ++k)
    if (watch.stalled(reports[k])) return static_cast<int>(k) + 1;
  return 0;
}

}  // namespace

TEST_CASE("stage stall: a flat feasible window hands on, progress, convergence, infeasible or restoration iterates do not",
          "[outer][continuation]") {
  const StageStallWatch::Settings settings{10, 1e-6, 1e-6, 10.0};
  std::vector<IterationReport> flat;
  // The throw's plateau: 134.857559 … 134.857581 J, violations 1e-13 … 1e-7.
  for (int k = 0; k < 40; ++k) flat.push_back(report(134.857559 + (k % 3 == 0 ? 2.2e-5 : 0.0), k % 3 == 0 ? 4e-13 : 9e-8));
  {
    StageStallWatch watch(settings);
    CHECK(stalledAt(watch, flat) == 10);  // as soon as a whole window is recorded
  }
  {
    // Steady progress of 1e-5 relative an iteration: never flat over 10.
    std::vector<IterationReport> descending;
    for (int k = 0; k < 100; ++k) descending.push_back(report(100.0 * (1.0 - 1e-5 * k), 1e-9));
    StageStallWatch watch(settings);
    CHECK(stalledAt(watch, descending) == 0);
  }
  {
    // A flat criterion with the rows not yet held: not a stall, and the window restarts after it.
    std::vector<IterationReport> reports = flat;
    reports[7].violation = 1e-3;
    StageStallWatch watch(settings);
    CHECK(stalledAt(watch, reports) == 8 + 10);  // the infeasible 8th, then a new window of 10
  }
  {
    // Restoration iterates (no iterate of this problem) restart the window too.
    std::vector<IterationReport> reports = flat;
    reports[5] = report(134.857559, 0.0, false);
    StageStallWatch watch(settings);
    CHECK(stalledAt(watch, reports) == 6 + 10);
  }
  {
    // A criterion near zero is compared absolutely (max(1, |f|)): 1e-7 J of noise on 1e-3 J.
    std::vector<IterationReport> small;
    for (int k = 0; k < 20; ++k) small.push_back(report(1e-3 + (k % 2) * 1e-7, 0.0));
    StageStallWatch watch(settings);
    CHECK(stalledAt(watch, small) == 10);
  }
  {
    // The weight shift's Gauss–Newton stage from its iteration 120: the criterion flat at
    // 90.5052 J, the dual infeasibility creeping from 1.6e-1 to 1.4e-2 by a few per cent an
    // iteration. Its first window falls by 14.7 (1.6e-1 to 1.1e-2: converging), the next by
    // 3.7 (3.8e-2 to 1.0e-2): stalled there, at the 11th iteration, as the stage did at 130.
    const std::vector<double> duals = {1.611e-1, 3.795e-2, 1.865e-2, 1.587e-2, 1.566e-2, 1.415e-2, 1.353e-2,
                                       1.248e-2, 1.183e-2, 1.097e-2, 1.037e-2, 9.642e-3};
    std::vector<IterationReport> creeping;
    for (std::size_t k = 0; k < duals.size(); ++k)
      creeping.push_back(report(90.505165 + (k % 2) * 1.2e-5, 1e-8, true, duals[k]));
    StageStallWatch watch(settings);
    CHECK(stalledAt(watch, creeping) == 11);
  }
  {
    // The lean reach's last iterations: the criterion flat at 89.46646 J while the dual
    // infeasibility falls from 1.0e-2 to 3.0e-5, Newton's method closing on the stage's own
    // optimum. Not a stall: the stage is left to end optimal.
    const std::vector<double> duals = {1.040e-2, 4.268e-2, 2.368e-3, 6.898e-4, 3.947e-4, 8.683e-5,
                                       6.462e-5, 1.132e-5, 7.546e-5, 2.991e-5};
    std::vector<IterationReport> converging;
    for (std::size_t k = 0; k < duals.size(); ++k) converging.push_back(report(89.466459, 1e-9, true, duals[k]));
    StageStallWatch watch(settings);
    CHECK(stalledAt(watch, converging) == 0);
    // Then the fall stops at 3e-5: stalled once a window falls by less than 10, from 8.7e-5
    // (the window of the 6th to the 15th iteration: 2.9).
    for (int k = 0; k < 10; ++k) converging.push_back(report(89.466459, 1e-9, true, 3e-5));
    StageStallWatch again(settings);
    CHECK(stalledAt(again, converging) == 15);
  }
  {
    // A non-finite dual infeasibility is no convergence.
    std::vector<IterationReport> reports = flat;
    reports[9].dualInfeasibility = std::numeric_limits<double>::quiet_NaN();
    for (std::size_t k = 0; k < 9; ++k) reports[k].dualInfeasibility = 1e3;
    StageStallWatch watch(settings);
    CHECK(stalledAt(watch, reports) == 10);
  }
  CHECK_THROWS(StageStallWatch(StageStallWatch::Settings{1, 1e-6, 1e-6, 10.0}));
  CHECK_THROWS(StageStallWatch(StageStallWatch::Settings{10, 1e-6, 1e-6, 1.0}));
}

TEST_CASE("continuation: a stage that ended worse than it began hands on its start, in the filter's order",
          "[outer][continuation]") {
  // Throw 41 (1.4 s, 6 m, 0.7 m left) with a margin-row stage between: the Gauss–Newton
  // stage's end, then that stage's end in restoration, both in the last stage's problem.
  const StagePoint gaussNewtonEnd{1.52e-5, 183.5185}, restorationEnd{7.44e-3, 239.1124};
  CHECK(stageEndDominated(gaussNewtonEnd, restorationEnd));
  // Lower in one, higher in the other: the end is kept (the filter would accept it).
  CHECK_FALSE(stageEndDominated({1.52e-5, 240.0}, restorationEnd));
  CHECK_FALSE(stageEndDominated({1e-2, 183.52}, restorationEnd));
  // The usual hand-over: a stage that started far from feasible and ended near an optimum.
  CHECK_FALSE(stageEndDominated({6.98, 61.39}, {1.45e-4, 167.85}));
  CHECK_FALSE(stageEndDominated({1e-3, 100.0}, {1e-9, 99.0}));
  // Equal in both: nothing was gained, the start is as good.
  CHECK(stageEndDominated(restorationEnd, restorationEnd));
}

TEST_CASE("continuation: a stage with another inner solver poses another problem, only where an inner problem picks the wrenches",
          "[outer][continuation]") {
  Scenario s = loadScenario(test::sourceDir() / "scenarios/hrp2_weight_shift.yaml");
  s.inner.solverName = "barrier";
  ContinuationStage stage = s.solve.continuation.at(0);
  stage.innerSolver = "active-set";
  stage.contactForces.clear();  // the run's formulation (the bundled stage's is bilevel's)
  s.solve.continuation = {stage};
  const Scenario first = continuationStage(s, 0), own = continuationStage(s, 1);
  CHECK(first.inner.solverName == "active-set");
  CHECK(own.inner.solverName == "barrier");
  CHECK_FALSE(posesScenarioProblem(first, s));  // its optimum does not end the run
  CHECK(posesScenarioProblem(own, s));
  // The same stage with the scenario's own solver (empty: the scenario's) differs in its Hessian only.
  s.solve.continuation[0].innerSolver.clear();
  CHECK(posesScenarioProblem(continuationStage(s, 0), s));
  // Single-level formulations have no inner problem: the inner solver does not tell two problems apart.
  s.solve.continuation[0].innerSolver = "active-set";
  s.contactForces = "variables";
  CHECK(posesScenarioProblem(continuationStage(s, 0), s));
  // A stage solved in another formulation poses another problem (the bundled stage: bilevel).
  s.solve.continuation[0].contactForces = "bilevel";
  CHECK(continuationStage(s, 0).contactForces == "bilevel");
  CHECK(continuationStage(s, 1).contactForces == "variables");
  CHECK_FALSE(posesScenarioProblem(continuationStage(s, 0), s));
}

TEST_CASE("continuation: a stage with another feasibility row poses another problem, only where an inner problem picks the wrenches",
          "[outer][continuation]") {
  Scenario s = loadScenario(test::sourceDir() / "scenarios/hrp2_weight_shift.yaml");
  s.inner.feasibility = InnerFeasibility::Margin;
  s.solve.continuation.at(0).innerSolver.clear();  // the stage differs in its Hessian and its row only
  s.solve.continuation.at(0).contactForces.clear();
  s.solve.continuation.at(0).feasibility = InnerFeasibility::Slack;
  const Scenario first = continuationStage(s, 0), own = continuationStage(s, s.solve.continuation.size());
  CHECK(first.inner.feasibility == InnerFeasibility::Slack);
  CHECK(own.inner.feasibility == InnerFeasibility::Margin);
  CHECK_FALSE(posesScenarioProblem(first, s));  // its optimum does not end the run
  // Unset: the scenario's row.
  s.solve.continuation[0].feasibility.reset();
  CHECK(continuationStage(s, 0).inner.feasibility == InnerFeasibility::Margin);
  // Single-level formulations have no inner problem: the row does not tell two problems apart.
  s.solve.continuation[0].feasibility = InnerFeasibility::Slack;
  s.contactForces = "variables";
  CHECK(posesScenarioProblem(continuationStage(s, 0), s));
}
