// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The subcommands of `mcopt`; each registers its options on the CLI11 app and returns
// the function that runs it (exit code).

#include <CLI/CLI.hpp>
#include <functional>

namespace mcopt::cli {

using Runner = std::function<int()>;

Runner addRobotInfo(CLI::App& robot);
Runner addRobotCheck(CLI::App& robot);
Runner addRobotInit(CLI::App& robot);
Runner addDynamics(CLI::App& app);
Runner addEvaluate(CLI::App& app);
Runner addInner(CLI::App& app);
Runner addRun(CLI::App& app);
Runner addStudy(CLI::App& app);
Runner addPlot(CLI::App& app);
Runner addReplay(CLI::App& app);
Runner addReport(CLI::App& app);
Runner addVerify(CLI::App& app);

}  // namespace mcopt::cli
