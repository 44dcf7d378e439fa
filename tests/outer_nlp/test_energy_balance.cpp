// SPDX-License-Identifier: BSD-3-Clause
// The energy balance (outer_nlp/energy_balance.hpp; docs/reference/scenario-file.md, "Energy balance"):
// the joints' net work plus the environment contacts' work equals the change of the robot's
// mechanical energy (and a thrown ball's), on every bundled scenario's problem, at motions
// that are not optima (a held contact is not held there: its work is part of the check); the
// identity fails when the wrenches or the states are not the ones the torques were computed
// with; the periodic boundary returns the motion exactly to its start.
#include <catch2/catch.hpp>

#include <random>
#include <stdexcept>
#include <string>

#include "common/perturbed_motion.hpp"
#include "common/test_support.hpp"
#include "outer_nlp/energy_balance.hpp"
#include "outer_nlp/posture_check.hpp"
#include "outer_nlp/motion_problem.hpp"

namespace mcopt {

namespace {

Eigen::VectorXd perturbedMotion(MotionProblem& problem, const Scenario& scenario, unsigned seed, double size) {
  Eigen::VectorXd x = initialPointThroughContacts(problem, scenario.start, scenario.end);
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> u(-size, size);
  for (int i = 0; i < problem.parametrization().parameterCount(); ++i) x[i] += u(random);
  // Within the joints' limits (the dynamics do not care, the contact models' rows do not enter);
  // continuous where a window's contact hands over between splines and closure.
  return problem.pointWithWrenchesFrom(problem, test::withWindowEndsMet(problem, x));
}

Scenario smaller(const std::string& name, int samples) {
  Scenario s = loadScenario(test::sourceDir() / "scenarios" / name);
  s.samples = samples;
  s.outputSamples = 20;
  return s;
}

}  // namespace

TEST_CASE("energy balance: the joints' and contacts' work is the change of mechanical energy, on every bundled scenario",
          "[outer][energy]") {
  // Samples chosen so that a throw's release (0.6 T, 0.5 T on the hand-supported one) stays a sample.
  // At least 10 instants an interval, as results have it: with 2 (tried under the sanitizers)
  // the hand-supported throw's residual was 1.6e-3 of its scale, Simpson's error at h = 0.12 s.
#ifdef MCOPT_UNDER_SANITIZERS
  const int samples = 11, atLeast = 10;
  const double kIdentityTolerance = 1e-5;
#else
  const int samples = 21, atLeast = 10;
  const double kIdentityTolerance = 1e-6;
#endif
  int covered = 0;
  for (const char* name : {"hrp2_kick.yaml", "hrp2_weight_shift.yaml", "hrp2_lean_reach.yaml",
                           "hrp2_throw.yaml", "hrp2_throw_one_foot.yaml", "hrp2_throw_hand_support.yaml",
                           "hrp2_throw_free_release.yaml"}) {
    const Scenario scenario = smaller(name, samples);
    MotionProblem problem(scenario);
    const Eigen::VectorXd x = perturbedMotion(problem, scenario, 7, 0.05);
    const int perInterval = energyGridInstants(scenario, atLeast);
    const EnergyBalance b = energyBalance(problem, x, perInterval);
    INFO(name << ": joints " << b.jointWork << " J, contacts " << b.contactWork << " J, ΔE_pot " << b.potentialChange
              << " J, ΔE_kin " << b.kineticChange << " J, ball " << b.ballEnergy << " J; residual "
              << b.mechanicalResidual() << " J of " << b.mechanicalScale() << " J; electrical residual "
              << b.electricalResidual() << " J");
    // The fine grid: perInterval instants an interval, a throw's release and each window's end twice.
    CHECK(b.instants >= perInterval * (samples - 1) + 1 + (scenario.ball ? 1 : 0));
    const Scenario fine = fineGridScenario(scenario, perInterval);
    CHECK(b.instants == MotionProblem(fine).sampleCount());
    CHECK(b.mechanicalScale() > 0.1);  // a motion that does something
    // Simpson's rule on a grid whose pairs do not straddle a knot: far below the 1e-4 asked
    // (at 11 samples, under the sanitizers, the hand-supported throw's is 1.6e-6).
    CHECK(std::abs(b.mechanicalResidual()) <= kIdentityTolerance * b.mechanicalScale());
    // The rotors' ∫ I_m N² q̈ q̇ dt by trapezoids against ΔE_rotor: the same quadrature's error.
    CHECK(std::abs(b.electricalResidual()) <= 1e-4 * std::max({std::abs(b.electricalEnergy), b.jouleLosses, std::abs(b.frictionDissipation), std::abs(b.jointWork)}));
    CHECK(b.positiveEnergy + b.braking == Approx(b.electricalEnergy).epsilon(1e-12).margin(1e-9));
    CHECK(b.jouleLosses >= 0.0);
    if (scenario.ball) CHECK(b.ballEnergy != 0.0);
    // Every contact holds (closed_chains.hpp): it does no work, whatever the motion.
    CHECK(std::abs(b.contactWork) <= 1e-12 * b.mechanicalScale());
    ++covered;
  }
  CHECK(covered == 7);
}

TEST_CASE("fine grids: a problem built without derivatives gives the same values and refuses derivatives",
          "[outer][energy]") {
  // The energy balance and `mcopt verify` evaluate the motion on thousands of instants: their
  // problem lays out its rows but no Jacobian (MotionProblemOptions::derivatives). Its values are
  // the full problem's, to the bit; a derivative asked of it is a programming error, not zeros.
  for (const char* name : {"hrp2_lean_reach.yaml", "hrp2_throw.yaml", "hrp2_kick.yaml"}) {
    INFO(name);
    const Scenario scenario = smaller(name, 11);
    // The point from a third problem: a closure's Newton starts where its problem's last
    // evaluation ended, so the two compared start from the same history (none).
    MotionProblem setup(scenario);
    const Eigen::VectorXd x = perturbedMotion(setup, scenario, 11, 0.05);
    MotionProblem full(scenario);
    MotionProblem values(scenario, {.hessian = scenario.solve.hessian, .derivatives = false});
    REQUIRE(values.constraintCount() == full.constraintCount());
    REQUIRE(values.variableCount() == full.variableCount());
    CHECK(full.jacobianNonZeros() > 0);
    CHECK(values.jacobianNonZeros() == 0);
    Eigen::VectorXd gFull, gValues;
    full.constraints(x, gFull);
    values.constraints(x, gValues);
    CHECK(gValues == gFull);
    CHECK(values.objective(x) == full.objective(x));
    const SampledPhysics a = full.sampledPhysics(x), b = values.sampledPhysics(x);
    CHECK(b.tau == a.tau);
    CHECK(b.power == a.power);
    CHECK(b.energy == a.energy);
    CHECK(b.closureDrift == a.closureDrift);
    Eigen::VectorXd jacobian;
    CHECK_THROWS_AS(values.jacobianValues(x, jacobian), std::logic_error);
  }
}

TEST_CASE("energy balance: the identity fails on a wrench or a state the torques were not computed with", "[outer][energy]") {
  // The lean reach. A contact that holds does no work, whatever its wrench: there the identity
  // cannot see how the wrenches are split, which the contact rows and `mcopt dynamics
  // --contacts` check. It sees a wrench on a frame that moves: the hand's, claimed at the
  // samples outside its window (where its arm is its splines'), in the balance but not in the
  // torques.
  Scenario scenario = smaller("hrp2_lean_reach.yaml", 21);
  scenario.controlPoints = 11;  // the perturbations below were sized for 11 (the bundled file has 15)
  const Scenario fineScenario = fineGridScenario(scenario, energyGridInstants(scenario, 10));
  MotionProblem problem(scenario), fine(fineScenario);
  const Eigen::VectorXd x = perturbedMotion(problem, scenario, 11, 0.05);
  const Eigen::VectorXd y = fine.pointWithWrenchesFrom(problem, x);
  const SampledPhysics physics = fine.sampledPhysics(y);
  const EnergyBalance b = energyBalanceOf(fine, physics);
  const double tolerance = 1e-4 * b.mechanicalScale();
  REQUIRE(std::abs(b.mechanicalResidual()) <= tolerance);

  SECTION("a contact wrench perturbed") {
    SampledPhysics p = physics;
    REQUIRE(p.wrenches.size() == 3);  // the left sole (reference), the right sole, the hand on the table
    const std::size_t hand = 2;
    int claimed = 0;
    for (Eigen::Index s = 0; s < p.time.size(); ++s)
      if (!p.active[hand][static_cast<std::size_t>(s)])
        p.active[hand][static_cast<std::size_t>(s)] = true, p.wrenches[hand](2, s) = 20.0, ++claimed;  // 20 N normal force
    REQUIRE(claimed > 0);
    const EnergyBalance perturbed = energyBalanceOf(fine, p);
    INFO("residual " << perturbed.mechanicalResidual() << " J against " << tolerance << " J");
    CHECK(std::abs(perturbed.mechanicalResidual()) > 10.0 * tolerance);
  }
  SECTION("a spline parameter perturbed under the same torques") {
    // One inner control point of the left knee (a joint that carries the body; the right leg's
    // follow the closure of the right sole, their splines unused).
    const int m = fine.parametrization().parametersPerJoint();
    const int knee = scenario.robot.jointIndex("LLEG_JOINT3");
    REQUIRE(knee >= 0);
    Eigen::VectorXd z = y;
    z[knee * m + m / 2] += 0.05;
    const SampledPhysics moved = fine.sampledPhysics(z);
    SampledPhysics p = physics;
    p.q = moved.q, p.v = moved.v, p.a = moved.a;
    const EnergyBalance perturbed = energyBalanceOf(fine, p);
    INFO("residual " << perturbed.mechanicalResidual() << " J against " << tolerance << " J");
    CHECK(std::abs(perturbed.mechanicalResidual()) > 10.0 * tolerance);
  }
}

TEST_CASE("periodic boundary: the motion ends exactly where it starts, at rest", "[outer][energy]") {
  Scenario scenario = smaller("hrp2_kick.yaml", 21);
  scenario.periodic = true;
  scenario.end = scenario.start;
  MotionProblem problem(scenario);
  CHECK(problem.parametrization().parametersPerJoint() == scenario.controlPoints - 5);
  CHECK(problem.parametrization().endParameter() == 0);
  const Eigen::VectorXd x = perturbedMotion(problem, scenario, 3, 0.2);
  const SampledPhysics p = problem.sampledPhysics(x);
  const Eigen::Index last = p.time.size() - 1;
  CHECK((p.q.col(last) - p.q.col(0)).cwiseAbs().maxCoeff() <= 1e-12);
  CHECK(p.v.col(0).cwiseAbs().maxCoeff() <= 1e-12);
  CHECK(p.v.col(last).cwiseAbs().maxCoeff() <= 1e-12);
  const EnergyBalance b = energyBalance(problem, x);
  CHECK(b.instantsPerInterval == 12);  // the kick's 6 knot spans and 20 intervals: 10 would put knots inside Simpson pairs
  CHECK(std::abs(b.potentialChange) <= 1e-9);
  CHECK(std::abs(b.kineticChange) <= 1e-9);
  CHECK(std::abs(b.jointWork) <= 1e-4 * std::max(1.0, b.jouleLosses));  // returns to its start: no net work
  CHECK(b.gravityReleased() <= 1e-9);
  // A fixed start fixes the end too: one set of bounds.
  scenario.fixStart = scenario.fixEnd = true;
  MotionProblem fixed(scenario);
  Eigen::VectorXd lower, upper;
  fixed.variableBounds(lower, upper);
  const int m = fixed.parametrization().parametersPerJoint();
  for (int j = 0; j < scenario.robot.jointCount(); ++j) {
    CHECK(lower[j * m] == scenario.start[j]);
    CHECK(upper[j * m] == scenario.start[j]);
  }
}

}  // namespace mcopt

namespace mcopt {

TEST_CASE("posture check: signed distance to a support polygon", "[outer][posture]") {
  // A 0.2 × 0.1 m rectangle and a second one beside it: the hull of both.
  const std::vector<Eigen::Vector2d> one = {{-0.1, -0.05}, {0.1, -0.05}, {0.1, 0.05}, {-0.1, 0.05}};
  CHECK(signedDistanceToHull(one, Eigen::Vector2d(0.0, 0.0)) == Approx(0.05));
  CHECK(signedDistanceToHull(one, Eigen::Vector2d(0.08, 0.0)) == Approx(0.02));
  CHECK(signedDistanceToHull(one, Eigen::Vector2d(0.0, 0.15)) == Approx(-0.10));
  CHECK(signedDistanceToHull(one, Eigen::Vector2d(0.13, 0.09)) == Approx(-0.05));  // from the corner (0.1, 0.05)
  std::vector<Eigen::Vector2d> two = one;
  for (const Eigen::Vector2d& c : one) two.push_back(c + Eigen::Vector2d(0.0, 0.2));
  two.push_back(Eigen::Vector2d(0.0, 0.1));  // inside: not a vertex of the hull
  CHECK(signedDistanceToHull(two, Eigen::Vector2d(0.0, 0.1)) == Approx(0.1));  // between the two, inside their hull
  CHECK(signedDistanceToHull(two, Eigen::Vector2d(0.3, 0.1)) == Approx(-0.2));
  // Two points have no inside.
  CHECK(signedDistanceToHull({{0.0, 0.0}, {1.0, 0.0}}, Eigen::Vector2d(0.5, 0.0)) == Approx(0.0).margin(1e-15));
  CHECK(signedDistanceToHull({{0.0, 0.0}, {1.0, 0.0}}, Eigen::Vector2d(0.5, 0.2)) == Approx(-0.2));
}

}  // namespace mcopt
