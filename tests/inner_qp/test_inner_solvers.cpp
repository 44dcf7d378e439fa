// SPDX-License-Identifier: BSD-3-Clause
// One catalogue of random inner problems through every solver (style.md §6): same optimum
// of the report model, feasible, KKT-certified; the pyramid's convergence to the cone; the
// wrench cone inside the report model; infeasible samples; warm starts.
#include <catch2/catch.hpp>
#include <numbers>

#include <limits>
#include <memory>
#include <string>

#include "common/random_inner_problem.hpp"
#include "common/test_support.hpp"
#include "inner_qp/inner_solver.hpp"

using namespace mcopt;
using test::RandomProblem;
using test::randomProblem;
using test::assemble;

namespace {

/// The data scale of inner_solver.hpp's relative tolerances: 1 + ‖H‖∞ + ‖c‖∞ + ‖W‖∞.
double inner_detail_scale(const ContactProblem& p) {
  return 1.0 + p.hessian.cwiseAbs().maxCoeff() + p.gradient.cwiseAbs().maxCoeff() + p.balanceTarget.cwiseAbs().maxCoeff();
}

double worstViolation(const ContactProblem& p, const Eigen::VectorXd& F) {
  double fzScale = 1.0;
  for (int i = 0; i < p.contactCount; ++i) fzScale = std::max(fzScale, 1.0 + std::abs(F[6 * i + 2]));
  return p.constraintViolation(F) / fzScale;
}

double minNormalForce(const ContactProblem& p, const Eigen::VectorXd& F) {
  double least = std::numeric_limits<double>::infinity();
  for (int i = 0; i < p.contactCount; ++i) least = std::min(least, F[6 * i + 2]);
  return least;
}

/// The least balance slack of two contacts at the world origin (identity frames) asked for a
/// pull, a slip or a tip (infeasible test below), by hand:
///   pull (0, 0, −f): contacts only push, so nothing helps: the slack is the demand;
///   slip (h, 0, f): the contacts' sum can give any (fx, fz) with |fx| ≤ μ_max fz (put the load
///     on the grippier one), so the slack is (h, f) minus its projection on the line fx = μ_max fz;
///   tip (0, 0, f, 0, m, 0): my ≤ a fz with a = max(−x_min) (−my = x_cop fz, formulation.md
///     §7), so the slack is (f, m) minus its projection on the line my = a fz.
Vector6 exactLeastSlack(const std::string& what, const Vector6& demand, const std::vector<ContactSpec>& contacts) {
  Vector6 slack = demand;
  if (what == "pull") return slack;
  double slope = 0.0;
  for (const ContactSpec& c : contacts) slope = std::max(slope, what == "slip" ? c.friction : -c.xMin);
  // Projection of (u, z) = (horizontal or moment, normal force) on the ray u = slope z.
  const int u = what == "slip" ? 0 : 4;
  const double z = demand[2], along = (demand[u] * slope + z) / (1.0 + slope * slope);
  slack[u] = demand[u] - slope * along;
  slack[2] = z - along;
  return slack;
}

double relativeGap(double value, double reference) { return std::abs(value - reference) / (1.0 + std::abs(reference)); }

/// One third-party solver on a problem, as it answers and polished (InnerSettings::polish).
struct RawAndPolished {
  std::string name;
  InnerResult raw, polished;
};
RawAndPolished solveRawAndPolished(std::unique_ptr<InnerSolver> (*make)(const InnerSettings&), const ContactProblem& p) {
  InnerSettings polishing;
  polishing.polish = true;
  RawAndPolished out;
  auto raw = make(InnerSettings{});
  out.name = raw->name();
  raw->solve(p, out.raw);
  make(polishing)->solve(p, out.polished);
  return out;
}

struct SolverTally {
  int optimal = 0;       ///< status Optimal (KKT-certified)
  int sameOptimum = 0;   ///< finite point, feasible to 1e-8 (1 + |fz|), objective within 1e-6 of the active set's
};

}  // namespace

TEST_CASE("the three solvers reach the same optimum of the report model", "[inner][solvers][catalogue]") {
  // Issue 5's acceptance: 1002 random feasible problems, 2, 3 and 4 contacts, the third
  // on a wall. The active-set method must certify every one (KKT residual ≤ 1e-9); SLSQP
  // and Ipopt must agree with it wherever they certify their own point.
  std::mt19937 rng(101);
  auto activeSet = makeActiveSetSolver();
  auto slsqp = makeSlsqpSolver();
  auto ipopt = makeIpoptSolver();
  SolverTally slsqpTally, ipoptTally;
  int problems = 0, unloaded = 0;
  double worstKkt = 0.0;
  // Under the sanitizers (ASan's allocator behind every Ipopt and MUMPS allocation: 25 s
  // become more than 10 minutes) a fifth of the catalogue runs; the acceptance count is the
  // Release build's.
  struct Measured {
    int unloaded, slsqpOptimal, slsqpSame, ipoptOptimal, ipoptSame;
  };
#ifdef MCOPT_UNDER_SANITIZERS
  constexpr int kPerContactCount = 67;
  constexpr Measured kMeasured{3, 200, 201, 201, 201};  // of 201
#else
  constexpr int kPerContactCount = 334;
  constexpr Measured kMeasured{43, 973, 1001, 998, 1001};  // of 1002
#endif
  for (int nc : {2, 3, 4}) {
    for (int trial = 0; trial < kPerContactCount; ++trial, ++problems) {
      const RandomProblem r = randomProblem(rng, nc);
      const ContactProblem p = assemble(r, "report");
      InnerResult reference;
      activeSet->solve(p, reference);
      INFO(nc << " contacts, trial " << trial << ": active-set " << toString(reference.status) << " ("
              << reference.message << "), KKT " << reference.kktResidual);
      REQUIRE(reference.status == InnerStatus::Optimal);
      CHECK(reference.kktResidual <= 1e-9);
      CHECK(worstViolation(p, reference.wrenches) <= 1e-8);
      worstKkt = std::max(worstKkt, reference.kktResidual);
      unloaded += minNormalForce(p, reference.wrenches) <= 1e-9 * inner_detail_scale(p);
      for (auto [solver, tally] : {std::pair{slsqp.get(), &slsqpTally}, std::pair{ipopt.get(), &ipoptTally}}) {
        InnerResult result;
        solver->solve(p, result);
        INFO(solver->name() << ": " << toString(result.status) << " (" << result.message << ") slack " << result.balanceSlack.transpose() << ", objective "
                            << result.objective << " vs " << reference.objective);
        // Never a wrong answer called optimal, never a feasible problem called infeasible.
        CHECK(result.status != InnerStatus::Infeasible);
        const bool agrees = result.wrenches.allFinite() && worstViolation(p, result.wrenches) <= 1e-8 &&
                            relativeGap(result.objective, reference.objective) <= 1e-6;
        tally->sameOptimum += agrees;
        if (result.status != InnerStatus::Optimal) continue;
        ++tally->optimal;
        CHECK(agrees);
        CHECK(result.kktResidual <= 1e-6);
      }
    }
  }
  WARN("of " << problems << " problems (" << unloaded << " with an unloaded contact at the optimum): active-set "
             << "optimal " << problems << ", worst KKT residual " << worstKkt << "; SLSQP optimal "
             << slsqpTally.optimal << ", at the same optimum " << slsqpTally.sameOptimum << "; Ipopt optimal "
             << ipoptTally.optimal << ", at the same optimum " << ipoptTally.sameOptimum);
  // The figures docs/theory/inner-problem.md states, as thresholds. The catalogue is seeded and the
  // three solvers are deterministic, so their counts are required exactly as measured. (SLSQP
  // had a margin of 1 % until the elastic phase's band rows reported their values: before, it
  // read whatever its constraint buffer held, docs/theory/inner-problem.md "Determinism".)
  CHECK(unloaded >= kMeasured.unloaded);  // the degenerate case the method is built for
  CHECK(ipoptTally.optimal >= kMeasured.ipoptOptimal);
  CHECK(ipoptTally.sameOptimum >= kMeasured.ipoptSame);
  CHECK(slsqpTally.optimal >= kMeasured.slsqpOptimal);
  CHECK(slsqpTally.sameOptimum >= kMeasured.slsqpSame);
}

TEST_CASE("with a positive definite objective the solvers agree on wrenches and multipliers too",
          "[inner][solvers]") {
  // 30 joints, as HRP-2: H is positive definite on the balance's null space, so the optimal
  // wrenches are unique and, with independent active constraints, so are the multipliers.
  std::mt19937 rng(109);
  auto activeSet = makeActiveSetSolver();
  auto ipopt = makeIpoptSolver();
  int compared = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const RandomProblem r = randomProblem(rng, 2 + trial % 3, 30);
    const ContactProblem p = assemble(r, "report");
    InnerResult a, b;
    activeSet->solve(p, a);
    ipopt->solve(p, b);
    REQUIRE(a.status == InnerStatus::Optimal);
    if (b.status != InnerStatus::Optimal) continue;
    ++compared;
    const double forceScale = 1.0 + a.wrenches.cwiseAbs().maxCoeff();
    CHECK((a.wrenches - b.wrenches).cwiseAbs().maxCoeff() <= 1e-5 * forceScale);
    const double multiplierScale = 1.0 + a.balanceMultipliers.cwiseAbs().maxCoeff();
    CHECK((a.balanceMultipliers - b.balanceMultipliers).cwiseAbs().maxCoeff() <= 1e-4 * multiplierScale);
  }
  WARN("Ipopt compared with the active-set method on " << compared << " of 40");
  CHECK(compared == 40);  // measured: every one (seeded, deterministic)
}

TEST_CASE("many-facet pyramids converge to the report optimum from above", "[inner][solvers]") {
  // An inscribed k-facet pyramid loses at most 1 − cos(π/k) of the cone's radius, so its
  // optimum is never better than the cone's and the worst gap over problems shrinks with k.
  // (Not monotone problem by problem: a 16-facet pyramid is not inside a 64-facet one.)
  std::mt19937 rng(103);
  auto activeSet = makeActiveSetSolver();
  auto ipopt = makeIpoptSolver();
  const std::vector<int> facetCounts = {16, 64, 256, 1024};
  std::vector<double> worstGap(facetCounts.size(), 0.0);
  int pyramidsSolved = 0, pyramidsInfeasible = 0, ipoptCompared = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const RandomProblem r = randomProblem(rng, 2 + trial % 3);
    InnerResult cone;
    activeSet->solve(assemble(r, "report"), cone);
    REQUIRE(cone.status == InnerStatus::Optimal);
    for (std::size_t f = 0; f < facetCounts.size(); ++f) {
      const ContactProblem pyramid = assemble(r, "pyramid", facetCounts[f]);
      InnerResult result;
      activeSet->solve(pyramid, result);
      INFO("trial " << trial << ", " << facetCounts[f] << " facets: " << toString(result.status) << " " << result.message);
      if (result.status == InnerStatus::Infeasible) {  // an inscribed pyramid may lose feasibility
        ++pyramidsInfeasible;
        continue;
      }
      REQUIRE(result.status == InnerStatus::Optimal);
      ++pyramidsSolved;
      CHECK(result.kktResidual <= 1e-9);
      const double gap = (result.objective - cone.objective) / (1.0 + std::abs(cone.objective));
      CHECK(gap >= -1e-9);
      worstGap[f] = std::max(worstGap[f], gap);
      if (f == 0) {  // a pure QP: the third-party solvers agree with it
        InnerResult check;
        ipopt->solve(pyramid, check);
        if (check.status != InnerStatus::Optimal) continue;
        CHECK(relativeGap(check.objective, result.objective) <= 1e-6);
        ++ipoptCompared;
      }
    }
  }
  // Every skip counted (seeded and deterministic: as measured).
  WARN(pyramidsSolved << " pyramids solved, " << pyramidsInfeasible << " infeasible; Ipopt compared on " << ipoptCompared);
  CHECK(pyramidsSolved + pyramidsInfeasible == 80);
  CHECK(pyramidsSolved == 80);  // measured: none infeasible
  CHECK(ipoptCompared == 20);
  for (std::size_t f = 1; f < facetCounts.size(); ++f) CHECK(worstGap[f] < worstGap[f - 1]);
  CHECK(worstGap.back() <= 1e-5);
}

TEST_CASE("the wrench cone's optimum is admissible for the report model, yaw bounds held", "[inner][solvers]") {
  std::mt19937 rng(113);
  auto activeSet = makeActiveSetSolver();
  int yawBinding = 0, solved = 0;
  for (int trial = 0; trial < 60; ++trial) {
    RandomProblem r = randomProblem(rng, 2 + trial % 3);
    r.tau0 *= 3.0;  // strong torques: the power-optimal wrenches lean on the yaw moment too
    const ContactProblem report = assemble(r, "report");
    const ContactProblem wrenchCone = assemble(r, "wrench-cone");
    InnerResult a, b;
    activeSet->solve(report, a);
    activeSet->solve(wrenchCone, b);
    REQUIRE(a.status == InnerStatus::Optimal);
    if (b.status == InnerStatus::Infeasible) continue;
    REQUIRE(b.status == InnerStatus::Optimal);
    ++solved;
    CHECK(b.kktResidual <= 1e-9);
    CHECK(worstViolation(report, b.wrenches) <= 1e-8);   // no slip the report model forbids
    CHECK(b.objective >= a.objective - 1e-6 * (1.0 + std::abs(a.objective)));
    // Rows 9–16 of each contact are the yaw bounds (contact_problem.cpp): where the report
    // optimum would spin a contact, the wrench cone's optimum holds it.
    bool spins = false;
    for (int i = 0; i < report.contactCount; ++i)
      for (int row = 17 * i + 9; row < 17 * i + 17; ++row)
        spins |= wrenchCone.inequality.row(row).dot(a.wrenches) - wrenchCone.inequalityBound[row] > 1e-6;
    yawBinding += spins;
  }
  WARN(solved << " wrench-cone problems solved; in " << yawBinding
              << " the report optimum would spin a contact (yaw rows violated), the wrench-cone optimum does not");
  // Seeded and deterministic (the active-set method): every one of the 60, as measured.
  CHECK(solved == 60);
  CHECK(yawBinding == 60);
}

TEST_CASE("infeasible problems: the active-set method proves it and finds the least slack", "[inner][solvers]") {
  // Two feet on the floor asked for what they cannot give: to pull (every contact unloaded
  // at the least slack, the cones' apex), to push sideways beyond friction (slip), to hold
  // a moment beyond the support area (tip). The active-set method's QPs are relaxations of
  // the inner problem, so its "infeasible" is a proof; its elastic solution is KKT-certified.
  // SLSQP and Ipopt must never call such a sample optimal or return NaN; where they say
  // infeasible, their slack can be no smaller than the least one.
  std::mt19937 rng(107);
  const std::vector<std::pair<const char*, Vector6>> demands = {
      {"pull", (Vector6() << 0, 0, -300, 0, 0, 0).finished()},
      {"slip", (Vector6() << 300, 0, 300, 0, 0, 0).finished()},
      {"tip", (Vector6() << 0, 0, 300, 0, 150, 0).finished()}};
  auto activeSet = makeActiveSetSolver();
  int thirdPartyInfeasible = 0, thirdPartyRuns = 0;
#ifdef MCOPT_UNDER_SANITIZERS
  constexpr int kTrials = 1;  // the third-party solvers' elastic phases are slow under ASan
  constexpr int kThirdPartyInfeasible = 1;
#else
  constexpr int kTrials = 3;
  constexpr int kThirdPartyInfeasible = 5;
#endif
  for (const auto& [what, demand] : demands) {
    for (int trial = 0; trial < kTrials; ++trial) {
      RandomProblem r = randomProblem(rng, 2);
      for (ContactSpec& c : r.contacts) c.pose = RigidTransform{};  // both on the floor, at the origin
      r.balance = demand;
      const ContactProblem p = assemble(r, "report");
      InnerResult least;
      activeSet->solve(p, least);
      INFO(what << ", trial " << trial << ", active-set: " << least.message << "; slack " << least.balanceSlack.transpose());
      REQUIRE(least.status == InnerStatus::Infeasible);
      CHECK(least.kktResidual <= 1e-9);
      // The exact least slack: W minus its projection onto what the contacts can give.
      const Vector6 expected = exactLeastSlack(what, demand, r.contacts);
      INFO("expected slack " << expected.transpose());
      CHECK((least.balanceSlack - expected).cwiseAbs().maxCoeff() <= 1e-6 * demand.norm());
      // Feasible for the shifted balance: the slack is what the contacts cannot give.
      CHECK(worstViolation(p, least.wrenches) <= 1e-8 + least.balanceSlack.cwiseAbs().maxCoeff());
      ContactProblem shifted = p;
      shifted.balanceTarget -= least.balanceSlack;
      CHECK(worstViolation(shifted, least.wrenches) <= 1e-8);
      for (auto make : {makeSlsqpSolver, makeIpoptSolver}) {
        auto solver = make(InnerSettings{});
        InnerResult result;
        solver->solve(p, result);
        INFO(solver->name() << ": " << toString(result.status) << ", " << result.message << "; slack "
                            << result.balanceSlack.transpose());
        ++thirdPartyRuns;
        CHECK(result.status != InnerStatus::Optimal);
        CHECK(result.wrenches.allFinite());
        CHECK(result.balanceSlack.allFinite());
        if (result.status != InnerStatus::Infeasible) continue;
        ++thirdPartyInfeasible;
        CHECK(result.balanceSlack.norm() >= least.balanceSlack.norm() - 1e-6 * 300.0);
        CHECK(result.balanceSlack.norm() <= 1.01 * least.balanceSlack.norm());
      }
    }
  }
  WARN("SLSQP and Ipopt certified " << thirdPartyInfeasible << " of " << thirdPartyRuns
                                    << " infeasible samples as infeasible; the rest they report failed");
  CHECK(thirdPartyRuns == 2 * kTrials * static_cast<int>(demands.size()));
  // Measured 5 of 18 (Release; 1 of 6 under the sanitizers):
  // fewer would mean an adapter lost its elastic phase.
  CHECK(thirdPartyInfeasible >= kThirdPartyInfeasible);
}

TEST_CASE("warm starts along a smooth motion cut the active-set iterations, not the accuracy", "[inner][solvers]") {
  // A sequence of problems whose data move smoothly, as successive samples of a motion do.
  std::mt19937 rng(127);
  const RandomProblem a = randomProblem(rng, 3, 30), b = randomProblem(rng, 3, 30);
  InnerSettings coldSettings;
  coldSettings.warmStart = false;
  auto warm = makeActiveSetSolver();
  auto cold = makeActiveSetSolver(coldSettings);
  InnerResult warmResult, coldResult;
  long warmIterations = 0, coldIterations = 0;
  constexpr int kSamples = 100;
  for (int k = 0; k < kSamples; ++k) {
    const double s = 0.5 - 0.5 * std::cos(std::numbers::pi * k / (kSamples - 1));
    RandomProblem r = a;
    r.wrenchToTorque = (1 - s) * a.wrenchToTorque + s * b.wrenchToTorque;
    r.tau0 = (1 - s) * a.tau0 + s * b.tau0;
    r.balance = (1 - s) * a.balance + s * b.balance;
    const ContactProblem p = assemble(r, "report");
    warm->solve(p, warmResult);  // the previous sample's result is the warm start
    cold->solve(p, coldResult);
    REQUIRE(warmResult.status == InnerStatus::Optimal);
    REQUIRE(coldResult.status == InnerStatus::Optimal);
    CHECK(warmResult.kktResidual <= 1e-9);
    CHECK(relativeGap(warmResult.objective, coldResult.objective) <= 1e-9);
    warmIterations += warmResult.iterations;
    coldIterations += coldResult.iterations;
  }
  WARN("mean active-set iterations per sample: warm " << double(warmIterations) / kSamples << ", cold "
                                                      << double(coldIterations) / kSamples);
  // docs/theory/inner-problem.md: warm 3.84, cold 10.73 a sample (seeded, deterministic).
  CHECK(double(warmIterations) / kSamples <= 3.84 + 1e-9);
  CHECK(double(coldIterations) / kSamples >= 10.73 - 1e-9);
}

TEST_CASE("polishing: SLSQP and Ipopt on their own active sets reach the active-set optimum, and certify a slight infeasibility",
          "[inner][solvers][polish]") {
  // docs/theory/inner-problem.md, "Polishing". Linear models (wrench cone, pyramid): the polished
  // answer is the active-set method's to rounding, where the raw one is within the solvers'
  // tolerances; a feasible problem is never called infeasible.
  std::mt19937 rng(131);
  auto activeSet = makeActiveSetSolver();
  int compared = 0, polishedOptimal = 0, rawOptimal = 0;
#ifdef MCOPT_UNDER_SANITIZERS
  constexpr int kTrials = 6;
#else
  constexpr int kTrials = 30;
#endif
  for (int trial = 0; trial < kTrials; ++trial) {
    const RandomProblem r = randomProblem(rng, 2 + trial % 3);
    const ContactProblem p = assemble(r, trial % 2 == 0 ? "wrench-cone" : "pyramid");
    InnerResult reference;
    activeSet->solve(p, reference);
    if (reference.status != InnerStatus::Optimal) continue;
    for (auto make : {makeSlsqpSolver, makeIpoptSolver}) {
      const auto [name, a, b] = solveRawAndPolished(make, p);
      INFO("trial " << trial << ", " << name << ": raw " << toString(a.status) << " (" << a.message << "), KKT "
                    << a.kktResidual << "; polished " << toString(b.status) << " (" << b.message << "), KKT " << b.kktResidual);
      ++compared;
      CHECK(b.status != InnerStatus::Infeasible);
      rawOptimal += a.status == InnerStatus::Optimal;
      if (b.status != InnerStatus::Optimal) continue;
      ++polishedOptimal;
      // Rounding, not the solver's tolerance: the objective to 1e-11, KKT to 1e-11.
      CHECK(relativeGap(b.objective, reference.objective) <= 1e-11);
      CHECK(b.kktResidual <= 1e-11);
      CHECK(worstViolation(p, b.wrenches) <= 1e-10);
      if (a.status == InnerStatus::Optimal) CHECK(b.kktResidual <= a.kktResidual);
    }
  }
  WARN("polished: " << polishedOptimal << " of " << compared << " optimal (raw: " << rawOptimal << ")");
  CHECK(compared == 2 * kTrials);
  CHECK(polishedOptimal >= rawOptimal);
  CHECK(polishedOptimal == compared);  // measured: every one

  // A tip beyond the support by a least slack of 0.05 N (two feet at the origin, 300 N):
  // below √1e-6 of the data's scale, which the raw solvers' certificates cannot tell from
  // zero (never infeasible on it); polished, the least-slack phase is certified to rounding
  // and the sample is infeasible with the exact slack, as the active-set method finds it.
  RandomProblem r = randomProblem(rng, 2);
  for (ContactSpec& c : r.contacts) c.pose = RigidTransform{};
  double reach = 0.0;
  for (const ContactSpec& c : r.contacts) reach = std::max(reach, -c.xMin);
  const double slackNorm = 0.05;
  r.balance << 0, 0, 300, 0, reach * 300 + slackNorm * std::sqrt(1.0 + reach * reach), 0;
  const ContactProblem tip = assemble(r, "wrench-cone");
  const Vector6 expected = exactLeastSlack("tip", r.balance, r.contacts);
  REQUIRE(expected.norm() == Approx(slackNorm).epsilon(1e-9));
  InnerResult least;
  activeSet->solve(tip, least);
  REQUIRE(least.status == InnerStatus::Infeasible);
  // The least-slack phase's Tikhonov term (its unique minimiser) moves it by ~1e-9 of the demand.
  CHECK((least.balanceSlack - expected).cwiseAbs().maxCoeff() <= 1e-8 * 300.0);
  for (auto make : {makeSlsqpSolver, makeIpoptSolver}) {
    const auto [name, a, b] = solveRawAndPolished(make, tip);
    INFO(name << ": raw " << toString(a.status) << " (" << a.message << "); polished " << toString(b.status) << " ("
                     << b.message << "), slack " << b.balanceSlack.transpose() << " against " << expected.transpose());
    CHECK(a.status != InnerStatus::Optimal);
    CHECK(a.status != InnerStatus::Infeasible);
    REQUIRE(b.status == InnerStatus::Infeasible);
    CHECK((b.balanceSlack - expected).cwiseAbs().maxCoeff() <= 1e-8 * 300.0);
    CHECK((b.leastSlackWrenches - least.leastSlackWrenches).cwiseAbs().maxCoeff() <= 1e-7 * 300.0);
  }
}
