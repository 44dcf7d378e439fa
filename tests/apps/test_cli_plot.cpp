// SPDX-License-Identifier: BSD-3-Clause
// `mcopt plot` (issue 16, docs/guides/plots.md): every figure of a result drawn as PNG and SVG, the
// plotted cumulative energy equal to result.json's, and results it cannot read refused.
#include <yaml-cpp/yaml.h>

#include <catch2/catch.hpp>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>

#include "common/run_command.hpp"
#include "common/scenario_variant.hpp"
#include "common/temp_dir.hpp"
#include "common/test_support.hpp"

using namespace mcopt;
using Catch::Matchers::Contains;

TEST_CASE("plot: every figure of a result, PNG and SVG, and the cumulative energy of result.json", "[cli][plot]") {
  const test::TempDir dir;
  const auto scenario = test::scenarioVariant(test::sourceDir() / "scenarios/hrp2_kick.yaml", dir, [](YAML::Node& root) {
    root["samples"] = 8;
    root["output_samples"] = 40;
  }, "kick.yaml");
  const auto out = dir.path() / "run";
  const auto run = test::runMcopt("run " + test::quoted(scenario) + " --out " + test::quoted(out) +
                                  " --configuration-optimisation off --max-iterations 8");
  INFO(run.all());
  REQUIRE(run.exitCode == 4);

  const auto r = test::runMcopt("plot " + test::quoted(out));
  INFO(r.all());
  REQUIRE(r.exitCode == 0);
  for (const char* figure : {"joint_positions", "joint_torques", "contact_wrenches", "center_of_pressure", "power_energy", "convergence"})
    for (const char* extension : {".png", ".svg"}) {
      const auto file = out / "plots" / (std::string(figure) + extension);
      INFO(file);
      REQUIRE(std::filesystem::exists(file));
      CHECK(std::filesystem::file_size(file) > 5000);
      CHECK_THAT(r.output, Contains(file.string()));
    }
  // The energy curve ends at the energy result.json reports over the same (output) samples.
  std::smatch m;
  REQUIRE(std::regex_search(r.output, m, std::regex(R"(cumulative energy (\S+) J, result.json energy_fine (\S+) J)")));
  const double plotted = std::stod(m[1].str()), reported = std::stod(m[2].str());
  CHECK(reported > 0.0);
  CHECK(std::abs(plotted - reported) <= 1e-9 * reported);

  const auto elsewhere = test::runMcopt("plot " + test::quoted(out) + " --out " + test::quoted(dir.path() / "figures"));
  CHECK(elsewhere.exitCode == 0);
  CHECK(std::filesystem::exists(dir.path() / "figures/convergence.png"));
  CHECK_FALSE(std::filesystem::exists(out / "plots/verify.png"));  // no verify.json yet

  // With mcopt verify's verify.json beside the result: its figure, and its instants marked
  // (docs/reference/verify.md); a verify.json it cannot read is refused by name.
  const auto verified = test::runMcopt("verify " + test::quoted(out));
  INFO(verified.all());
  REQUIRE((verified.exitCode == 0 || verified.exitCode == 1));
  const auto marked = test::runMcopt("plot " + test::quoted(out));
  INFO(marked.all());
  REQUIRE(marked.exitCode == 0);
  for (const char* extension : {".png", ".svg"}) {
    const auto file = out / "plots" / (std::string("verify") + extension);
    CHECK(std::filesystem::exists(file));
    CHECK_THAT(marked.output, Contains(file.string()));
  }
  std::ofstream(out / "verify.json") << R"({"passed": false, "checks": [{"kind": "task", "failing_times": ["soon"]}]})";
  const auto refused = test::runMcopt("plot " + test::quoted(out));
  CHECK(refused.exitCode == 2);
  CHECK_THAT(refused.errors, Contains((out / "verify.json").string() + ": checks[0]: expected a kind and failing_times"));
}

TEST_CASE("plot: a folder without a result, or a result without its fields, is refused", "[cli][plot]") {
  const test::TempDir dir;
  const auto none = test::runMcopt("plot " + test::quoted(dir.path()));
  CHECK(none.exitCode == 2);
  CHECK_THAT(none.errors, Contains((dir.path() / "result.json").string() + ": file not found"));
  dir.write("result.json", R"({"status": "optimal", "time": [0, 1]})");
  const auto old = test::runMcopt("plot " + test::quoted(dir.path()));
  CHECK(old.exitCode == 2);
  CHECK_THAT(old.errors, Contains("result.json: no 'joint_limits' field"));
  dir.write("result.json", "{ not json");
  const auto broken = test::runMcopt("plot " + test::quoted(dir.path()));
  CHECK(broken.exitCode == 2);
  CHECK_THAT(broken.errors, Contains("result.json: cannot read a result"));
}
