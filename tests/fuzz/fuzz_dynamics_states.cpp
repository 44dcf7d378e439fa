// SPDX-License-Identifier: BSD-3-Clause
// `mcopt dynamics --states` input (docs/reference/input-files.md) on HRP-2, with derivatives: the
// command's own reader and the dynamics it runs.
#include "tests/fuzz/fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace fuzz = mcopt::fuzz;
  const std::filesystem::path states = fuzz::workDir() / "states.json";
  fuzz::writeFile(states, data, size);
  fuzz::runCommand(mcopt::cli::addDynamics, {"dynamics", "--robot", fuzz::hrp2File("hrp2.urdf").string(), "--reference-body",
                                             "l_sole", "--states", states.string(), "--derivatives", "--out",
                                             (fuzz::workDir() / "dynamics-out.json").string()});
  return 0;
}
