// SPDX-License-Identifier: BSD-3-Clause
// `mcopt replay` (issue 16, docs/guides/replay.md): the page's scene against the result it is drawn
// from — every body at every sample, the contact force in world axes equal to the wrench the
// environment applies (W0 with one contact) — and results it cannot draw refused. The page in
// a browser: tests/python/test_replay.py.
#include <yaml-cpp/yaml.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "common/run_command.hpp"
#include "common/scenario_variant.hpp"
#include "common/temp_dir.hpp"
#include "common/test_support.hpp"

using namespace mcopt;
using Catch::Matchers::Contains;
using Json = nlohmann::json;

namespace {

std::string readText(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// A kick of 8 samples optimised for 4 iterations, in dir/run.
std::filesystem::path smallKick(const test::TempDir& dir) {
  const auto scenario = test::scenarioVariant(test::sourceDir() / "scenarios/hrp2_kick.yaml", dir, [](YAML::Node& root) {
    root["samples"] = 8;
    root["output_samples"] = 40;
  }, "kick.yaml");
  const auto out = dir.path() / "run";
  const auto run = test::runMcopt("run " + test::quoted(scenario) + " --out " + test::quoted(out) +
                                  " --configuration-optimisation off --max-iterations 4");
  INFO(run.all());
  REQUIRE(run.exitCode == 4);
  return out;
}

}  // namespace

TEST_CASE("replay: one page holding three.js, the viewer and the scene of the result", "[cli][replay]") {
  const test::TempDir dir;
  const auto out = smallKick(dir);
  const auto r = test::runMcopt("replay " + test::quoted(out));
  INFO(r.all());
  REQUIRE(r.exitCode == 0);
  const auto page = out / "replay.html";
  CHECK_THAT(r.output, Contains(page.string()));
  const std::string html = readText(page);
  CHECK_THAT(html, Contains("OrbitControls"));
  CHECK(html.find("<script src") == std::string::npos);

  const std::string open = "<script type=\"application/json\" id=\"mcopt-scene\">";
  const std::size_t begin = html.find(open) + open.size();
  const Json scene = Json::parse(html.substr(begin, html.find("</script>", begin) - begin));
  const Json result = Json::parse(readText(out / "result.json"));
  const std::size_t N = result["time"].size();
  REQUIRE(N == 8);
  CHECK(scene["time"] == result["time"]);
  REQUIRE(scene["bodies"].size() == 31);  // HRP-2: the waist and 30 jointed bodies
  for (const Json& body : scene["bodies"]) {
    INFO(body["name"]);
    REQUIRE(body["poses"].size() == N);
    CHECK(!body["shapes"].empty());
    for (const Json& p : body["poses"])
      CHECK(std::hypot(std::hypot(p[3].get<double>(), p[4].get<double>()), std::hypot(p[5].get<double>(), p[6].get<double>())) ==
            Approx(1.0).margin(3e-5));
  }
  // The reference sole holds its pose: the floor is at its height, its pose the reference pose.
  CHECK(scene["floor_height"].get<double>() == Approx(0.0).margin(1e-9));
  REQUIRE(scene["contacts"].size() == 1);
  const Json& sole = scene["contacts"][0];
  for (std::size_t k = 0; k < N; ++k) {
    CHECK(sole["active"][k].get<bool>());
    for (int i = 0; i < 3; ++i) {
      CHECK(sole["poses"][k][i].get<double>() == Approx(0.0).margin(1e-9));
      // With one contact its force, in world axes, is W0's force (docs/reference/scenario-file.md).
      CHECK(sole["force"][k][i].get<double>() == Approx(result["reference_wrench"][k][i].get<double>()).margin(1e-5));
    }
  }
}

TEST_CASE("replay: results it cannot draw are refused, naming the file and field", "[cli][replay]") {
  const test::TempDir dir;
  const auto out = smallKick(dir);
  const Json result = Json::parse(readText(out / "result.json"));
  const auto refused = [&](const std::string& name, const Json& changed) {
    const auto folder = dir.path() / name;
    std::filesystem::create_directories(folder);
    std::ofstream(folder / "result.json") << changed.dump();
    const auto r = test::runMcopt("replay " + test::quoted(folder));
    INFO(r.all());
    CHECK(r.exitCode == 2);
    CHECK(!std::filesystem::exists(folder / "replay.html"));
    return r.errors;
  };
  const auto at = [&](const std::string& name) { return (dir.path() / name / "result.json").string() + ": "; };

  Json noFiles = result;
  noFiles.erase("robot_files");
  CHECK_THAT(refused("old", noFiles), Contains(at("old") + "robot_files: missing (a result of an older mcopt run? run it again)"));

  Json shortQ = result;
  shortQ["q"].erase(shortQ["q"].begin());
  CHECK_THAT(refused("short", shortQ), Contains(at("short") + "q: expected one posture per sample (8)"));

  Json badPosture = result;
  badPosture["q"][3][2] = "x";
  CHECK_THAT(refused("posture", badPosture), Contains(at("posture") + "q[3][2]: expected a number"));

  Json unknownContact = result;
  unknownContact["contacts"][0]["name"] = "nose";
  CHECK_THAT(refused("contact", unknownContact), Contains(at("contact") + "contacts[0].name: 'nose' is not a surface of "));

  Json badWrench = result;
  badWrench["contacts"][0]["wrench"][2] = Json::array({1.0, 2.0});
  CHECK_THAT(refused("wrench", badWrench), Contains(at("wrench") + "contacts[0].wrench[2]: expected a list of 6 numbers, got 2"));

  Json missingUrdf = result;
  missingUrdf["robot_files"]["urdf"] = (dir.path() / "none.urdf").string();
  CHECK_THAT(refused("urdf", missingUrdf), Contains("none.urdf"));

  const auto empty = test::runMcopt("replay " + test::quoted(dir.path()));
  CHECK(empty.exitCode == 2);
  CHECK_THAT(empty.errors, Contains("result.json: file not found"));
}
