// SPDX-License-Identifier: BSD-3-Clause
// Inner/<solver>/<contact-model>/<contacts>: one inner solve, cycling through the 100
// samples of an HRP-2 motion in order (each warm-started from the previous sample, as in
// use; "active-set-cold" without). BilevelDynamics/<n>Contacts100/hrp2[/slsqp|/ipopt]: the report's
// Figure 5.2 "dynamic model", a whole motion (splines → Newton–Euler → inner solve at every
// sample → torques, power, energy), N = 100. Threads: OMP_NUM_THREADS (the figure is
// for one: OMP_NUM_THREADS=1).
#include <benchmark/benchmark.h>

#include "bench/bench_fixture.hpp"
#include "bench/hrp2_motion.hpp"
#include "core/robot_files.hpp"
#include "inner_qp/multi_contact_dynamics.hpp"

namespace mcopt::bench {

namespace {

void addInnerCounters(benchmark::State& state, const MultiContactResult& r) {
  const auto samples = static_cast<double>(r.status.size());
  state.counters["iterations/sample"] = r.iterations.cast<double>().sum() / samples;
  state.counters["infeasible"] = r.infeasibleSamples;
  state.counters["failed"] = r.failedSamples;
}

void innerSolve(benchmark::State& state, const std::string& solver, const std::string& model, int contacts) {
  const Hrp2Motion motion;
  MultiContactSettings settings;
  settings.problem.model = makeContactModel(model);
  MultiContactEvaluator evaluator(motion.model, loadActuators(kHrp2 / "actuators.yaml", motion.robot),
                                  SampledTrajectory(motion.parametrization, 100), motion.contacts(contacts), settings);
  MultiContactResult reference;
  std::vector<ContactProblem> problems;
  evaluator.evaluate(motion.parameters, 1.5, reference, problems);
  const bool cold = solver == "active-set-cold";
  InnerSettings solverSettings;
  solverSettings.warmStart = !cold;
  auto inner = makeInnerSolver(cold ? "active-set" : solver, solverSettings);
  InnerResult result;
  long iterations = 0, solves = 0, failed = 0;
  std::size_t s = 0;
  for (auto _ : state) {
    if (s == 0 && solver != "active-set") result = InnerResult{};  // each pass starts cold for the NLP solvers
    inner->solve(problems[s], result);
    iterations += result.iterations;
    failed += result.status == InnerStatus::Failed;
    ++solves;
    s = (s + 1) % problems.size();
  }
  state.counters["iterations/solve"] = static_cast<double>(iterations) / static_cast<double>(solves);
  state.counters["failed/solve"] = static_cast<double>(failed) / static_cast<double>(solves);
  state.counters["variables"] = 6 * contacts;
}

void bilevelDynamics(benchmark::State& state, int contacts, const std::string& solver) {
  const Hrp2Motion motion;
  MultiContactSettings settings;
  settings.solverName = solver;
  MultiContactEvaluator evaluator(motion.model, loadActuators(kHrp2 / "actuators.yaml", motion.robot),
                                  SampledTrajectory(motion.parametrization, 100), motion.contacts(contacts), settings);
  MultiContactResult result;
  evaluator.evaluate(motion.parameters, 1.5, result);
  for (auto _ : state) {
    evaluator.evaluate(motion.parameters, 1.5, result);
    benchmark::DoNotOptimize(result.motion.energy);
  }
  if (!std::isfinite(result.motion.energy)) state.SkipWithError("non-finite energy");
  addInnerCounters(state, result);
  state.counters["inner_us/motion"] = result.innerTimeUs;
}

}  // namespace

void registerInnerBenchmarks() {
  for (const char* solver : {"active-set", "active-set-cold", "slsqp", "ipopt"})
    for (const std::string& modelName : contactModelNames())
      for (int contacts : {2, 3, 4})
        benchmark::RegisterBenchmark(
            ("Inner/" + std::string(solver) + "/" + modelName + "/" + std::to_string(contacts)).c_str(), innerSolve,
            std::string(solver), modelName, contacts)
            ->Unit(benchmark::kMicrosecond);
  // The active-set method under the plain name (the figure earlier tables quote), the NLP
  // solvers with theirs.
  for (const auto& [contacts, label] : std::vector<std::pair<int, std::string>>{{2, "Two"}, {3, "Three"}})
    for (const std::string& solver : innerSolverNames())
      benchmark::RegisterBenchmark(("BilevelDynamics/" + label + "Contacts100/hrp2" + (solver == "active-set" ? "" : "/" + solver)).c_str(),
                                   bilevelDynamics, contacts, solver)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
}

}  // namespace mcopt::bench
