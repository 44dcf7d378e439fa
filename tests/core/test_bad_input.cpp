// SPDX-License-Identifier: BSD-3-Clause
// Every bad-input case of the robot files gets an InputError naming the file and the
// element or field (issue 2 acceptance).
#include <catch2/catch.hpp>

#include "common/temp_dir.hpp"
#include "common/test_support.hpp"
#include "core/actuators.hpp"
#include "core/dynamics_model.hpp"
#include "core/errors.hpp"
#include "core/robot_files.hpp"
#include "core/trajectory_evaluation.hpp"

using namespace mcopt;
using Catch::Matchers::Contains;

namespace {

std::string urdfLink(const std::string& name, const std::string& mass = "1", const std::string& ixx = "0.01",
                 const std::string& izz = "0.01") {
  return "<link name=\"" + name + "\"><inertial><mass value=\"" + mass + "\"/><inertia ixx=\"" + ixx +
         "\" iyy=\"0.01\" izz=\"" + izz + "\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial></link>";
}

std::string joint(const std::string& name, const std::string& parent, const std::string& child,
                  const std::string& type = "revolute") {
  return "<joint name=\"" + name + "\" type=\"" + type + "\"><parent link=\"" + parent + "\"/><child link=\"" + child +
         "\"/><axis xyz=\"0 0 1\"/><limit lower=\"-1\" upper=\"1\" effort=\"10\" velocity=\"2\"/></joint>";
}

std::string robot(const std::string& body) { return "<robot name=\"test\">" + body + "</robot>"; }

const std::string kGood = robot(urdfLink("base") + urdfLink("arm") + urdfLink("hand") + joint("shoulder", "base", "arm") +
                                joint("wrist", "arm", "hand"));

}  // namespace

TEST_CASE("URDF errors name the file and the element", "[input][urdf]") {
  test::TempDir dir;
  SECTION("missing file") {
    CHECK_THROWS_WITH(loadUrdfFile(dir.path() / "absent.urdf"), Contains("absent.urdf") && Contains("cannot open"));
  }
  SECTION("malformed XML") {
    const auto file = dir.write("broken.urdf", "<robot name=\"x\"><link name=\"a\"></robot");
    CHECK_THROWS_WITH(loadUrdfFile(file), Contains("broken.urdf") && Contains("not a valid URDF"));
  }
  SECTION("duplicate link names") {
    CHECK_THROWS_WITH(loadUrdfString(robot(urdfLink("a") + urdfLink("a")), "dup.urdf"),
                      Contains("dup.urdf") && Contains("'a'"));
  }
  SECTION("duplicate joint names") {
    CHECK_THROWS_WITH(loadUrdfString(robot(urdfLink("a") + urdfLink("b") + urdfLink("c") + joint("j", "a", "b") + joint("j", "b", "c")),
                                     "dupj.urdf"),
                      Contains("dupj.urdf") && Contains("'j'"));
  }
  SECTION("negative mass") {
    const std::string bad = urdfLink("b", "-2");
    CHECK_THROWS_WITH(loadUrdfString(robot(urdfLink("a") + bad + joint("j", "a", "b")), "neg.urdf"),
                      Contains("neg.urdf") && Contains("link 'b'") && Contains("negative mass"));
  }
  SECTION("inertia not positive definite") {
    const std::string bad = urdfLink("b", "1", "-0.5");
    CHECK_THROWS_WITH(loadUrdfString(robot(urdfLink("a") + bad + joint("j", "a", "b")), "pd.urdf"),
                      Contains("pd.urdf") && Contains("link 'b'") && Contains("not positive definite"));
  }
  SECTION("inertia breaking the triangle inequality") {
    const std::string bad = urdfLink("b", "1", "0.01", "0.5");
    CHECK_THROWS_WITH(loadUrdfString(robot(urdfLink("a") + bad + joint("j", "a", "b")), "tri.urdf"),
                      Contains("tri.urdf") && Contains("link 'b'") && Contains("triangle inequality"));
    // Allowed explicitly, it becomes a warning.
    const RobotModel allowed = loadUrdfString(robot(urdfLink("a") + bad + joint("j", "a", "b")), "tri.urdf", {true});
    REQUIRE(allowed.warnings.size() == 1);
    CHECK_THAT(allowed.warnings[0], Contains("triangle inequality"));
  }
  SECTION("floating and planar joints are rejected") {
    CHECK_THROWS_WITH(loadUrdfString(robot(urdfLink("a") + urdfLink("b") + joint("free", "a", "b", "floating")), "f.urdf"),
                      Contains("f.urdf") && Contains("joint 'free'") && Contains("floating"));
    CHECK_THROWS_WITH(loadUrdfString(robot(urdfLink("a") + urdfLink("b") + joint("flat", "a", "b", "planar")), "p.urdf"),
                      Contains("p.urdf") && Contains("joint 'flat'") && Contains("planar"));
  }
  SECTION("a link with two parents (a loop) is rejected") {
    CHECK_THROWS_WITH(loadUrdfString(robot(urdfLink("a") + urdfLink("b") + urdfLink("c") + joint("j1", "a", "c") + joint("j2", "b", "c")),
                                     "loop.urdf"),
                      Contains("loop.urdf"));
  }
  SECTION("links whose joints form a loop apart from the root are rejected, not dropped (found by fuzzing)") {
    // b → c → b hangs from nothing: urdfdom accepts it, with 'a' as the root.
    CHECK_THROWS_WITH(loadUrdfString(robot(urdfLink("a") + urdfLink("b") + urdfLink("c") + joint("j1", "b", "c") + joint("j2", "c", "b")),
                                     "cycle.urdf"),
                      Contains("cycle.urdf: links not connected to the root link 'a' (their joints form a loop): b, c"));
  }
  SECTION("a file that is not UTF-8 is refused at its line, before a name with a stray byte reaches JSON (found by fuzzing)") {
    CHECK_THROWS_WITH(loadUrdfString("<?xml version=\"1.0\"?>\n<robot name=\"t\xBB\">" + urdfLink("a") + "</robot>", "latin.urdf"),
                      Contains("latin.urdf:2: not valid UTF-8 (byte 0xBB)"));
    // Overlong forms and surrogates are not UTF-8 either; multi-byte names are.
    CHECK_THROWS_WITH(loadUrdfString(robot(urdfLink("\xC0\xAF")), "overlong.urdf"), Contains("overlong.urdf:1: not valid UTF-8"));
    CHECK_THROWS_WITH(loadUrdfString(robot(urdfLink("\xED\xA0\x80")), "surrogate.urdf"), Contains("not valid UTF-8 (byte 0xA0)"));
    CHECK_THROWS_WITH(loadUrdfString(robot(urdfLink("\xE2\x82")), "cut.urdf"), Contains("not valid UTF-8"));
    CHECK(loadUrdfString(robot(urdfLink("h\xC3\xBC" "fte") + urdfLink("\xF0\x9F\xA6\xBE") + joint("j", "h\xC3\xBC" "fte", "\xF0\x9F\xA6\xBE")),
                         "utf8.urdf").bodies.size() == 2);
  }
  SECTION("unknown body") {
    const RobotModel model = loadUrdfString(kGood, "good.urdf");
    CHECK_THROWS_WITH(DynamicsModel(model, "no_such_link"), Contains("good.urdf") && Contains("unknown body 'no_such_link'"));
    CHECK_THROWS_WITH(model.jointIndex("elbow"), Contains("unknown joint 'elbow'"));
  }
  SECTION("mimic tags are ignored with a warning") {
    const std::string mimic = "<joint name=\"m\" type=\"revolute\"><parent link=\"arm\"/><child link=\"finger\"/>"
                              "<axis xyz=\"1 0 0\"/><limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/>"
                              "<mimic joint=\"wrist\" multiplier=\"2\"/></joint>";
    const std::string xml = robot(urdfLink("base") + urdfLink("arm") + urdfLink("hand") + urdfLink("finger") +
                                  joint("shoulder", "base", "arm") + joint("wrist", "arm", "hand") + mimic);
    const RobotModel model = loadUrdfString(xml, "mimic.urdf");
    CHECK(model.jointCount() == 3);
    REQUIRE(model.warnings.size() == 1);
    CHECK_THAT(model.warnings[0], Contains("joint 'm'") && Contains("mimic") && Contains("the joint is independent"));
  }
  SECTION("mimic tags on fixed joints: merged, one true warning for all of them") {
    auto fixedMimic = [](const std::string& name, const std::string& parent, const std::string& child) {
      return "<joint name=\"" + name + "\" type=\"fixed\"><parent link=\"" + parent + "\"/><child link=\"" + child +
             "\"/><mimic joint=\"wrist\"/></joint>";
    };
    const std::string xml = robot(urdfLink("base") + urdfLink("arm") + urdfLink("hand") + urdfLink("f1") + urdfLink("f2") +
                                  joint("shoulder", "base", "arm") + joint("wrist", "arm", "hand") +
                                  fixedMimic("g1", "hand", "f1") + fixedMimic("g2", "hand", "f2"));
    const RobotModel model = loadUrdfString(xml, "gripper.urdf");
    CHECK(model.jointCount() == 2);
    REQUIRE(model.warnings.size() == 1);
    CHECK_THAT(model.warnings[0], Contains("<mimic> on 2 fixed joints (g1, g2)") && Contains("merged into its parent body") &&
                                      !Contains("independent"));
  }
}

TEST_CASE("fixed joints merge into their parent, massless links are fine", "[urdf]") {
  const std::string xml = robot(urdfLink("base") + "<link name=\"frame\"/>" + urdfLink("tool") +
                                "<joint name=\"f1\" type=\"fixed\"><parent link=\"base\"/><child link=\"frame\"/><origin xyz=\"0 0 1\"/></joint>"
                                "<joint name=\"f2\" type=\"fixed\"><parent link=\"frame\"/><child link=\"tool\"/><origin xyz=\"1 0 0\"/></joint>");
  const RobotModel model = loadUrdfString(xml, "merge.urdf");
  CHECK(model.bodyCount() == 1);
  CHECK(model.jointCount() == 0);
  CHECK(model.frames.size() == 3);
  CHECK(model.totalMass() == Approx(2.0));
  CHECK(model.bodies[0].inertia.com.isApprox(Vector3(0.5, 0.0, 0.5)));
  // Parallel axis: each 1 kg point sits √0.5 m from the combined com, in the x–z plane.
  CHECK(model.bodies[0].inertia.inertiaAboutCom(1, 1) == Approx(0.01 * 2 + 2 * 0.5));
  CHECK(model.frames[model.frameIndex("tool")].placement.translation.isApprox(Vector3(1.0, 0.0, 1.0)));
}

TEST_CASE("actuator, contact and posture files: errors name file, line and field", "[input][yaml]") {
  test::TempDir dir;
  const RobotModel model = loadUrdfString(kGood, "good.urdf");
  SECTION("a valid actuator file overrides the URDF defaults") {
    const auto file = dir.write("act.yaml", "defaults: {gear_ratio: 50}\njoints:\n  wrist: {torque_constant: 0.02, torque_limit: 3}\n");
    const ActuatorSet set = loadActuators(file, model);
    CHECK(set.joints[0].gearRatio == 50);
    CHECK(set.joints[0].torqueLimit == 10);  // URDF effort
    CHECK(set.joints[1].torqueLimit == 3);
    CHECK(set.joints[1].torqueConstant == 0.02);
  }
  SECTION("unknown joint") {
    const auto file = dir.write("act.yaml", "joints:\n  shoulder: {gear_ratio: 100}\n  elbow: {gear_ratio: 100}\n");
    CHECK_THROWS_WITH(loadActuators(file, model), Contains("act.yaml:3") && Contains("joints.elbow") && Contains("unknown joint"));
  }
  SECTION("unknown key") {
    const auto file = dir.write("act.yaml", "joints:\n  shoulder: {gear_ration: 100}\n");
    CHECK_THROWS_WITH(loadActuators(file, model), Contains("act.yaml:2") && Contains("joints.shoulder.gear_ration") &&
                                                      Contains("unknown key"));
  }
  SECTION("impossible numbers and wrong types") {
    const auto neg = dir.write("neg.yaml", "joints:\n  shoulder:\n    resistance: -1\n");
    CHECK_THROWS_WITH(loadActuators(neg, model), Contains("neg.yaml:3") && Contains("resistance") && Contains("negative"));
    const auto text = dir.write("text.yaml", "joints:\n  shoulder:\n    gear_ratio: fast\n");
    CHECK_THROWS_WITH(loadActuators(text, model), Contains("text.yaml:3") && Contains("gear_ratio") && Contains("number"));
    const auto nan = dir.write("nan.yaml", "joints:\n  shoulder:\n    gear_ratio: .nan\n");
    CHECK_THROWS_WITH(loadActuators(nan, model), Contains("nan.yaml:3") && Contains("finite"));
  }
  SECTION("a key that is a list or a mapping, not a name (found by fuzzing)") {
    const auto top = dir.write("key.yaml", "joints:\n  shoulder: {gear_ratio: 100}\n[a, b]: 1\n");
    CHECK_THROWS_WITH(loadActuators(top, model), Contains("key.yaml:3") && Contains("a key must be a name"));
    const auto inner = dir.write("joint.yaml", "joints:\n  ? {x: 1}\n  : {gear_ratio: 100}\n");
    CHECK_THROWS_WITH(loadActuators(inner, model), Contains("joint.yaml:2"));
    const auto posture = dir.write("p.yaml", "postures:\n  bent: {[shoulder]: 0.3}\n");
    CHECK_THROWS_WITH(loadPostures(posture, model), Contains("p.yaml:2"));
  }
  SECTION("a folder where a file is named (found by fuzzing)") {
    CHECK_THROWS_WITH(loadContactSurfaces(dir.path(), model), Contains(dir.path().string() + ": not a file"));
    CHECK_THROWS_WITH(loadUrdfFile(dir.path()), Contains(dir.path().string() + ": not a file"));
  }
  SECTION("a file that is not UTF-8 is refused at its line; UTF-16 is transcoded (found by fuzzing)") {
    const auto latin = dir.write("l.yaml", "contact_surfaces:\n  pa\xBBlm: {link: hand, rectangle: [-0.1, 0.1, -0.05, 0.05]}\n");
    CHECK_THROWS_WITH(loadContactSurfaces(latin, model), Contains("l.yaml:2: not valid UTF-8 (byte 0xBB)"));
    const std::string text = "contact_surfaces:\n  palm: {link: hand, rectangle: [-0.1, 0.1, -0.05, 0.05]}\n";
    std::string utf16 = "\xFF\xFE";  // little-endian byte-order mark
    for (const char c : text) utf16 += std::string{c, '\0'};
    const auto wide = dir.write("w.yaml", utf16);
    const auto surfaces = loadContactSurfaces(wide, model);
    REQUIRE(surfaces.size() == 1);
    CHECK(surfaces[0].name == "palm");
  }
  SECTION("malformed YAML") {
    const auto file = dir.write("bad.yaml", "joints: [unclosed\n");
    CHECK_THROWS_WITH(loadActuators(file, model), Contains("bad.yaml") && Contains("malformed YAML"));
  }
  SECTION("contact surfaces") {
    const auto good = dir.write("c.yaml", "contact_surfaces:\n  palm: {link: hand, position: [0, 0, -0.1], rectangle: [-0.1, 0.1, -0.05, 0.05], friction: 0.6}\n");
    const auto surfaces = loadContactSurfaces(good, model);
    REQUIRE(surfaces.size() == 1);
    CHECK(surfaces[0].friction == 0.6);
    const auto unknown = dir.write("u.yaml", "contact_surfaces:\n  palm: {link: foot, rectangle: [-0.1, 0.1, -0.05, 0.05]}\n");
    CHECK_THROWS_WITH(loadContactSurfaces(unknown, model), Contains("u.yaml:2") && Contains("unknown body 'foot'"));
    const auto empty = dir.write("e.yaml", "contact_surfaces:\n  palm: {link: hand, rectangle: [0.1, -0.1, -0.05, 0.05]}\n");
    CHECK_THROWS_WITH(loadContactSurfaces(empty, model), Contains("e.yaml:2") && Contains("rectangle"));
    const auto mu = dir.write("m.yaml", "contact_surfaces:\n  palm: {link: hand, rectangle: [-0.1, 0.1, -0.05, 0.05], friction: 0}\n");
    CHECK_THROWS_WITH(loadContactSurfaces(mu, model), Contains("m.yaml:2") && Contains("friction") && Contains("positive"));
  }
  SECTION("postures") {
    const auto file = dir.write("p.yaml", "postures:\n  up: {shoulder: 0.5}\n  bad: {knee: 1}\n");
    CHECK_THROWS_WITH(loadPostures(file, model), Contains("p.yaml:3") && Contains("postures.bad.knee") && Contains("unknown joint"));
  }
}

TEST_CASE("trajectory evaluation refuses NaN parameters and impossible durations", "[input][spline]") {
  const RobotModel model = loadUrdfString(kGood, "good.urdf");
  const DynamicsModel dynamics(model, "base");
  const MotionParametrization parametrization(model.jointCount());
  TrajectoryEvaluator evaluator(dynamics, defaultActuators(model), SampledTrajectory(parametrization, 10));
  TrajectoryResult result;
  Eigen::VectorXd x = Eigen::VectorXd::Zero(parametrization.parameterCount());
  CHECK_NOTHROW(evaluator.evaluate(x, 1.0, result));
  CHECK_THROWS_WITH(evaluator.evaluate(x, 0.0, result), Contains("duration must be positive"));
  CHECK_THROWS_WITH(evaluator.evaluate(x, std::nan(""), result), Contains("duration"));
  CHECK_THROWS_WITH(evaluator.evaluate(Eigen::VectorXd::Zero(3), 1.0, result), Contains("expected 10 spline parameters, got 3"));
  x[4] = std::nan("");
  CHECK_THROWS_WITH(evaluator.evaluate(x, 1.0, result), Contains("NaN"));
  CHECK_THROWS_WITH(MotionParametrization(3, 5), Contains("at least 7 control points"));
  CHECK_THROWS_WITH(SampledTrajectory(parametrization, 1), Contains("at least 2 samples"));
}
