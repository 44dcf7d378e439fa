// SPDX-License-Identifier: BSD-3-Clause
// `mcopt study`: sweeps of scenarios run as studies (docs/reference/studies.md).
//   mcopt study SWEEP.yaml [--jobs N | --slurm [--wait]] [--out DIR]   prepare, then run the unfinished cases
//   mcopt study collect DIR [--no-plots]                                 cases.csv and summary plots
//   mcopt study case DIR K                                               one case (what pool processes and array tasks run)
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <iomanip>
#include <iostream>
#include <memory>
#include <thread>

#include "apps/commands.hpp"
#include "apps/python_script.hpp"
#include "core/errors.hpp"
#include "study/case_runner.hpp"
#include "study/cases_table.hpp"
#include "study/child_process.hpp"
#include "study/local_pool.hpp"
#include "study/slurm_array.hpp"
#include "study/study_folder.hpp"
#include "study/sweep.hpp"

namespace mcopt::cli {

namespace {

using namespace mcopt::study;

constexpr int kExitUnfinished = 1;
constexpr int kExitInterrupted = 130;

volatile std::sig_atomic_t stopRequested = 0;
extern "C" void requestStudyStop(int) { stopRequested = 1; }

struct StudyOptions {
  std::string sweep, out;
  int jobs = 0;  ///< 0: cores / threads a case
  bool slurm = false, wait = false;
  std::string collectFolder;
  bool noPlots = false;
  std::string caseFolder;
  std::size_t caseIndex = 0;
};

bool onPath(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::string rest = path ? path : "";
  while (!rest.empty()) {
    const std::size_t colon = rest.find(':');
    const std::filesystem::path candidate = std::filesystem::path(rest.substr(0, colon)) / program;
    if (::access(candidate.c_str(), X_OK) == 0) return true;
    rest = colon == std::string::npos ? "" : rest.substr(colon + 1);
  }
  return false;
}

std::string caseLabel(const StudyDescription& study, std::size_t k) {
  std::string label = "case " + std::to_string(k) + " (";
  for (std::size_t i = 0; i < study.fields.size(); ++i)
    label += (i == 0 ? "" : ", ") + study.fields[i] + " = " + study.values[k][i];
  return label + ")";
}

std::string reportText(const CaseReport& r) {
  std::ostringstream text;
  text << r.status;
  if (r.energy) text << ", energy " << std::setprecision(6) << *r.energy << " J";
  if (r.maxViolation) text << ", violation " << std::setprecision(2) << *r.maxViolation;
  if (r.iterations) text << ", " << *r.iterations << " iterations";
  if (r.seconds) text << ", " << std::fixed << std::setprecision(1) << *r.seconds << " s";
  if (!r.host.empty()) text << " on " << r.host;
  return text.str();
}

/// Writes cases.csv and, unless told not to, the plots; prints a line a case. Returns the
/// number of unfinished cases, or -1 when the plots could not be drawn.
int collect(const StudyFolder& folder, bool plots) {
  const StudyDescription study = readStudy(folder);
  const std::vector<CaseReport> reports = writeCasesCsv(folder, study);
  int unfinished = 0;
  for (std::size_t k = 0; k < reports.size(); ++k) {
    std::cout << "  " << caseLabel(study, k) << ": " << reportText(reports[k]) << "\n";
    unfinished += reports[k].state != CaseState::Finished;
  }
  std::cout << "cases: " << folder.casesCsv().string() << " (" << reports.size() - static_cast<std::size_t>(unfinished)
            << " of " << reports.size() << " finished)\n";
  if (!plots) return unfinished;
  const auto [exit, output] = runPythonScript("plot_study.py", {folder.casesCsv().string(), (folder.root() / "plots").string()});
  if (!exit.exited || exit.code != 0) {
    std::cerr << "mcopt: error: the plots were not drawn (" << pythonFailure("plot_study.py", exit) << ")\n";
    return -1;
  }
  std::cout << "plots: " << (folder.root() / "plots").string() << "/energy_vs_*.png, .svg\n";
  return unfinished;
}

int runStudy(const StudyOptions& o) {
  const Sweep sweep = loadSweep(o.sweep);
  const std::vector<StudyCase> cases = designCases(sweep);
  validateCases(sweep, cases);  // before anything is written or submitted
  const StudyFolder folder(o.out.empty() ? "out/study_" + std::filesystem::path(o.sweep).stem().string() : o.out);
  if (o.slurm && !onPath("sbatch"))
    throw InputError("--slurm: sbatch not found on PATH (install Debian's slurm-wlm; a local cluster: scripts/slurm-local.sh start)");
  prepareStudy(folder, sweep, cases);
  const StudyDescription study = readStudy(folder);
  // Cases still running from an earlier start (pool processes on this host, array tasks squeue
  // still lists) are left to it, never run twice at once.
  std::vector<std::size_t> todo, running;
  for (std::size_t k : unfinishedCases(folder, study)) {
    const std::optional<CaseRecord> record = readCaseRecord(folder, k);
    (record && attemptStillRunning(*record) ? running : todo).push_back(k);
  }
  std::cout << "mcopt study " << o.sweep << "\n";
  if (!sweep.description.empty()) std::cout << "  " << sweep.description << "\n";
  std::cout << "  " << cases.size() << " cases (" << toString(sweep.design) << " over";
  for (const VariedField& f : sweep.varied) std::cout << " " << f.path.text;
  std::cout << ") in " << folder.root().string() << "; " << cases.size() - todo.size() - running.size() << " finished, " << todo.size()
            << " to run";
  if (!running.empty()) std::cout << "; " << running.size() << " still running from an earlier start (" << arrayRanges(running) << "): left to it";
  std::cout << "\n";
  if (todo.empty()) return collect(folder, true) == 0 ? 0 : kExitUnfinished;

  const std::filesystem::path mcopt = currentExecutable();
  if (o.slurm) {
    SlurmSubmission submission;
    try {
      submission = submitSlurmArray(folder, sweep, todo, mcopt, o.wait);
    } catch (const std::runtime_error& e) {
      std::cerr << "mcopt: error: " << e.what() << "\n";
      return kExitUnfinished;
    }
    std::cout << "submitted Slurm job array " << submission.jobId << " (" << todo.size() << " tasks: " << arrayRanges(todo)
              << "; script " << submission.script.string() << ")\n";
    if (!o.wait) {
      std::cout << "follow it with: squeue -j " << submission.jobId << "; then: mcopt study collect " << folder.root().string() << "\n";
      return 0;
    }
    const int unfinished = collect(folder, true);
    return unfinished == 0 ? 0 : kExitUnfinished;
  }

  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int jobs = o.jobs > 0 ? o.jobs : std::max(1, cores / study.resources.threads);
  std::cout << "  local pool: " << jobs << " cases at a time, " << study.resources.threads << " thread(s) each\n";
  stopRequested = 0;
  std::signal(SIGINT, requestStudyStop);
  std::signal(SIGTERM, requestStudyStop);
  PoolEvents events;
  events.onStart = [&](std::size_t k) { std::cout << "  started  " << caseLabel(study, k) << std::endl; };
  events.onEnd = [&](std::size_t k, const CaseReport& r) {
    std::cout << "  ended    " << caseLabel(study, k) << ": " << reportText(r) << std::endl;
  };
  const bool complete = runLocalPool(folder, todo, jobs, mcopt, events, stopRequested);
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
  const int unfinished = collect(folder, true);
  if (!complete) {
    std::cerr << "mcopt: study interrupted: the unfinished cases run when it is started again\n";
    return kExitInterrupted;
  }
  return unfinished == 0 ? 0 : kExitUnfinished;
}

int runOneCase(const StudyOptions& o) {
  stopRequested = 0;
  std::signal(SIGINT, requestStudyStop);
  std::signal(SIGTERM, requestStudyStop);
  return runCase(StudyFolder(o.caseFolder), o.caseIndex, currentExecutable(), stopRequested);
}

}  // namespace

Runner addStudy(CLI::App& command) {
  auto o = std::make_shared<StudyOptions>();
  command.add_option("sweep", o->sweep, "sweep YAML file (docs/reference/studies.md)")->check(CLI::ExistingFile);
  command.add_option("--out", o->out, "the study folder (default out/study_<sweep name>)");
  command.add_option("--jobs", o->jobs, "cases at a time on this machine (default: cores / resources.threads)")
      ->check(CLI::PositiveNumber);
  auto* slurm = command.add_flag("--slurm", o->slurm, "submit the unfinished cases as one Slurm job array (sbatch)");
  command.add_flag("--wait", o->wait, "with --slurm: wait for the array to end, then collect")->needs(slurm);
  command.get_option("--jobs")->excludes(slurm);
  CLI::App* collectCommand = command.add_subcommand("collect", "cases.csv and summary plots of a study folder");
  collectCommand->add_option("folder", o->collectFolder, "the study folder")->required()->check(CLI::ExistingDirectory);
  collectCommand->add_flag("--no-plots", o->noPlots, "write cases.csv only");
  CLI::App* caseCommand = command.add_subcommand("case", "run one case of a prepared study (what pool processes and Slurm array tasks run)");
  caseCommand->add_option("folder", o->caseFolder, "the study folder")->required()->check(CLI::ExistingDirectory);
  caseCommand->add_option("index", o->caseIndex, "the case's index")->required();
  return [o, &command, collectCommand, caseCommand]() -> int {
    if (collectCommand->parsed()) {
      std::cout << "mcopt study collect " << o->collectFolder << "\n";
      const int unfinished = collect(StudyFolder(o->collectFolder), !o->noPlots);
      return unfinished < 0 ? kExitUnfinished : 0;
    }
    if (caseCommand->parsed()) return runOneCase(*o);
    if (o->sweep.empty()) throw InputError("mcopt study: give a sweep file, or `collect DIR` (" + command.get_name() + " --help)");
    return runStudy(*o);
  };
}

}  // namespace mcopt::cli
