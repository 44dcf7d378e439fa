// SPDX-License-Identifier: BSD-3-Clause
// The fact the `exact` Hessian option rests on (outer_nlp/motion_hessian.cpp,
// outer_nlp/derivative_stencil.hpp): in the world frame rooted at the reference body, the
// joint torques Γ0 and the reference wrench W0 — and with them their first derivatives — are
// trigonometric polynomials of degree 2 in each revolute joint's angle (a moved body's inertia
// X* I X⁻¹ is second-degree in cos q, sin q, its velocity and acceleration first-degree),
// quadratic in the velocities and affine in the accelerations. Checked by their spectra: at
// 2K + 1 equally spaced angles the Fourier coefficients above degree 2 vanish, and the
// degree-2 ones do not (the degree is reached, so a stencil of lower degree would be wrong).
#include <catch2/catch.hpp>

#include <cmath>
#include <complex>
#include <random>

#include "common/robots.hpp"
#include "core/dynamics_derivatives.hpp"
#include "core/dynamics_model.hpp"

namespace mcopt {

namespace {

/// Γ0, W0 and their derivatives in q, q̇, q̈ at (q, v, a), as one vector.
Eigen::VectorXd outputsAndDerivatives(const DynamicsModel& model, DynamicsData& data, DynamicsDerivatives& d,
                                      const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd& a) {
  inverseDynamicsDerivatives(model, data, d, q, v, a);
  const Eigen::Index n = q.size();
  Eigen::VectorXd out(n + 6 + 3 * (n + 6) * n);
  out << data.tau, data.referenceWrench, d.dtauDq.reshaped(), d.dtauDv.reshaped(), d.dtauDa.reshaped(),
      d.dwrenchDq.reshaped(), d.dwrenchDv.reshaped(), d.dwrenchDa.reshaped();
  return out;
}

}  // namespace

TEST_CASE("dynamics: trigonometric of degree 2 in each angle, quadratic in q̇, affine in q̈", "[core][dynamics]") {
  std::mt19937 rng(41);
  for (const test::NamedRobot& named : test::allRobots()) {
    const RobotModel robot = test::load(named);
    const DynamicsModel model(robot, robot.bodies.front().name);
    DynamicsData data(model);
    DynamicsDerivatives derivatives(model);
    Eigen::VectorXd q, v, a;
    test::randomState(rng, robot, q, v, a);
    const int n = model.jointCount();
    double reached = 0.0, reachedInV = 0.0;  // the largest degree-2 coefficient and second difference in q̇, relative
    for (int j = 0; j < n; j += std::max(1, n / 8)) {
      if (robot.joints[static_cast<std::size_t>(j)].type == JointType::Prismatic) continue;
      INFO(named.name << ", joint " << robot.joints[static_cast<std::size_t>(j)].name);
      // Angles: the spectrum at 2K + 1 = 9 points holds degrees 0 … 4 without aliasing.
      constexpr int points = 9;
      std::vector<Eigen::VectorXd> samples;
      Eigen::VectorXd probe = q;
      for (int m = 0; m < points; ++m) {
        probe[j] = q[j] + 2.0 * M_PI * m / points;
        samples.push_back(outputsAndDerivatives(model, data, derivatives, probe, v, a));
      }
      const double scale = std::max(1.0, samples.front().cwiseAbs().maxCoeff());
      for (int k = 2; k <= 4; ++k) {
        Eigen::VectorXcd coefficient = Eigen::VectorXcd::Zero(samples.front().size());
        for (int m = 0; m < points; ++m) coefficient += samples[static_cast<std::size_t>(m)].cast<std::complex<double>>() *
                                                        std::polar(1.0 / points, -2.0 * M_PI * k * m / points);
        const double size = coefficient.cwiseAbs().maxCoeff() / scale;
        if (k == 2) reached = std::max(reached, size);
        else CHECK(size < 1e-12);
      }
      // q̇_j: third differences vanish (quadratic), second ones do not (somewhere: a massless
      // finger's are zero); q̈_j: second differences vanish.
      auto along = [&](Eigen::VectorXd& component, double t) {
        const double saved = component[j];
        component[j] = saved + t;
        const Eigen::VectorXd out = outputsAndDerivatives(model, data, derivatives, q, v, a);
        component[j] = saved;
        return out;
      };
      const Eigen::VectorXd third = along(v, 1.5) - 3.0 * along(v, 0.5) + 3.0 * along(v, -0.5) - along(v, -1.5);
      const Eigen::VectorXd second = along(v, 1.0) - 2.0 * along(v, 0.0) + along(v, -1.0);
      CHECK(third.cwiseAbs().maxCoeff() < 1e-11 * scale);
      reachedInV = std::max(reachedInV, second.cwiseAbs().maxCoeff() / scale);
      const Eigen::VectorXd secondInA = along(a, 1.0) - 2.0 * along(a, 0.0) + along(a, -1.0);
      CHECK(secondInA.cwiseAbs().maxCoeff() < 1e-11 * scale);
    }
    INFO(named.name);
    CHECK(reached > 1e-6);
    CHECK(reachedInV > 1e-6);
  }
}

}  // namespace mcopt
