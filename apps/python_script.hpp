// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The figures are drawn by Python scripts with matplotlib (scripts/plot_*.py), run as child
// processes: `mcopt plot` and `mcopt study collect`; `mcopt report` measures with one.

#include <string>
#include <utility>
#include <vector>

#include "study/child_process.hpp"

namespace mcopt::cli {

/// Python with matplotlib: $MCOPT_PYTHON, else Debian's /usr/bin/python3 (where
/// python3-matplotlib installs), else python3 on PATH.
std::string pythonInterpreter();

/// Runs scripts/NAME (apps/data_paths.hpp: installed or in the source tree) with the arguments: its exit and standard output
/// (its standard error goes to ours).
std::pair<study::ChildExit, std::string> runPythonScript(const std::string& name, const std::vector<std::string>& arguments);

/// Runs scripts/NAME with the arguments, its output and errors on ours as it goes (long
/// scripts: `mcopt report`).
study::ChildExit runPythonScriptAttached(const std::string& name, const std::vector<std::string>& arguments);

/// Why a script's figures were not drawn, for an error line.
std::string pythonFailure(const std::string& name, const study::ChildExit& exit);

}  // namespace mcopt::cli
