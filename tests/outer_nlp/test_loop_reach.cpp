// SPDX-License-Identifier: BSD-3-Clause
// The loops' reach (closed_chains.hpp LoopReach, outer_nlp/loop_reach_term.cpp): the longest
// reach is the largest the loop takes and where its closing Jacobian is singular; the rows'
// exact derivatives through the closure against central differences; one row a closed sample
// and none without the margin; the refusals, with the file's line.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "common/nlp_jacobian.hpp"
#include "common/perturbed_motion.hpp"
#include "common/scenario_variant.hpp"
#include "common/temp_dir.hpp"
#include "common/test_support.hpp"
#include "core/errors.hpp"
#include "core/inverse_dynamics.hpp"
#include "core/kinematics.hpp"
#include "outer_nlp/closed_chains.hpp"
#include "outer_nlp/motion_problem.hpp"

namespace mcopt {

namespace {

Scenario withMargin(const char* file, double margin, int samples) {
  Scenario s = loadScenario(test::sourceDir() / "scenarios" / file);
  s.samples = samples;
  s.outputSamples = 20;
  s.closureReachMargin = margin;
  return s;
}

std::vector<int> rowsOfKind(const MotionProblem& problem, const std::string& kind) {
  std::vector<int> rows;
  for (int r = 0; r < problem.constraintCount(); ++r)
    if (problem.rowKind(r) == kind) rows.push_back(r);
  return rows;
}

}  // namespace

TEST_CASE("loop reach: the longest reach is the largest the loop takes and where its closure is singular", "[outer][closure]") {
  // HRP-2's right leg (the weight shift's right sole) and right arm (the lean reach's hand).
  for (const char* file : {"hrp2_weight_shift.yaml", "hrp2_lean_reach.yaml"}) {
    const Scenario s = withMargin(file, 0.0, 8);
    const MotionProblem problem(s);
    const ClosedChains& chains = *problem.closedChains();
    const DynamicsModel& model = problem.model();
    DynamicsData data(model);
    std::mt19937 random(3);
    std::uniform_real_distribution<double> angle(-M_PI, M_PI);
    for (int i = 0; i < chains.contactCount(); ++i) {
      const LoopReach& reach = chains.reach(i);
      INFO(file << ", contact " << chains.contacts()[static_cast<std::size_t>(i)].name << ": longest " << reach.longest << " m");
      // The ratio never exceeds 1 over random angles of the whole loop (limits ignored, as the
      // closure ignores them), and comes near it.
      double largest = 0.0, segments = 0.0;
      for (int trial = 0; trial < 4000; ++trial) {
        Eigen::VectorXd q = s.start;
        for (int k = 0; k < 6; ++k) q[chains.closingJoints()[static_cast<std::size_t>(6 * i + k)]] = angle(random);
        forwardKinematics(model, data, q);
        largest = std::max(largest, chains.reachRatio(data, i));
      }
      CHECK(largest <= 1.0 + 1e-12);
      CHECK(largest > 0.99);
      // At most the sum of the loop's segments between its joint origins (triangle inequality).
      forwardKinematics(model, data, s.start);
      Vector3 previous = data.position[static_cast<std::size_t>(reach.inner)] +
                         data.rotation[static_cast<std::size_t>(reach.inner)] * reach.innerPoint;
      for (int k = 1; k < 6; ++k) {
        const int b = model.positionOfJoint(chains.closingJoints()[static_cast<std::size_t>(6 * i + k)]);
        const Vector3 origin =
            data.position[static_cast<std::size_t>(b)] +
            data.rotation[static_cast<std::size_t>(b)] * model.treeJoints()[static_cast<std::size_t>(b)].after.inverse().translation;
        segments += (origin - previous).norm();
        previous = origin;
      }
      CHECK(reach.longest <= segments + 1e-12);
    }
  }
  // At the longest reach the closing Jacobian is singular: HRP-2's straight leg (posture zero,
  // its knee at its lower limit) is the weight shift's loop at ratio 1, where the closure refuses
  // to start (test_closed_chains.cpp).
  const Scenario s = withMargin("hrp2_weight_shift.yaml", 0.0, 8);
  const MotionProblem problem(s);
  DynamicsData data(problem.model());
  forwardKinematics(problem.model(), data, Eigen::VectorXd::Zero(problem.model().jointCount()));
  CHECK(problem.closedChains()->reachRatio(data, 0) == Approx(1.0).epsilon(1e-12));
}

TEST_CASE("loop reach: the rows' exact derivatives through the closure (central differences)", "[outer][closure]") {
  for (const std::string forces : {"bilevel", "splines"}) {
    for (const char* file : {"hrp2_weight_shift.yaml", "hrp2_lean_reach.yaml"}) {
      Scenario s = withMargin(file, 1e-3, 10);
      s.contactForces = forces;
      s.controlPoints = 9;
      s.fixStart = s.fixEnd = false;
      MotionProblem problem(s);
      Eigen::VectorXd x = test::perturbedMotion(problem, 0.05, 5);
      const std::vector<int> rows = rowsOfKind(problem, "loop_reach");
      REQUIRE(!rows.empty());
      // h = 3e-6: the closure's Newton rounding (1e-12) against the truncation (test_multi_contact_problem.cpp).
      const test::RowDerivativeCheck c = test::rowDerivatives(problem, x, rows, 3e-6);
      INFO(forces << ", " << file << ": " << rows.size() << " rows, worst relative difference " << c.worst << ", largest entry "
                  << c.largest);
      CHECK(c.largest > 1e-3);  // the rows move with the motion
      CHECK(c.worst < 1e-7);
    }
  }
}

TEST_CASE("loop reach: one row a sample where the loop is closed and none without the margin", "[outer][closure]") {
  const int samples = 12;
  // (A motion problem keeps a reference to its scenario.)
  const Scenario none = withMargin("hrp2_weight_shift.yaml", 0.0, samples);
  CHECK(rowsOfKind(MotionProblem(none), "loop_reach").empty());
  const Scenario shiftScenario = withMargin("hrp2_weight_shift.yaml", 2e-3, samples);
  MotionProblem shift(shiftScenario);
  const std::vector<int> rows = rowsOfKind(shift, "loop_reach");
  CHECK(static_cast<int>(rows.size()) == shift.samples().sampleCount());  // the right sole, held throughout
  double lower = 0.0, upper = 0.0;
  Eigen::VectorXd lowerBounds, upperBounds;
  shift.constraintBounds(lowerBounds, upperBounds);
  lower = lowerBounds[rows.front()], upper = upperBounds[rows.front()];
  CHECK(std::isinf(lower));
  CHECK(upper == Approx(1.0 - 2e-3).epsilon(1e-15));
  CHECK(shift.rowName(rows.front()).find("reach of the loop of r_sole (RLEG_JOINT0 to RLEG_JOINT5)") != std::string::npos);
  // The lean reach: the right sole throughout, the hand inside its window only.
  const Scenario leanScenario = withMargin("hrp2_lean_reach.yaml", 1e-3, samples);
  MotionProblem lean(leanScenario);
  int sole = 0, hand = 0;
  for (const int r : rowsOfKind(lean, "loop_reach")) (lean.rowName(r).find("r_sole") != std::string::npos ? sole : hand) += 1;
  CHECK(sole == lean.samples().sampleCount());
  int handSamples = 0;
  for (int k = 0; k < lean.samples().sampleCount(); ++k) handSamples += lean.contactActive(1, k) ? 1 : 0;
  CHECK(hand == handSamples);
  CHECK(hand > 0);
  CHECK(hand < lean.samples().sampleCount());
}

TEST_CASE("loop reach: the margin's bad values and a posture beyond it are refused, naming the file and field",
          "[outer][closure][input]") {
  const test::TempDir dir;
  const auto file = [&](const char* source, const std::string& value, const std::string& name) {
    return test::scenarioVariant(test::sourceDir() / "scenarios" / source, dir,
                                 [&](YAML::Node& root) { root["closure_reach_margin"] = YAML::Load(value); }, name);
  };
  CHECK_THROWS_WITH(loadScenario(file("hrp2_weight_shift.yaml", "1.0", "one.yaml")),
                    Catch::Contains("one.yaml:") && Catch::Contains("closure_reach_margin") && Catch::Contains("[0, 1)"));
  CHECK_THROWS_WITH(loadScenario(file("hrp2_weight_shift.yaml", "-0.1", "negative.yaml")),
                    Catch::Contains("negative.yaml:") && Catch::Contains("closure_reach_margin") && Catch::Contains("negative"));
  CHECK_THROWS_WITH(loadScenario(file("hrp2_kick.yaml", "0.001", "kick.yaml")),
                    Catch::Contains("kick.yaml:") && Catch::Contains("closure_reach_margin") && Catch::Contains("no loop"));
  // Half-sitting's right leg is far more than half stretched: a fixed start there is refused.
  const Scenario tooMuch = loadScenario(file("hrp2_weight_shift.yaml", "0.5", "half.yaml"));
  REQUIRE(tooMuch.fixStart);
  CHECK_THROWS_WITH(MotionProblem(tooMuch), Catch::Contains("half.yaml") && Catch::Contains("closure_reach_margin") &&
                                                Catch::Contains("fixed start posture") && Catch::Contains("r_sole"));
}

}  // namespace mcopt
