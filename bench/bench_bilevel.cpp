// SPDX-License-Identifier: BSD-3-Clause
// The report's Figure 5.2 for a multi-contact motion, timed on the code `mcopt run` runs (the
// motion problem's one loop over the samples, outer_nlp/motion_problem.cpp), N = 100:
//   BilevelDynamics/<scenario>100/hrp2[/<inner solver>]: the "dynamic model", one evaluation
//     of the motion (splines → closure → Newton–Euler → the inner problem at every sample →
//     torques, power, every row's value, the energy);
//   BilevelGradient/<scenario>100/hrp2/<backend>: the "gradient", the same with every output's
//     derivatives through the inner KKT sensitivity (dense, KLU or UMFPACK factorisation): the
//     energy's gradient and the constraint Jacobian (every torque's among its rows) with
//     respect to the motion's parameters and duration, as Ipopt asks for them.
// <scenario>: WeightShift (the bundled weight shift: two soles, one of them an environment
// contact over the whole motion) and LeanReach (the bundled lean reach: the soles, and the right
// hand on the table over its window), both on 100 samples, the bilevel formulation and the
// scenario's contact model, at the run's initial motion (through a posture that reaches the
// table over the hand's window). Each timed evaluation alternates between that point and a
// neighbour (every spline parameter moved by up to 0.01 rad): every inner solve starts from its
// sample's answer at the other point, as between two Ipopt iterates. Threads: OMP_NUM_THREADS
// (the figures in docs/benchmarks are for one).
#include <benchmark/benchmark.h>

#include <random>

#include "inner_qp/inner_solver.hpp"
#include "outer_nlp/motion_problem.hpp"
#include "outer_nlp/scenario_run.hpp"

namespace mcopt::bench {

namespace {

struct BilevelCase {
  std::string label, file;
};

const std::vector<BilevelCase>& bilevelCases() {
  static const std::vector<BilevelCase> cases = {{"WeightShift100", "hrp2_weight_shift.yaml"},
                                                 {"LeanReach100", "hrp2_lean_reach.yaml"}};
  return cases;
}

Scenario bilevelScenario(const BilevelCase& c, const std::string& solver, KktBackend backend) {
  Scenario scenario = loadScenario(std::filesystem::path(MCOPT_SOURCE_DIR) / "scenarios" / c.file);
  scenario.samples = 100;
  scenario.contactForces = "bilevel";
  scenario.inner.solverName = solver;
  scenario.sensitivity.backend = backend;
  return scenario;
}

/// The run's initial point and its neighbour.
std::array<Eigen::VectorXd, 2> bilevelPoints(MotionProblem& problem) {
  const Scenario& scenario = problem.scenario();
  const Eigen::VectorXd x0 = initialPointThroughContacts(problem, scenario.start, scenario.end, nullptr, {});
  Eigen::VectorXd x1 = x0;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> step(-0.01, 0.01);
  for (int k = 0; k < problem.parametrization().parameterCount(); ++k) x1[k] += step(rng);
  return {x0, x1};
}

void addInnerCounters(benchmark::State& state, const MotionProblem& problem) {
  const MotionProblem::InnerStatistics inner = problem.innerStatistics();
  state.counters["iterations/sample"] = inner.meanIterations;
  state.counters["infeasible"] = inner.infeasible;
  state.counters["failed"] = inner.failed;
  state.counters["variables"] = problem.variableCount();
}

void bilevelDynamics(benchmark::State& state, const BilevelCase& c, const std::string& solver) {
  const Scenario scenario = bilevelScenario(c, solver, KktBackend::Dense);
  MotionProblem problem(scenario);
  const auto points = bilevelPoints(problem);
  double energy = problem.objective(points[1]);
  std::size_t next = 0;
  for (auto _ : state) {
    energy = problem.objective(points[next]);
    benchmark::DoNotOptimize(energy);
    next = 1 - next;
  }
  if (!std::isfinite(energy)) state.SkipWithError("non-finite energy");
  addInnerCounters(state, problem);
}

void bilevelGradient(benchmark::State& state, const BilevelCase& c, KktBackend backend) {
  const Scenario scenario = bilevelScenario(c, "active-set", backend);
  MotionProblem problem(scenario);
  const auto points = bilevelPoints(problem);
  Eigen::VectorXd gradient, jacobian;
  problem.objectiveGradient(points[1], gradient);
  problem.jacobianValues(points[1], jacobian);
  std::size_t next = 0;
  for (auto _ : state) {
    problem.objectiveGradient(points[next], gradient);
    problem.jacobianValues(points[next], jacobian);
    benchmark::DoNotOptimize(jacobian.data());
    next = 1 - next;
  }
  if (!gradient.allFinite() || !jacobian.allFinite()) state.SkipWithError("non-finite gradient");
  addInnerCounters(state, problem);
}

}  // namespace

void registerBilevelBenchmarks() {
  for (const BilevelCase& c : bilevelCases()) {
    // The active-set method under the plain name (the figure earlier tables quote), the other
    // registered solvers with theirs.
    for (const std::string& solver : innerSolverNames())
      benchmark::RegisterBenchmark(("BilevelDynamics/" + c.label + "/hrp2" + (solver == "active-set" ? "" : "/" + solver)).c_str(),
                                   bilevelDynamics, c, solver)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
    for (const KktBackend backend : {KktBackend::Dense, KktBackend::SparseKlu, KktBackend::SparseUmfpack})
      benchmark::RegisterBenchmark(("BilevelGradient/" + c.label + "/hrp2/" + toString(backend)).c_str(), bilevelGradient,
                                   c, backend)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
  }
}

}  // namespace mcopt::bench
