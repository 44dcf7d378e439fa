// SPDX-License-Identifier: BSD-3-Clause
#include "study/case_runner.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <algorithm>
#include <chrono>
#include <ctime>
#include <fstream>
#include <iostream>
#include <thread>

#include "core/errors.hpp"
#include "study/child_process.hpp"

namespace mcopt::study {

namespace {

std::string hostName() {
  char name[256] = {};
  ::gethostname(name, sizeof name - 1);
  return name;
}

std::string now() {
  const std::time_t t = std::time(nullptr);
  char text[64];
  std::strftime(text, sizeof text, "%Y-%m-%d %H:%M:%S UTC", std::gmtime(&t));
  return text;
}

}  // namespace

bool attemptStillRunning(const CaseRecord& record) {
  if (!record.end.empty()) return false;
  if (!record.slurmJob.empty()) {
    const auto [exit, output] = runAndCapture({"squeue", "--noheader", "--jobs=" + record.slurmJob, "--format=%i"});
    return exit.exited && exit.code == 0 && output.find_first_not_of(" \n") != std::string::npos;
  }
  return record.host == hostName() && record.pid > 0 && record.pid != ::getpid() && ::kill(static_cast<pid_t>(record.pid), 0) == 0;
}

int runCase(const StudyFolder& folder, std::size_t k, const std::filesystem::path& mcopt, const volatile std::sig_atomic_t& stop) {
  const StudyDescription study = readStudy(folder);
  if (k >= study.caseCount())
    throw InputError("case " + std::to_string(k) + ": the study in " + folder.root().string() + " has " +
                     std::to_string(study.caseCount()) + " cases");
  if (caseReport(folder, k).state == CaseState::Finished) {
    std::cout << "case " << k << ": already finished\n";
    return 0;
  }
  const std::optional<CaseRecord> previous = readCaseRecord(folder, k);
  if (previous && attemptStillRunning(*previous)) {
    std::cout << "case " << k << ": already running (" << (previous->slurmJob.empty() ? "process " + std::to_string(previous->pid) : "Slurm task " + previous->slurmJob)
              << " on " << previous->host << "): not started twice\n";
    return 1;
  }
  CaseRecord record;
  record.host = hostName();
  record.attempts = (previous ? previous->attempts : 0) + 1;
  record.pid = ::getpid();
  const char* arrayJob = std::getenv("SLURM_ARRAY_JOB_ID");
  const char* arrayTask = std::getenv("SLURM_ARRAY_TASK_ID");
  if (arrayJob && arrayTask) record.slurmJob = std::string(arrayJob) + "_" + arrayTask;
  writeCaseRecord(folder, k, record);
  // An earlier attempt's result (a timed-out or stopped run's last iterate) is kept beside the
  // new one, never overwritten: result.attempt-N holds attempt N's.
  std::string kept;
  if (previous && std::filesystem::exists(folder.resultFolder(k))) {
    const std::filesystem::path aside =
        folder.caseFolder(k) / ("result.attempt-" + std::to_string(std::max(previous->attempts, 1)));
    std::filesystem::remove_all(aside);
    std::filesystem::rename(folder.resultFolder(k), aside);
    kept = "; attempt " + std::to_string(std::max(previous->attempts, 1)) + "'s result kept in " + aside.filename().string();
  }
  {
    std::ofstream log(folder.logFile(k), std::ios::app);
    log << "=== case " << k << ", attempt " << record.attempts << " on " << record.host << ", " << now() << kept << "\n";
  }

  SpawnOptions options;
  options.output = folder.logFile(k);
  options.environment = {{"OMP_NUM_THREADS", std::to_string(study.resources.threads)}};
  const auto clock = std::chrono::steady_clock::now();
  const auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - clock).count(); };
  const pid_t child = spawnProcess({mcopt.string(), "run", folder.scenarioFile(k).string(), "--out", folder.resultFolder(k).string()}, options);

  bool timedOut = false, cancelled = false;
  double terminatedAt = -1.0;
  int status = 0;
  const double limit = study.resources.timeLimitSeconds;
  for (;;) {
    const pid_t done = ::waitpid(child, &status, WNOHANG);
    if (done == child) break;
    if (done < 0 && errno != EINTR) break;
    if (terminatedAt < 0.0 && (stop != 0 || (limit > 0.0 && elapsed() >= limit))) {
      // Slurm's own time limit arrives as SIGTERM too: within its last minute it is a timeout.
      timedOut = limit > 0.0 && elapsed() >= limit - 60.0;
      cancelled = !timedOut;
      ::kill(child, SIGTERM);
      terminatedAt = elapsed();
    } else if (terminatedAt >= 0.0 && elapsed() - terminatedAt > kKillGraceSeconds) {
      ::kill(child, SIGKILL);
      terminatedAt = 1e300;  // once
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  const ChildExit exit = childExit(status);
  // The stop may arrive as the run ends, or reach the run before its own handler is set
  // (scancel signals every process of the task at once): it decides, not the loop's timing.
  if (!timedOut && !cancelled && stop != 0) {
    timedOut = limit > 0.0 && elapsed() >= limit - 60.0;
    cancelled = !timedOut;
  }
  const bool stoppedBySignal = !exit.exited && (exit.signal == SIGTERM || exit.signal == SIGINT || exit.signal == SIGKILL);
  record.seconds = elapsed();
  record.exitCode = exit.code;
  record.signal = exit.signal;
  const bool finished = caseReport(folder, k).state == CaseState::Finished;
  if (finished) record.end = "completed";
  else if (timedOut) record.end = "timeout";
  else if (cancelled || (exit.exited && exit.code == 130) || stoppedBySignal) record.end = "cancelled";
  else if (!exit.exited) record.end = "crashed";
  else record.end = "failed";
  writeCaseRecord(folder, k, record);
  const CaseReport report = caseReport(folder, k);
  std::cout << "case " << k << ": " << report.status;
  if (!exit.exited) std::cout << " (signal " << exit.signal << ")";
  else if (!finished) std::cout << " (exit code " << exit.code << "; " << folder.logFile(k).string() << ")";
  std::cout << " after " << record.seconds << " s on " << record.host << "\n";
  return finished ? 0 : 1;
}

}  // namespace mcopt::study
