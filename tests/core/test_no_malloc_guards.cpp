// SPDX-License-Identifier: BSD-3-Clause
// Debug builds (MCOPT_CHECK_MALLOC) only: every per-sample path arms Eigen's no-malloc check
// once warm (core/no_malloc_scope.hpp), and an allocation introduced on a guarded path stops
// the program. What the allocation counter (test_no_allocation.cpp) proves in every build,
// these guards enforce while a debug build runs anything at all.
#include <catch2/catch.hpp>

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <random>
#include <set>
#include <string>

#include "common/test_support.hpp"
#include "core/no_malloc_scope.hpp"
#include "core/robot_files.hpp"
#include "core/trajectory_gradient.hpp"
#include "inner_qp/multi_contact_dynamics.hpp"
#include "outer_nlp/motion_problem.hpp"
#include "outer_nlp/scenario.hpp"
#include "sensitivity/multi_contact_gradient.hpp"

using namespace mcopt;

namespace {

std::set<std::string> armedPaths;
void recordPath(const char* path) { armedPaths.insert(path); }

/// The kick's outer evaluation, twice: the second is warm and guarded.
void evaluateKickTwice(int samples) {
  Scenario scenario = loadScenario(test::sourceDir() / "scenarios" / "hrp2_kick.yaml");
  scenario.samples = samples;
  MotionProblem problem(scenario);
  Eigen::VectorXd x = problem.initialPoint(scenario.start, scenario.end), gradient;
  for (int pass = 0; pass < 2; ++pass) {
    problem.objectiveGradient(x, gradient);
    x *= 1.0 + 1e-6;
  }
}

volatile double sink = 0.0;
void allocateOnPurpose(const char* path) {
  if (std::string(path) != "outer evaluation") return;
  Eigen::VectorXd introduced = Eigen::VectorXd::Ones(64);  // a heap allocation on the guarded path
  sink = introduced.sum();
}

}  // namespace

TEST_CASE("every per-sample path arms its no-malloc guard once warm", "[allocation][debug]") {
  const RobotModel robot = loadUrdfFile(test::hrp2().urdf);
  const DynamicsModel model(robot, "l_sole");
  const ActuatorSet actuators = loadActuators(test::sourceDir() / "robots/hrp2/actuators.yaml", robot);
  const auto surfaces = loadContactSurfaces(test::sourceDir() / "robots/hrp2/contacts.yaml", robot);
  const std::vector<ContactSurface> soles(surfaces.begin(), surfaces.begin() + 2);
  const MotionParametrization parametrization(robot.jointCount());
  const Eigen::VectorXd x =
      parametrization.constantMotion(loadPostures(test::sourceDir() / "robots/hrp2/postures.yaml", robot).at("half_sitting"));
  armedPaths.clear();
  noMallocProbe = recordPath;
  TrajectoryEvaluator evaluator(model, actuators, SampledTrajectory(parametrization, 20));
  TrajectoryGradientEvaluator gradientEvaluator(model, actuators, SampledTrajectory(parametrization, 20));
  MultiContactEvaluator inner(model, actuators, SampledTrajectory(parametrization, 20), soles);
  MultiContactGradientEvaluator sensitivity(model, actuators, SampledTrajectory(parametrization, 20), soles);
  TrajectoryResult result;
  TrajectoryGradient gradient;
  MultiContactResult multi;
  MultiContactGradient multiGradient;
  for (int pass = 0; pass < 2; ++pass) {
    evaluator.evaluate(x, 1.5, result);
    gradientEvaluator.evaluate(x, 1.5, result, gradient);
    inner.evaluate(x, 1.5, multi);
    sensitivity.evaluate(x, 1.5, multi, multiGradient);
  }
  evaluateKickTwice(20);
  noMallocProbe = nullptr;
  for (const char* path : {"trajectory evaluation", "trajectory gradient", "inner solves", "sensitivity", "outer evaluation"}) {
    INFO(path);
    CHECK(armedPaths.count(path) == 1);
  }
}

// The child run of the next test: allocates on purpose as the outer evaluation's guard arms.
TEST_CASE("(child) an allocation under the outer evaluation's guard", "[.no-malloc-child]") {
  noMallocProbe = allocateOnPurpose;
  evaluateKickTwice(10);
  noMallocProbe = nullptr;
}

TEST_CASE("an allocation introduced on a guarded per-sample path stops the debug build", "[allocation][debug]") {
  // Run in a child process (this executable, the hidden test above): Eigen's check aborts.
  const std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
  const std::string command = "'" + self + "' '[.no-malloc-child]' 2>&1";
  FILE* child = popen(command.c_str(), "r");
  REQUIRE(child != nullptr);
  std::string output;
  char buffer[4096];
  while (const std::size_t read = std::fread(buffer, 1, sizeof buffer, child)) output.append(buffer, read);
  const int status = pclose(child);
  INFO(output);
  // Catch reports the abort, then raises it again; popen's shell reports a child's signal as
  // exit status 128 + signal.
  const bool aborted = (WIFSIGNALED(status) && WTERMSIG(status) == SIGABRT) ||
                       (WIFEXITED(status) && WEXITSTATUS(status) == 128 + SIGABRT);
  CHECK(aborted);
  CHECK_THAT(output, Catch::Matchers::Contains("heap allocation is forbidden") &&
                         Catch::Matchers::Contains("(child) an allocation under the outer evaluation's guard"));
}
