// SPDX-License-Identifier: BSD-3-Clause
// Debug builds only: sizes on the per-sample hot path are assertions (core/hot_path_checks.hpp);
// a wrong size aborts with a message naming the function, instead of reading past a buffer.
#include <catch2/catch.hpp>

#include <cstdio>
#include <filesystem>
#include <string>
#include <sys/wait.h>

#include "common/test_support.hpp"
#include "core/dynamics_derivatives.hpp"
#include "core/inverse_dynamics.hpp"
#include "core/robot_files.hpp"

using namespace mcopt;

namespace {

/// Runs the hidden test `name` of this executable in a child; its output and whether it aborted.
std::pair<std::string, bool> runChild(const std::string& name) {
  const std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
  FILE* child = popen(("'" + self + "' '" + name + "' 2>&1").c_str(), "r");
  REQUIRE(child != nullptr);
  std::string output;
  char buffer[4096];
  while (const std::size_t read = std::fread(buffer, 1, sizeof buffer, child)) output.append(buffer, read);
  const int status = pclose(child);
  // Catch reports the abort, then raises it again; the shell reports a signal as 128 + signal.
  return {output, (WIFSIGNALED(status) && WTERMSIG(status) == SIGABRT) ||
                      (WIFEXITED(status) && WEXITSTATUS(status) == 128 + SIGABRT)};
}

}  // namespace

TEST_CASE("(child) inverse dynamics given a short q", "[.debug-check-child-q]") {
  const RobotModel robot = loadUrdfFile(test::hrp2().urdf);
  const DynamicsModel model(robot, "l_sole");
  DynamicsData data(model);
  const Eigen::VectorXd shortQ = Eigen::VectorXd::Zero(model.jointCount() - 1), v = Eigen::VectorXd::Zero(model.jointCount());
  inverseDynamics(model, data, shortQ, v, v);
}

TEST_CASE("(child) derivatives into another model's buffers", "[.debug-check-child-derivatives]") {
  const RobotModel robot = loadUrdfFile(test::hrp2().urdf);
  const DynamicsModel model(robot, "l_sole");
  const RobotModel small = loadUrdfString(
      "<robot name=\"one\"><link name=\"a\"><inertial><mass value=\"1\"/><inertia ixx=\"0.1\" iyy=\"0.1\" izz=\"0.1\" "
      "ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial></link></robot>",
      "one.urdf");
  DynamicsData data(model);
  DynamicsDerivatives other(DynamicsModel(small, "a"));
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(model.jointCount());
  inverseDynamicsDerivatives(model, data, other, zero, zero, zero);
}

TEST_CASE("a wrong size on the dynamics hot path aborts a debug build, naming the function", "[debug]") {
  const auto [shortQ, abortedQ] = runChild("[.debug-check-child-q]");
  INFO(shortQ);
  CHECK(abortedQ);
  CHECK_THAT(shortQ, Catch::Matchers::Contains("inverseDynamics: q, v and a must have jointCount() entries"));
  const auto [derivatives, abortedDerivatives] = runChild("[.debug-check-child-derivatives]");
  INFO(derivatives);
  CHECK(abortedDerivatives);
  CHECK_THAT(derivatives, Catch::Matchers::Contains("inverseDynamicsDerivatives: derivatives were made for another model"));
}
