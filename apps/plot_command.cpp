// SPDX-License-Identifier: BSD-3-Clause
// `mcopt plot RESULT_DIR [--out DIR]`: figures of one optimised motion, PNG and SVG, drawn by
// scripts/plot_result.py with matplotlib (docs/guides/plots.md).
#include <filesystem>
#include <iostream>
#include <memory>

#include "apps/commands.hpp"
#include "apps/python_script.hpp"
#include "core/errors.hpp"

namespace mcopt::cli {

namespace {

struct PlotOptions {
  std::string result, out;
};

int plot(const PlotOptions& o) {
  const std::filesystem::path result = std::filesystem::path(o.result) / "result.json";
  if (!std::filesystem::is_regular_file(result)) throw InputError(result.string() + ": file not found (give the folder `mcopt run --out` wrote)");
  const std::filesystem::path out = o.out.empty() ? std::filesystem::path(o.result) / "plots" : std::filesystem::path(o.out);
  const auto [exit, written] = runPythonScript("plot_result.py", {o.result, out.string()});
  // The script exits 2 for a result it cannot read (its message names the file and field).
  if (exit.exited && exit.code == 2) return 2;
  if (!exit.exited || exit.code != 0) {
    std::cerr << "mcopt: error: the figures were not drawn (" << pythonFailure("plot_result.py", exit) << ")\n";
    return 1;
  }
  std::cout << "mcopt plot " << o.result << "\n" << written;
  return 0;
}

}  // namespace

Runner addPlot(CLI::App& command) {
  auto o = std::make_shared<PlotOptions>();
  command.add_option("result", o->result, "a result folder of mcopt run (with result.json)")->required()->check(CLI::ExistingDirectory);
  command.add_option("--out", o->out, "folder for the figures (default RESULT/plots)");
  return [o] { return plot(*o); };
}

}  // namespace mcopt::cli
