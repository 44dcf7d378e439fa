// SPDX-License-Identifier: BSD-3-Clause
// `mcopt study` as a user meets it (issue 17, docs/reference/studies.md): a sweep on the local pool and
// as a Slurm job array on a real single-node cluster (scripts/slurm-local.sh) giving the same
// cases.csv, restarts after a killed pool and after scancel that run only the unfinished
// cases, a case stopped at its time limit, and bad sweep files refused before anything runs.
#include <signal.h>
#include <sys/types.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <chrono>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "common/run_command.hpp"
#include "common/temp_dir.hpp"
#include "common/test_support.hpp"

using namespace mcopt;
using Catch::Matchers::Contains;
using Json = nlohmann::json;

namespace {

using mcopt::test::kUnderSanitizers;

/// Four cases of the kick at 10 samples: two stopped at 15 iterations (≈ 0.5 s), two at 100
/// (≈ 3 s), so that a test can stop the study while only the last two run.
/// `longIterations`: the iteration limit of cases 2 and 3; with `neverConverged`, a tolerance
/// no case reaches, so that each runs exactly that many iterations.
std::filesystem::path fourCaseSweep(const test::TempDir& dir, const std::string& extra = "", int longIterations = 100,
                                    bool neverConverged = false) {
  return dir.write("sweep.yaml", "description: four short kicks\nscenario: " + (test::sourceDir() / "scenarios/hrp2_kick.yaml").string() +
                                     "\nset:\n  samples: 10\n  initialisation.configuration_optimisation: false\n"
                                     "  hessian: gauss-newton\n  continuation: []\n" +  // one stage: max_iter bounds the run
                                     (neverConverged ? "  solver.tol: 1.0e-14\n  solver.acceptable_iter: 0\n" : "") +
                                     "vary:\n  - {field: solver.max_iter, values: [15, " + std::to_string(longIterations) + "]}\n"
                                     "  - {field: 'tasks[kick].target[0]', values: [0.8, 1.0]}\n"
                                     "resources: {threads: 1, memory: 1G}\n" + extra);
}

std::string fileText(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

/// cases.csv without its last two columns (seconds, host), which differ from run to run.
std::string casesWithoutTimesAndHosts(const std::filesystem::path& out) {
  std::istringstream csv(fileText(out / "cases.csv"));
  std::string line, kept;
  while (std::getline(csv, line)) {
    const std::size_t host = line.rfind(','), seconds = line.rfind(',', host - 1);
    kept += line.substr(0, seconds) + "\n";
  }
  return kept;
}

Json caseRecord(const std::filesystem::path& out, int k) {
  std::ifstream in(out / "cases" / ("000" + std::to_string(k)) / "case.json");
  return in ? Json::parse(in) : Json();
}

std::string resultStatus(const std::filesystem::path& out, int k) {
  std::ifstream in(out / "cases" / ("000" + std::to_string(k)) / "result" / "result.json");
  return in ? Json::parse(in).value("status", "") : "";
}

/// Waits until `ready` holds (true) or the time is up (false).
bool waitFor(const std::function<bool()>& ready, double seconds) {
  const auto start = std::chrono::steady_clock::now();
  while (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() < seconds) {
    if (ready()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return ready();
}

/// Cases 0 and 1 have final results, cases 2 and 3 have started.
/// Whether case k's run has started Ipopt's iterations (its log shows the progress header):
/// stopped from then on it has an iterate to write. A loaded machine can keep it in the
/// configuration optimisation for seconds after its record appears.
bool iterating(const std::filesystem::path& out, int k) {
  const auto log = out / "cases" / (std::string(k < 10 ? "000" : "00") + std::to_string(k)) / "run.log";
  return std::filesystem::exists(log) && fileText(log).find("   iter ") != std::string::npos;
}

bool firstTwoDoneLastTwoRunning(const std::filesystem::path& out) {
  return resultStatus(out, 0) == "maximum_iterations" && resultStatus(out, 1) == "maximum_iterations" &&
         !caseRecord(out, 2).is_null() && !caseRecord(out, 3).is_null() && iterating(out, 2) && iterating(out, 3);
}

/// A restart ran cases 2 and 3 a second time and left 0 and 1 alone: their records and results
/// are those of the first start.
void requireOnlyUnfinishedRerun(const std::filesystem::path& out, const std::string& result0, const std::string& result1) {
  CHECK(caseRecord(out, 0)["attempts"] == 1);
  CHECK(caseRecord(out, 1)["attempts"] == 1);
  CHECK(caseRecord(out, 2)["attempts"] == 2);
  CHECK(caseRecord(out, 3)["attempts"] == 2);
  CHECK(fileText(out / "cases/0000/result/result.json") == result0);
  CHECK(fileText(out / "cases/0001/result/result.json") == result1);
  for (int k = 0; k < 4; ++k) CHECK(caseRecord(out, k)["end"] == "completed");
  CHECK(resultStatus(out, 2) == "maximum_iterations");
}

}  // namespace

TEST_CASE("study: bad sweep files are refused with file, line and field, and nothing is written", "[cli][study]") {
  const test::TempDir dir;
  const std::string kick = (test::sourceDir() / "scenarios/hrp2_kick.yaml").string();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"vary:\n  - {field: objective.nonsense, values: [1]}\n", "sweep.yaml:3: vary[0].values[0]: objective.nonsense = 1: the scenario refuses it: objective.nonsense: unknown key"},
      {"vary:\n  - {field: 'tasks[throw].target[0]', values: [1]}\n", "sweep.yaml:3: vary[0]: tasks[throw].target[0]: 'tasks' has no element named 'throw'"},
      {"vary:\n  - {field: samples, values: [10, ten]}\n", "sweep.yaml:3: vary[0].values[1]: samples = ten: the scenario refuses it: samples: expected a number"},
      {"vary: []\n", "sweep.yaml:2: vary: an empty design"},
      {"design: latin-hypercube\nvary:\n  - {field: samples, range: [10, 20]}\n", "sweep.yaml:1: cases: missing required field"},
  };
  for (const auto& [body, expected] : cases) {
    INFO(body);
    const auto sweep = dir.write("sweep.yaml", "scenario: " + kick + "\n" + body);
    const auto out = dir.path() / "out";
    const auto r = test::runMcopt("study " + test::quoted(sweep) + " --out " + test::quoted(out));
    CHECK(r.exitCode == 2);
    CHECK_THAT(r.errors, Contains(dir.path().string()) && Contains(expected));
    CHECK(!std::filesystem::exists(out));
  }
  const auto r = test::runMcopt("study collect " + test::quoted(dir.path()));
  CHECK(r.exitCode == 2);
  CHECK_THAT(r.errors, Contains("study.json") && Contains("no study here"));
}

TEST_CASE("study: the local pool runs every case, and killed midway and started again it runs only the unfinished ones", "[cli][study]") {
  if (kUnderSanitizers) return;  // ten optimisations: the Release build runs them
  const test::TempDir dir;
  const auto sweep = fourCaseSweep(dir);

  // A whole study, then collect: cases.csv, and the plots drawn by matplotlib.
  const auto whole = dir.path() / "whole";
  const auto r = test::runMcopt("study " + test::quoted(sweep) + " --jobs 2 --out " + test::quoted(whole));
  INFO(r.all());
  REQUIRE(r.exitCode == 0);
  CHECK_THAT(r.output, Contains("4 cases (grid over solver.max_iter tasks[kick].target[0])") && Contains("4 of 4 finished"));
  const std::string cases = casesWithoutTimesAndHosts(whole);
  CHECK_THAT(cases, Contains("case,solver.max_iter,tasks[kick].target[0],status,energy,max_violation,iterations\n0,15,0.8,maximum_iterations,") &&
                        Contains("\n3,100,1.0,maximum_iterations,"));
  for (const char* plot : {"energy_vs_solver.max_iter.png", "energy_vs_tasks_kick_.target_0.svg"})
    CHECK(std::filesystem::file_size(whole / "plots" / plot) > 1000);
  // Each case's scenario is the base with its values, and its result says it ran that scenario.
  CHECK_THAT(fileText(whole / "cases/0002/scenario.yaml"), Contains("# solver.max_iter = 100") && Contains("max_iter: 100"));

  // Started again on a finished study: nothing runs.
  const auto again = test::runMcopt("study " + test::quoted(sweep) + " --jobs 2 --out " + test::quoted(whole));
  CHECK(again.exitCode == 0);
  CHECK_THAT(again.output, Contains("4 finished, 0 to run"));
  CHECK(caseRecord(whole, 3)["attempts"] == 1);

  // Killed outright (SIGKILL) while cases 2 and 3 run: the runners die with the pool, each
  // stopping its run, which writes its last iterate; a restart runs 2 and 3 only.
  const auto killed = dir.path() / "killed";
  const std::string command = "sh -c '" + std::string(MCOPT_EXECUTABLE) + " study " + sweep.string() + " --jobs 2 --out " +
                              killed.string() + " >" + (dir.path() / "pool.log").string() + " 2>&1 & echo $!'";
  FILE* pipe = ::popen(command.c_str(), "r");
  REQUIRE(pipe != nullptr);
  char pidText[32] = {};
  REQUIRE(std::fgets(pidText, sizeof pidText, pipe) != nullptr);
  ::pclose(pipe);
  const pid_t pool = static_cast<pid_t>(std::stol(pidText));
  REQUIRE(waitFor([&] { return firstTwoDoneLastTwoRunning(killed); }, 60.0));
  ::kill(pool, SIGKILL);
  REQUIRE(waitFor([&] { return caseRecord(killed, 2).contains("end") && caseRecord(killed, 3).contains("end"); }, 30.0));
  CHECK(caseRecord(killed, 2)["end"] == "cancelled");
  CHECK(resultStatus(killed, 2) == "interrupted");  // the last iterate, not a half-written file
  const auto collected = test::runMcopt("study collect " + test::quoted(killed) + " --no-plots");
  CHECK_THAT(collected.output, Contains("2 of 4 finished"));
  CHECK_THAT(fileText(killed / "cases.csv"), Contains("\n2,100,0.8,cancelled,"));
  const std::string result0 = fileText(killed / "cases/0000/result/result.json"), result1 = fileText(killed / "cases/0001/result/result.json");

  const auto restart = test::runMcopt("study " + test::quoted(sweep) + " --jobs 2 --out " + test::quoted(killed));
  INFO(restart.all());
  REQUIRE(restart.exitCode == 0);
  CHECK_THAT(restart.output, Contains("2 finished, 2 to run"));
  requireOnlyUnfinishedRerun(killed, result0, result1);
  CHECK(casesWithoutTimesAndHosts(killed) == cases);  // the same results as the uninterrupted study
}

TEST_CASE("study: a case past its time limit is stopped, keeps its last iterate and is reported as a timeout", "[cli][study]") {
  if (kUnderSanitizers) return;
  const test::TempDir dir;
  const auto sweep = dir.write("sweep.yaml", "scenario: " + (test::sourceDir() / "scenarios/hrp2_kick.yaml").string() +
                                                 "\nset: {samples: 10, initialisation.configuration_optimisation: false}\n"
                                                 "vary:\n  - {field: solver.max_iter, values: [3000]}\nresources: {time: 2}\n");
  const auto out = dir.path() / "out";
  const auto r = test::runMcopt("study " + test::quoted(sweep) + " --out " + test::quoted(out));
  INFO(r.all());
  CHECK(r.exitCode == 1);
  CHECK_THAT(r.output, Contains("case 0 (solver.max_iter = 3000): timeout, energy") && Contains("0 of 1 finished"));
  CHECK(caseRecord(out, 0)["end"] == "timeout");
  CHECK(caseRecord(out, 0)["seconds"].get<double>() < 2.0 + 5.0);
  CHECK(resultStatus(out, 0) == "interrupted");
  // A restart runs the case again and keeps the first attempt's iterate beside the new one.
  const std::string first = fileText(out / "cases/0000/result/result.json");
  const auto again = test::runMcopt("study " + test::quoted(sweep) + " --out " + test::quoted(out));
  INFO(again.all());
  CHECK(again.exitCode == 1);
  CHECK(caseRecord(out, 0)["attempts"] == 2);
  CHECK(fileText(out / "cases/0000/result.attempt-1/result.json") == first);
  CHECK(resultStatus(out, 0) == "interrupted");
  CHECK_THAT(fileText(out / "cases/0000/run.log"), Contains("attempt 2 on") && Contains("attempt 1's result kept in result.attempt-1"));
}

#ifdef MCOPT_HAVE_SLURM
TEST_CASE("study: a Slurm job array on a local cluster gives the local pool's cases, and after scancel a restart runs only the unfinished ones",
          "[cli][study][slurm]") {
  if (kUnderSanitizers) return;
  if (::geteuid() != 0) {
    WARN("not root: slurmd cannot start jobs; the Slurm study test does not run");  // CI runs as root
    return;
  }
  const test::TempDir dir;
  const auto cluster = dir.path() / "slurm";
  const std::string script = (test::sourceDir() / "scripts/slurm-local.sh").string();
  const int started = std::system((script + " start " + cluster.string() + " >" + (dir.path() / "slurm-start.log").string() + " 2>&1").c_str());
  // The cluster stops whatever happens below.
  struct Stop {
    std::string command;
    ~Stop() { (void)!std::system(command.c_str()); }
  } stop{script + " stop " + cluster.string() + " >/dev/null 2>&1"};
  INFO(fileText(dir.path() / "slurm-start.log"));
  REQUIRE(started == 0);
  const std::string environment = "SLURM_CONF=" + (cluster / "slurm.conf").string();
  // Cases 2 and 3 run 300 iterations (about 7 s each here): scancel must land while they run,
  // and with 100 (2 s) a loaded machine let case 2 finish first.
  const auto sweep = fourCaseSweep(dir, "", 300, true);

  const auto pool = dir.path() / "pool", slurm = dir.path() / "slurm-study";
  REQUIRE(test::runMcopt("study " + test::quoted(sweep) + " --jobs 2 --out " + test::quoted(pool)).exitCode == 0);
  const auto r = test::runMcopt("study " + test::quoted(sweep) + " --slurm --wait --out " + test::quoted(slurm), environment);
  INFO(r.all());
  REQUIRE(r.exitCode == 0);
  CHECK_THAT(r.output, Contains("submitted Slurm job array") && Contains("(4 tasks: 0-3;") && Contains("4 of 4 finished"));
  CHECK(casesWithoutTimesAndHosts(slurm) == casesWithoutTimesAndHosts(pool));
  CHECK_THAT(fileText(slurm / "slurm/array-1.sh"), Contains("#SBATCH --array=0-3") && Contains("#SBATCH --mem=1G") &&
                                                       Contains("#SBATCH --cpus-per-task=1") && Contains("study case"));
  CHECK(caseRecord(slurm, 3)["slurm_job"].get<std::string>().size() > 2);

  // Submitted without waiting; cancelled with scancel while cases 2 and 3 run.
  const auto cancelled = dir.path() / "cancelled";
  const auto submitted = test::runMcopt("study " + test::quoted(sweep) + " --slurm --out " + test::quoted(cancelled), environment);
  REQUIRE(submitted.exitCode == 0);
  const std::size_t at = submitted.output.find("Slurm job array ");
  REQUIRE(at != std::string::npos);
  const std::string job = std::to_string(std::stol(submitted.output.substr(at + 16)));
  REQUIRE(waitFor([&] { return firstTwoDoneLastTwoRunning(cancelled); }, 60.0));
  REQUIRE(std::system((environment + " scancel " + job).c_str()) == 0);
  REQUIRE(waitFor([&] { return caseRecord(cancelled, 2).contains("end") && caseRecord(cancelled, 3).contains("end"); }, 30.0));
  CHECK(caseRecord(cancelled, 2)["end"] == "cancelled");
  const std::string result0 = fileText(cancelled / "cases/0000/result/result.json"), result1 = fileText(cancelled / "cases/0001/result/result.json");
  const auto restart = test::runMcopt("study " + test::quoted(sweep) + " --slurm --wait --out " + test::quoted(cancelled), environment);
  INFO(restart.all());
  REQUIRE(restart.exitCode == 0);
  CHECK_THAT(restart.output, Contains("(2 tasks: 2-3;"));
  CHECK_THAT(fileText(cancelled / "slurm/array-2.sh"), Contains("#SBATCH --array=2-3"));
  requireOnlyUnfinishedRerun(cancelled, result0, result1);
  CHECK(casesWithoutTimesAndHosts(cancelled) == casesWithoutTimesAndHosts(pool));
}
#endif
