// SPDX-License-Identifier: BSD-3-Clause
// `mcopt inner --problems` input (docs/theory/inner-problem.md): the command's reader, the active-set
// solver with warm starts along the problems, and the KKT sensitivity of each result.
#include "tests/fuzz/fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace fuzz = mcopt::fuzz;
  const std::filesystem::path problems = fuzz::workDir() / "problems.json";
  fuzz::writeFile(problems, data, size);
  fuzz::runCommand(mcopt::cli::addInner, {"inner", "--problems", problems.string(), "--sensitivity", "--out",
                                          (fuzz::workDir() / "inner-out.json").string()});
  return 0;
}
