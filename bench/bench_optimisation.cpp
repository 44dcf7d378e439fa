// SPDX-License-Identifier: BSD-3-Clause
// Optimisation/<scenario>/<formulation>[/<inner solver>]: Ipopt on a bundled scenario's motion
// problem (formulation.md §9, §10), from the scenario's initial motion, for a fixed number of
// iterations (counter `max_iter`; the multi-contact scenarios do not converge yet, docs/
// scenarios.md): wall time of the run, iterations done, time per iteration, the status and
// the largest violation reached. Each repetition builds the problem anew (cold inner warm
// starts), as `mcopt run` does. Threads: OMP_NUM_THREADS.
#include <benchmark/benchmark.h>

#include <chrono>

#include "outer_nlp/outer_solver.hpp"
#include "outer_nlp/motion_problem.hpp"

namespace mcopt::bench {

namespace {

constexpr int kIterations = 5;

void optimisation(benchmark::State& state, const std::string& file, const std::string& forces, const std::string& solver) {
  Scenario scenario = loadScenario(std::filesystem::path(MCOPT_SOURCE_DIR) / "scenarios" / file);
  scenario.contactForces = forces;
  scenario.inner.solverName = solver;
  SolverOption limit;
  limit.name = "max_iter", limit.type = SolverOption::Type::Integer, limit.integer = kIterations;
  scenario.solve.solverOptions.push_back(limit);
  OuterSolverSettings settings;
  settings.options = scenario.solve.solverOptions;
  settings.problemHessian = scenario.solve.hessian != HessianOption::LimitedMemory;
  OuterOutcome outcome;
  double violation = 0.0, seconds = 0.0;
  for (auto _ : state) {
    const auto clock = std::chrono::steady_clock::now();
    MotionProblem problem(scenario);
    const Eigen::VectorXd x0 = problem.initialPoint(scenario.start, scenario.end);
    outcome = solveOuter(problem, x0, settings, nullptr);
    seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - clock).count();
    state.SetIterationTime(seconds);
    violation = outcome.x.size() == x0.size() ? problem.violations(outcome.x).overall : -1.0;
  }
  if (outcome.x.size() == 0) state.SkipWithError(("Ipopt returned no iterate: " + outcome.message).c_str());
  state.counters["max_iter"] = kIterations;
  state.counters["iterations"] = outcome.iterations;
  state.counters["s_per_iteration"] = seconds / std::max(1, outcome.iterations);
  state.counters["violation"] = violation;
  state.counters["optimal"] = outcome.optimal() ? 1 : 0;
}

}  // namespace

void registerOptimisationBenchmarks() {
  for (const char* file : {"hrp2_weight_shift.yaml", "hrp2_lean_reach.yaml"}) {
    const std::string name = std::string(file).substr(5, std::string(file).size() - 10);  // hrp2_X.yaml → X
    auto add = [&](const std::string& label, const std::string& forces, const std::string& solver) {
      benchmark::RegisterBenchmark(("Optimisation/" + name + "/" + label).c_str(), optimisation, std::string(file), forces,
                                   solver)
          ->Unit(benchmark::kSecond)
          ->UseManualTime()
          ->Iterations(1);
    };
    for (const char* solver : {"active-set", "slsqp", "ipopt"})
      add(std::string("bilevel/") + solver, "bilevel", solver);
    add("splines", "splines", "active-set");
    add("variables", "variables", "active-set");
  }
}

}  // namespace mcopt::bench
