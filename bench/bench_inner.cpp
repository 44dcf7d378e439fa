// SPDX-License-Identifier: BSD-3-Clause
// Inner/<solver>/<contact-model>/<contacts>: one inner solve, cycling through the 100
// samples of an HRP-2 motion in order (each warm-started from the previous sample, as in
// use; "active-set-cold" without). The problems come from the library's multi-contact
// evaluator on a motion of fixed contact surfaces (bench/hrp2_motion.hpp); the whole motion's
// figures, on the code `mcopt run` runs, are bench_bilevel.cpp's.
#include <benchmark/benchmark.h>

#include "bench/bench_fixture.hpp"
#include "bench/hrp2_motion.hpp"
#include "core/robot_files.hpp"
#include "inner_qp/multi_contact_dynamics.hpp"

namespace mcopt::bench {

namespace {

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
    // Each pass starts cold for the NLP solvers; ours stay warm along the motion.
    if (s == 0 && solver != "active-set" && solver != "barrier") result = InnerResult{};
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

}  // namespace

void registerInnerBenchmarks() {
  for (const char* solver : {"active-set", "active-set-cold", "slsqp", "ipopt"})
    for (const std::string& modelName : contactModelNames())
      for (int contacts : {2, 3, 4})
        benchmark::RegisterBenchmark(
            ("Inner/" + std::string(solver) + "/" + modelName + "/" + std::to_string(contacts)).c_str(), innerSolve,
            std::string(solver), modelName, contacts)
            ->Unit(benchmark::kMicrosecond);
  // The barrier solver's central points (linear contact models only), warm along the motion.
  for (const char* modelName : {"pyramid", "wrench-cone"})
    for (int contacts : {2, 3, 4})
      benchmark::RegisterBenchmark(("Inner/barrier/" + std::string(modelName) + "/" + std::to_string(contacts)).c_str(),
                                   innerSolve, std::string("barrier"), std::string(modelName), contacts)
          ->Unit(benchmark::kMicrosecond);
}

}  // namespace mcopt::bench
