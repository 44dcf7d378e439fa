// SPDX-License-Identifier: BSD-3-Clause
// The barrier inner solver (inner_qp/barrier_solver.cpp, docs/theory/inner-problem.md, "The
// barrier-smoothed inner problem"): its answer is the central point at μ (every row strictly
// inside, s_i z_i = μ), its objective lies within rows × μ above the exact optimum and tends to
// it as μ falls, infeasible samples keep the exact elastic answer, and its derivative from the
// sensitivity system agrees with central differences — also across a switch of the exact
// optimum's active set, where the exact derivative jumps.
#include <catch2/catch.hpp>

#include "common/random_inner_problem.hpp"
#include "core/errors.hpp"
#include "sensitivity/inner_sensitivity.hpp"

using namespace mcopt;
using Catch::Matchers::Contains;

namespace {

InnerSettings barrierSettings(double mu, bool warm = false) {
  InnerSettings s;
  s.barrier = mu;
  s.warmStart = warm;
  return s;
}

InnerResult solved(InnerSolver& solver, const ContactProblem& p) {
  InnerResult r;
  solver.solve(p, r);
  return r;
}

/// The problem with τ0 component `which` (or W component which − n) moved by `step`.
ContactProblem moved(test::RandomProblem r, const std::string& model, int which, double step) {
  if (which < r.tau0.size())
    r.tau0[which] += step;
  else
    r.balance[which - r.tau0.size()] += step;
  return test::assemble(r, model);
}

/// Trial k of a seeded family: two to four contacts on 30 joints (so that F is unique), the
/// wrench cone and the pyramid in turn.
struct LinearTrial {
  std::string model;
  test::RandomProblem data;
  ContactProblem problem;
};
LinearTrial linearTrial(std::mt19937& rng, int trial) {
  LinearTrial t{trial % 2 == 0 ? "wrench-cone" : "pyramid", test::randomProblem(rng, 2 + trial % 3, 30), {}};
  t.problem = test::assemble(t.data, t.model);
  return t;
}

}  // namespace

TEST_CASE("barrier: the central point at μ, within rows × μ of the exact optimum, tending to it as μ falls",
          "[inner][barrier]") {
  std::mt19937 rng(811);
  auto exact = makeActiveSetSolver();
  int checked = 0;
  for (int trial = 0; trial < 30; ++trial) {
    const LinearTrial t = linearTrial(rng, trial);
    const std::string& model = t.model;
    const ContactProblem& p = t.problem;
    const InnerResult reference = solved(*exact, p);
    REQUIRE(reference.status == InnerStatus::Optimal);
    const double rows = static_cast<double>(p.inequality.rows());
    double previousDistance = std::numeric_limits<double>::infinity();
    for (double mu : {1.0, 1e-2, 1e-4, 1e-6}) {
      INFO("trial " << trial << " (" << model << "), mu " << mu);
      auto barrier = makeBarrierSolver(barrierSettings(mu));
      const InnerResult b = solved(*barrier, p);
      REQUIRE(b.status == InnerStatus::Optimal);
      CHECK(b.barrier == mu);
      CHECK(b.activeSet.empty());
      CHECK(b.kktResidual <= 1e-9);
      // Strictly inside, each row's slack times its multiplier μ.
      const Eigen::VectorXd slack = p.inequalityBound - p.inequality * b.wrenches;
      CHECK(slack.minCoeff() > 0.0);
      // (a slack b − G F carries the rounding of b and G F, ~1e-14 of them, times z = μ / s)
      for (Eigen::Index i = 0; i < slack.size(); ++i)
        CHECK(std::abs(slack[i] * b.inequalityMultipliers[i] - mu) <=
              1e-6 * mu + 1e-14 * (1.0 + std::abs(p.inequalityBound[i])) * b.inequalityMultipliers[i]);
      CHECK((p.balance * b.wrenches - p.balanceTarget).cwiseAbs().maxCoeff() <= 1e-9 * p.dataScale());
      // The duality gap bounds the suboptimality: exact ≤ barrier ≤ exact + rows μ (the
      // Tikhonov term, not in the objective, to rounding).
      const double tikhonov = 0.5 * p.tikhonov * (b.wrenches.squaredNorm() + reference.wrenches.squaredNorm());
      CHECK(b.objective >= reference.objective - 1e-9 * (1.0 + std::abs(reference.objective)) - tikhonov);
      CHECK(b.objective <= reference.objective + rows * mu + 1e-9 * (1.0 + std::abs(reference.objective)) + tikhonov);
      const double distance = (b.wrenches - reference.wrenches).cwiseAbs().maxCoeff();
      CHECK(distance <= previousDistance * 1.0000001);
      previousDistance = distance;
    }
    // At μ = 1e-6 W the wrenches are the exact optimum's to well below a newton.
    CHECK(previousDistance <= 1e-2);
    ++checked;
  }
  CHECK(checked == 30);
}

TEST_CASE("barrier: dF/dτ0 and dF/dW agree with central differences, across the exact optimum's active-set switches",
          "[sensitivity][barrier]") {
  std::mt19937 rng(823);
  auto barrier = makeBarrierSolver(barrierSettings(1e-2));
  int checked = 0;
  for (int trial = 0; trial < 16; ++trial) {
    const LinearTrial t = linearTrial(rng, trial);
    const std::string& model = t.model;
    const test::RandomProblem& r = t.data;
    const ContactProblem& p = t.problem;
    const InnerResult b = solved(*barrier, p);
    REQUIRE(b.status == InnerStatus::Optimal);
    InnerSensitivity sensitivity;
    const SensitivityDiagnostics& d = sensitivity.factorize(p, b);
    INFO("trial " << trial << " (" << model << "): " << d.describe());
    CHECK(d.activeRows == 0);
    CHECK(d.size == p.variableCount() + 6);
    CHECK_FALSE(d.degenerate());
    Eigen::MatrixXd dTau0, dBalance;
    sensitivity.dataSensitivities(p, dTau0, dBalance);
    for (int which = 0; which < r.tau0.size() + 6; ++which) {
      const double step = which < r.tau0.size() ? 1e-4 : 1e-3;
      const Eigen::VectorXd difference =
          (solved(*barrier, moved(r, model, which, step)).wrenches - solved(*barrier, moved(r, model, which, -step)).wrenches) /
          (2.0 * step);
      const Eigen::VectorXd analytic = which < r.tau0.size() ? Eigen::VectorXd(dTau0.col(which))
                                                               : Eigen::VectorXd(dBalance.col(which - r.tau0.size()));
      INFO("parameter " << which);
      CHECK((analytic - difference).cwiseAbs().maxCoeff() <= 1e-5 * std::max(1.0, difference.cwiseAbs().maxCoeff()));
    }
    ++checked;
  }
  CHECK(checked == 16);
}

namespace {

struct Walk {
  int switches = 0;
  double exactJump = 0.0, barrierJump = 0.0;  ///< largest change of dF/dτ0 between neighbouring steps
};

/// Walks τ0 along `direction` in `steps` steps (the admissible set stays as it is; the
/// objective turns): the exact optimum's active set switches on the way.
Walk walkTorque(const test::RandomProblem& base, const Eigen::VectorXd& direction, int steps) {
  auto exact = makeActiveSetSolver();
  auto barrier = makeBarrierSolver(barrierSettings(1e-1));
  Walk w;
  std::vector<int> previousActive;
  Eigen::MatrixXd previousExact, previousBarrier;
  for (int k = 0; k <= steps; ++k) {
    test::RandomProblem r = base;
    r.tau0 += (-1.0 + 2.0 * k / steps) * direction;
    const ContactProblem p = test::assemble(r, "wrench-cone");
    const InnerResult e = solved(*exact, p), b = solved(*barrier, p);
    REQUIRE(e.status == InnerStatus::Optimal);
    REQUIRE(b.status == InnerStatus::Optimal);
    InnerSensitivity se, sb;
    Eigen::MatrixXd unused, dExact, dBarrier;
    se.factorize(p, e);
    se.dataSensitivities(p, dExact, unused);
    sb.factorize(p, b);
    sb.dataSensitivities(p, dBarrier, unused);
    if (previousExact.size() > 0) {
      if (e.activeSet != previousActive) ++w.switches;
      w.exactJump = std::max(w.exactJump, (dExact - previousExact).cwiseAbs().maxCoeff());
      w.barrierJump = std::max(w.barrierJump, (dBarrier - previousBarrier).cwiseAbs().maxCoeff());
    }
    previousActive = e.activeSet;
    previousExact = dExact;
    previousBarrier = dBarrier;
  }
  return w;
}

}  // namespace

TEST_CASE("barrier: where the exact derivative jumps, the barrier derivative turns over continuously",
          "[sensitivity][barrier]") {
  // Refining the walk four times: the exact dF/dτ0 keeps its jumps (a kink of F), the
  // barrier's steps shrink with the step (a continuous derivative).
  std::mt19937 rng(829);
  const test::RandomProblem base = test::randomProblem(rng, 2, 30);
  const Eigen::VectorXd direction = 10.0 * test::randomProblem(rng, 2, 30).tau0;  // ±300 N m a joint
  const Walk coarse = walkTorque(base, direction, 200), fine = walkTorque(base, direction, 800);
  INFO(coarse.switches << " switches; largest step of dF/dτ0 over 200 steps: exact " << coarse.exactJump << ", barrier "
                       << coarse.barrierJump << "; over 800: exact " << fine.exactJump << ", barrier " << fine.barrierJump);
  REQUIRE(coarse.switches >= 1);
  CHECK(fine.exactJump >= 0.7 * coarse.exactJump);
  CHECK(fine.barrierJump <= 0.5 * coarse.barrierJump);  // measured: 0.37 (exact: 1.0)
}

TEST_CASE("barrier: an infeasible sample keeps the exact elastic answer", "[inner][barrier]") {
  std::mt19937 rng(839);
  const test::RandomProblem r = test::randomProblem(rng, 2, 30);
  test::RandomProblem pulling = r;
  pulling.balance << 0, 0, -300, 0, 0, 0;  // contacts only push
  const ContactProblem p = test::assemble(pulling, "wrench-cone");
  const InnerResult e = solved(*makeActiveSetSolver(), p), b = solved(*makeBarrierSolver(barrierSettings(1e-3)), p);
  REQUIRE(e.status == InnerStatus::Infeasible);
  CHECK(b.status == InnerStatus::Infeasible);
  CHECK(b.barrier == 0.0);
  CHECK((b.balanceSlack - e.balanceSlack).cwiseAbs().maxCoeff() <= 1e-9 * p.dataScale());
  CHECK_THAT(b.message, Contains("no central path"));
}

TEST_CASE("barrier: warm starts from the neighbouring answer give the cold answer", "[inner][barrier]") {
  std::mt19937 rng(853);
  const test::RandomProblem base = test::randomProblem(rng, 3, 30);
  auto warm = makeBarrierSolver(barrierSettings(1e-3, true));
  auto cold = makeBarrierSolver(barrierSettings(1e-3));
  InnerResult carried;
  for (int k = 0; k < 20; ++k) {
    test::RandomProblem r = base;
    r.tau0 *= 1.0 + 0.05 * k;
    const ContactProblem p = test::assemble(r, "wrench-cone");
    warm->solve(p, carried);
    const InnerResult fresh = solved(*cold, p);
    REQUIRE(carried.status == InnerStatus::Optimal);
    REQUIRE(fresh.status == InnerStatus::Optimal);
    CHECK((carried.wrenches - fresh.wrenches).cwiseAbs().maxCoeff() <= 1e-7 * (1.0 + fresh.wrenches.cwiseAbs().maxCoeff()));
    if (k > 0) CHECK(carried.iterations <= 15);  // re-centred by Newton steps alone, no exact solve
  }
}

TEST_CASE("barrier: second-order cones and a non-positive μ are refused, by name", "[inner][barrier][input]") {
  std::mt19937 rng(857);
  const test::RandomProblem r = test::randomProblem(rng, 2, 30);
  InnerResult result;
  CHECK_THROWS_WITH(makeBarrierSolver(barrierSettings(1e-3))->solve(test::assemble(r, "report"), result),
                    Contains("second-order friction cones") && Contains("pyramid or wrench-cone"));
  CHECK_THROWS_WITH(makeBarrierSolver(barrierSettings(0.0)), Contains("barrier parameter must be a positive number"));
  CHECK_THROWS_WITH(makeBarrierSolver(barrierSettings(-1.0)), Contains("barrier parameter must be a positive number"));
}
