// SPDX-License-Identifier: BSD-3-Clause
// `mcopt robot check`: each named posture at rest on both feet and on each, against what
// `mcopt dynamics` computes of the same posture, and the same answer whichever foot is first.
#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <iterator>
#include <string>
#include <nlohmann/json.hpp>

#include "common/run_command.hpp"
#include "common/temp_dir.hpp"
#include "common/test_support.hpp"
#include "core/inverse_dynamics.hpp"
#include "core/robot_files.hpp"
#include "core/robot_model.hpp"

using namespace mcopt;
using Catch::Matchers::Contains;
using Json = nlohmann::json;

namespace {

const std::filesystem::path kHrp2 = test::sourceDir() / "robots/hrp2";

Json checkJson(const std::string& arguments) {
  const auto r = test::runMcopt("robot check " + arguments + " --json");
  INFO(r.all());
  REQUIRE(r.exitCode == 0);
  return Json::parse(r.output);
}

const Json& find(const Json& report, const std::string& posture, const std::vector<std::string>& support) {
  for (const Json& c : report.at("checks"))
    if (c.at("posture") == posture && c.at("support").get<std::vector<std::string>>() == support) return c;
  FAIL("no check of " << posture << " on " << support.size() << " feet");
  throw std::logic_error("unreachable");
}

}  // namespace

TEST_CASE("robot check: half-sitting on both feet and on one, as inverse dynamics says", "[cli][robot]") {
  const Json report = checkJson(test::quoted(kHrp2) + " --feet l_sole,r_sole");
  CHECK(report.at("feet") == Json({"l_sole", "r_sole"}));
  CHECK(report.at("checks").size() == 3 * 2);  // zero and half_sitting, each on both feet and on each
  // The values in use for every joint, with where each came from.
  REQUIRE(report.at("joints").size() == 30);
  for (const Json& j : report.at("joints"))
    if (j.at("name") == "RLEG_JOINT3") {
      CHECK(j.at("effort").get<double>() == 250.0);
      CHECK(j.at("sources").at("effort") == "actuator file joints.RLEG_JOINT3");
      CHECK(j.at("sources").at("rotor_inertia") == "actuator file joints.RLEG_JOINT3");
    }

  const Json& both = find(report, "half_sitting", {"l_sole", "r_sole"});
  CHECK(both.at("checked") == true);
  CHECK(both.at("holdable") == true);
  CHECK(both.at("support_margin_m").get<double>() > 0.05);  // between the feet, well inside
  CHECK(both.at("inner_status") == "optimal");
  // Half-sitting is symmetric: its centre of mass halfway between the soles (0.12 m apart).
  CHECK(both.at("center_of_mass_m")[1].get<double>() == Approx(-0.06).margin(2e-3));
  // The right leg's stretch: its hip-ankle distance (RLEG_JOINT0 to RLEG_JOINT5) at
  // half-sitting over the same at the zero posture, where HRP-2's leg is straight (its longest).
  {
    const RobotModel robot = loadUrdfFile(kHrp2 / "hrp2.urdf");
    const DynamicsModel model(robot, "BODY");
    DynamicsData data(model);
    const auto hipToAnkle = [&](const Eigen::VectorXd& q) {
      forwardKinematics(model, data, q);
      return (data.position[static_cast<std::size_t>(model.positionOfJoint(robot.findJoint("RLEG_JOINT5")))] -
              data.position[static_cast<std::size_t>(model.positionOfJoint(robot.findJoint("RLEG_JOINT0")))])
          .norm();
    };
    const auto postures = loadPostures(kHrp2 / "postures.yaml", robot);
    const double expected = hipToAnkle(postures.at("half_sitting")) / hipToAnkle(Eigen::VectorXd::Zero(robot.jointCount()));
    CHECK(expected < 0.99);
    CHECK(both.at("loop_reach").get<double>() == Approx(expected).epsilon(1e-9));
  }
  CHECK(!find(report, "half_sitting", {"l_sole"}).contains("loop_reach"));  // one foot: no loop

  // On one sole: HRP-2's soles are 0.13 m wide and 0.12 m apart, so the centre of mass halfway
  // between them is 5 mm inside either (robots/hrp2/contacts.yaml).
  const Json& left = find(report, "half_sitting", {"l_sole"});
  CHECK(left.at("holdable") == true);
  CHECK(left.at("support_margin_m").get<double>() == Approx(0.005).margin(2e-3));
  // Straight legs: the closure of the second sole is singular there, and the check says so.
  const Json& zero = find(report, "zero", {"l_sole", "r_sole"});
  CHECK(zero.at("checked") == false);
  CHECK_THAT(zero.at("note").get<std::string>(), Contains("singular"));

  // On the left sole alone, at rest: the sole carries the weight at the centre of mass, so the
  // reference wrench of `mcopt dynamics` puts the centre of mass where the check does, and its
  // torques against `robot info`'s limits give the check's largest ratio.
  const auto info = test::runMcopt("robot info --robot " + test::quoted(kHrp2 / "hrp2.urdf") + " --actuators " +
                                   test::quoted(kHrp2 / "actuators.yaml") + " --json");
  REQUIRE(info.exitCode == 0);
  const Json joints = Json::parse(info.output).at("joints");
  const std::map<std::string, double> halfSitting = {
      {"RLEG_JOINT2", -0.453786}, {"RLEG_JOINT3", 0.872665},  {"RLEG_JOINT4", -0.418879}, {"LLEG_JOINT2", -0.453786},
      {"LLEG_JOINT3", 0.872665},  {"LLEG_JOINT4", -0.418879}, {"RARM_JOINT0", 0.261799},  {"RARM_JOINT1", -0.174533},
      {"RARM_JOINT3", -0.523599}, {"RARM_JOINT6", 0.174533},  {"LARM_JOINT0", 0.261799},  {"LARM_JOINT1", 0.174533},
      {"LARM_JOINT3", -0.523599}, {"LARM_JOINT6", 0.174533}};  // robots/hrp2/postures.yaml
  Json states = {{"joint_names", Json::array()}, {"states", Json::array({{{"q", Json::array()}}})}};
  for (const Json& joint : joints) {
    const std::string name = joint.at("name");
    states["joint_names"].push_back(name);
    states["states"][0]["q"].push_back(halfSitting.count(name) ? halfSitting.at(name) : 0.0);
  }
  test::TempDir dir;
  const auto file = dir.write("s.json", states.dump());
  const auto out = dir.path() / "d.json";
  const auto d = test::runMcopt("dynamics --robot " + test::quoted(kHrp2 / "hrp2.urdf") + " --reference-body l_sole --states " +
                                test::quoted(file) + " --out " + test::quoted(out));
  INFO(d.all());
  REQUIRE(d.exitCode == 0);
  std::ifstream in(out);
  const Json result = Json::parse(in).at("results").at(0);
  const Json& w = result.at("reference_wrench");
  const double fz = w[2].get<double>();
  // The sole's moment about its origin is c × (m g ẑ): n_x = c_y f_z, n_y = −c_x f_z.
  CHECK(left.at("center_of_mass_m")[0].get<double>() == Approx(-w[4].get<double>() / fz).margin(1e-9));
  CHECK(left.at("center_of_mass_m")[1].get<double>() == Approx(w[3].get<double>() / fz).margin(1e-9));
  double worst = -1.0;
  std::string worstJoint;
  for (std::size_t j = 0; j < joints.size(); ++j) {
    const double ratio = std::abs(result.at("tau")[j].get<double>()) / joints[j].at("effort").get<double>();
    if (ratio > worst) worst = ratio, worstJoint = joints[j].at("name");
  }
  const Json& largest = left.at("largest_static_torque");
  CHECK(largest.at("joint") == worstJoint);
  CHECK(largest.at("torque_N_m").get<double>() / largest.at("limit_N_m").get<double>() == Approx(worst).epsilon(1e-9));
  CHECK(left.at("static_electrical_power_W").get<double>() > 0.0);
}

TEST_CASE("robot check: the same answer whichever foot is named first", "[cli][robot]") {
  const Json a = checkJson(test::quoted(kHrp2) + " --feet l_sole,r_sole");
  const Json b = checkJson(test::quoted(kHrp2));  // the feet in the contact file's order: r_sole first
  REQUIRE(b.at("feet") == Json({"r_sole", "l_sole"}));
  const Json& both = find(a, "half_sitting", {"l_sole", "r_sole"});
  const Json& swapped = find(b, "half_sitting", {"r_sole", "l_sole"});
  // The support polygon and the centre of mass in another frame, the same margin; the same split
  // of the load between the feet, so the same static power.
  CHECK(swapped.at("support_margin_m").get<double>() == Approx(both.at("support_margin_m").get<double>()).margin(1e-9));
  CHECK(swapped.at("static_electrical_power_W").get<double>() ==
        Approx(both.at("static_electrical_power_W").get<double>()).epsilon(1e-6));
  CHECK(find(b, "half_sitting", {"l_sole"}).at("support_margin_m").get<double>() ==
        Approx(find(a, "half_sitting", {"l_sole"}).at("support_margin_m").get<double>()).margin(1e-9));
}

TEST_CASE("robot check: a posture with a foot lifted is not checked on both feet, and bad input is named", "[cli][robot][input]") {
  test::TempDir dir;
  const auto postures = dir.write("postures.yaml", "postures:\n  knee_up: {RLEG_JOINT2: -1.2, RLEG_JOINT3: 1.5}\n");
  const auto files = " --robot " + test::quoted(kHrp2 / "hrp2.urdf") + " --contacts " + test::quoted(kHrp2 / "contacts.yaml");
  const Json report = checkJson(files + " --postures " + test::quoted(postures) + " --feet l_sole,r_sole");
  const Json& both = find(report, "knee_up", {"l_sole", "r_sole"});
  CHECK(both.at("checked") == false);
  CHECK_THAT(both.at("note").get<std::string>(), Contains("r_sole tilted"));
  CHECK(find(report, "knee_up", {"l_sole"}).at("checked") == true);

  const auto out = dir.path() / "check.json";
  auto expectError = [&](const std::string& arguments, const std::vector<std::string>& fragments) {
    const auto r = test::runMcopt("robot check " + arguments + " --out " + test::quoted(out));
    INFO(r.all());
    CHECK(r.exitCode == 2);
    for (const auto& f : fragments) CHECK_THAT(r.errors, Contains(f));
    CHECK_FALSE(std::filesystem::exists(out));
  };
  expectError(test::quoted(dir.path()), {"expected one .urdf file in the robot folder, found 0"});
  expectError(files + " --postures " + test::quoted(postures) + " --feet l_sole,left_foot",
              {"--feet: 'left_foot' is not a contact surface", "(it has r_sole, l_sole, r_hand, l_hand)"});
  expectError(files + " --postures " + test::quoted(dir.path() / "none.yaml"), {"none.yaml", "file not found"});
  const auto hands = dir.write("hands.yaml", "contact_surfaces:\n  palm: {link: r_palm, rectangle: [-0.02, 0.02, -0.02, 0.02]}\n");
  expectError(" --robot " + test::quoted(kHrp2 / "hrp2.urdf") + " --contacts " + test::quoted(hands) + " --postures " +
                  test::quoted(postures),
              {"cannot tell the two feet", "--feet"});
}

TEST_CASE("non-physical inertias: refused by run and robot check, loaded with their warning when allowed", "[cli][robot]") {
  // HRP-2 with one link whose principal moments break the triangle inequality (0.01 + 0.01 < 0.5).
  const test::TempDir dir;
  std::ifstream in(kHrp2 / "hrp2.urdf");
  std::string urdf((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string original = R"(<inertia ixx="0.0807" ixy="0" ixz="0" iyy="0.06" iyz="0" izz="0.0807"/>)";
  const std::size_t at = urdf.find(original);
  REQUIRE(at != std::string::npos);
  urdf.replace(at, original.size(), R"(<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.5"/>)");
  const auto folder = dir.path() / "robot";
  std::filesystem::create_directories(folder);
  std::ofstream(folder / "hrp2.urdf") << urdf;
  for (const char* side : {"actuators.yaml", "contacts.yaml", "postures.yaml"}) std::filesystem::copy_file(kHrp2 / side, folder / side);

  const auto refused = test::runMcopt("robot check " + test::quoted(folder));
  CHECK(refused.exitCode == 2);
  CHECK_THAT(refused.errors, Contains("triangle inequality") && Contains("--allow-nonphysical-inertia"));
  const auto allowed = test::runMcopt("robot check " + test::quoted(folder) + " --allow-nonphysical-inertia --json");
  INFO(allowed.all());
  CHECK(allowed.exitCode == 0);
  CHECK_THAT(allowed.errors, Contains("mcopt: warning: ") && Contains("triangle inequality"));

  // A scenario on it: refused, allowed by the flag or by its own field, with the warning.
  std::ifstream kickFile(test::sourceDir() / "scenarios/hrp2_kick.yaml");
  std::string kick((std::istreambuf_iterator<char>(kickFile)), std::istreambuf_iterator<char>());
  for (const char* side : {"hrp2.urdf", "actuators.yaml", "contacts.yaml", "postures.yaml"}) {
    const std::string from = std::string("../robots/hrp2/") + side;
    kick.replace(kick.find(from), from.size(), (folder / side).string());
  }
  // On 20 samples: the run is one iteration, the point is what loads (100 samples: 45 s of this
  // test under the sanitizers).
  const std::string bundledSamples = "samples: 100";
  REQUIRE(kick.find(bundledSamples) != std::string::npos);
  kick.replace(kick.find(bundledSamples), bundledSamples.size(), "samples: 20");
  const auto scenario = dir.write("kick.yaml", kick);
  const auto field = dir.write("kick_allowed.yaml", kick + "allow_nonphysical_inertia: true\n");
  const std::string limits = " --max-iterations 1 --configuration-optimisation off --out " + test::quoted(dir.path() / "out");
  const auto run = test::runMcopt("run " + test::quoted(scenario) + limits);
  CHECK(run.exitCode == 2);
  CHECK_THAT(run.errors, Contains("triangle inequality") && Contains("allow_nonphysical_inertia: true"));
  for (const std::string& how : {test::quoted(scenario) + " --allow-nonphysical-inertia", test::quoted(field)}) {
    const auto ran = test::runMcopt("run " + how + limits);
    INFO(ran.all());
    CHECK((ran.exitCode == 0 || ran.exitCode == 4));
    CHECK_THAT(ran.errors, Contains("mcopt: warning: ") && Contains("triangle inequality"));
  }
}

TEST_CASE("robot check --plot: each contact surface drawn against its link's geometry", "[cli][robot][plot]") {
  const test::TempDir dir;
  const auto r = test::runMcopt("robot check " + test::quoted(kHrp2) + " --feet l_sole,r_sole --plot " +
                                test::quoted(dir.path() / "figures"));
  INFO(r.all());
  REQUIRE(r.exitCode == 0);
  for (const char* file : {"contacts.png", "contacts.svg"}) {
    const auto path = dir.path() / "figures" / file;
    REQUIRE(std::filesystem::exists(path));
    CHECK(std::filesystem::file_size(path) > 10000);
  }
  // The SVG names every surface of robots/hrp2/contacts.yaml and where its geometry came from.
  std::ifstream svg(dir.path() / "figures" / "contacts.svg");
  const std::string text{std::istreambuf_iterator<char>(svg), {}};
  for (const char* surface : {"l_sole on l_sole", "r_sole on r_sole", "l_hand on l_palm", "r_hand on r_palm"})
    CHECK_THAT(text, Contains(surface));
}
