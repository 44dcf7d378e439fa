// OuterHessian/Kick100/hrp2/<option>: one evaluation of the Lagrangian's Hessian of the
// bundled kick's motion problem (100 samples, 150 spline parameters) at its initial motion,
// with unit multipliers, for each `hessian:` option that evaluates one (docs/scenarios.md,
// "Hessian and convergence"); beside it Gradient/OneContact100/hrp2 (bench_sensitivity.cpp)
// and the whole problem's gradient and Jacobian (OuterGradient/Kick100/hrp2), the unit
// these options are counted in. Threads: OMP_NUM_THREADS.
#include <benchmark/benchmark.h>

#include "outer_nlp/motion_problem.hpp"

namespace mcopt::bench {

namespace {

Scenario kick(HessianOption hessian) {
  Scenario scenario = loadScenario(std::filesystem::path(MCOPT_SOURCE_DIR) / "scenarios/hrp2_kick.yaml");
  scenario.hessian = hessian;
  return scenario;
}

void outerHessian(benchmark::State& state, HessianOption option) {
  const Scenario scenario = kick(option);
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

void outerGradient(benchmark::State& state) {
  const Scenario scenario = kick(HessianOption::LimitedMemory);
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
  benchmark::RegisterBenchmark("OuterGradient/Kick100/hrp2", outerGradient)->Unit(benchmark::kMillisecond);
  for (const HessianOption option : {HessianOption::FiniteDifferences, HessianOption::SampleDifferences})
    benchmark::RegisterBenchmark((std::string("OuterHessian/Kick100/hrp2/") + toString(option)).c_str(), outerHessian, option)
        ->Unit(benchmark::kMillisecond);
}

}  // namespace mcopt::bench
