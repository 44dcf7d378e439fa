// SPDX-License-Identifier: BSD-3-Clause
// The throw (formulation.md §10, issue 15): the ballistic flight's exact gradients and Hessians, the
// throw rows and the carried ball through the whole outer problem against central
// differences (fixed and free duration, so fixed and free release time; double and single
// support), and the ball's load: Γ with the ball is Γ without it plus Jᵀ m (p̈ − g), until the
// release and not after.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <random>

#include "common/finite_differences.hpp"
#include "common/nlp_jacobian.hpp"
#include "common/perturbed_motion.hpp"
#include "common/test_support.hpp"
#include "core/inverse_dynamics.hpp"
#include "core/kinematics.hpp"
#include "core/trajectory_evaluation.hpp"
#include "outer_nlp/ballistic_flight.hpp"
#include "outer_nlp/motion_problem.hpp"

namespace mcopt {

namespace {

/// The bundled throw on a coarser grid (t_r = 1.2 s of 2.0 s stays a sample: u = 0.6).
Scenario throwScenario(int samples) {
  Scenario s = loadScenario(test::sourceDir() / "scenarios/hrp2_throw.yaml");
  s.samples = samples;
  s.outputSamples = 20;
  s.solve.continuation.clear();
  return s;
}

/// The support sole alone (Γ = Γ0): the right sole's contact and its closure rows removed.
void singleSupport(Scenario& s) {
  s.contacts.clear();
  s.tasks.erase(std::remove_if(s.tasks.begin(), s.tasks.end(), [](const TaskSpec& t) { return t.closure; }), s.tasks.end());
}

Eigen::Matrix<double, 9, 1> flightValues(const Eigen::Matrix<double, 6, 1>& pv, double height, double g) {
  const BallisticFlight f = ballisticFlight(pv.head<3>(), pv.tail<3>(), height, g);
  Eigen::Matrix<double, 9, 1> out;
  out << f.flightTime, f.landing, f.apexAboveTarget, f.speed, f.elevation, 0, 0, 0;
  return out;
}

/// The world position of a point of a frame, by forward kinematics alone.
Vector3 pointPosition(const DynamicsModel& model, const Eigen::VectorXd& q, int frame, const Vector3& point) {
  DynamicsData data(model);
  forwardKinematics(model, data, q);
  const RigidTransform pose = framePose(model, data, frame);
  return pose.rotation * point + pose.translation;
}

}  // namespace

TEST_CASE("ballistic flight: it crosses the target's height at the landing point, with exact gradients and Hessians",
          "[outer][throw]") {
  std::mt19937 random(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double g = 9.81;
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::Matrix<double, 6, 1> pv;
    pv << u(random), u(random), 1.0 + 0.5 * u(random), 3.0 * u(random), 3.0 * u(random), 3.0 * u(random);
    const double height = 0.3 * u(random);
    const BallisticFlight f = ballisticFlight(pv.head<3>(), pv.tail<3>(), height, g);
    // The flight p + v τ + ½ g τ² at τ: at the target's height, at the landing point, descending.
    const Vector3 at = pv.head<3>() + pv.tail<3>() * f.flightTime + 0.5 * Vector3(0, 0, -g) * f.flightTime * f.flightTime;
    CHECK(f.flightTime > 0.0);
    CHECK(std::abs(at.z() - height) < 1e-12);
    CHECK((at.head<2>() - f.landing).norm() < 1e-12);
    CHECK(pv[5] - g * f.flightTime < 0.0);
    // Gradients against central differences.
    Eigen::VectorXd x = pv;
    const Eigen::MatrixXd fd = test::centralDifferences(x, 1e-6, [&] {
      return Eigen::VectorXd(flightValues(x, height, g));
    });
    Eigen::MatrixXd exact(6, 6);
    exact << f.flightTimeGradient, f.landingGradient, f.apexGradient, f.speedGradient, f.elevationGradient;
    INFO("trial " << trial);
    CHECK(test::scaledError(exact, fd.topRows(6)) < 1e-7);
    // Hessians against central differences of the exact gradients.
    const std::array<const Matrix6*, 6> hessians{&f.flightTimeHessian, &f.landingHessian[0], &f.landingHessian[1],
                                                 &f.apexHessian, &f.speedHessian, &f.elevationHessian};
    const Eigen::MatrixXd dGradient = test::centralDifferences(x, 1e-6, [&] {
      Eigen::MatrixXd gradients(6, 6);
      const BallisticFlight probe = ballisticFlight(x.head<3>(), x.tail<3>(), height, g);
      gradients << probe.flightTimeGradient, probe.landingGradient, probe.apexGradient, probe.speedGradient,
          probe.elevationGradient;
      return Eigen::VectorXd(gradients.transpose().reshaped());  // quantity k's gradient at 6 k .. 6 k + 5
    });
    for (int k = 0; k < 6; ++k) {
      INFO("quantity " << k);
      const Matrix6& hessian = *hessians[static_cast<std::size_t>(k)];
      CHECK((hessian - hessian.transpose()).norm() <= 1e-14 * (1.0 + hessian.norm()));
      CHECK(test::scaledError(hessian, dGradient.middleRows(6 * k, 6)) < 1e-7);
    }
  }
  // A ball that never reaches the target's height: the apex row is negative, τ the apex's.
  const BallisticFlight low = ballisticFlight(Vector3(0, 0, 1.0), Vector3(1.0, 0, 0.5), 2.0, g);
  CHECK(low.apexAboveTarget < 0.0);
  CHECK(low.flightTime == Approx(0.5 / g));
}

TEST_CASE("throw: the ball's load is Jᵀ m (p̈ − g) at its point", "[outer][throw]") {
  const Scenario s = throwScenario(11);
  const ThrownBall& ball = *s.ball;
  const DynamicsModel bare(s.robot, s.referenceBody, s.referencePose, s.gravity);
  const DynamicsModel loaded(withPointMass(s.robot, ball.frame, ball.point, ball.mass), s.referenceBody, s.referencePose,
                             s.gravity);
  std::mt19937 random(11);
  const int n = bare.jointCount();
  for (int trial = 0; trial < 3; ++trial) {
    const Eigen::VectorXd q = s.start + test::randomVector(random, n, 0.3);
    const Eigen::VectorXd v = test::randomVector(random, n, 1.0), a = test::randomVector(random, n, 2.0);
    DynamicsData withBall(loaded), without(bare);
    inverseDynamics(loaded, withBall, q, v, a);
    inverseDynamics(bare, without, q, v, a);
    // p̈ by central differences of the point's position along q(t) = q + v t + ½ a t².
    const double h = 1e-4;
    auto at = [&](double t) { return pointPosition(bare, Eigen::VectorXd(q + v * t + 0.5 * a * t * t), ball.frame, ball.point); };
    const Vector3 acceleration = (at(h) - 2.0 * at(0.0) + at(-h)) / (h * h);
    // J by central differences of the position in q.
    Eigen::VectorXd probe = q;
    const Eigen::MatrixXd J = test::centralDifferences(probe, 1e-6, [&] {
      return Eigen::VectorXd(pointPosition(bare, probe, ball.frame, ball.point));
    });
    const Eigen::VectorXd expected = J.transpose() * (ball.mass * (acceleration - s.gravity));
    INFO("trial " << trial << ": largest difference " << (withBall.tau - without.tau - expected).cwiseAbs().maxCoeff());
    CHECK((withBall.tau - without.tau - expected).cwiseAbs().maxCoeff() < 1e-5 * (1.0 + expected.cwiseAbs().maxCoeff()));
  }
}

TEST_CASE("throw: the release sample is evaluated loaded and released, and the ball is dropped there", "[outer][throw]") {
  Scenario s = throwScenario(11);
  singleSupport(s);  // Γ = Γ0, no inner problem: the loads are the dynamics'
  MotionProblem problem(s);
  REQUIRE(problem.sampleCount() == 12);
  const Eigen::VectorXd x = test::perturbedMotion(problem, 0.05, 5);
  const SampledPhysics p = problem.sampledPhysics(x);
  // Samples 0..6 carry the ball (the sixth twice: 1.2 s), 7.. do not.
  CHECK(p.time[6] == Approx(1.2));
  CHECK(p.time[7] == p.time[6]);
  for (int k = 0; k < problem.sampleCount(); ++k) CHECK(problem.sampleCarriesBall(k) == (k <= 6));
  CHECK(p.q.col(6) == p.q.col(7));
  const ThrownBall& ball = *s.ball;
  const DynamicsModel bare(s.robot, s.referenceBody, s.referencePose, s.gravity);
  const DynamicsModel loaded(withPointMass(s.robot, ball.frame, ball.point, ball.mass), s.referenceBody, s.referencePose,
                             s.gravity);
  for (int k = 0; k < problem.sampleCount(); ++k) {
    const DynamicsModel& model = k <= 6 ? loaded : bare;
    DynamicsData data(model);
    inverseDynamics(model, data, p.q.col(k), p.v.col(k), p.a.col(k));
    INFO("sample " << k);
    CHECK((p.tau.col(k) - data.tau).cwiseAbs().maxCoeff() < 1e-9);
  }
  // The ball's load differs between the two evaluations at t_r.
  CHECK((p.tau.col(6) - p.tau.col(7)).cwiseAbs().maxCoeff() > 1e-3);
  // The energy integrates each side of the release over its own half interval: the trapezoid
  // over the sample times (t_r twice) is the problem's objective with the smooth maximum's ε → 0.
  s.smoothing = 1e-9;
  MotionProblem sharp(s);
  CHECK(sharp.objective(x) == Approx(positiveEnergy(p.power, p.time)).epsilon(1e-7));
}

TEST_CASE("throw: exact derivatives of the throw rows and the carried ball, fixed and free release time",
          "[outer][throw]") {
  for (const bool doubleSupport : {true, false}) {
    for (const bool freeDuration : {false, true}) {
#ifdef MCOPT_UNDER_SANITIZERS
      if (doubleSupport && !freeDuration) continue;  // three of the four cases; Release runs all
#endif
      Scenario s = throwScenario(11);
      if (!doubleSupport) singleSupport(s);
      s.fixStart = s.fixEnd = false;
      // Every optional row bounded, so that each is in the Jacobian.
      for (TaskSpec& t : s.tasks) {
        if (t.task->kind() == "throw_landing") t.lower[2] = 0.1, t.upper[2] = 2.0;
        if (t.task->kind() == "throw_release") t.lower.head<2>() << 1.0, -0.5, t.upper.head<2>() << 9.0, 1.2;
      }
      // With a free duration the release t_r = 0.6 T moves with it: a free release time.
      if (freeDuration) s.duration.lower = 1.5, s.duration.upper = 3.0;
      MotionProblem problem(s);
      Eigen::VectorXd x = test::perturbedMotion(problem, 0.02, 9);
      if (freeDuration) x[problem.parametrization().parameterCount()] = 2.3;
      // Every inner problem feasible: an infeasible sample's torques have no optimum to
      // differentiate (its φ row does; test_multi_contact_problem.cpp).
      Eigen::VectorXd g;
      problem.constraints(x, g);
      REQUIRE(problem.infeasibleSamples() == 0);
      // Double support: at 1e-6 the truncation error of the differences reaches 4e-6 on a sample
      // whose inner optimum is strongly curved in T (1e-5: 4e-4, O(h²)), and the right sole,
      // held by the closure (closed_chains.hpp), puts rounding noise of about 1e-12 on the
      // outputs that a step of 1e-7 reads as 2e-6: differences at 4e-6 and 2e-6, extrapolated
      // (O(h⁴)). Single support, 1e-6 (at 1e-7 round-off reaches 1.1e-6).
      const test::DerivativeErrors e =
          doubleSupport ? test::derivativeErrors(problem, x, 4e-6, true) : test::derivativeErrors(problem, x, 1e-6);
      INFO((doubleSupport ? "double support" : "single support") << (freeDuration ? ", free T and t_r" : "")
                                                                  << ": gradient " << e.gradient << ", Jacobian "
                                                                  << e.jacobian << ", off the pattern " << e.offPattern);
      CHECK(e.gradient < 1e-6);
      CHECK(e.jacobian < 1e-6);
      CHECK(e.offPattern < 1e-6);
    }
  }
}

}  // namespace mcopt
