// SPDX-License-Identifier: BSD-3-Clause
// The fine grid of a single-level formulation (outer_nlp/fine_grid_motion.hpp): where the
// formulation's wrenches break a contact row between the samples, the closest admissible
// distribution of the same total wrench, nothing moved at the samples or where nothing is
// broken, and the energy identity on the wrenches it carries.
#include <catch2/catch.hpp>

#include <optional>

#include "common/test_support.hpp"
#include "core/dynamics_data.hpp"
#include "core/inverse_dynamics.hpp"
#include "core/kinematics.hpp"
#include "outer_nlp/contact_admissibility.hpp"
#include "outer_nlp/energy_balance.hpp"
#include "outer_nlp/fine_grid_motion.hpp"
#include "outer_nlp/motion_problem.hpp"
#include "outer_nlp/motion_verification.hpp"

namespace mcopt {

namespace {

constexpr int kInstants = 8;  // instants per sample interval

/// Each active contact's wrench at instant s as a world wrench about the world origin, summed.
Vector6 totalWrench(const MotionProblem& fine, const SampledPhysics& p, Eigen::Index s) {
  const Scenario& scenario = fine.scenario();
  DynamicsData data(fine.model());
  inverseDynamics(fine.model(), data, p.q.col(s), p.v.col(s), p.a.col(s));
  Vector6 total = Vector6::Zero();
  for (std::size_t c = 0; c < p.contactNames.size(); ++c) {
    if (!p.active[c][static_cast<std::size_t>(s)]) continue;
    const ContactSurface& surface = c == 0 ? scenario.support : scenario.contacts[c - 1].surface;
    const RigidTransform pose = framePose(fine.model(), data, surface.frame) * surface.placement;
    const Vector3 f = pose.rotation * p.wrenches[c].col(s).head<3>();
    total.head<3>() += f;
    total.tail<3>() += pose.rotation * p.wrenches[c].col(s).tail<3>() + pose.translation.cross(f);
  }
  return total;
}

/// The worst broken contact row (bound − row, > 0 where broken) at instant s.
double brokenRow(const Scenario& scenario, const SampledPhysics& p, Eigen::Index s) {
  const double weight = scenario.robot.totalMass() * scenario.gravity.norm();
  double worst = -1e300;
  for (std::size_t c = 0; c < p.contactNames.size(); ++c) {
    if (!p.active[c][static_cast<std::size_t>(s)]) continue;
    const ContactSurface& surface = c == 0 ? scenario.support : scenario.contacts[c - 1].surface;
    const ContactAdmissibilityRows rows(surface, RigidTransform{}, weight, scenario.inner.problem);
    Eigen::VectorXd values(rows.rowCount());
    rows.evaluate(p.wrenches[c].col(s), values);
    values = -values;
    values[0] += scenario.minimumNormalForce;
    worst = std::max(worst, values.maxCoeff());
  }
  return worst;
}

bool isSample(const MotionProblem& problem, double T, double t) {
  for (int k = 0; k < problem.sampleCount(); ++k)
    if (std::abs(problem.sampleTime(k, T) - t) <= 1e-9) return true;
  return false;
}

}  // namespace

TEST_CASE("fine grid: a single-level formulation's wrenches broken between the samples are redistributed, the total kept",
          "[outer][verify][multi-contact]") {
  for (const std::string forces : {"variables", "splines"}) {
    Scenario s = loadScenario(test::sourceDir() / "scenarios/hrp2_weight_shift.yaml");
    s.samples = 8, s.outputSamples = 20, s.forceControlPoints = 6;
    s.contactForces = forces;
    MotionProblem problem(s);
    const Eigen::VectorXd start = problem.initialPoint(s.start, s.end);
    const double T = problem.duration(start);
    const Scenario plainScenario = fineGridScenario(s, kInstants);
    MotionProblem plain(plainScenario, {.hessian = plainScenario.solve.hessian, .derivatives = false});

    // The first spline parameter whose nudge moves the motion enough that the wrenches the
    // formulation holds at the samples (the inner problems' exact optima there) break a contact
    // row between them.
    const int m = problem.parametrization().parametersPerJoint();
    std::optional<Eigen::VectorXd> x;
    for (int j = 0; j < s.robot.jointCount() && !x; ++j)
      for (int l = 2; l + 2 < m && !x; ++l)
        for (const double delta : {0.2, 0.4}) {
          Eigen::VectorXd motion = problem.motionParameters(start);
          motion[j * m + l] += delta;
          const Eigen::VectorXd candidate = problem.pointFromMotion(motion, T);
          if (problem.violations(candidate).of("contact_cop") > 1e-9 || problem.violations(candidate).of("contact_friction") > 1e-9)
            continue;  // broken at a sample: no inner problem could hold it
          const SampledPhysics p = plain.sampledPhysics(plain.pointWithWrenchesFrom(problem, candidate), MotionProblem::ClosureDrift::Skipped);
          for (Eigen::Index k = 0; k < p.time.size() && !x; ++k)
            if (brokenRow(s, p, k) > 1e-3) x = candidate;
          if (x) break;
        }
    INFO(forces);
    REQUIRE(x);

    const SampledPhysics before = plain.sampledPhysics(plain.pointWithWrenchesFrom(problem, *x), MotionProblem::ClosureDrift::Skipped);
    const FineGridMotion fine(problem, *x, kInstants, 1e-6);
    const SampledPhysics& after = fine.physics();
    const WrenchRedistribution& moved = fine.redistribution();
    CHECK(moved.applies);
    CHECK(moved.instants > 0);
    CHECK(moved.unreachable == 0);
    REQUIRE(after.time.size() == before.time.size());
    int changed = 0;
    for (Eigen::Index k = 0; k < after.time.size(); ++k) {
      INFO("t = " << after.time[k]);
      // The motion is the same; every instant's wrenches hold their rows.
      CHECK((after.q.col(k) - before.q.col(k)).cwiseAbs().maxCoeff() <= 1e-12);
      CHECK(brokenRow(s, after, k) <= 1e-9);
      const bool broken = brokenRow(s, before, k) > 1e-6;
      double change = 0.0;
      for (std::size_t c = 0; c < after.contactNames.size(); ++c)
        change = std::max(change, (after.wrenches[c].col(k) - before.wrenches[c].col(k)).cwiseAbs().maxCoeff());
      if (!broken || isSample(problem, T, after.time[k])) {
        CHECK(change <= 1e-9);  // nothing moves where nothing is broken, nor at a sample
        continue;
      }
      ++changed;
      CHECK(change <= moved.largestChange + 1e-12);
      // The same total wrench on the robot: the same dynamics, another split.
      CHECK((totalWrench(fine.problem(), after, k) - totalWrench(plain, before, k)).cwiseAbs().maxCoeff() <= 1e-7);
    }
    CHECK(changed == moved.instants);

    // The closest: no nearer admissible split than the inner problem's at the same instant (the
    // bilevel fine grid's, which holds the same total), and the torques and energy those
    // wrenches give satisfy the mechanical identity.
    Scenario bilevelScenario = plainScenario;
    bilevelScenario.contactForces = "bilevel";
    bilevelScenario.inner.solverName = "active-set";
    MotionProblem bilevel(bilevelScenario, {.hessian = bilevelScenario.solve.hessian, .derivatives = false});
    const SampledPhysics inner = bilevel.sampledPhysics(bilevel.pointFromMotion(problem.motionParameters(*x), T), MotionProblem::ClosureDrift::Skipped);
    for (Eigen::Index k = 0; k < after.time.size(); ++k) {
      double toAfter = 0.0, toInner = 0.0;
      for (std::size_t c = 0; c < after.contactNames.size(); ++c) {
        toAfter += (after.wrenches[c].col(k) - before.wrenches[c].col(k)).squaredNorm();
        toInner += (inner.wrenches[c].col(k) - before.wrenches[c].col(k)).squaredNorm();
      }
      if (brokenRow(s, before, k) > 1e-6 && brokenRow(s, inner, k) <= 1e-9) CHECK(toAfter <= toInner * (1.0 + 1e-9) + 1e-12);
    }
    // A held contact does no work, so the split does not change the joints' work: the identity's
    // residual (the quadrature's, of a motion nudged on 8 samples) is the formulation's own.
    const EnergyBalance b = energyBalanceOf(fine.problem(), fine.physics()), own = energyBalanceOf(plain, before);
    CHECK(b.jointWork == Approx(own.jointWork).epsilon(1e-9).margin(1e-9));
    CHECK(b.mechanicalResidual() == Approx(own.mechanicalResidual()).epsilon(1e-9).margin(1e-9));
    CHECK(b.positiveEnergy != own.positiveEnergy);  // the motors' torques, and their losses, are the new split's
    const EnergyBalance balance = energyBalance(problem, *x, kInstants);
    CHECK(balance.redistribution.instants == moved.instants);
    // The formulation's own account of its wrenches, not the carrier's.
    CHECK(balance.wrenchesBetweenSamples == (forces == "splines" ? "splines" : "linear interpolation"));
    CHECK(verifyMotion(problem, *x, {.instantsPerInterval = kInstants}).wrenchesBetweenSamples == balance.wrenchesBetweenSamples);
  }
}

TEST_CASE("fine grid: bilevel wrenches and a single contact are never redistributed", "[outer][verify]") {
  // The kick (the reference sole alone) and the bilevel weight shift (an inner problem at each instant).
  for (const char* file : {"scenarios/hrp2_kick.yaml", "scenarios/hrp2_weight_shift.yaml"}) {
    Scenario s = loadScenario(test::sourceDir() / file);
    s.samples = 8, s.outputSamples = 20;
    s.solve.continuation.clear();
    MotionProblem problem(s);
    const FineGridMotion fine(problem, problem.initialPoint(s.start, s.end), 4, 1e-6);
    INFO(file);
    CHECK_FALSE(fine.redistribution().applies);
    CHECK(fine.redistribution().instants == 0);
  }
}

}  // namespace mcopt
