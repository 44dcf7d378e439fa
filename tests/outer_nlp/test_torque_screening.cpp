// SPDX-License-Identifier: BSD-3-Clause
// Torque-limit screening (docs/theory/outer-problem.md, "Torque-limit screening"): the motion problem
// with some torque-limit rows left out is the full problem minus exactly those rows — same
// objective and gradient, every remaining row with the same value, bounds and Jacobian —, and
// the rows it leaves out are the ones whose |Γ| is below the fraction of their limit.
#include <catch2/catch.hpp>

#include <random>

#include "common/screened_rows.hpp"
#include "common/test_support.hpp"
#include "core/errors.hpp"
#include "outer_nlp/motion_problem.hpp"

namespace mcopt {

TEST_CASE("torque-limit screening: the screened problem is the full one without those rows", "[outer][screening]") {
  Scenario s = loadScenario(test::sourceDir() / "scenarios/hrp2_kick.yaml");
  s.samples = 16;
  s.outputSamples = 20;
  MotionProblem full(s);
  Eigen::VectorXd x = full.initialPoint(s.start, s.end);
  std::mt19937 random(17);
  std::uniform_real_distribution<double> u(-0.1, 0.1);
  for (int i = 0; i < full.parametrization().parameterCount(); ++i) x[i] += u(random);

  const double fraction = 0.05;
  const std::vector<bool> below = full.torquesBelow(x, fraction);
  const SampledPhysics physics = full.sampledPhysics(x);
  int omitted = 0, kept = 0;
  for (int sample = 0; sample < s.samples; ++sample)
    for (int j = 0; j < 30; ++j) {
      const double limit = s.actuators.joints[static_cast<std::size_t>(j)].torqueLimit;
      const bool isBelow = below[static_cast<std::size_t>(sample * 30 + j)];
      CHECK(isBelow == (std::abs(physics.tau(j, sample)) < fraction * limit));
      (isBelow ? omitted : kept) += 1;
    }
  INFO(omitted << " rows below " << fraction << " of their limit, " << kept << " above");
  REQUIRE(omitted > 0);
  REQUIRE(kept > 0);  // both kinds present: the check means something

  MotionProblem screened(s, {s.solve.hessian, below});
  CHECK(screened.omittedTorqueRowCount() == omitted);
  REQUIRE(screened.constraintCount() == full.constraintCount() - omitted);
  CHECK(screened.variableCount() == full.variableCount());
  CHECK(screened.objective(x) == full.objective(x));
  Eigen::VectorXd gradientFull, gradientScreened;
  full.objectiveGradient(x, gradientFull);
  screened.objectiveGradient(x, gradientScreened);
  CHECK(gradientScreened == gradientFull);

  // Every remaining row: the same value, bounds and Jacobian row as in the full problem.
  int torqueRows = 0;
  test::checkScreenedRows(full, screened, x, [&](int r, int) { torqueRows += screened.rowKind(r) == "torque_limit"; });
  CHECK(torqueRows == kept);

  CHECK_THROWS_AS(MotionProblem(s, {s.solve.hessian, std::vector<bool>(7, true)}), InputError);
}

}  // namespace mcopt
