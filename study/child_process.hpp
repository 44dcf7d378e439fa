// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Starting and waiting for child processes, for the study's case runner, local pool and Slurm
// submission (POSIX fork/exec: each optimisation runs in a process of its own, because Ipopt
// with MUMPS is not safe to run twice at once in one process).

#include <sys/types.h>

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace mcopt::study {

struct SpawnOptions {
  std::filesystem::path output;  ///< standard output and error appended to this file; empty: inherited
  std::vector<std::pair<std::string, std::string>> environment;  ///< variables set in the child
  bool dieWithParent = true;  ///< the child gets SIGTERM when its parent dies (prctl PDEATHSIG)
};

/// Starts argv[0] (a path) with the arguments; throws std::runtime_error when it cannot.
pid_t spawnProcess(const std::vector<std::string>& argv, const SpawnOptions& options);

/// How a child ended: its exit code, or the signal that ended it.
struct ChildExit {
  bool exited = false;
  int code = -1;
  int signal = 0;
};
ChildExit childExit(int waitStatus);

/// Runs a command to its end and returns its exit and standard output (for sbatch, sinfo).
std::pair<ChildExit, std::string> runAndCapture(const std::vector<std::string>& argv);

/// The absolute path of the running executable (/proc/self/exe).
std::filesystem::path currentExecutable();

}  // namespace mcopt::study
