// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A study's folder (docs/reference/studies.md, "The study folder"): study.json (the design and the
// resources), one folder per case with its scenario, the result folder of `mcopt run`, the
// runner's record and the run's log; slurm/ for array scripts and their output; cases.csv and
// plots/ from `mcopt study collect`. Every file is written atomically.

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "study/sweep.hpp"

namespace mcopt::study {

class StudyFolder {
 public:
  explicit StudyFolder(std::filesystem::path root);
  const std::filesystem::path& root() const { return root_; }
  std::filesystem::path studyFile() const { return root_ / "study.json"; }
  std::filesystem::path caseFolder(std::size_t k) const;
  std::filesystem::path scenarioFile(std::size_t k) const { return caseFolder(k) / "scenario.yaml"; }
  std::filesystem::path resultFolder(std::size_t k) const { return caseFolder(k) / "result"; }
  std::filesystem::path recordFile(std::size_t k) const { return caseFolder(k) / "case.json"; }
  std::filesystem::path logFile(std::size_t k) const { return caseFolder(k) / "run.log"; }
  std::filesystem::path slurmFolder() const { return root_ / "slurm"; }
  std::filesystem::path casesCsv() const { return root_ / "cases.csv"; }

 private:
  std::filesystem::path root_;
};

/// What study.json holds: enough to run and collect the cases without the sweep file.
struct StudyDescription {
  std::filesystem::path sweepFile, baseScenario;
  std::string design;
  std::vector<std::string> fields;               ///< the varied field paths
  std::vector<std::vector<std::string>> values;  ///< per case, per field, as text
  CaseResources resources;
  std::size_t caseCount() const { return values.size(); }
};

/// Writes study.json and each case's scenario.yaml. A folder that already holds a study must
/// hold this one — the same design and the same case scenarios — or InputError names the
/// first difference (nothing is written then).
void prepareStudy(const StudyFolder& folder, const Sweep& sweep, const std::vector<StudyCase>& cases);

/// Reads study.json; InputError when it is missing or not a study's.
StudyDescription readStudy(const StudyFolder& folder);

/// Where a case stands, from its result.json and the runner's record (case.json).
enum class CaseState {
  Pending,    ///< never started
  Running,    ///< started and not ended (or its runner was killed outright)
  Finished,   ///< result.json with a final status: optimal or not, a restart does not run it again
  Failed,     ///< the run ended without a result (an error; see run.log)
  TimedOut,   ///< stopped at the case's time limit; the last iterate is its result
  Cancelled,  ///< stopped by SIGTERM, SIGINT or SIGKILL (scancel, Ctrl-C, a killed pool); its last iterate, if it had one
  Crashed     ///< the run died of a signal of its own (SIGSEGV, SIGABRT…) before writing a result
};
/// "pending", "running", "finished", "failed", "timeout", "cancelled", "crashed".
const char* toString(CaseState state);

struct CaseReport {
  CaseState state = CaseState::Pending;
  std::string status;  ///< the result's status when finished, else the state's name
  std::optional<double> energy, maxViolation, seconds;
  std::optional<int> iterations;
  std::string host;
  int attempts = 0;
};

CaseReport caseReport(const StudyFolder& folder, std::size_t k);

/// The runner's record of one attempt (case.json); `end` is empty while it runs.
struct CaseRecord {
  std::string host, end;
  std::string slurmJob;  ///< "JOB_TASK" when run as a Slurm array task
  int attempts = 0, exitCode = -1, signal = 0;
  long pid = 0;
  double seconds = 0.0;
};
std::optional<CaseRecord> readCaseRecord(const StudyFolder& folder, std::size_t k);
void writeCaseRecord(const StudyFolder& folder, std::size_t k, const CaseRecord& record);

/// The cases without a final result, in order: those a (re)start runs.
std::vector<std::size_t> unfinishedCases(const StudyFolder& folder, const StudyDescription& study);

}  // namespace mcopt::study
