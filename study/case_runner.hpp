// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Runs one case of a study (docs/reference/studies.md, "Running a case"): what a local pool's process and
// a Slurm array task execute (`mcopt study case DIR K`).

#include <csignal>
#include <cstddef>
#include <filesystem>

#include "study/study_folder.hpp"

namespace mcopt::study {

/// Runs `mcopt run` on case k's scenario into its result folder, in a child process with the
/// study's threads (OMP_NUM_THREADS), its output appended to run.log, and records the attempt
/// in case.json (host, attempts, how it ended, seconds). At the case's time limit, or when
/// `stop` becomes non-zero (SIGTERM from scancel or from the pool, Ctrl-C), the run gets
/// SIGTERM and writes its last iterate (status interrupted); SIGKILL follows after
/// kKillGraceSeconds. A case already finished is not run again. Returns 0 when the case is
/// finished (a final status in its result.json), 1 otherwise.
int runCase(const StudyFolder& folder, std::size_t k, const std::filesystem::path& mcopt,
            const volatile std::sig_atomic_t& stop);

/// Whether the attempt a record describes is still running: its Slurm task is still listed by
/// squeue, or its runner's process is alive on this host. A record of a runner that was killed
/// outright (or of another host without Slurm) says "running" but is not.
bool attemptStillRunning(const CaseRecord& record);

inline constexpr double kKillGraceSeconds = 20.0;

}  // namespace mcopt::study
