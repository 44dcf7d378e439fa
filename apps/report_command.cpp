// SPDX-License-Identifier: BSD-3-Clause
// `mcopt report [--quick] [--out DIR] [--time-limit S] [--docs FILE]`: the report's figures and
// tables measured on this machine, beside the report's own (docs/benchmarks/index.md). The
// measuring is scripts/report.py's: per-evaluation times from mcopt-bench, whole
// optimisations from this executable's `run` in child processes.
#include <filesystem>
#include <iostream>
#include <memory>

#include "apps/commands.hpp"
#include "apps/python_script.hpp"
#include "core/errors.hpp"

namespace mcopt::cli {

namespace {

struct ReportOptions {
  bool quick = false;
  std::string out = "mcopt-report", docs;
  double timeLimit = 600.0;
};

int report([[maybe_unused]] const ReportOptions& o) {  // unused without the benchmarks
#ifndef MCOPT_BENCH_EXECUTABLE
  throw InputError("mcopt was built without its benchmarks (MCOPT_BUILD_BENCH=OFF): configure with it on for mcopt report");
#else
  const std::filesystem::path bench = MCOPT_BENCH_EXECUTABLE;
  if (!std::filesystem::is_regular_file(bench))
    throw InputError(bench.string() + ": mcopt-bench not found (cmake --build the build folder's mcopt-bench target)");
  if (!(o.timeLimit > 0.0)) throw InputError("--time-limit: expected a positive number of seconds");
  if (!o.docs.empty() && !std::filesystem::is_regular_file(o.docs)) throw InputError(o.docs + ": --docs: file not found");
  std::vector<std::string> arguments = {"--mcopt", study::currentExecutable().string(), "--bench", bench.string(), "--source", MCOPT_SOURCE_DIR,
                                        "--out", o.out, "--time-limit", std::to_string(o.timeLimit)};
  if (o.quick) arguments.emplace_back("--quick");
  if (!o.docs.empty()) arguments.insert(arguments.end(), {"--docs", o.docs});
  const study::ChildExit exit = runPythonScriptAttached("report.py", arguments);
  if (!exit.exited || exit.code != 0) {
    std::cerr << "mcopt: error: the report was not completed (" << pythonFailure("report.py", exit) << ")\n";
    return 1;
  }
  return 0;
#endif
}

}  // namespace

Runner addReport(CLI::App& command) {
  auto o = std::make_shared<ReportOptions>();
  command.add_flag("--quick", o->quick, "few repetitions and one Ipopt iteration a run (what CI runs)");
  command.add_option("--out", o->out, "folder for report.md, report.json and the runs")->capture_default_str();
  command.add_option("--time-limit", o->timeLimit, "seconds after which a whole optimisation is stopped (SIGINT)")
      ->capture_default_str();
  command.add_option("--docs", o->docs, "a Markdown file whose generated block gets the tables (docs/benchmarks/index.md)");
  return [o] { return report(*o); };
}

}  // namespace mcopt::cli
