// SPDX-License-Identifier: BSD-3-Clause
#include "study/slurm_array.hpp"

#include <chrono>
#include <cmath>
#include <thread>
#include <cstdio>
#include <stdexcept>

#include "core/atomic_file.hpp"
#include "study/child_process.hpp"

namespace mcopt::study {

namespace {

std::string shellQuoted(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

/// Slurm's D-HH:MM:SS.
std::string slurmTime(double seconds) {
  const long total = static_cast<long>(std::ceil(seconds));
  char text[64];
  std::snprintf(text, sizeof text, "%ld-%02ld:%02ld:%02ld", total / 86400, total / 3600 % 24, total / 60 % 60, total % 60);
  return text;
}

}  // namespace

std::string arrayRanges(const std::vector<std::size_t>& indices) {
  std::string text;
  for (std::size_t i = 0; i < indices.size();) {
    std::size_t j = i;
    while (j + 1 < indices.size() && indices[j + 1] == indices[j] + 1) ++j;
    text += (text.empty() ? "" : ",") + std::to_string(indices[i]);
    if (j > i) text += "-" + std::to_string(indices[j]);
    i = j + 1;
  }
  return text;
}

std::string arrayScript(const StudyFolder& folder, const Sweep& sweep, const std::vector<std::size_t>& cases,
                        const std::filesystem::path& mcopt) {
  const std::filesystem::path root = std::filesystem::absolute(folder.root()).lexically_normal();
  std::string s = "#!/bin/bash\n# A study's cases as a Slurm job array, written by `mcopt study --slurm` (docs/reference/studies.md).\n";
  s += "# Sweep " + std::filesystem::absolute(sweep.file).lexically_normal().string() + "\n";
  s += "#SBATCH --job-name=mcopt-study\n";
  s += "#SBATCH --array=" + arrayRanges(cases) + "\n";
  s += "#SBATCH --output=" + (root / "slurm" / "%A_%a.out").string() + "\n";
  s += "#SBATCH --ntasks=1\n#SBATCH --cpus-per-task=" + std::to_string(sweep.resources.threads) + "\n";
  if (sweep.resources.timeLimitSeconds > 0.0) s += "#SBATCH --time=" + slurmTime(sweep.resources.timeLimitSeconds + 60.0) + "\n";
  if (!sweep.resources.memory.empty()) s += "#SBATCH --mem=" + sweep.resources.memory + "\n";
  if (!sweep.slurm.partition.empty()) s += "#SBATCH --partition=" + sweep.slurm.partition + "\n";
  if (!sweep.slurm.account.empty()) s += "#SBATCH --account=" + sweep.slurm.account + "\n";
  for (const std::string& option : sweep.slurm.options) s += "#SBATCH " + option + "\n";
  s += "exec " + shellQuoted(mcopt.string()) + " study case " + shellQuoted(root.string()) + " \"$SLURM_ARRAY_TASK_ID\"\n";
  return s;
}

SlurmSubmission submitSlurmArray(const StudyFolder& folder, const Sweep& sweep, const std::vector<std::size_t>& cases,
                                 const std::filesystem::path& mcopt, bool wait) {
  std::filesystem::create_directories(folder.slurmFolder());
  SlurmSubmission submission;
  for (int n = 1;; ++n) {
    submission.script = folder.slurmFolder() / ("array-" + std::to_string(n) + ".sh");
    if (!std::filesystem::exists(submission.script)) break;
  }
  writeFileAtomically(submission.script, arrayScript(folder, sweep, cases, mcopt));
  const auto [exit, output] = runAndCapture({"sbatch", "--parsable", submission.script.string()});
  // --parsable prints "jobid" or "jobid;cluster".
  submission.jobId = output.substr(0, output.find_first_of(";\n"));
  if (submission.jobId.empty() || submission.jobId.find_first_not_of("0123456789") != std::string::npos)
    throw std::runtime_error("sbatch did not submit " + submission.script.string() + " (exit code " + std::to_string(exit.code) +
                             (output.empty() ? "" : ": " + output) + ")");
  if (wait) waitForSlurmJob(submission.jobId);
  return submission;
}

void waitForSlurmJob(const std::string& jobId) {
  // squeue lists a job while any of its tasks is pending, running or completing. (sbatch
  // --wait polls at intervals growing to tens of seconds: a short study would wait longer
  // than it ran.)
  for (;;) {
    const auto [exit, output] = runAndCapture({"squeue", "--noheader", "--array", "--jobs=" + jobId, "--format=%i"});
    if (exit.exited && exit.code == 0 && output.find_first_not_of(" \n") == std::string::npos) return;
    if (!exit.exited || (exit.code != 0 && output.empty())) {
      // squeue refuses a job id the controller has forgotten: the job ended long ago.
      const auto [check, listed] = runAndCapture({"squeue", "--noheader", "--format=%i"});
      if (!check.exited || check.code != 0) throw std::runtime_error("squeue failed while waiting for job " + jobId);
      if (listed.find(jobId) == std::string::npos) return;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
  }
}

}  // namespace mcopt::study
