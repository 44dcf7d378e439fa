// SPDX-License-Identifier: BSD-3-Clause
// Scenario YAML as `mcopt run` reads it (docs/reference/scenario-file.md): the loader with its side files,
// then the motion problem built from it, up to where Ipopt would start.
#include "core/errors.hpp"
#include "outer_nlp/motion_problem.hpp"
#include "outer_nlp/scenario.hpp"
#include "tests/fuzz/fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path file = mcopt::fuzz::workDir() / "scenarios" / "fuzzed.yaml";
  mcopt::fuzz::writeFile(file, data, size);
  try {
    const mcopt::Scenario scenario = mcopt::loadScenario(file);
    mcopt::MotionProblem problem(scenario);
  } catch (const mcopt::InputError& e) {
    mcopt::fuzz::refused(e);
  }
  return 0;
}
