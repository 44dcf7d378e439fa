// SPDX-License-Identifier: BSD-3-Clause
#include "study/local_pool.hpp"

#include <sys/wait.h>

#include <cerrno>
#include <chrono>
#include <map>
#include <thread>

#include "study/child_process.hpp"

namespace mcopt::study {

bool runLocalPool(const StudyFolder& folder, const std::vector<std::size_t>& cases, int jobs,
                  const std::filesystem::path& mcopt, const PoolEvents& events, const volatile std::sig_atomic_t& stop) {
  std::map<pid_t, std::size_t> running;
  std::size_t next = 0;
  bool stopping = false;
  while (next < cases.size() || !running.empty()) {
    if (stop != 0 && !stopping) {
      stopping = true;
      for (const auto& [pid, k] : running) ::kill(pid, SIGTERM);
    }
    while (!stopping && next < cases.size() && static_cast<int>(running.size()) < jobs) {
      const std::size_t k = cases[next++];
      // The runner's output is the case's progress line; the run's own output goes to run.log.
      const pid_t pid = spawnProcess({mcopt.string(), "study", "case", folder.root().string(), std::to_string(k)},
                                     SpawnOptions{folder.caseFolder(k) / "runner.log", {}, true});
      running.emplace(pid, k);
      if (events.onStart) events.onStart(k);
    }
    if (stopping && running.empty()) break;
    int status = 0;
    const pid_t done = ::waitpid(-1, &status, WNOHANG);
    if (done > 0) {
      const auto it = running.find(done);
      if (it == running.end()) continue;
      const std::size_t k = it->second;
      running.erase(it);
      if (events.onEnd) events.onEnd(k, caseReport(folder, k));
      continue;
    }
    if (done < 0 && errno == ECHILD) running.clear();
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return !stopping && next == cases.size();
}

}  // namespace mcopt::study
