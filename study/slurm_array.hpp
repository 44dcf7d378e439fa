// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A study's cases as one Slurm job array (docs/reference/studies.md, "Slurm"): one array task a case,
// each running `mcopt study case DIR $SLURM_ARRAY_TASK_ID`, submitted with sbatch.

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "study/study_folder.hpp"
#include "study/sweep.hpp"

namespace mcopt::study {

/// "0-3,5,7-9": the indices as sbatch --array writes them.
std::string arrayRanges(const std::vector<std::size_t>& indices);

/// The batch script: #SBATCH lines for the array, the output files (slurm/%A_%a.out), one CPU a
/// thread, the case's memory, and a time limit one minute longer than the case's (so that the
/// runner stops the run itself and keeps its last iterate), then the case runner.
std::string arrayScript(const StudyFolder& folder, const Sweep& sweep, const std::vector<std::size_t>& cases,
                        const std::filesystem::path& mcopt);

struct SlurmSubmission {
  std::string jobId;
  std::filesystem::path script;
};

/// Writes the script to slurm/array-N.sh and submits it (sbatch --parsable); with `wait`,
/// returns when every task has ended. Throws std::runtime_error with sbatch's
/// words when it refuses.
SlurmSubmission submitSlurmArray(const StudyFolder& folder, const Sweep& sweep, const std::vector<std::size_t>& cases,
                                 const std::filesystem::path& mcopt, bool wait);

/// Returns when squeue no longer lists any task of the job.
void waitForSlurmJob(const std::string& jobId);

}  // namespace mcopt::study
