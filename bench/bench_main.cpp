// SPDX-License-Identifier: BSD-3-Clause
// mcopt-bench: every benchmark is named Module/Case/robot so a run can be filtered
// (--benchmark_filter=InverseDynamics/PerSample). Machine, build type and commit are
// printed with the numbers. Threads for the trajectory cases: OMP_NUM_THREADS.
#include <benchmark/benchmark.h>
#include <omp.h>

namespace mcopt::bench {
void registerDynamicsBenchmarks();
void registerInnerBenchmarks();
void registerBilevelBenchmarks();
void registerOptimisationBenchmarks();
void registerOuterHessianBenchmarks();
}

int main(int argc, char** argv) {
  benchmark::AddCustomContext("mcopt_commit", MCOPT_GIT_COMMIT);
  benchmark::AddCustomContext("mcopt_build_type", MCOPT_BUILD_TYPE);
  benchmark::AddCustomContext("omp_max_threads", std::to_string(omp_get_max_threads()));
  mcopt::bench::registerDynamicsBenchmarks();
  mcopt::bench::registerInnerBenchmarks();
  mcopt::bench::registerBilevelBenchmarks();
  mcopt::bench::registerOptimisationBenchmarks();
  mcopt::bench::registerOuterHessianBenchmarks();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
