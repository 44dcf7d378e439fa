// SPDX-License-Identifier: BSD-3-Clause
// mcopt: whole-body motion optimisation for humanoid robots in multi-contact.
#include <unistd.h>

#include <cstdlib>
#include <iostream>

#include "apps/commands.hpp"
#include "core/errors.hpp"
#include "core/version.hpp"

namespace {

// One BLAS kernel set on every processor that has it (docs/developers/determinism.md): OpenBLAS
// picks its kernels by processor when it loads, before main, and MUMPS's factorisations round
// differently with each set, so Ipopt took other paths on other processors (a throw neighbour
// optimal with the Haswell kernels ended maximum_iterations with the AVX-512 ones). On a
// processor with AVX2 and FMA, unless OPENBLAS_CORETYPE is set already, the command starts
// itself again with OPENBLAS_CORETYPE=Haswell; where that fails it goes on as it is.
void pinBlasKernels(char** argv) {
#if defined(__x86_64__) && defined(__linux__)
  if (std::getenv("OPENBLAS_CORETYPE") != nullptr) return;
  __builtin_cpu_init();
  if (!__builtin_cpu_supports("avx2") || !__builtin_cpu_supports("fma")) return;
  if (setenv("OPENBLAS_CORETYPE", "Haswell", 1) != 0) return;
  execv("/proc/self/exe", argv);
  unsetenv("OPENBLAS_CORETYPE");  // not started again: this process keeps the kernels it has
#else
  (void)argv;
#endif
}

}  // namespace

int main(int argc, char** argv) {
  pinBlasKernels(argv);
  CLI::App app{"mcopt — whole-body motion optimisation for humanoid robots in multi-contact"};
  app.set_version_flag("--version", std::string("mcopt ") + mcopt::kVersion);
  app.require_subcommand(1);
  CLI::App* robot = app.add_subcommand("robot", "inspect a robot description");
  robot->require_subcommand(1);
  mcopt::cli::Runner run;
  std::vector<std::pair<CLI::App*, mcopt::cli::Runner>> runners;
  CLI::App* info = robot->add_subcommand("info", "bodies, actuated joints, mass and centre of mass");
  runners.emplace_back(info, mcopt::cli::addRobotInfo(*info));
  CLI::App* check = robot->add_subcommand("check", "whether the robot can hold each named posture, on both feet and on each");
  runners.emplace_back(check, mcopt::cli::addRobotCheck(*check));
  CLI::App* init = robot->add_subcommand("init", "write a robot folder from a URDF: side files, a standing posture, starter scenarios");
  runners.emplace_back(init, mcopt::cli::addRobotInit(*init));
  CLI::App* dynamics = app.add_subcommand("dynamics", "inverse dynamics of given states at a fixed reference body");
  runners.emplace_back(dynamics, mcopt::cli::addDynamics(*dynamics));
  CLI::App* evaluate = app.add_subcommand("evaluate", "torques, reference wrench and energy of a spline motion");
  runners.emplace_back(evaluate, mcopt::cli::addEvaluate(*evaluate));
  CLI::App* runCommand = app.add_subcommand("run", "optimise a motion from a scenario file with Ipopt");
  runners.emplace_back(runCommand, mcopt::cli::addRun(*runCommand));
  CLI::App* study = app.add_subcommand("study", "sweeps of scenarios on a local process pool or as a Slurm job array");
  runners.emplace_back(study, mcopt::cli::addStudy(*study));
  CLI::App* plotCommand = app.add_subcommand("plot", "figures of an optimised motion (PNG and SVG, matplotlib)");
  runners.emplace_back(plotCommand, mcopt::cli::addPlot(*plotCommand));
  CLI::App* replayCommand = app.add_subcommand("replay", "a self-contained HTML page animating an optimised motion in 3-D (three.js)");
  runners.emplace_back(replayCommand, mcopt::cli::addReplay(*replayCommand));
  CLI::App* reportCommand = app.add_subcommand("report", "the report's figures and tables measured on this machine, beside its own");
  runners.emplace_back(reportCommand, mcopt::cli::addReport(*reportCommand));
  CLI::App* verify = app.add_subcommand("verify", "certify a result's motion between its samples: every constraint on a fine grid");
  runners.emplace_back(verify, mcopt::cli::addVerify(*verify));
  CLI::App* inner = app.add_subcommand("inner", "solve per-sample contact-force problems given as data");
  runners.emplace_back(inner, mcopt::cli::addInner(*inner));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0; an option refused is bad input like any other: 2
    // (docs/guides/troubleshooting.md), not CLI11's own codes.
    return app.exit(e) == 0 ? 0 : 2;
  }
  try {
    for (auto& [command, runner] : runners)
      if (command->parsed()) return runner();
  } catch (const mcopt::InputError& e) {
    std::cerr << "mcopt: error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "mcopt: internal error: " << e.what() << "\n";
    return 3;
  }
  return 1;
}
