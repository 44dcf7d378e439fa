// SPDX-License-Identifier: BSD-3-Clause
// Sweeps (docs/reference/studies.md): field paths, the three designs, validation of every case by the
// scenario loader with errors at the sweep's own lines, array ranges, the study folder.
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <fstream>
#include <set>

#include "common/temp_dir.hpp"
#include "common/test_support.hpp"
#include "core/errors.hpp"
#include "study/case_runner.hpp"
#include "study/cases_table.hpp"
#include "study/field_path.hpp"
#include "study/slurm_array.hpp"
#include "study/study_folder.hpp"
#include "study/sweep.hpp"

using namespace mcopt;
using namespace mcopt::study;
using Catch::Matchers::Contains;
using Catch::Matchers::StartsWith;

namespace {

const std::filesystem::path kKick = test::sourceDir() / "scenarios/hrp2_kick.yaml";

std::filesystem::path writeSweep(const test::TempDir& dir, const std::string& body) {
  return dir.write("sweep.yaml", "scenario: " + kKick.string() + "\n" + body);
}

std::string loadError(const std::filesystem::path& file) {
  try {
    const Sweep sweep = loadSweep(file);
    validateCases(sweep, designCases(sweep));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("study: field paths name keys, list indices and list elements by name", "[study]") {
  YAML::Node root = YAML::Load("samples: 100\ntasks:\n  - {name: kick, target: [1.0, 0.0, 0.0]}\n  - {name: other, target: [0, 0, 0]}\n");
  setField(root, parseFieldPath("tasks[kick].target[0]"), YAML::Node(0.5));
  setField(root, parseFieldPath("tasks[1].target[2]"), YAML::Node(7));
  setField(root, parseFieldPath("samples"), YAML::Node(20));
  setField(root, parseFieldPath("inner.solver"), YAML::Node("slsqp"));  // an absent optional mapping is created
  CHECK(root["tasks"][0]["target"][0].as<double>() == 0.5);
  CHECK(root["tasks"][0]["target"][1].as<double>() == 0.0);
  CHECK(root["tasks"][1]["target"][2].as<int>() == 7);
  CHECK(root["tasks"][1]["name"].as<std::string>() == "other");  // the other element untouched
  CHECK(root["samples"].as<int>() == 20);
  CHECK(root["inner"]["solver"].as<std::string>() == "slsqp");

  const auto refused = [&](const std::string& path) {
    try {
      setField(root, parseFieldPath(path), YAML::Node(1));
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  CHECK_THAT(refused("tasks[throw].target[0]"), Contains("'tasks' has no element named 'throw'"));
  CHECK_THAT(refused("tasks[5]"), Contains("'tasks' has 2 elements: no [5]"));
  CHECK_THAT(refused("samples.x"), Contains("'samples' is not a mapping"));
  CHECK_THAT(refused("missing[0]"), Contains("'missing' is not a list (it is absent)"));
  for (const char* bad : {"", "a..b", "a.", "[0]", "a[", "a[]", "a b", "a]b"}) {
    INFO(bad);
    CHECK_THROWS_AS(parseFieldPath(bad), std::invalid_argument);
  }
}

TEST_CASE("study: a field read by its path is the field set there, and a missing one says which step", "[study]") {
  const YAML::Node root = YAML::Load("samples: 100\ntasks:\n  - {name: kick, target: [1.0, 0.0, 0.0]}\n  - {name: other, target: [0, 0, 2]}\n");
  CHECK(getField(root, parseFieldPath("samples")).as<int>() == 100);
  CHECK(getField(root, parseFieldPath("tasks[kick].target[0]")).as<double>() == 1.0);
  CHECK(getField(root, parseFieldPath("tasks[1].target[2]")).as<int>() == 2);
  CHECK(getField(root, parseFieldPath("tasks[other].name")).as<std::string>() == "other");
  // A copy: changing what was read leaves the tree as it was.
  YAML::Node read = getField(root, parseFieldPath("tasks[kick].target"));
  read[0] = 9.0;
  CHECK(root["tasks"][0]["target"][0].as<double>() == 1.0);
  const auto refused = [&](const std::string& path) {
    try {
      (void)getField(root, parseFieldPath(path));
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  CHECK_THAT(refused("inner.solver"), Contains("'inner' is not set"));
  CHECK_THAT(refused("tasks[throw]"), Contains("'tasks' has no element named 'throw'"));
  CHECK_THAT(refused("tasks[7]"), Contains("'tasks' has 2 elements: no [7]"));
  CHECK_THAT(refused("samples.x"), Contains("'samples' is not a mapping"));
  CHECK_THAT(refused("samples[0]"), Contains("'samples' is not a list"));
}

TEST_CASE("study: a grid runs through every combination, the first field slowest", "[study]") {
  const test::TempDir dir;
  const Sweep sweep = loadSweep(writeSweep(dir, "vary:\n  - {field: samples, values: [10, 12, 14]}\n"
                                                "  - {field: 'tasks[kick].target[0]', values: [0.8, 1.0]}\n"));
  const std::vector<StudyCase> cases = designCases(sweep);
  REQUIRE(cases.size() == 6);
  for (std::size_t k = 0; k < 6; ++k) {
    CHECK(cases[k].index == k);
    CHECK(cases[k].values[0].as<int>() == 10 + 2 * static_cast<int>(k / 2));
    CHECK(cases[k].values[1].as<double>() == (k % 2 == 0 ? 0.8 : 1.0));
    CHECK(cases[k].scenario["samples"].as<int>() == cases[k].values[0].as<int>());
    CHECK(cases[k].scenario["tasks"][0]["target"][0].as<double>() == cases[k].values[1].as<double>());
    // Side files absolute: the case's scenario is written in the study folder.
    CHECK(std::filesystem::path(cases[k].scenario["robot"].as<std::string>()).is_absolute());
  }
  REQUIRE_NOTHROW(validateCases(sweep, cases));
}

TEST_CASE("study: fields varied together take their k-th values in one case", "[study]") {
  const test::TempDir dir;
  // The kick's duration with its instant and its foot's window: alone, 1.2 s would leave the
  // 1.6 s window beyond the motion; together they make valid cases.
  const std::string body = "vary:\n"
                           "  - together:\n"
                           "      - {field: duration, values: [1.2, 1.6, 2.0]}\n"
                           "      - {field: 'tasks[kick].time', values: [0.6, 0.8, 1.0]}\n"
                           "      - {field: 'tasks[right foot in the air].window[1]', values: [1.2, 1.6, 2.0]}\n"
                           "  - {field: 'tasks[kick].target[0]', values: [0.8, 1.2]}\n";
  const Sweep sweep = loadSweep(writeSweep(dir, body));
  CHECK(sweep.axes.size() == 2);
  REQUIRE(sweep.varied.size() == 4);
  const std::vector<StudyCase> cases = designCases(sweep);
  REQUIRE(cases.size() == 6);
  for (const StudyCase& c : cases) {
    const double duration = c.values[0].as<double>();
    CHECK(c.values[1].as<double>() == Approx(duration / 2));
    CHECK(c.values[2].as<double>() == duration);
    CHECK(c.scenario["duration"].as<double>() == duration);
    CHECK(c.scenario["tasks"][1]["window"][1].as<double>() == duration);
    CHECK(c.values[3].as<double>() == (c.index % 2 == 0 ? 0.8 : 1.2));  // the last axis fastest
  }
  CHECK(cases[2].values[0].as<double>() == 1.6);
  REQUIRE_NOTHROW(validateCases(sweep, cases));
  // Random designs draw once an axis: the fields of one keep their pairing.
  const Sweep drawn = loadSweep(writeSweep(dir, "design: latin-hypercube\ncases: 6\n" + body));
  for (const StudyCase& c : designCases(drawn)) {
    CHECK(c.values[1].as<double>() == Approx(c.values[0].as<double>() / 2));
    CHECK(c.values[2].as<double>() == c.values[0].as<double>());
  }
  // A refused value of the group is reported at its line, with the values it was tried with.
  const std::string refused = loadError(writeSweep(dir,
                                                   "vary:\n  - together:\n      - {field: duration, values: [1.6, 1.2]}\n"
                                                   "      - {field: 'tasks[kick].time', values: [0.8, 1.4]}\n"));
  CHECK_THAT(refused, Contains("sweep.yaml:4: vary[0].together[0].values[1]: duration = 1.2, tasks[kick].time = 1.4: the scenario refuses it:"));
}

TEST_CASE("study: random and Latin-hypercube designs are seeded, in range, and stratified", "[study]") {
  const test::TempDir dir;
  const std::string fields = "vary:\n  - {field: objective.acceleration_weight, range: [0.001, 1.0], scale: log}\n"
                             "  - {field: samples, range: [10, 50], integer: true}\n"
                             "  - {field: friction_sharpness, values: [0.5, 1.0, 2.0, 4.0]}\n";
  for (const std::string design : {"random", "latin-hypercube"}) {
    INFO(design);
    const Sweep a = loadSweep(writeSweep(dir, "design: " + design + "\ncases: 8\nseed: 42\n" + fields));
    const Sweep b = loadSweep(writeSweep(dir, "design: " + design + "\ncases: 8\nseed: 42\n" + fields));
    const Sweep c = loadSweep(writeSweep(dir, "design: " + design + "\ncases: 8\nseed: 43\n" + fields));
    const auto ca = designCases(a), cb = designCases(b), cc = designCases(c);
    REQUIRE(ca.size() == 8);
    bool differs = false;
    std::set<int> strata;
    std::map<std::string, int> choices;
    for (std::size_t k = 0; k < 8; ++k) {
      for (std::size_t i = 0; i < 3; ++i) {
        CHECK(valueText(ca[k].values[i]) == valueText(cb[k].values[i]));  // the same seed, the same cases
        differs = differs || valueText(ca[k].values[i]) != valueText(cc[k].values[i]);
      }
      const double eps = ca[k].values[0].as<double>();
      CHECK(eps >= 0.001);
      CHECK(eps <= 1.0);
      strata.insert(static_cast<int>(std::floor((std::log(eps) - std::log(0.001)) / (std::log(1.0) - std::log(0.001)) * 8)));
      const std::string samples = valueText(ca[k].values[1]);
      CHECK(samples.find('.') == std::string::npos);  // integer: true
      CHECK(std::stoi(samples) >= 10);
      CHECK(std::stoi(samples) <= 50);
      ++choices[valueText(ca[k].values[2])];
    }
    CHECK(differs);  // another seed, other cases
    if (design == "latin-hypercube") {
      CHECK(strata.size() == 8);  // each of the 8 strata of the log-range once
      CHECK(choices.size() == 4);  // 8 strata over 4 values: each value twice
      for (const auto& [value, count] : choices) CHECK(count == 2);
    }
    REQUIRE_NOTHROW(validateCases(a, ca));
  }
}

TEST_CASE("study: bad sweep files are refused at their line and field", "[study]") {
  const test::TempDir dir;
  struct Case {
    std::string body, expected;
  };
  const std::vector<Case> cases = {
      {"vary:\n  - {field: 'tasks[kick].target[0]', values: [0.8]}\n  - {field: objective.nonsense, values: [1]}\n",
       "sweep.yaml:4: vary[1].values[0]: objective.nonsense = 1: the scenario refuses it: objective.nonsense: unknown key"},
      {"vary:\n  - {field: 'tasks[throw].target[0]', values: [0.8]}\n",
       "sweep.yaml:3: vary[0]: tasks[throw].target[0]: 'tasks' has no element named 'throw'"},
      {"vary:\n  - field: samples\n    values: [10, many]\n",
       "sweep.yaml:4: vary[0].values[1]: samples = many: the scenario refuses it: samples: expected a number"},
      {"vary:\n  - {field: contact_forces, values: [bilevel, sideways]}\n",
       "sweep.yaml:3: vary[0].values[1]: contact_forces = sideways: the scenario refuses it: contact_forces:"},
      {"set: {samples: 1}\nvary:\n  - {field: duration, values: [1.6]}\n",
       "sweep.yaml:2: set.samples: samples = 1: the scenario refuses it: samples: expected an integer ≥ 2"},
      {"vary: []\n", "sweep.yaml:2: vary: an empty design"},
      {"vary:\n  - {field: samples, values: []}\n", "sweep.yaml:3: vary[0].values: an empty list"},
      {"design: random\nvary:\n  - {field: samples, values: [10]}\n", "sweep.yaml:1: cases: missing required field"},
      {"design: random\ncases: 0\nvary:\n  - {field: samples, values: [10]}\n", "sweep.yaml:3: cases: expected an integer ≥ 1"},
      {"vary:\n  - {field: samples, range: [10, 20]}\n", "sweep.yaml:3: vary[0].range: a grid needs values"},
      {"vary:\n  - {field: 'a..b', values: [1]}\n", "sweep.yaml:3: vary[0].field: field path 'a..b'"},
      {"vary:\n  - {field: samples, values: [10]}\n  - {field: samples, values: [12]}\n", "sweep.yaml:4: vary[1].field: 'samples' is varied twice"},
      {"vary:\n  - {field: samples, values: [10]}\nresources: {memory: lots}\n", "sweep.yaml:4: resources.memory: expected a size"},
      {"vary:\n  - {field: samples, values: [10]}\nresources: {time: -3}\n", "sweep.yaml:4: resources.time: must be positive"},
      {"vary:\n  - {field: samples, values: [10]}\nslurm: {queue: x}\n", "sweep.yaml:4: slurm.queue: unknown key"},
      {"vary:\n  - {field: samples, values: [10]}\nextra: 1\n", "sweep.yaml:4: extra: unknown key"},
      {"vary:\n  - together:\n      - {field: samples, values: [10, 12]}\n      - {field: duration, values: [1.6]}\n",
       "sweep.yaml:5: vary[0].together[1].values: 1 values where samples has 2: fields varied together list as many values"},
      {"design: random\ncases: 2\nvary:\n  - together:\n      - {field: samples, values: [10, 12]}\n      - {field: duration, range: [1, 2]}\n",
       "sweep.yaml:7: vary[0].together[1].range: fields varied together list their values, not a range"},
      {"vary:\n  - together:\n      - {field: samples, values: [10]}\n", "sweep.yaml:4: vary[0].together: expected a list of at least two fields"},
      {"vary:\n  - together:\n      - {field: samples, values: [10]}\n      - {field: samples, values: [12]}\n",
       "sweep.yaml:5: vary[0].together[1].field: 'samples' is varied twice"},
  };
  for (const Case& c : cases) {
    INFO(c.body);
    const std::string error = loadError(writeSweep(dir, c.body));
    CHECK_THAT(error, StartsWith((dir.path() / "").string()) && Contains(c.expected));
  }
  // A combination that only fails together is reported at its case.
  const std::string together = loadError(writeSweep(
      dir, "set: {duration: 2.0}\nvary:\n  - {field: duration, values: [2.0, 1.7]}\n  - {field: 'tasks[kick].time', values: [0.8, 1.8]}\n"));
  CHECK_THAT(together, Contains("sweep.yaml:4: vary[0]: case 3 (duration = 1.7, tasks[kick].time = 1.8): the scenario refuses it: tasks[0].time:"));
}

TEST_CASE("study: the bundled sweeps' cases are valid scenarios", "[study]") {
  std::size_t sweeps = 0;
  for (const auto& entry : std::filesystem::directory_iterator(test::sourceDir() / "scenarios/studies")) {
    if (entry.path().extension() != ".yaml") continue;
    INFO(entry.path());
    const Sweep sweep = loadSweep(entry.path());
    const std::vector<StudyCase> cases = designCases(sweep);
    CHECK(cases.size() >= 4);
    REQUIRE_NOTHROW(validateCases(sweep, cases));
    ++sweeps;
  }
  CHECK(sweeps >= 4);
}

TEST_CASE("study: array ranges as sbatch writes them", "[study]") {
  CHECK(arrayRanges({0, 1, 2, 3}) == "0-3");
  CHECK(arrayRanges({2, 3, 5, 7, 8, 9}) == "2-3,5,7-9");
  CHECK(arrayRanges({4}) == "4");
}

TEST_CASE("study: the folder refuses another study and reports each case's state", "[study]") {
  const test::TempDir dir;
  const Sweep sweep = loadSweep(writeSweep(dir, "vary:\n  - {field: samples, values: [10, 12]}\n"));
  const auto cases = designCases(sweep);
  const StudyFolder folder(dir.path() / "out");
  prepareStudy(folder, sweep, cases);
  REQUIRE_NOTHROW(prepareStudy(folder, sweep, cases));  // the same study again: a restart
  const StudyDescription study = readStudy(folder);
  CHECK(study.caseCount() == 2);
  CHECK(study.fields == std::vector<std::string>{"samples"});
  CHECK(study.values[1] == std::vector<std::string>{"12"});
  CHECK(unfinishedCases(folder, study) == std::vector<std::size_t>{0, 1});

  const Sweep other = loadSweep(writeSweep(dir, "vary:\n  - {field: samples, values: [10, 14]}\n"));
  CHECK_THROWS_WITH(prepareStudy(folder, other, designCases(other)), Contains("holds another study") && Contains("'cases'"));

  // Case 0 finished (a final status), case 1 interrupted by scancel: only case 1 is unfinished.
  std::filesystem::create_directories(folder.resultFolder(0));
  std::filesystem::create_directories(folder.resultFolder(1));
  std::ofstream(folder.resultFolder(0) / "result.json") << R"({"status": "maximum_iterations", "energy": 1.5, "max_violation": 1e-7,
    "solver": {"iterations": 20, "iterations_all_stages": 20}, "timings": {"total_seconds": 2.0}})";
  std::ofstream(folder.resultFolder(1) / "result.json") << R"({"status": "interrupted", "energy": 3.0})";
  writeCaseRecord(folder, 0, {"node1", "completed", "", 1, 4, 0, 10, 2.0});
  writeCaseRecord(folder, 1, {"node2", "cancelled", "7_1", 1, 130, 0, 11, 1.0});
  CHECK(unfinishedCases(folder, study) == std::vector<std::size_t>{1});
  const std::vector<CaseReport> reports = writeCasesCsv(folder, study);
  CHECK(reports[0].state == CaseState::Finished);
  CHECK(reports[1].state == CaseState::Cancelled);
  std::ifstream csv(folder.casesCsv());
  std::string header, row0, row1;
  std::getline(csv, header), std::getline(csv, row0), std::getline(csv, row1);
  CHECK(header == "case,samples,status,energy,max_violation,iterations,seconds,host");
  CHECK(row0 == "0,10,maximum_iterations,1.5,9.9999999999999995e-08,20,2,node1");
  CHECK(row1 == "1,12,cancelled,3,,,,node2");
}

TEST_CASE("study: the inner solver and the contact-force formulation vary like any field", "[study]") {
  const test::TempDir dir;
  const auto file = dir.write("sweep.yaml", "scenario: " + (test::sourceDir() / "scenarios/hrp2_weight_shift.yaml").string() +
                                                "\nvary:\n  - {field: contact_forces, values: [bilevel, splines]}\n"
                                                "  - {field: inner.solver, values: [active-set, slsqp, ipopt]}\n");
  const Sweep sweep = loadSweep(file);
  const std::vector<StudyCase> cases = designCases(sweep);
  REQUIRE(cases.size() == 6);
  CHECK(cases[4].scenario["contact_forces"].as<std::string>() == "splines");
  CHECK(cases[4].scenario["inner"]["solver"].as<std::string>() == "slsqp");
  CHECK(cases[4].scenario["inner"]["contact_model"].as<std::string>() == "wrench-cone");  // the rest of `inner` kept
  REQUIRE_NOTHROW(validateCases(sweep, cases));
  const auto bad = dir.write("bad.yaml", "scenario: " + (test::sourceDir() / "scenarios/hrp2_weight_shift.yaml").string() +
                                             "\nvary:\n  - {field: inner.solver, values: [active-set, cplex]}\n");
  const Sweep badSweep = loadSweep(bad);
  CHECK_THROWS_WITH(validateCases(badSweep, designCases(badSweep)), Contains("bad.yaml:3: vary[0].values[1]: inner.solver = cplex: the scenario refuses it: inner.solver:"));
}

TEST_CASE("study: an attempt whose runner is alive on this host is still running, one whose runner died is not", "[study]") {
  char host[256] = {};
  ::gethostname(host, sizeof host - 1);
  CaseRecord alive;
  alive.host = host;
  alive.pid = ::getppid();  // the process that started this test: alive while it runs
  CHECK(attemptStillRunning(alive));
  CaseRecord ended = alive;
  ended.end = "completed";
  CHECK_FALSE(attemptStillRunning(ended));
  CaseRecord elsewhere = alive;
  elsewhere.host = std::string(host) + "-another";
  CHECK_FALSE(attemptStillRunning(elsewhere));  // without Slurm, another host's record cannot be checked: stale
  // A runner that has exited: its pid, reaped, names no process.
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  int status = 0;
  ::waitpid(child, &status, 0);
  CaseRecord dead = alive;
  dead.pid = child;
  CHECK_FALSE(attemptStillRunning(dead));
}
