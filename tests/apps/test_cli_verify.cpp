// SPDX-License-Identifier: BSD-3-Clause
// `mcopt verify` (docs/reference/verify.md) on a result: what it reads — the parameters, never the
// sampled arrays — and bad input refused with the file or field, exit 2, nothing written. The
// bundled optima are verified where the run tests reach them (test_cli_run.cpp); a torque limit
// broken between samples only is tests/outer_nlp/test_motion_verification.cpp.
#include <yaml-cpp/yaml.h>

#include <catch2/catch.hpp>

#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>

#include "common/json_file.hpp"
#include "common/run_command.hpp"
#include "common/scenario_variant.hpp"
#include "common/temp_dir.hpp"
#include "common/test_support.hpp"
#include "common/verify_result.hpp"

using namespace mcopt;
using Catch::Matchers::Contains;
using Json = nlohmann::json;

namespace {

const std::filesystem::path kKick = test::sourceDir() / "scenarios/hrp2_kick.yaml";

/// A real result of the kick on 20 samples after one iteration (not an optimum: what it is does
/// not matter here; 100 samples took 20 s a run under the sanitizers).
std::filesystem::path kickResult(const test::TempDir& dir) {
  const auto scenario = test::scenarioVariant(kKick, dir, [](YAML::Node& root) { root["samples"] = 20; }, "kick.yaml");
  const auto out = dir.path() / "kick";
  const auto r = test::runMcopt("run " + test::quoted(scenario) + " --out " + test::quoted(out) +
                                " --max-iterations 1 --configuration-optimisation off");
  INFO(r.all());
  REQUIRE(std::filesystem::exists(out / "result.json"));
  return out;
}

void write(const std::filesystem::path& file, const Json& j) { std::ofstream(file) << j.dump(1); }

}  // namespace

TEST_CASE("verify: it certifies the parameters' motion, not the sampled arrays beside them", "[cli][verify]") {
  const test::TempDir dir;
  const auto result = kickResult(dir);
  const test::Verified before = test::verifyResult(result);
  INFO(before.all);
  REQUIRE((before.exitCode == 0 || before.exitCode == 1));
  CHECK(before.exitCode == (before.report.at("passed").get<bool>() ? 0 : 1));
  CHECK(std::filesystem::exists(result / "verify.json"));
  CHECK(test::readJson(result / "verify.json") == before.report);
  // Every sampled array replaced by nonsense: the motion they claimed to describe is not read.
  Json edited = test::readJson(result / "result.json");
  for (const char* field : {"q", "v", "a", "torques", "power", "reference_wrench"})
    for (Json& row : edited[field])
      for (Json& value : row) value = 1e3;
  for (Json& t : edited["time"]) t = 0.0;
  edited["energy"] = -1.0;
  for (Json& c : edited["contacts"]) c["wrench"] = Json::array();
  write(result / "result.json", edited);
  const test::Verified after = test::verifyResult(result);
  INFO(after.all);
  CHECK(after.exitCode == before.exitCode);
  for (const char* field : {"passed", "checks", "energy", "energy_balance", "instants", "duration"}) {
    INFO(field);
    CHECK(after.report.at(field) == before.report.at(field));
  }
  CHECK(before.report.at("energy").at("sampled_J").get<double>() > 0.0);
}

TEST_CASE("verify: bad input is refused with the file or field, exit 2, nothing written", "[cli][verify]") {
  const test::TempDir dir;
  const auto result = kickResult(dir);
  const Json original = test::readJson(result / "result.json");
  const auto weightShift = test::sourceDir() / "scenarios/hrp2_weight_shift.yaml";
  struct Case {
    const char* what;
    std::function<void(Json&)> edit;  ///< of result.json (null: a folder without one)
    std::string arguments, expected;
  };
  const std::vector<Case> cases = {
      {"a folder without result.json", nullptr, "", "result.json: no such file"},
      {"a result of an older format", [](Json& j) { j.erase("format"); }, "", "format: a result of an older format"},
      {"a result of other joints", [](Json& j) { j["joint_names"][3] = "KNEE"; }, "", "joint_names: the result's joints"},
      {"a scenario of other contacts", [](Json&) {}, "--scenario " + test::quoted(weightShift), "contacts: the result's contacts"},
      {"force variables missing", [](Json& j) { j.erase("contact_force_variables"); }, "", "contact_force_variables: missing"},
      {"too few spline parameters", [](Json& j) { j["parameters"]["RLEG_JOINT3"].erase(0); }, "",
       "parameters.RLEG_JOINT3: 3 spline parameters"},
      {"a non-numeric --fine", [](Json&) {}, "--fine ten", "--fine"},
      {"--fine 0", [](Json&) {}, "--fine 0", "--fine: 0: expected an integer ≥ 1"},
  };
  // A loop, not sections: Catch would run the kick again for each section.
  for (const Case& c : cases) {
    INFO(c.what);
    const auto folder = dir.path() / "broken";
    std::filesystem::remove_all(folder);
    std::filesystem::create_directories(folder);
    if (c.edit) {
      Json broken = original;
      c.edit(broken);
      write(folder / "result.json", broken);
    }
    const auto out = dir.path() / "elsewhere.json";
    const auto r = test::runMcopt("verify " + test::quoted(folder) + " " + c.arguments + " --out " + test::quoted(out));
    INFO(r.all());
    CHECK(r.exitCode == 2);
    CHECK_THAT(r.errors, Contains(c.expected));
    if (c.edit && c.arguments.empty()) CHECK_THAT(r.errors, Contains((folder / "result.json").string()));
    CHECK_FALSE(std::filesystem::exists(out));
    CHECK_FALSE(std::filesystem::exists(folder / "verify.json"));
  }
}
