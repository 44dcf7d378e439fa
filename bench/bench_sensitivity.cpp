// BilevelGradient/<n>Contacts100/hrp2/<backend>: the report's Figure 5.2 "gradient" of a
// multi-contact motion — energy and every sampled torque (and contact wrench) w.r.t. all
// 150 motion parameters and T, N = 100 — through the inner KKT sensitivity factorised per
// sample with the dense (Eigen LU) or SuiteSparse (KLU, UMFPACK) path. Threads: OMP_NUM_THREADS.
#include <benchmark/benchmark.h>

#include "bench/hrp2_motion.hpp"
#include "sensitivity/multi_contact_gradient.hpp"

namespace mcopt::bench {

namespace {

void bilevelGradient(benchmark::State& state, int contacts, KktBackend backend) {
  const Hrp2Motion motion;
  SensitivitySettings sensitivity;
  sensitivity.backend = backend;
  MultiContactGradientEvaluator evaluator(motion.model, loadActuators(kHrp2 / "actuators.yaml", motion.robot),
                                          SampledTrajectory(motion.parametrization, 100), motion.contacts(contacts), {},
                                          sensitivity);
  MultiContactResult result;
  MultiContactGradient gradient;
  evaluator.evaluate(motion.parameters, 1.5, result, gradient);
  for (auto _ : state) {
    evaluator.evaluate(motion.parameters, 1.5, result, gradient);
    benchmark::DoNotOptimize(gradient.torqueAndEnergy.energyGradient.data());
  }
  if (!gradient.torqueAndEnergy.energyGradient.allFinite()) state.SkipWithError("non-finite gradient");
  state.counters["degenerate"] = gradient.degenerateSamples;
  state.counters["no_derivative"] = gradient.samplesWithoutDerivative;
  state.counters["parameters"] = motion.parametrization.parameterCount() + 1;
}

}  // namespace

void registerSensitivityBenchmarks() {
  for (KktBackend backend : {KktBackend::Dense, KktBackend::SparseKlu, KktBackend::SparseUmfpack}) {
    const std::string suffix = std::string("/hrp2/") + toString(backend);
    benchmark::RegisterBenchmark(("BilevelGradient/TwoContacts100" + suffix).c_str(), bilevelGradient, 2, backend)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
    benchmark::RegisterBenchmark(("BilevelGradient/ThreeContacts100" + suffix).c_str(), bilevelGradient, 3, backend)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  }
}

}  // namespace mcopt::bench
