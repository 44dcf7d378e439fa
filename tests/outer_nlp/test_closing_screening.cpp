// SPDX-License-Identifier: BSD-3-Clause
// Screening of the closing joints' limit rows (`limits.closing_screening`; docs/theory/outer-problem.md,
// "Torque-limit screening"): the motion problem with some closing_joint_limit rows left out is
// the full problem minus exactly those rows, and the rows it leaves out are the ones whose
// value lies within the fraction of their range about its middle.
#include <catch2/catch.hpp>


#include "common/perturbed_motion.hpp"
#include "common/screened_rows.hpp"
#include "common/scenario_variant.hpp"
#include "common/temp_dir.hpp"
#include "common/test_support.hpp"
#include "core/errors.hpp"
#include "outer_nlp/motion_problem.hpp"

namespace mcopt {

TEST_CASE("closing-row screening: the screened problem is the full one without the rows inside the fraction",
          "[outer][screening]") {
  Scenario s = loadScenario(test::sourceDir() / "scenarios/hrp2_weight_shift.yaml");
  s.samples = 12;
  s.outputSamples = 12;
  MotionProblem full(s);
  const Eigen::VectorXd x = test::perturbedMotion(full, 0.3, 5);

  // Which rows a fraction leaves out, from the full problem's own row values and bounds.
  const double fraction = 0.2;
  Eigen::VectorXd g, lower, upper;
  full.constraints(x, g);
  full.constraintBounds(lower, upper);
  int inside = 0, outside = 0;
  for (int r = 0; r < full.constraintCount(); ++r) {
    if (full.rowKind(r) != "closing_joint_limit") continue;
    const double middle = 0.5 * (lower[r] + upper[r]), half = 0.5 * (upper[r] - lower[r]);
    (std::abs(g[r] - middle) < fraction * half ? inside : outside) += 1;
  }
  INFO(inside << " closing rows inside " << fraction << " of their range, " << outside << " outside");
  REQUIRE(inside > 0);
  REQUIRE(outside > 0);  // both kinds present: the check means something

  const std::vector<bool> below = full.closingLimitsBelow(x, fraction);
  MotionProblemOptions options{s.solve.hessian, {}};
  options.omittedClosingRows = below;
  MotionProblem screened(s, options);
  CHECK(screened.omittedClosingRowCount() == inside);
  REQUIRE(screened.constraintCount() == full.constraintCount() - inside);
  CHECK(screened.variableCount() == full.variableCount());
  CHECK(screened.objective(x) == full.objective(x));

  // Every remaining row: the same value, bounds and Jacobian row as in the full problem; every
  // remaining closing row outside the fraction.
  int closingRows = 0;
  test::checkScreenedRows(full, screened, x, [&](int r, int f) {
    if (screened.rowKind(r) != "closing_joint_limit") return;
    ++closingRows;
    CHECK(std::abs(g[f] - 0.5 * (lower[f] + upper[f])) >= fraction * 0.5 * (upper[f] - lower[f]));
  });
  CHECK(closingRows == outside);

  MotionProblemOptions wrong{s.solve.hessian, {}};
  wrong.omittedClosingRows = std::vector<bool>(7, true);
  CHECK_THROWS_AS(MotionProblem(s, wrong), InputError);
}

TEST_CASE("closing-row screening: a fraction of 1 or more is refused with the field named", "[outer][screening]") {
  const test::TempDir dir;
  const auto file = test::scenarioVariant(test::sourceDir() / "scenarios/hrp2_weight_shift.yaml", dir,
                                          [](YAML::Node& root) { root["limits"]["closing_screening"] = 1.0; }, "one.yaml");
  CHECK_THROWS_WITH(loadScenario(file), Catch::Contains("one.yaml") && Catch::Contains("limits.closing_screening") &&
                                            Catch::Contains("expected a fraction of the range in [0, 1)"));
}

}  // namespace mcopt
