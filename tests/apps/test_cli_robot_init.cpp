// SPDX-License-Identifier: BSD-3-Clause
// `mcopt robot init`: a robot folder from a URDF alone. On our HRP-2 it must find what its
// hand-written folder says (the soles, a standing posture it holds) and scale the starter
// scenarios to HRP-2's own bundled timings; on robots we did not write (../shared) the folder it
// writes must check and run; what it cannot do it refuses, writing nothing.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <nlohmann/json.hpp>
#include <yaml-cpp/yaml.h>

#include "common/run_command.hpp"
#include "common/temp_dir.hpp"
#include "common/test_support.hpp"

using namespace mcopt;
using Catch::Matchers::Contains;
using Json = nlohmann::json;
namespace fs = std::filesystem;

namespace {

const fs::path kHrp2Urdf = test::sourceDir() / "robots/hrp2/hrp2.urdf";

test::CommandResult init(const fs::path& urdf, const fs::path& out) {
  return test::runMcopt("robot init " + test::quoted(urdf) + " --out " + test::quoted(out));
}

/// The check of `posture` on both feet in `mcopt robot check DIR --json`.
Json bothFeet(const fs::path& folder, const std::string& posture) {
  const auto r = test::runMcopt("robot check " + test::quoted(folder) + " --json");
  INFO(r.all());
  REQUIRE(r.exitCode == 0);
  const Json report = Json::parse(r.output);
  for (const Json& c : report.at("checks"))
    if (c.at("posture") == posture && c.at("support").size() == 2) return c;
  FAIL("no check of " << posture << " on both feet");
  return {};
}

std::vector<double> numbers(const YAML::Node& node) { return node.as<std::vector<double>>(); }

}  // namespace

TEST_CASE("robot init: HRP-2 from its URDF alone gives its soles, a standing posture it holds, HRP-2's own timings",
          "[cli][robot]") {
  const test::TempDir dir;
  const fs::path out = dir.path() / "hrp2";
  const auto r = init(kHrp2Urdf, out);
  INFO(r.all());
  REQUIRE(r.exitCode == 0);
  for (const char* file : {"hrp2.urdf", "actuators.yaml", "contacts.yaml", "postures.yaml", "scenarios/kick.yaml",
                           "scenarios/weight_shift.yaml", "scenarios/throw.yaml"})
    CHECK(fs::exists(out / file));

  // The soles: the URDF's sole links, their rectangles the footprint of the feet's inertia boxes,
  // which for our HRP-2 are the soles of robots/hrp2/contacts.yaml (hrp2-facts.md).
  const YAML::Node contacts = YAML::LoadFile((out / "contacts.yaml").string())["contact_surfaces"];
  CHECK(contacts["left_sole"]["link"].as<std::string>() == "l_sole");
  CHECK(contacts["right_sole"]["link"].as<std::string>() == "r_sole");
  const std::vector<double> sole = numbers(contacts["left_sole"]["rectangle"]);
  const std::vector<double> bundled{-0.095, 0.135, -0.065, 0.065};
  for (int k = 0; k < 4; ++k) CHECK(sole[k] == Approx(bundled[k]).margin(1e-3));
  CHECK(contacts["right_hand"]["link"].as<std::string>() == "r_palm");
  CHECK(contacts["left_hand"]["link"].as<std::string>() == "l_palm");

  // The standing posture: held on both feet with the centre of mass between them (the soles are
  // 0.12 m apart), knees bent (the closure of the second foot is regular there).
  const Json standing = bothFeet(out, "standing");
  CHECK(standing.at("checked") == true);
  CHECK(standing.at("holdable") == true);
  CHECK_FALSE(standing.contains("note"));  // no sole tilted, none above the other
  CHECK(standing.at("support_margin_m").get<double>() > 0.1);
  CHECK(standing.at("center_of_mass_m")[1].get<double>() == Approx(-0.06).margin(1e-6));
  const YAML::Node postures = YAML::LoadFile((out / "postures.yaml").string())["postures"];
  CHECK(postures["standing"]["RLEG_JOINT3"].as<double>() > 0.3);
  CHECK(postures["standing"]["LLEG_JOINT3"].as<double>() == Approx(postures["standing"]["RLEG_JOINT3"].as<double>()).margin(1e-6));

  // Scaled from HRP-2's dimensions, HRP-2 gets its bundled scenarios' timings and targets.
  const YAML::Node kick = YAML::LoadFile((out / "scenarios/kick.yaml").string());
  CHECK(kick["duration"].as<double>() == Approx(1.6));
  CHECK(kick["tasks"][0]["time"].as<double>() == Approx(0.8));
  CHECK(kick["tasks"][0]["target"][0].as<double>() == Approx(1.0));
  CHECK(kick["tasks"][1]["upper"][1].as<double>() == Approx(-0.14));  // as the bundled kick's
  const YAML::Node shift = YAML::LoadFile((out / "scenarios/weight_shift.yaml").string());
  CHECK(shift["duration"].as<double>() == Approx(2.4));
  CHECK(shift["tasks"][1]["time"].as<double>() == Approx(1.2));
  const YAML::Node toss = YAML::LoadFile((out / "scenarios/throw.yaml").string());
  CHECK(toss["duration"].as<double>() == Approx(2.0));
  CHECK(toss["tasks"][0]["time"].as<double>() == Approx(1.2));
  CHECK(toss["tasks"][0]["ball_mass"].as<double>() == Approx(0.2));
  CHECK(toss["tasks"][0]["target"][0].as<double>() == Approx(4.0));  // the starter's distance (the bundled 6 m less 2)
  // Both two-sole starters keep the right leg's loop short of full stretch.
  CHECK(shift["closure_reach_margin"].as<double>() == Approx(1e-3));
  CHECK(toss["closure_reach_margin"].as<double>() == Approx(1e-3));

  // Every value of actuators.yaml an estimate or the URDF's, and said so.
  std::ifstream actuators(out / "actuators.yaml");
  const std::string text{std::istreambuf_iterator<char>(actuators), {}};
  CHECK_THAT(text, Contains("ESTIMATE"));
  CHECK_THAT(text, Contains("URDF <limit effort="));
}

TEST_CASE("robot init: the starter scenarios load and run", "[cli][robot]") {
  const test::TempDir dir;
  const fs::path out = dir.path() / "hrp2";
  REQUIRE(init(kHrp2Urdf, out).exitCode == 0);
#ifdef MCOPT_UNDER_SANITIZERS
  const std::vector<std::string> scenarios{"kick"};
#else
  const std::vector<std::string> scenarios{"kick", "weight_shift", "throw"};
#endif
  for (const std::string& s : scenarios) {
    const auto r = test::runMcopt("run " + test::quoted(out / "scenarios" / (s + ".yaml")) + " --max-iterations 2 --out " +
                                  test::quoted(dir.path() / ("run-" + s)));
    INFO(s << "\n" << r.all());
    CHECK((r.exitCode == 0 || r.exitCode == 4));  // 4: stopped at the iteration cap
    CHECK(fs::exists(dir.path() / ("run-" + s) / "result.json"));
  }
}

TEST_CASE("robot init: what it cannot do it refuses, writing nothing", "[cli][robot]") {
  const test::TempDir dir;

  SECTION("a folder that is not empty") {
    const fs::path out = dir.path() / "taken";
    fs::create_directories(out);
    std::ofstream(out / "mine.txt") << "keep\n";
    const auto r = init(kHrp2Urdf, out);
    CHECK(r.exitCode == 2);
    CHECK_THAT(r.all(), Contains("exists and is not an empty folder: nothing written"));
    CHECK(std::distance(fs::directory_iterator(out), fs::directory_iterator{}) == 1);
  }
  SECTION("a folder that cannot be written") {
    const fs::path file = dir.write("plain-file", "not a folder\n");
    const auto r = init(kHrp2Urdf, file / "robot");
    CHECK(r.exitCode == 2);
    CHECK_THAT(r.all(), Contains("nothing written"));
  }
  SECTION("a robot without feet it can find") {
    // One arm: its only end is not two feet.
    const fs::path urdf = dir.write("arm.urdf", R"(<robot name="arm">
  <link name="base"><inertial><mass value="2"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="upper"><inertial><mass value="1"/><origin xyz="0 0 -0.15"/><inertia ixx="0.01" iyy="0.01" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="lower"><inertial><mass value="1"/><origin xyz="0 0 -0.15"/><inertia ixx="0.01" iyy="0.01" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/><origin xyz="0 0.2 0"/><axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="50" velocity="3"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="lower"/><origin xyz="0 0 -0.3"/><axis xyz="0 1 0"/><limit lower="0" upper="2.5" effort="30" velocity="3"/></joint>
</robot>
)");
    const auto r = init(urdf, dir.path() / "arm");
    CHECK(r.exitCode == 2);
    CHECK_THAT(r.all(), Contains("cannot find the robot's two feet"));
    CHECK_FALSE(fs::exists(dir.path() / "arm"));
  }
  SECTION("a floating joint") {
    const fs::path urdf = dir.write("floating.urdf", R"(<robot name="floating">
  <link name="world"/>
  <link name="body"><inertial><mass value="2"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="free" type="floating"><parent link="world"/><child link="body"/></joint>
</robot>
)");
    const auto r = init(urdf, dir.path() / "floating");
    CHECK(r.exitCode == 2);
    CHECK_THAT(r.all(), Contains("floating"));
    CHECK_FALSE(fs::exists(dir.path() / "floating"));
  }
  // No staging folder left behind in any case.
  for (const auto& entry : fs::directory_iterator(dir.path()))
    CHECK(entry.path().filename().string().find("mcopt-init") == std::string::npos);
}

#ifdef MCOPT_SHARED_DIR
TEST_CASE("robot init: Talos, JVRC-1 and iCub (robots we did not write) set up, stand, and their starters run",
          "[cli][robot][shared]") {
  const fs::path robots = test::sharedDir() / "robots";
  for (const auto& [name, urdf] : {std::pair{"talos", robots / "talos/talos_reduced.urdf"},
                                   std::pair{"jvrc1", robots / "jvrc1/jvrc1.urdf"},
                                   std::pair{"icub", robots / "icub/icub.urdf"}}) {
    INFO(name);
    const test::TempDir dir;
    const fs::path out = dir.path() / name;
    const auto r = init(urdf, out);
    INFO(r.all());
    REQUIRE(r.exitCode == 0);
    const Json standing = bothFeet(out, "standing");
    CHECK(standing.at("holdable") == true);
    CHECK(standing.at("support_margin_m").get<double>() > 0.05);
    if (std::string(name) == "talos") {
      // Talos's arm is longer than HRP-2's (4.6 m by its length) and its joints slower (2.7–4.6
      // rad/s against 5): the throw's distance follows the hand's speed squared.
      const YAML::Node toss = YAML::LoadFile((out / "scenarios/throw.yaml").string());
      CHECK(toss["tasks"][0]["target"][0].as<double>() < 4.5);
      CHECK_THAT(r.output, Contains("m/s with its arm's and trunk's joints at their velocity limits"));
    }
#ifndef MCOPT_UNDER_SANITIZERS
    // Full runs take minutes each (docs/tutorials/own-robot.md has them); here each starter
    // loads, passes its checks and takes its first Ipopt iterations.
    for (const char* s : {"kick", "weight_shift", "throw"}) {
      const auto run = test::runMcopt("run " + test::quoted(out / "scenarios" / (std::string(s) + ".yaml")) +
                                      " --max-iterations 2 --out " + test::quoted(dir.path() / (std::string("run-") + s)));
      INFO(s << "\n" << run.all());
      CHECK((run.exitCode == 0 || run.exitCode == 4));
    }
#endif
  }
}

TEST_CASE("robot init: Romeo's non-physical inertias need the flag, which its starters then carry", "[cli][robot][shared]") {
  const fs::path urdf = test::sharedDir() / "robots/romeo/romeo.urdf";
  const test::TempDir dir;
  const auto refused = init(urdf, dir.path() / "refused");
  CHECK(refused.exitCode == 2);
  CHECK_THAT(refused.all(), Contains("RShoulderYawLink") && Contains("--allow-nonphysical-inertia"));
  CHECK_FALSE(fs::exists(dir.path() / "refused"));

  const fs::path out = dir.path() / "romeo";
  const auto r = test::runMcopt("robot init " + test::quoted(urdf) + " --out " + test::quoted(out) + " --allow-nonphysical-inertia");
  INFO(r.all());
  REQUIRE(r.exitCode == 0);
  for (const char* s : {"kick", "weight_shift", "throw"})
    CHECK(YAML::LoadFile((out / "scenarios" / (std::string(s) + ".yaml")).string())["allow_nonphysical_inertia"].as<bool>());
  const auto check = test::runMcopt("robot check " + test::quoted(out) + " --allow-nonphysical-inertia --json");
  INFO(check.all());
  REQUIRE(check.exitCode == 0);
  const Json report = Json::parse(check.output);  // held: the loop reads into it
  for (const Json& c : report.at("checks"))
    if (c.at("posture") == "standing" && c.at("support").size() == 2) CHECK(c.at("holdable") == true);
}
#endif
