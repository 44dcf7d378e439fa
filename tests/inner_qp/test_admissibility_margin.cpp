// SPDX-License-Identifier: BSD-3-Clause
// The admissibility margin (inner_qp/admissibility_margin.hpp): its maximiser balances the
// robot and keeps every scaled row by at least the margin, its gradient in the balance wrench
// is the balance multiplier (central differences), its sign says whether the inner problem
// has an admissible wrench (the active-set solver's status, along walks that leave the
// admissible set), it grows towards the linear programme's margin as ε falls, and warm starts
// give the cold answer.
#include <catch2/catch.hpp>

#include "common/random_inner_problem.hpp"
#include "core/errors.hpp"
#include "inner_qp/admissibility_margin.hpp"
#include "inner_qp/inner_solver.hpp"

using namespace mcopt;
using Catch::Matchers::Contains;

namespace {

constexpr double kWeight = 600.0;  // m g [N] of the margin's scale

MarginResult marginOf(const ContactProblem& p, double epsilon = 1e-3, const std::vector<int>& warm = {}) {
  MarginSettings s;
  s.weight = kWeight;
  s.regularisation = epsilon;
  AdmissibilityMargin margin(p, s);
  MarginResult r;
  r.activeSet = warm;
  margin.solve(p, r);
  return r;
}

/// ‖row i over the scaled variables‖ (forces by m g, moments by m g ℓ, ℓ = 0.1 m).
double scaledRowNorm(const ContactProblem& p, int row) {
  Eigen::RowVectorXd scaled = p.inequality.row(row);
  for (int c = 0; c < p.contactCount; ++c) {
    const int column = p.contactColumn[static_cast<std::size_t>(c)];
    scaled.segment(column, 3) *= kWeight;
    scaled.segment(column + 3, 3) *= kWeight * 0.1;
  }
  return scaled.norm();
}

}  // namespace

TEST_CASE("admissibility margin: a balancing maximiser inside every row by the margin and a gradient in W that "
          "matches central differences",
          "[inner][margin]") {
  std::mt19937 rng(4242);
  int checked = 0;
  for (int trial = 0; trial < 30; ++trial) {
    const std::string model = trial % 2 == 0 ? "wrench-cone" : "pyramid";
    test::RandomProblem data = test::randomProblem(rng, 2 + trial % 3, 30);
    const ContactProblem p = test::assemble(data, model);
    INFO("trial " << trial << " (" << model << ", " << p.contactCount << " contacts)");
    const MarginResult r = marginOf(p);
    REQUIRE(r.solved);
    // The random problems are balanced by wrenches strictly inside their rows.
    CHECK(r.margin > 0.0);
    CHECK((p.balance * r.wrenches - p.balanceTarget).cwiseAbs().maxCoeff() <= 1e-9 * kWeight);
    for (int i = 0; i < p.inequality.rows(); ++i)
      CHECK(p.inequality.row(i).dot(r.wrenches) - p.inequalityBound[i] <= -r.margin * scaledRowNorm(p, i) + 1e-9 * kWeight);
    // ∂m/∂W against central differences (m is C¹, its gradient piecewise linear: h small).
    for (int k = 0; k < 6; ++k) {
      const double h = 1e-4 * kWeight * (k < 3 ? 1.0 : 0.1);
      test::RandomProblem plus = data, minus = data;
      plus.balance[k] += h, minus.balance[k] -= h;
      const double fd = (marginOf(test::assemble(plus, model)).margin - marginOf(test::assemble(minus, model)).margin) / (2 * h);
      INFO("W component " << k << ": exact " << r.balanceGradient[k] << ", central differences " << fd);
      CHECK(std::abs(r.balanceGradient[k] - fd) <= 1e-6 * (1.0 + std::abs(fd)) / (k < 3 ? kWeight : 0.1 * kWeight));
    }
    // Warm from its own active set: the same answer.
    const MarginResult warm = marginOf(p, 1e-3, r.activeSet);
    CHECK(std::abs(warm.margin - r.margin) <= 1e-12);
    ++checked;
  }
  CHECK(checked == 30);
}

TEST_CASE("admissibility margin: its sign is the inner problem's feasibility along walks out of the admissible set",
          "[inner][margin]") {
  // W walked along a random direction until the inner problem has no admissible wrench: the
  // margin is positive where the active-set solver finds an optimum away from the boundary,
  // negative wherever it reports the sample infeasible, and crosses zero in between.
  std::mt19937 rng(99);
  auto exact = makeActiveSetSolver();
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int crossings = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const std::string model = trial % 2 == 0 ? "wrench-cone" : "pyramid";
    test::RandomProblem data = test::randomProblem(rng, 2 + trial % 2, 30);
    Vector6 direction;
    for (int k = 0; k < 6; ++k) direction[k] = u(rng) * (k < 3 ? kWeight : 0.1 * kWeight);
    bool sawFeasible = false, sawInfeasible = false;
    double previous = 0.0;
    for (int step = 0; step <= 60; ++step) {
      test::RandomProblem walked = data;
      walked.balance = data.balance + (0.05 * step) * direction;
      const ContactProblem p = test::assemble(walked, model);
      InnerResult inner;
      exact->solve(p, inner);
      const MarginResult m = marginOf(p);
      REQUIRE(m.solved);
      INFO("trial " << trial << " step " << step << ": margin " << m.margin << ", inner " << toString(inner.status));
      if (inner.status == InnerStatus::Infeasible) {
        CHECK(m.margin < 0.0);
        sawInfeasible = true;
      } else if (m.margin > 0.0) {
        CHECK(inner.status == InnerStatus::Optimal);
        sawFeasible = true;
      }
      if (step > 0 && m.margin > 0.0) CHECK(m.margin < previous + 1.0);  // bounded steps, no jump
      previous = m.margin;
    }
    crossings += sawFeasible && sawInfeasible;
  }
  CHECK(crossings >= 15);
}

TEST_CASE("admissibility margin: it grows towards the linear programme's margin as ε falls", "[inner][margin]") {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 10; ++trial) {
    const ContactProblem p = test::assemble(test::randomProblem(rng, 2 + trial % 3, 30), "wrench-cone");
    double previous = -std::numeric_limits<double>::infinity();
    for (double epsilon : {1e-1, 1e-2, 1e-3, 1e-4, 1e-5}) {
      const MarginResult r = marginOf(p, epsilon);
      REQUIRE(r.solved);
      INFO("trial " << trial << ", ε " << epsilon << ": margin " << r.margin);
      CHECK(r.margin >= previous - 1e-12);
      previous = r.margin;
    }
  }
}

TEST_CASE("admissibility margin: models with a second-order cone or a force alone are refused, naming the contact",
          "[inner][margin]") {
  std::mt19937 rng(3);
  const test::RandomProblem data = test::randomProblem(rng, 2, 12);
  CHECK_THROWS_WITH(marginOf(test::assemble(data, "report")), Contains("contact 'contact0'") && Contains("second-order friction cone"));
  ContactProblemSettings settings;
  settings.model = makeContactModel("wrench-cone");
  settings.byContact["contact1"] = makeContactModel("point");
  const ContactProblem pointHand = assembleContactProblem(data.contacts, data.wrenchToTorque, data.tau0, data.balance,
                                                          data.weights, data.linear, settings);
  CHECK_THROWS_WITH(marginOf(pointHand), Contains("contact 'contact1'"));
  MarginSettings zero;
  zero.weight = 0.0;
  CHECK_THROWS_WITH(AdmissibilityMargin(test::assemble(data, "wrench-cone"), zero), Contains("must be positive"));
}
