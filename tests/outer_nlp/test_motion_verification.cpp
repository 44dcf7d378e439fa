// SPDX-License-Identifier: BSD-3-Clause
// A motion verified between its samples (outer_nlp/motion_verification.hpp): on one instant an
// interval it sees what the problem's own rows see; a torque limit broken between two samples
// only — a spline parameter nudged until it is — is found there, named by joint and instant,
// while every sampled row still holds.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <optional>

#include "common/test_support.hpp"
#include "outer_nlp/energy_balance.hpp"
#include "outer_nlp/motion_problem.hpp"
#include "outer_nlp/motion_verification.hpp"
#include "outer_nlp/scenario_run.hpp"

namespace mcopt {

namespace {

/// The bundled kick on a coarse grid: 12 samples leave room between them.
Scenario coarseKick() {
  Scenario s = loadScenario(test::sourceDir() / "scenarios/hrp2_kick.yaml");
  s.samples = 12;
  s.outputSamples = 20;
  s.solve.torqueScreening = 0.0;
  s.solve.continuation.clear();
  return s;
}

const VerificationCheck& checkOf(const MotionVerification& v, const std::string& kind) {
  for (const VerificationCheck& c : v.checks)
    if (c.kind == kind) return c;
  FAIL("no check " << kind);
  throw std::logic_error("unreachable");
}

/// max_s |Γ_js| / L_j over the given physics.
double peakRatio(const SampledPhysics& p, int joint, double limit) { return p.tau.row(joint).cwiseAbs().maxCoeff() / limit; }

}  // namespace

TEST_CASE("verify: with one instant an interval, the rows it checks are the problem's own", "[outer][verify]") {
  const Scenario s = coarseKick();
  MotionProblem problem(s);
  const Eigen::VectorXd x = problem.initialPoint(s.start, s.end);
  VerificationSettings settings;
  settings.instantsPerInterval = 1;
  const MotionVerification v = verifyMotion(problem, x, settings);
  CHECK(v.instants == s.samples);
  const MotionProblem::Violations sampled = problem.violations(x);
  std::vector<std::string> compared;
  for (const ConstraintKindInfo& kind : problem.rowKinds()) {
    if (!kind.verified) continue;
    for (const VerificationCheck& c : v.checks)
      if (c.kind == kind.name) {
        INFO(c.kind);
        CHECK(c.worst == Approx(sampled.of(kind.name)).margin(1e-12));
        compared.push_back(c.kind);
      }
  }
  // The kick's rows: velocity and torque limits, its reference contact's and its task's.
  for (const char* kind : {"velocity_limit", "torque_limit", "contact_unilateral", "task"})
    CHECK(std::count(compared.begin(), compared.end(), kind) == 1);
}

TEST_CASE("verify: a spline parameter nudged so that a torque limit breaks between two samples only", "[outer][verify]") {
  const Scenario s = coarseKick();
  MotionProblem problem(s);
  // The search's grid (MotionProblem keeps a reference to its scenario): 5 instants an interval
  // under the sanitizers, where its hundreds of evaluations took a minute; verify's own is 10.
#ifdef MCOPT_UNDER_SANITIZERS
  const Scenario fineScenario = fineGridScenario(s, 5);
#else
  const Scenario fineScenario = fineGridScenario(s, 10);
#endif
  MotionProblem fine(fineScenario);
  const Eigen::VectorXd x0 = problem.initialPoint(s.start, s.end);
  const int m = problem.parametrization().parametersPerJoint();
  // Per joint, the largest |Γ| / L at the samples and on the fine grid.
  auto peaks = [&](const Eigen::VectorXd& x) {
    const SampledPhysics sampled = problem.sampledPhysics(x);
    const SampledPhysics between = fine.sampledPhysics(fine.pointWithWrenchesFrom(problem, x));
    Eigen::MatrixXd ratio = Eigen::MatrixXd::Zero(s.robot.jointCount(), 2);
    for (int j = 0; j < s.robot.jointCount(); ++j) {
      const double limit = s.actuators.joints[static_cast<std::size_t>(j)].torqueLimit;
      if (std::isfinite(limit)) ratio.row(j) << peakRatio(sampled, j, limit), peakRatio(between, j, limit);
    }
    return ratio;
  };
  // The first joint and parameter whose nudge δ brings that joint's peak torque on the fine grid
  // 0.5 % past its limit while at the samples every joint's stays below its own, and on the fine
  // grid every other joint's too: δ by bisection on the fine grid's peak.
  std::optional<Eigen::VectorXd> planted;
  int plantedJoint = -1;
  for (int j = 0; j < s.robot.jointCount() && !planted; ++j) {
    if (!std::isfinite(s.actuators.joints[static_cast<std::size_t>(j)].torqueLimit)) continue;
    for (int l = 1; l + 1 < m && !planted; ++l)
      for (const double sign : {1.0, -1.0}) {
        auto nudged = [&](double delta) {
          Eigen::VectorXd x = x0;
          x[j * m + l] += sign * delta;
          return x;
        };
        double below = 0.0, above = 0.05;
        while (above < 2.0 && peaks(nudged(above))(j, 1) < 1.005) below = above, above *= 2.0;
        if (above >= 2.0) continue;
        for (int k = 0; k < 20; ++k) {
          const double middle = 0.5 * (below + above);
          (peaks(nudged(middle))(j, 1) < 1.005 ? below : above) = middle;
        }
        Eigen::MatrixXd ratio = peaks(nudged(above));
        const double sampled = ratio.col(0).maxCoeff();
        ratio(j, 1) = 0.0;
        if (sampled < 0.999 && ratio.col(1).maxCoeff() < 1.0) {
          planted = nudged(above);
          plantedJoint = j;
          break;
        }
      }
  }
  REQUIRE(planted);
  const std::string joint = s.robot.joints[static_cast<std::size_t>(plantedJoint)].name;
  INFO("planted on " << joint);
  // The problem's rows at the samples see nothing wrong with the torques.
  CHECK(problem.violations(*planted).of("torque_limit") == 0.0);
  const MotionVerification v = verifyMotion(problem, *planted);
  const VerificationCheck& torque = checkOf(v, "torque_limit");
  CHECK_FALSE(torque.passed());
  CHECK_FALSE(v.passed());
  CHECK(torque.where == "torque limit of " + joint);
  CHECK(torque.betweenSamples);
  // Its instant lies strictly between two samples, as does every instant it fails at.
  const SampledPhysics sampled = problem.sampledPhysics(*planted);
  REQUIRE_FALSE(torque.failingTimes.empty());
  for (const double t : torque.failingTimes)
    for (Eigen::Index k = 0; k < sampled.time.size(); ++k) CHECK(std::abs(t - sampled.time[k]) > 1e-9);
  CHECK(torque.worst > 0.004 * s.actuators.joints[static_cast<std::size_t>(plantedJoint)].torqueLimit);
  const std::vector<std::string> failures = v.failures();
  CHECK(std::find(failures.begin(), failures.end(), "torque_limit") != failures.end());
}

}  // namespace mcopt

namespace mcopt {

TEST_CASE("refine: a round's grid halves every interval, keeps every sample and a throw's release", "[outer][verify]") {
  Scenario s = loadScenario(test::sourceDir() / "scenarios/hrp2_throw.yaml");
  s.samples = 11;
  MotionProblem coarse(s);
  const Eigen::VectorXd x = coarse.initialPoint(s.start, s.end);
  const Scenario refined = refinedScenario(s, coarse.motionParameters(x), coarse.duration(x));
  CHECK(refined.samples == 21);
  CHECK(refined.solve.continuation.empty());
  CHECK_FALSE(refined.solve.configurationOptimisation);
  REQUIRE(refined.initialMotion);
  MotionProblem fine(refined);
  const SampledPhysics a = coarse.sampledPhysics(x), b = fine.sampledPhysics(fine.pointWithWrenchesFrom(coarse, x));
  // Every sample of the coarse grid is one of the fine grid's, with the same state there.
  for (Eigen::Index k = 0; k < a.time.size(); ++k) {
    Eigen::Index found = -1;
    for (Eigen::Index l = 0; l < b.time.size() && found < 0; ++l)
      if (std::abs(b.time[l] - a.time[k]) <= 1e-12) found = l;
    INFO("sample " << k << " at " << a.time[k] << " s");
    REQUIRE(found >= 0);
    CHECK((b.q.col(found) - a.q.col(k)).cwiseAbs().maxCoeff() <= 1e-12);
  }
  REQUIRE(a.release);
  REQUIRE(b.release);
  CHECK(b.release->time == Approx(a.release->time).margin(1e-12));
}

}  // namespace mcopt
