// SPDX-License-Identifier: BSD-3-Clause
// OuterHessian/Kick100/hrp2/<option>: one evaluation of the Lagrangian's Hessian of the
// bundled kick's motion problem (100 samples, 150 spline parameters) at its initial motion,
// with unit multipliers, for each `hessian:` option that evaluates one (docs/theory/outer-problem.md,
// "Hessian and convergence"); beside it Gradient/OneContact100/hrp2 (bench_dynamics.cpp)
// and the whole problem's gradient and Jacobian (OuterGradient/Kick100/hrp2), the unit
// these options are counted in. OuterGradient/weight_shift/<formulation>[/<inner solver>]:
// the same on the bundled weight shift for each contact-force formulation (formulation.md §9).
// OuterHessian/<scenario>/gauss-newton and OuterGradient/lean_reach/bilevel/active-set: the
// bilevel multi-contact scenarios' first stage (closed chains: the closing joints' map in
// every sample) at their initial motion.
// Threads: OMP_NUM_THREADS.
#include <benchmark/benchmark.h>

#include "inner_qp/inner_solver.hpp"
#include "outer_nlp/motion_problem.hpp"

namespace mcopt::bench {

namespace {

Scenario kick(HessianOption hessian) {
  Scenario scenario = loadScenario(std::filesystem::path(MCOPT_SOURCE_DIR) / "scenarios/hrp2_kick.yaml");
  // The smooth maximum with ε = 0.01 W, the kick's first stage and its criterion until the
  // bundled kick took the epigraph form (2026-11-26): the figures in docs/ compare with it.
  scenario.energyForm = EnergyForm::SmoothMaximum;
  scenario.smoothing = 0.01;
  scenario.solve.hessian = hessian;
  return scenario;
}

void outerHessian(benchmark::State& state, const Scenario& scenario) {
  MotionProblem problem(scenario);
  const Eigen::VectorXd x = problem.initialPoint(scenario.start, scenario.end);
  const Eigen::VectorXd multipliers = Eigen::VectorXd::Ones(problem.constraintCount());
  Eigen::VectorXd values;
  for (auto _ : state) {
    problem.lagrangianHessian(x, 1.0, multipliers, values);
    benchmark::DoNotOptimize(values.data());
  }
  state.counters["variables"] = problem.nonlinearVariableCount();
}

void outerGradient(benchmark::State& state, const Scenario& scenario) {
  MotionProblem problem(scenario);
  Eigen::VectorXd x = problem.initialPoint(scenario.start, scenario.end);
  Eigen::VectorXd gradient, jacobian;
  for (auto _ : state) {
    x[1] += 1e-12;  // a new point: defeat the evaluation cache
    problem.objectiveGradient(x, gradient);
    problem.jacobianValues(x, jacobian);
    benchmark::DoNotOptimize(jacobian.data());
  }
}

}  // namespace

void registerOuterHessianBenchmarks() {
  benchmark::RegisterBenchmark("OuterGradient/Kick100/hrp2", outerGradient, kick(HessianOption::LimitedMemory))
      ->Unit(benchmark::kMillisecond);
  // The report's Figure 5.2 "gradient" for each way of choosing the contact forces: the whole
  // outer gradient and Jacobian of the bundled weight shift (60 samples, both soles).
  const auto weightShift = [](const std::string& forces, const std::string& solver) {
    Scenario scenario = loadScenario(std::filesystem::path(MCOPT_SOURCE_DIR) / "scenarios/hrp2_weight_shift.yaml");
    scenario.contactForces = forces;
    scenario.inner.solverName = solver;
    return scenario;
  };
  for (const std::string& solver : innerSolverNames())
    benchmark::RegisterBenchmark(("OuterGradient/weight_shift/bilevel/" + solver).c_str(), outerGradient,
                                 weightShift("bilevel", solver))
        ->Unit(benchmark::kMillisecond);
  for (const std::string forces : {"splines", "variables"})
    benchmark::RegisterBenchmark(("OuterGradient/weight_shift/" + forces).c_str(), outerGradient,
                                 weightShift(forces, "active-set"))
        ->Unit(benchmark::kMillisecond);
  for (const HessianOption option : {HessianOption::FiniteDifferences, HessianOption::SampleDifferences,
                                     HessianOption::GaussNewton, HessianOption::Exact})
    benchmark::RegisterBenchmark((std::string("OuterHessian/Kick100/hrp2/") + toString(option)).c_str(), outerHessian,
                                 kick(option))
        ->Unit(benchmark::kMillisecond);
  const auto bundled = [](const std::string& file) {
    Scenario scenario = loadScenario(std::filesystem::path(MCOPT_SOURCE_DIR) / "scenarios" / file);
    scenario.solve.hessian = HessianOption::GaussNewton;
    return scenario;
  };
  benchmark::RegisterBenchmark("OuterGradient/lean_reach/bilevel/active-set", outerGradient, bundled("hrp2_lean_reach.yaml"))
      ->Unit(benchmark::kMillisecond);
  for (const std::string name : {"weight_shift", "lean_reach"})
    benchmark::RegisterBenchmark(("OuterHessian/" + name + "/gauss-newton").c_str(), outerHessian,
                                 bundled("hrp2_" + name + ".yaml"))
        ->Unit(benchmark::kMillisecond);
}

}  // namespace mcopt::bench
