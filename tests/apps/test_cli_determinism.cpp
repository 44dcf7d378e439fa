// SPDX-License-Identifier: BSD-3-Clause
// Determinism (issue 19, docs/developers/determinism.md "Determinism"): the same input gives the same
// output, to the bit, with 1 and 2 OpenMP threads and from run to run — every number of
// result.json but the clocks', and every side file byte for byte.
#include <yaml-cpp/yaml.h>

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>

#include "common/run_command.hpp"
#include "common/scenario_variant.hpp"
#include "common/temp_dir.hpp"
#include "common/test_support.hpp"
#include "inner_qp/inner_solver.hpp"

using namespace mcopt;
using Json = nlohmann::json;

namespace {

using mcopt::test::kUnderSanitizers;

std::string readText(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// result.json without the clocks' readings (and the folder it was written to).
Json withoutClocks(const std::filesystem::path& out) {
  Json r = Json::parse(readText(out / "result.json"));
  r.erase("timings");
  for (Json& line : r["history"]) {
    line.erase("elapsed_seconds");
    line.erase("seconds");
    if (line.contains("inner")) line["inner"].erase("solve_seconds");
  }
  for (Json& stage : r["continuation"]) stage.erase("seconds");
  for (const char* end : {"start", "end"})
    if (r["configuration_optimisation"].contains(end)) r["configuration_optimisation"][end].erase("seconds");
  if (r["configuration_optimisation"].contains("contacts"))
    for (Json& contact : r["configuration_optimisation"]["contacts"]) contact.erase("seconds");
  return r;
}

/// Runs `mcopt run` with 1 thread, 2 threads and 2 threads again, and compares. The output
/// folders' names differ in length, so that each run's heap holds other bytes before the solve.
void sameWithAnyThreads(const test::TempDir& dir, const std::filesystem::path& scenario, const std::string& arguments) {
  std::vector<std::filesystem::path> outs;
  for (const char* threads : {"1", "2", "2"}) {
    const auto out = dir.path() / ("run-" + std::to_string(outs.size()) + std::string(40 * outs.size(), 'x'));
    const auto r = test::runMcopt("run " + test::quoted(scenario) + " --out " + test::quoted(out) + " " + arguments,
                                  std::string("OMP_NUM_THREADS=") + threads);
    INFO(r.all());
    REQUIRE((r.exitCode == 0 || r.exitCode == 4));
    outs.push_back(out);
  }
  const Json one = withoutClocks(outs[0]), two = withoutClocks(outs[1]), again = withoutClocks(outs[2]);
  CHECK(one["solver"]["iterations"].get<int>() > 0);
  for (const auto& [key, value] : one.items()) {
    INFO("result.json field " << key);
    CHECK(value == two[key]);    // 1 thread against 2
    CHECK(two[key] == again[key]);  // run to run
  }
  for (const char* file : {"trajectory.csv", "states.json", "contact_wrenches.json"}) {
    INFO(file);
    CHECK(readText(outs[0] / file) == readText(outs[1] / file));
    CHECK(readText(outs[1] / file) == readText(outs[2] / file));
  }
}

}  // namespace

TEST_CASE("determinism: the kick, configuration optimisation and Newton steps, with 1 and 2 threads", "[cli][determinism]") {
  const test::TempDir dir;
  const auto scenario = test::scenarioVariant(test::sourceDir() / "scenarios/hrp2_kick.yaml", dir, [](YAML::Node& root) {
    root["samples"] = kUnderSanitizers ? 10 : 24;
    root["output_samples"] = 50;
  }, "kick.yaml");
  sameWithAnyThreads(dir, scenario, "--max-iterations 5 --checkpoint-seconds -1");
}

TEST_CASE("determinism: the bilevel weight shift, inner solves warm-started, with 1 and 2 threads", "[cli][determinism]") {
  const test::TempDir dir;
  const auto scenario = test::scenarioVariant(test::sourceDir() / "scenarios/hrp2_weight_shift.yaml", dir, [](YAML::Node& root) {
    root["samples"] = kUnderSanitizers ? 8 : 20;
  }, "weight_shift.yaml");
  sameWithAnyThreads(dir, scenario, "--contact-forces bilevel --inner-solver active-set --max-iterations 3 --checkpoint-seconds -1");
}

// A checkpoint (--checkpoint-seconds) writes the current iterate's run files. It used to
// evaluate the run's own problem, whose bilevel samples then started their next solves from the
// checkpoint's answers: the result's torques and wrenches differed in their last bits with when
// the clock had called for a checkpoint — with the thread count, the machine, the load.
TEST_CASE("determinism: checkpoints after every iteration leave the result as no checkpoint does", "[cli][determinism]") {
  const test::TempDir dir;
  const auto scenario = test::scenarioVariant(test::sourceDir() / "scenarios/hrp2_weight_shift.yaml", dir, [](YAML::Node& root) {
    if (kUnderSanitizers) root["samples"] = 8;
  }, "weight_shift.yaml");
  std::vector<Json> results;
  for (const char* every : {"0", "-1"}) {
    const auto out = dir.path() / (std::string("checkpoints") + every);
    const auto r = test::runMcopt("run " + test::quoted(scenario) + " --out " + test::quoted(out) +
                                      " --max-iterations 10 --checkpoint-seconds " + every,
                                  "OMP_NUM_THREADS=2");
    INFO(r.all());
    REQUIRE((r.exitCode == 0 || r.exitCode == 4));
    results.push_back(withoutClocks(out));
  }
  CHECK(results[0]["solver"]["iterations"].get<int>() > 0);
  for (const auto& [key, value] : results[0].items()) {
    INFO("result.json field " << key);
    CHECK(value == results[1][key]);
  }
}

// While InnerNlp left the elastic phase's band rows unwritten, SLSQP read whatever its
// constraint buffer held, and this run's 12th iteration differed in the seventh digit with
// the output folder's name (docs/theory/inner-problem.md, "Determinism").
TEST_CASE("determinism: the bilevel weight shift with SLSQP inside, whatever the heap held before", "[cli][determinism]") {
  const test::TempDir dir;
  const auto scenario = test::scenarioVariant(test::sourceDir() / "scenarios/hrp2_weight_shift.yaml", dir, [](YAML::Node& root) {
    root["samples"] = kUnderSanitizers ? 8 : 60;
    root["hessian"] = "gauss-newton";  // its first stage alone: the sample-differences stage re-solves 90 states a sample
    root.remove("continuation");
  }, "weight_shift.yaml");
  sameWithAnyThreads(dir, scenario, "--inner-solver slsqp --max-iterations 14 --checkpoint-seconds -1");
}

TEST_CASE("determinism: mcopt inner with 1 and 2 threads and from run to run", "[cli][determinism]") {
  // A motion's inner problems (two soles, then a hand as well): the fuzz seed, reused.
  const auto problems = test::sourceDir() / "tests/fuzz/corpus/inner_problems/two_soles_then_hand.json";
  const test::TempDir dir;
  for (const std::string& solver : innerSolverNames()) {  // every registered solver
    std::vector<Json> outputs;
    for (const char* threads : {"1", "2", "2"}) {
      const auto out = dir.path() / (solver + "-" + std::to_string(outputs.size()) + ".json");
      const std::string model = solver == "barrier" ? " --contact-model wrench-cone" : "";  // linear models only
      const auto r = test::runMcopt("inner --problems " + test::quoted(problems) + " --solver " + solver + model +
                                    " --sensitivity --out " + test::quoted(out), std::string("OMP_NUM_THREADS=") + threads);
      INFO(solver << ": " << r.all());
      // The three the report compares solve every problem here; a failed problem (exit 1) is
      // written all the same and must come out the same too.
      const bool reportSolver = solver == "active-set" || solver == "slsqp" || solver == "ipopt" || solver == "barrier";
      if (reportSolver)
        REQUIRE(r.exitCode == 0);
      else
        REQUIRE((r.exitCode == 0 || r.exitCode == 1));
      Json output = Json::parse(readText(out));
      for (Json& result : output["results"]) result.erase("solve_time_us");
      outputs.push_back(output);
    }
    INFO(solver);
    CHECK(outputs[0]["results"].size() == 3);
    CHECK(outputs[0] == outputs[1]);
    CHECK(outputs[1] == outputs[2]);
  }
}

// Issue 45: every bundled scenario with two or more contacts, in every contact-force
// formulation, 20 Ipopt iterations of its first stage on fewer samples, the same to the bit with
// 1 and 2 threads (the per-sample loop's warm starts follow fixed chunks of samples, not threads).
TEST_CASE("determinism: every bundled multi-contact scenario in each formulation over 20 iterations with 1 and 2 threads",
          "[cli][determinism]") {
  int scenarios = 0;
  for (const auto& entry : std::filesystem::directory_iterator(test::sourceDir() / "scenarios")) {
    if (entry.path().extension() != ".yaml") continue;
    const YAML::Node root = YAML::LoadFile(entry.path().string());
    if (!root["contacts"] || root["contacts"].size() < 2) continue;
    ++scenarios;
    for (const std::string forces : {"bilevel", "splines", "variables"}) {  // the formulations (`mcopt run --help`)
      INFO(entry.path().filename().string() << ", contact_forces " << forces);
      const test::TempDir dir;
      const auto scenario = test::scenarioVariant(entry.path(), dir, [](YAML::Node& variant) {
        // Fewer samples; a fifth of the throws' intervals keeps their release on the grid.
        const int intervals = variant["samples"].as<int>() - 1;
        variant["samples"] = intervals % 5 == 0 ? intervals / 5 + 1 : (kUnderSanitizers ? 8 : 20);
        variant["hessian"] = "gauss-newton";  // the first stage alone (the second re-solves each sample's states)
        variant.remove("continuation");
      }, entry.path().filename().string());
      sameWithAnyThreads(dir, scenario, "--contact-forces " + forces + " --max-iterations 20 --checkpoint-seconds -1");
    }
  }
  CHECK(scenarios == 5);  // the weight shift, the lean reach and the three throws on both soles
}

TEST_CASE("determinism: the command loads one BLAS kernel set on every AVX2 processor and keeps a set the caller chose",
          "[cli][determinism]") {
  // docs/developers/determinism.md: OpenBLAS picks its kernels by processor when it loads, and
  // the paths Ipopt takes depend on them. OPENBLAS_VERBOSE=2 makes it name the set it loaded,
  // on standard error, once per process: the last name is the one the command ran with.
  const auto lastCore = [](const std::string& errors) {
    const std::size_t at = errors.rfind("Core: ");
    return at == std::string::npos ? std::string() : errors.substr(at + 6, errors.find('\n', at) - at - 6);
  };
  __builtin_cpu_init();
  const bool avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  const test::CommandResult pinned = test::runMcopt("--version", "env -u OPENBLAS_CORETYPE OPENBLAS_VERBOSE=2");
  INFO(pinned.all());
  REQUIRE(pinned.exitCode == 0);
  CHECK(pinned.output.rfind("mcopt ", 0) == 0);
  if (avx2) CHECK(lastCore(pinned.errors) == "Haswell");
  const test::CommandResult chosen = test::runMcopt("--version", "OPENBLAS_CORETYPE=Nehalem OPENBLAS_VERBOSE=2");
  INFO(chosen.all());
  REQUIRE(chosen.exitCode == 0);
  CHECK(lastCore(chosen.errors) == "Nehalem");
  CHECK(chosen.errors.find("Haswell") == std::string::npos);
}
