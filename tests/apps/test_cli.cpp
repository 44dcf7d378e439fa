// SPDX-License-Identifier: BSD-3-Clause
// The `mcopt` command as a user meets it: outputs, formats, messages and exit codes.
#include <catch2/catch.hpp>
#include <fstream>
#include <nlohmann/json.hpp>

#include "common/run_command.hpp"
#include "common/temp_dir.hpp"
#include "common/test_support.hpp"

using namespace mcopt;
using Catch::Matchers::Contains;
using Json = nlohmann::json;

namespace {
const std::filesystem::path kHrp2 = test::sourceDir() / "robots/hrp2";
}

TEST_CASE("robot info --json reports the HRP-2 joints, mass and centre of mass", "[cli][hrp2]") {
  const auto r = test::runMcopt("robot info --robot " + test::quoted(kHrp2 / "hrp2.urdf") + " --actuators " +
                                test::quoted(kHrp2 / "actuators.yaml") + " --json");
  REQUIRE(r.exitCode == 0);
  const Json info = Json::parse(r.output);
  REQUIRE(info["joints"].size() == 30);
  CHECK(std::abs(info["total_mass"].get<double>() - 58.0) <= 0.5);
  CHECK(info["com"].size() == 3);
  for (const auto& joint : info["joints"]) {
    for (const char* key : {"name", "lower", "upper", "velocity", "effort"}) CHECK(joint.contains(key));
    CHECK(joint["effort"].get<double>() > 0.0);
  }
  // The actuator file overrides the URDF velocity limits.
  CHECK(info["joints"][0]["velocity"].get<double>() != Approx(5.0));
}

TEST_CASE("robot info: each actuator value's source, and a note on friction read from the URDF", "[cli]") {
  test::TempDir dir;
  const auto urdf = dir.write("tiny.urdf", R"(<?xml version="1.0"?>
<robot name="tiny">
  <link name="base"><inertial><mass value="2.0"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="hip" type="revolute">
    <parent link="base"/><child link="thigh"/><axis xyz="0 1 0"/>
    <limit lower="-1.5" upper="1.5" effort="50" velocity="3"/><dynamics damping="0.1" friction="0.2"/>
  </joint>
  <link name="thigh"><inertial><mass value="1.0"/><inertia ixx="0.004" iyy="0.004" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="knee" type="continuous"><parent link="thigh"/><child link="shin"/><axis xyz="0 1 0"/></joint>
  <link name="shin"><inertial><mass value="0.5"/><inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
</robot>)");
  // The URDF alone: its limits and its <dynamics>, the latter said to be read as motor side.
  auto r = test::runMcopt("robot info --robot " + test::quoted(urdf) + " --json");
  REQUIRE(r.exitCode == 0);
  Json info = Json::parse(r.output);
  const Json& hip = info["joints"][0];
  CHECK(hip["viscous_friction"] == 0.1);
  CHECK(hip["dry_friction"] == 0.2);
  CHECK(hip["sources"]["viscous_friction"] == "URDF <dynamics damping>");
  CHECK(hip["sources"]["dry_friction"] == "URDF <dynamics friction>");
  CHECK(hip["sources"]["effort"] == "URDF <limit effort>");
  CHECK(hip["sources"]["gear_ratio"] == "default");
  CHECK(info["joints"][1]["sources"]["effort"] == "default");  // a continuous joint without <limit>
  REQUIRE(info["notes"].size() == 2);
  CHECK_THAT(info["notes"][0].get<std::string>(), Contains("1 joint (hip) take viscous friction from the URDF <dynamics damping>") &&
                                                   Contains("used as motor-side viscous friction"));
  r = test::runMcopt("robot info --robot " + test::quoted(urdf));
  CHECK_THAT(r.errors, Contains("mcopt: note: 1 joint (hip) take dry friction from the URDF <dynamics friction>"));
  CHECK_THAT(r.output, Contains("viscous friction") && Contains("URDF <dynamics damping> (1)") && Contains("default (1)"));
  // An actuator file that sets the viscous friction and the gear ratio: its values, and one note left.
  const auto actuators = dir.write("actuators.yaml", "defaults: {gear_ratio: 100}\njoints:\n  hip: {viscous_friction: 0.0}\n");
  r = test::runMcopt("robot info --robot " + test::quoted(urdf) + " --actuators " + test::quoted(actuators) + " --json");
  REQUIRE(r.exitCode == 0);
  info = Json::parse(r.output);
  CHECK(info["joints"][0]["sources"]["viscous_friction"] == "actuator file joints.hip");
  CHECK(info["joints"][0]["sources"]["gear_ratio"] == "actuator file defaults");
  CHECK(info["joints"][0]["viscous_friction"] == 0.0);
  REQUIRE(info["notes"].size() == 1);
  CHECK_THAT(info["notes"][0].get<std::string>(), Contains("dry friction"));
}

TEST_CASE("robot info prints a readable table", "[cli]") {
  const auto r = test::runMcopt("robot info --robot " + test::quoted(kHrp2 / "hrp2.urdf"));
  REQUIRE(r.exitCode == 0);
  CHECK_THAT(r.output, Contains("30 actuated joints") && Contains("RLEG_JOINT3") && Contains("58.000 kg"));
}

TEST_CASE("dynamics: states in, torques and reference wrench out", "[cli]") {
  test::TempDir dir;
  const auto states = dir.write("s.json", R"({"joint_names": ["RLEG_JOINT3", "LLEG_JOINT3"],
    "reference_pose": {"position": [0.1, 0.2, 0.0], "quaternion_xyzw": [0, 0, 0.3826834, 0.9238795]},
    "states": [{"q": [0.5, 0.4], "v": [0.1, 0.2], "a": [1.0, -1.0]}, {"q": [0, 0]}]})");
  const auto out = dir.path() / "out.json";
  const auto r = test::runMcopt("dynamics --robot " + test::quoted(kHrp2 / "hrp2.urdf") +
                                " --reference-body l_sole --states " + test::quoted(states) + " --out " + test::quoted(out));
  REQUIRE(r.exitCode == 0);
  std::ifstream in(out);
  const Json result = Json::parse(in);
  REQUIRE(result["results"].size() == 2);
  CHECK(result["joint_names"][0] == "RLEG_JOINT3");
  CHECK(result["results"][0]["tau"].size() == 2);
  // Standing still at zero: the reference sole carries the weight, straight up.
  const auto wrench = result["results"][1]["reference_wrench"];
  CHECK(wrench[2].get<double>() == Approx(58.0 * 9.81).epsilon(1e-12));
  CHECK(std::abs(wrench[0].get<double>()) <= 1e-9);
}

#ifdef MCOPT_SHARED_DIR
TEST_CASE("dynamics reproduces the Pinocchio reference file through the command", "[cli][reference]") {
  const auto reference = test::sharedDir() / "reference/pinocchio/jvrc1_L_ANKLE_P_S.json";
  const auto r = test::runMcopt("dynamics --robot " + test::quoted(test::sharedDir() / "robots/jvrc1/jvrc1.urdf") +
                                " --reference-body L_ANKLE_P_S --states " + test::quoted(reference));
  REQUIRE(r.exitCode != 0);  // the reference file carries expected values: unknown keys are refused
  CHECK_THAT(r.errors, Contains("unknown key"));
  // Strip the expected values and run again.
  test::TempDir dir;
  std::ifstream in(reference);
  Json ref = Json::parse(in);
  Json input = {{"joint_names", ref["joint_names"]}, {"gravity", ref["gravity"]}, {"reference_pose", ref["reference_pose"]},
                {"states", Json::array()}};
  for (const auto& s : ref["states"]) input["states"].push_back({{"q", s["q"]}, {"v", s["v"]}, {"a", s["a"]}});
  const auto file = dir.write("in.json", input.dump());
  const auto ok = test::runMcopt("dynamics --robot " + test::quoted(test::sharedDir() / "robots/jvrc1/jvrc1.urdf") +
                                 " --reference-body L_ANKLE_P_S --derivatives --states " + test::quoted(file));
  REQUIRE(ok.exitCode == 0);
  const Json out = Json::parse(ok.output);
  for (std::size_t s = 0; s < ref["states"].size(); ++s)
    for (const char* key : {"tau", "reference_wrench"})
      for (std::size_t k = 0; k < ref["states"][s][key].size(); ++k) {
        const double expected = ref["states"][s][key][k];
        CHECK(std::abs(out["results"][s][key][k].get<double>() - expected) <= 1e-8 * (1 + std::abs(expected)));
      }
  // --derivatives: row-major, rows outputs, columns inputs, both in joint_names order.
  for (std::size_t s = 0; s < ref["states"].size(); ++s)
    for (const char* key : {"dtau_dq", "dtau_dv", "dtau_da", "dwrench_dq", "dwrench_dv", "dwrench_da"}) {
      const auto& expected = ref["states"][s][key];
      const auto& ours = out["results"][s][key];
      REQUIRE(ours.size() == expected.size());
      double worst = 0.0;
      for (std::size_t row = 0; row < expected.size(); ++row)
        for (std::size_t c = 0; c < expected[row].size(); ++c) {
          const double e = expected[row][c];
          worst = std::max(worst, std::abs(ours[row][c].get<double>() - e) / (1 + std::abs(e)));
        }
      INFO(key);
      CHECK(worst <= 1e-6);
    }
}
#endif

TEST_CASE("dynamics: bad input gets a clear error and a non-zero exit", "[cli][input]") {
  test::TempDir dir;
  const std::string robot = " --robot " + test::quoted(kHrp2 / "hrp2.urdf");
  auto run = [&](const std::string& json, const std::string& extra = "") {
    return test::runMcopt("dynamics" + robot + extra + " --states " + test::quoted(dir.write("in.json", json)));
  };
  auto r = run(R"({"joint_names": ["KNEE"], "states": []})");
  CHECK(r.exitCode == 2);
  CHECK_THAT(r.errors, Contains("in.json") && Contains("joint_names[0]") && Contains("unknown joint 'KNEE'"));
  r = run(R"({"joint_names": ["RLEG_JOINT3"], "states": [{"q": [1, 2]}]})");
  CHECK_THAT(r.errors, Contains("states[0].q") && Contains("expected a list of 1 numbers"));
  r = run(R"({"states": [{"q": "x"}]})");
  CHECK_THAT(r.errors, Contains("states[0].q"));
  r = run(R"({"states": [], "reference_pose": {"quaternion_xyzw": [0, 0, 0, 0]}})");
  CHECK_THAT(r.errors, Contains("zero quaternion"));
  r = run(R"({"states": []})", " --reference-body no_such_link");
  CHECK(r.exitCode == 2);
  CHECK_THAT(r.errors, Contains("unknown body 'no_such_link'"));
  r = run(R"({"states": [ )");
  CHECK_THAT(r.errors, Contains("malformed JSON"));
  // A number beyond a double is a malformed file too, not an internal error (found by fuzzing).
  r = run(R"({"states": [{"q": [5e99999]}]})");
  CHECK(r.exitCode == 2);
  CHECK_THAT(r.errors, Contains("in.json: malformed JSON") && Contains("number overflow"));
  r = test::runMcopt("dynamics --robot " + test::quoted(dir.write("bad.urdf", "<robot")) + " --states x.json");
  CHECK(r.exitCode == 2);
  CHECK_THAT(r.errors, Contains("bad.urdf") && Contains("not a valid URDF"));
}

TEST_CASE("evaluate runs the bundled example motion and writes its results atomically", "[cli][hrp2]") {
  test::TempDir dir;
  const auto r = test::runMcopt("evaluate " + test::quoted(test::sourceDir() / "scenarios/hrp2_arm_raise.yaml") +
                                " --out " + test::quoted(dir.path()));
  REQUIRE(r.exitCode == 0);
  CHECK_THAT(r.output, Contains("electrical energy"));
  std::ifstream in(dir.path() / "result.json");
  const Json result = Json::parse(in);
  CHECK(result["energy"].get<double>() > 0.0);
  CHECK(result["tau"].size() == 100);
  CHECK(std::filesystem::exists(dir.path() / "trajectory.csv"));
  for (const auto& entry : std::filesystem::directory_iterator(dir.path()))
    CHECK(entry.path().string().find(".tmp.") == std::string::npos);  // no temporary left behind
}
