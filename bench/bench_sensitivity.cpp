// SPDX-License-Identifier: BSD-3-Clause
// BilevelGradient/<n>Contacts100/hrp2/<backend>: the report's Figure 5.2 "gradient" of a
// multi-contact motion — energy and every sampled torque (and contact wrench) w.r.t. all
// 150 motion parameters and T, N = 100 — through the inner KKT sensitivity factorised per
// sample with the dense (Eigen LU) or SuiteSparse (KLU, UMFPACK) path. Threads: OMP_NUM_THREADS.
#include <benchmark/benchmark.h>

#include <tuple>

#include "bench/hrp2_motion.hpp"
#include "sensitivity/multi_contact_gradient.hpp"

namespace mcopt::bench {

namespace {

void bilevelGradient(benchmark::State& state, int contacts, KktBackend backend, KktLayout layout) {
  const Hrp2Motion motion;
  SensitivitySettings sensitivity;
  sensitivity.backend = backend;
  sensitivity.layout = layout;
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
  // Per-sample factorisation with each backend, and the all-samples block-diagonal one ("-all").
  const std::vector<std::tuple<std::string, KktBackend, KktLayout>> variants = {
      {"dense", KktBackend::Dense, KktLayout::PerSample},
      {"klu", KktBackend::SparseKlu, KktLayout::PerSample},
      {"umfpack", KktBackend::SparseUmfpack, KktLayout::PerSample},
      {"klu-all", KktBackend::SparseKlu, KktLayout::AllSamples},
      {"umfpack-all", KktBackend::SparseUmfpack, KktLayout::AllSamples}};
  for (const auto& [name, backend, layout] : variants) {
    for (const auto& [label, contacts] : {std::pair{"TwoContacts100", 2}, std::pair{"ThreeContacts100", 3}})
      benchmark::RegisterBenchmark(("BilevelGradient/" + std::string(label) + "/hrp2/" + name).c_str(), bilevelGradient,
                                   contacts, backend, layout)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
  }
}

}  // namespace mcopt::bench
