// SPDX-License-Identifier: BSD-3-Clause
// Clamped cubic B-splines (formulation.md §3): basis properties, derivatives against
// central differences, rest at both ends, continuous limits through control points,
// local parameter weights.
#include <catch2/catch.hpp>

#include "common/test_support.hpp"
#include "core/bspline.hpp"

using namespace mcopt;

TEST_CASE("basis: partition of unity, four non-zero functions, derivatives match differences", "[spline]") {
  for (int n : {7, 9, 12}) {
    const BSplineBasis basis(n);
    for (double u = 0.0; u <= 1.0; u += 0.0137) {
      const LocalBasis b = basis.evaluate(u);
      REQUIRE(b.first >= 0);
      REQUIRE(b.first + 3 < n);
      double sum = 0, sum1 = 0, sum2 = 0;
      for (int i = 0; i < 4; ++i) sum += b.value[i], sum1 += b.d1[i], sum2 += b.d2[i];
      CHECK(sum == Approx(1.0).margin(1e-14));
      CHECK(sum1 == Approx(0.0).margin(1e-11));
      CHECK(sum2 == Approx(0.0).margin(1e-9));
      // Central differences of the full basis vector (away from knots, where d2 jumps).
      const double h = 1e-6;
      if (u < 2 * h || u > 1 - 2 * h) continue;
      auto full = [&](double x, int order) {
        Eigen::VectorXd out = Eigen::VectorXd::Zero(n);
        const LocalBasis l = basis.evaluate(x);
        for (int i = 0; i < 4; ++i) out[l.first + i] = order == 0 ? l.value[i] : l.d1[i];
        return out;
      };
      Eigen::VectorXd value = Eigen::VectorXd::Zero(n), d1 = value, d2 = value;
      for (int i = 0; i < 4; ++i) value[b.first + i] = b.value[i], d1[b.first + i] = b.d1[i], d2[b.first + i] = b.d2[i];
      const double spans = n - 3;
      const bool nearKnot = std::abs(u * spans - std::round(u * spans)) < 1e-4;
      CHECK(test::scaledError((full(u + h, 0) - full(u - h, 0)) / (2 * h), d1) <= 1e-7);
      if (!nearKnot) CHECK(test::scaledError((full(u + h, 1) - full(u - h, 1)) / (2 * h), d2) <= 1e-6);
    }
  }
}

TEST_CASE("trajectories rest at both ends and follow their parameters", "[spline]") {
  std::mt19937 rng(3);
  const MotionParametrization p(4, 9);
  CHECK(p.parametersPerJoint() == 5);
  const SampledTrajectory samples(p, 50);
  const Eigen::VectorXd x = test::randomVector(rng, p.parameterCount(), 1.0);
  Eigen::MatrixXd points;
  p.controlPoints(x, points);
  Eigen::VectorXd q(4), v(4), a(4);
  const double T = 1.7;
  samples.evaluate(0, points, T, q, v, a);
  for (int j = 0; j < 4; ++j) CHECK(q[j] == Approx(x[j * 5]).margin(1e-14));
  CHECK(v.cwiseAbs().maxCoeff() <= 1e-12);
  CHECK(a.cwiseAbs().maxCoeff() <= 1e-10);
  samples.evaluate(49, points, T, q, v, a);
  for (int j = 0; j < 4; ++j) CHECK(q[j] == Approx(x[j * 5 + 4]).margin(1e-14));
  CHECK(v.cwiseAbs().maxCoeff() <= 1e-12);
  CHECK(a.cwiseAbs().maxCoeff() <= 1e-10);
}

TEST_CASE("position and velocity stay within their control points over the whole motion", "[spline]") {
  std::mt19937 rng(5);
  const MotionParametrization p(3, 9);
  const SampledTrajectory fine(p, 2001);
  const Eigen::VectorXd x = test::randomVector(rng, p.parameterCount(), 1.0);
  Eigen::MatrixXd points, velocityPoints;
  const double T = 0.8;
  p.controlPoints(x, points);
  p.velocityControlPoints(points, T, velocityPoints);
  Eigen::VectorXd q(3), v(3), a(3);
  double maxVelocity = 0.0;
  for (int s = 0; s < fine.sampleCount(); ++s) {
    fine.evaluate(s, points, T, q, v, a);
    for (int j = 0; j < 3; ++j) {
      CHECK(q[j] <= points.row(j).maxCoeff() + 1e-12);
      CHECK(q[j] >= points.row(j).minCoeff() - 1e-12);
      CHECK(v[j] <= velocityPoints.row(j).maxCoeff() + 1e-12);
      CHECK(v[j] >= velocityPoints.row(j).minCoeff() - 1e-12);
      maxVelocity = std::max(maxVelocity, std::abs(v[j]));
    }
  }
  CHECK(maxVelocity > 0.1);  // the motion really moves
}

TEST_CASE("local parameter weights are the derivatives of q, dq/du, d²q/du² w.r.t. the parameters", "[spline]") {
  std::mt19937 rng(9);
  const MotionParametrization p(1, 9);
  const SampledTrajectory samples(p, 37);
  Eigen::VectorXd x = test::randomVector(rng, p.parameterCount(), 1.0);
  const double T = 1.3, h = 1e-6;
  Eigen::MatrixXd points;
  Eigen::VectorXd q(1), v(1), a(1), qp(1), vp(1), ap(1), qm(1), vm(1), am(1);
  for (int s = 0; s < samples.sampleCount(); ++s) {
    const LocalParameterWeights& w = samples.weights(s);
    Eigen::Vector3d fromWeights[5];
    for (auto& e : fromWeights) e.setZero();
    for (int k = 0; k < w.count; ++k)
      fromWeights[w.parameter[k]] = Eigen::Vector3d(w.value[k], w.d1[k] / T, w.d2[k] / (T * T));
    for (int k = 0; k < p.parameterCount(); ++k) {
      const double saved = x[k];
      x[k] = saved + h;
      p.controlPoints(x, points);
      samples.evaluate(s, points, T, qp, vp, ap);
      x[k] = saved - h;
      p.controlPoints(x, points);
      samples.evaluate(s, points, T, qm, vm, am);
      x[k] = saved;
      const Eigen::Vector3d fd((qp[0] - qm[0]) / (2 * h), (vp[0] - vm[0]) / (2 * h), (ap[0] - am[0]) / (2 * h));
      CHECK(test::scaledError(fromWeights[k], fd) <= 1e-7);
    }
  }
}
