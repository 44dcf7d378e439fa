// SPDX-License-Identifier: BSD-3-Clause
// Task kinds as models (outer_nlp/task.hpp): each kind's calcDiff against its calc and against
// central differences in q and q̇; the orientation angle's value; the registry read from a
// scenario file, one task of every registered kind.
#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>
#include <random>

#include "common/every_task_kind.hpp"
#include "common/finite_differences.hpp"
#include "common/temp_dir.hpp"
#include "common/test_support.hpp"
#include "core/inverse_dynamics.hpp"
#include "core/spatial.hpp"
#include "outer_nlp/ball_flight_task.hpp"
#include "outer_nlp/motion_problem.hpp"

namespace mcopt {

namespace {

/// The kick's tasks of every kind, and a throw's two rows from the right hand (HRP-2).
std::vector<TaskSpec> tasksToCheck(const Scenario& scenario) {
  std::vector<TaskSpec> tasks = test::everyTaskKind(scenario);
  const int hand = scenario.robot.frameIndex("RARM_LINK6");
  for (const auto part : {BallFlightTask::Part::Landing, BallFlightTask::Part::Release}) {
    TaskSpec t;
    t.name = "throw";
    t.task = std::make_shared<BallFlightTask>(part, hand, Vector3(0.0, 0.0, -0.1), Vector3(4.0, -0.5, 0.2), 9.81);
    t.lower.setConstant(3, -1.0), t.upper.setConstant(3, 1.0);
    tasks.push_back(t);
  }
  return tasks;
}

}  // namespace

TEST_CASE("tasks: each kind's calcDiff is its calc's value and derivatives in q and q̇", "[outer][tasks]") {
  const Scenario scenario = loadScenario(test::sourceDir() / "scenarios/hrp2_kick.yaml");
  const DynamicsModel model(scenario.robot, scenario.referenceBody, scenario.referencePose, scenario.gravity);
  const int n = model.jointCount();
  DynamicsData data(model);
  TaskWorkspace workspace(model);
  std::mt19937 random(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd q = scenario.start, v(n), a(n);
  for (int j = 0; j < n; ++j) q[j] += 0.2 * u(random), v[j] = 1.5 * u(random), a[j] = 3.0 * u(random);

  for (const TaskSpec& spec : tasksToCheck(scenario)) {
    const Task& task = *spec.task;
    const int d = task.dimension();
    INFO("task " << task.kind() << " on " << spec.name);
    REQUIRE(d >= 1);
    REQUIRE(d <= kMaxTaskDimension);
    CHECK(spec.lower.size() == d);
    for (int c = 0; c < d; ++c) CHECK_FALSE(task.componentName(c).empty());
    auto value = [&]() {
      inverseDynamics(model, data, q, v, a);
      Eigen::VectorXd y(d);
      task.calc(model, data, workspace, y);
      return y;
    };
    const Eigen::VectorXd y = value();
    Eigen::VectorXd yDiff(d);
    Eigen::MatrixXd dq(d, n), dv(d, n);
    inverseDynamics(model, data, q, v, a);
    task.calcDiff(model, data, workspace, yDiff, dq, dv);
    CHECK((yDiff - y).norm() <= 1e-14 * (1.0 + y.norm()));
    const Eigen::MatrixXd numericQ = test::centralDifferences(q, 1e-6, value);
    const Eigen::MatrixXd numericV = test::centralDifferences(v, 1e-6, value);
    INFO("|dq − differences| " << (dq - numericQ).norm() << ", |dv − differences| " << (dv - numericV).norm());
    CHECK((dq - numericQ).norm() <= 1e-6 * (1.0 + dq.norm()));
    CHECK((dv - numericV).norm() <= 1e-6 * (1.0 + dv.norm()));
    if (!task.readsVelocity()) CHECK(dv.norm() == 0.0);
    CHECK((task.reads() == TaskQuantity::CenterOfMass ? task.frame() == -1 : task.frame() >= 0));
  }
}

TEST_CASE("tasks: orientation_angle is 1 − cos θ of the angle between the body and its target", "[outer][tasks]") {
  const Scenario scenario = loadScenario(test::sourceDir() / "scenarios/hrp2_kick.yaml");
  const DynamicsModel model(scenario.robot, scenario.referenceBody, scenario.referencePose, scenario.gravity);
  DynamicsData data(model);
  TaskWorkspace workspace(model);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(model.jointCount());
  inverseDynamics(model, data, scenario.start, zero, zero);
  const int chest = scenario.robot.frameIndex("CHEST_LINK1");
  const Matrix3 rotation = framePose(model, data, chest).rotation;
  for (const double angle : {0.0, 0.05, 0.7, 2.5}) {
    // The target turned by −angle about an oblique axis in the body: Rtᵀ R turns by angle.
    const Matrix3 target = rotation * rotationAboutAxis(Vector3(1.0, -2.0, 0.5).normalized(), angle).transpose();
    const auto task = makeOrientationAngleTask(chest, target);
    Eigen::VectorXd y(1);
    task->calc(model, data, workspace, y);
    CHECK(y[0] == Approx(1.0 - std::cos(angle)).margin(1e-14));
  }
}

TEST_CASE("tasks: a scenario file names every registered kind, each read into its model and bounds", "[outer][tasks]") {
  const test::TempDir dir;
  const auto robots = test::sourceDir() / "robots/hrp2";
  std::ofstream out(dir.path() / "tasks.yaml");
  out << "robot: " << (robots / "hrp2.urdf").string() << "\nactuators: " << (robots / "actuators.yaml").string()
      << "\ncontact_surfaces: " << (robots / "contacts.yaml").string() << "\npostures: " << (robots / "postures.yaml").string()
      << "\nreference_body: l_sole\ncontacts: [l_sole]\nduration: 1.6\nsamples: 20\ncontrol_points: 9\n"
         "start: {posture: half_sitting}\nend: {posture: half_sitting}\ntasks:\n"
         "  - {kind: position, body: r_sole, point: [0.1, 0, 0], window: [0.2, 1.0], lower: [null, null, 0.03]}\n"
         "  - {kind: orientation, body: r_sole, target: [0, 0, 0.1], tolerance: 0.02, time: 0.8}\n"
         "  - {kind: orientation_angle, body: CHEST_LINK1, target: [0, 0.05, 0], tolerance: 0.1, window: [0, 1.6]}\n"
         "  - {kind: linear_velocity, body: r_sole, time: 0.8, target: [1, null, null], tolerance: 0.1}\n"
         "  - {kind: angular_velocity, body: r_sole, time: 0.8, upper: [1, 1, 1]}\n"
         "  - {kind: center_of_mass, time: 0.4, target: [0.0, 0.05, null]}\n";
  out.close();
  const Scenario s = loadScenario(dir.path() / "tasks.yaml");
  REQUIRE(s.tasks.size() == taskKinds().size());
  for (std::size_t i = 0; i < s.tasks.size(); ++i) {
    INFO("tasks[" << i << "]");
    CHECK(s.tasks[i].task->kind() == taskKinds()[i].kind);
    CHECK(s.tasks[i].lower.size() == s.tasks[i].dimension());
    CHECK(s.tasks[i].upper.size() == s.tasks[i].dimension());
  }
  const TaskSpec& angle = s.tasks[2];
  CHECK(angle.dimension() == 1);
  CHECK(angle.window);
  CHECK(std::isinf(angle.lower[0]));
  CHECK(angle.upper[0] == Approx(1.0 - std::cos(0.1)));
  CHECK(s.tasks[1].upper[2] == Approx(0.02));
  CHECK(s.tasks[3].lower[0] == Approx(0.9));
  CHECK(std::isinf(s.tasks[3].lower[1]));
  CHECK(taskKindList() == "position, orientation, orientation_angle, linear_velocity, angular_velocity, center_of_mass, or throw");
}

}  // namespace mcopt
