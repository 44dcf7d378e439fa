// SPDX-License-Identifier: BSD-3-Clause
// The linear inverted pendulum's least travel times (outer_nlp/timing_check.hpp): the formula
// against a simulation of the strategy it claims is fastest, against random admissible motions
// that must never beat it, and the check on scenarios (the bundled weight shift passes, the same
// one four times faster does not).
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "common/test_support.hpp"
#include "outer_nlp/scenario.hpp"
#include "outer_nlp/timing_check.hpp"

using namespace mcopt;

namespace {

constexpr double kOmega = 3.5;  // √(g / h) of a centre of mass 0.8 m high

/// The pendulum from (x, ξ) under zero-moment point p(x, ξ) until x reaches `to` (semi-implicit
/// steps of dt); the time, or infinity after `limit` seconds.
template <class Policy>
double simulate(double x, double xi, double to, Policy policy, double dt = 1e-5, double limit = 5.0) {
  double t = 0.0;
  while (t < limit) {
    if (x >= to) return t;
    const double p = policy(x, xi);
    xi += dt * kOmega * (xi - p);  // ξ̇ = ω (ξ − p)
    x += dt * kOmega * (xi - x);   // ẋ = ω (ξ − x)
    t += dt;
  }
  return std::numeric_limits<double>::infinity();
}

}  // namespace

TEST_CASE("pendulum travel time: the bang-then-hold strategy simulated takes the time the formula gives", "[outer][timing]") {
  const double a = -0.2, b = 0.1;
  // From rest at x0: p = a until ξ = b, then p = b.
  for (const double to : {-0.05, 0.0, 0.05, 0.09}) {
    const double x0 = -0.08;
    const double simulated = simulate(x0, x0, to, [&](double, double xi) { return xi < b ? a : xi; }, 1e-6);
    CHECK(pendulumTravelTime(x0, to, a, b, kOmega, PendulumLeg::FromRest) == Approx(simulated).epsilon(1e-3));
  }
  // Between targets: from the best state, ξ = b.
  const double between = simulate(-0.08, b, 0.05, [&](double, double) { return b; }, 1e-6);
  CHECK(pendulumTravelTime(-0.08, 0.05, a, b, kOmega, PendulumLeg::Between) == Approx(between).epsilon(1e-3));
  // Moving down mirrors moving up.
  CHECK(pendulumTravelTime(0.0, -0.15, a, b, kOmega, PendulumLeg::FromRest) ==
        Approx(pendulumTravelTime(0.0, 0.15, -b, -a, kOmega, PendulumLeg::FromRest)));
  // A target at or beyond the support's edge cannot be reached and stopped at.
  CHECK(std::isinf(pendulumTravelTime(0.0, b, a, b, kOmega, PendulumLeg::FromRest)));
  CHECK(std::isinf(pendulumTravelTime(0.0, 0.2, a, b, kOmega, PendulumLeg::Between)));
  // To rest: the motion ending at rest at `to`, run backwards from rest, is the formula's; forward,
  // it starts at `from` with the speed that brings it to rest exactly (simulated: the reversed
  // pendulum with the convergent component at b, x(T − s) = b + (to − b) cosh ωs).
  const double to = -0.05, from = -0.15;
  const double s = pendulumTravelTime(from, to, a, b, kOmega, PendulumLeg::ToRest);
  CHECK(b + (to - b) * std::cosh(kOmega * s) == Approx(from).margin(1e-12));
}

TEST_CASE("pendulum travel time: no admissible motion from rest beats it", "[outer][timing]") {
  const double a = -0.2, b = 0.1, x0 = -0.08, to = 0.04;
  const double bound = pendulumTravelTime(x0, to, a, b, kOmega, PendulumLeg::FromRest);
  std::mt19937 random(42);
  std::uniform_real_distribution<double> zmp(a, b);
  for (int trial = 0; trial < 40; ++trial) {
    double p = zmp(random);
    int steps = 0;
    // A zero-moment point drawn anew every 2 ms, kept where the capture point stays in [a, b].
    const double t = simulate(x0, x0, to, [&](double, double xi) {
      if (++steps % 200 == 0) p = zmp(random);
      return xi >= b ? std::max(p, xi) : xi <= a ? std::min(p, xi) : p;
    }, 1e-5, 2.0);
    CHECK(t >= bound - 1e-3);
  }
}

TEST_CASE("timing check: the bundled weight shift leaves time enough, four times faster it does not", "[outer][timing]") {
  const Scenario bundled = loadScenario(test::sourceDir() / "scenarios/hrp2_weight_shift.yaml");
  MotionProblem problem(bundled);
  const std::vector<TimingCheck> checks = checkCenterOfMassTimings(problem);
  // Start → left, left → right, right → left, left → end: along y (x is free).
  REQUIRE(checks.size() == 4);
  for (const TimingCheck& c : checks) {
    INFO(c.message());
    CHECK(c.axis == 'y');
    CHECK_FALSE(c.tooShort());
    CHECK(c.needed > 0.05);
  }
  CHECK(checks[0].from == "the start posture at rest");
  CHECK(checks[3].task == "the end posture at rest");

  Scenario fast = bundled;
  for (TaskSpec& task : fast.tasks) task.start /= 4.0, task.end /= 4.0;
  MotionProblem fastProblem(fast);
  int tooShort = 0;
  for (const TimingCheck& c : checkCenterOfMassTimings(fastProblem)) tooShort += c.tooShort();
  CHECK(tooShort == 3);  // the three targets 0.15 s apart; the end leg has 1.95 s
}
