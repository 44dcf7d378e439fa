// SPDX-License-Identifier: BSD-3-Clause
// The exact Hessian's stencils (outer_nlp/derivative_stencil.hpp): exact, to rounding, on
// every polynomial / trigonometric polynomial of their degree (a line for the one-sided
// stencil), at any point and step — and
// wrong one degree above, so that a degree understated in motion_hessian.cpp cannot pass.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "outer_nlp/derivative_stencil.hpp"

namespace mcopt {

namespace {

template <class Function>
double apply(const DerivativeStencil& s, double at, Function&& f) {
  double sum = s.centre * f(at);
  for (int m = 0; m < s.size(); ++m) sum += s.weights[static_cast<std::size_t>(m)] * f(at + s.offsets[static_cast<std::size_t>(m)]);
  return sum;
}

}  // namespace

TEST_CASE("derivative stencils: exact on their degree, not above", "[outer][hessian]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int degree = 1; degree <= 6; ++degree) {
    INFO("degree " << degree);
    const DerivativeStencil poly = polynomialStencil(degree, 0.7), trig = trigonometricStencil(degree);
    const int exactDegree = 2 * ((degree + 1) / 2);  // central differences hold every even degree up to 2M
    for (int trial = 0; trial < 5; ++trial) {
      std::vector<double> c(static_cast<std::size_t>(exactDegree + 2)), s(c.size());
      for (std::size_t k = 0; k < c.size(); ++k) c[k] = u(rng), s[k] = u(rng);
      const double at = 2.0 * u(rng);
      auto polynomial = [&](int top) {
        return [&, top](double x) {
          double value = 0.0;
          for (int k = top; k >= 0; --k) value = value * x + c[static_cast<std::size_t>(k)];
          return value;
        };
      };
      auto polynomialSlope = [&](int top) {
        double slope = 0.0;
        for (int k = top; k >= 1; --k) slope = slope * at + k * c[static_cast<std::size_t>(k)];
        return slope;
      };
      CHECK(apply(poly, at, polynomial(exactDegree)) == Approx(polynomialSlope(exactDegree)).epsilon(1e-11).margin(1e-11));
      CHECK(std::abs(apply(poly, at, polynomial(exactDegree + 1)) - polynomialSlope(exactDegree + 1)) > 1e-6);
      auto trigonometric = [&](int top) {
        return [&, top](double x) {
          double value = c[0];
          for (int k = 1; k <= top; ++k) value += c[static_cast<std::size_t>(k)] * std::cos(k * x) + s[static_cast<std::size_t>(k)] * std::sin(k * x);
          return value;
        };
      };
      auto trigonometricSlope = [&](int top) {
        double slope = 0.0;
        for (int k = 1; k <= top; ++k) slope += k * (s[static_cast<std::size_t>(k)] * std::cos(k * at) - c[static_cast<std::size_t>(k)] * std::sin(k * at));
        return slope;
      };
      CHECK(apply(trig, at, trigonometric(degree)) == Approx(trigonometricSlope(degree)).epsilon(1e-12).margin(1e-12));
      CHECK(std::abs(apply(trig, at, trigonometric(degree + 1)) - trigonometricSlope(degree + 1)) > 1e-6);
    }
  }
  // The one-sided stencil of the affine directions (q̈, force variables): exact on a line at
  // any step, wrong on a parabola.
  for (const double step : {0.3, 1.0, 4.0}) {
    const DerivativeStencil affine = affineStencil(step);
    const double at = 0.8;
    CHECK(apply(affine, at, [](double x) { return 2.5 - 1.75 * x; }) == Approx(-1.75).epsilon(1e-14));
    CHECK(std::abs(apply(affine, at, [](double x) { return 2.5 - 1.75 * x + 0.5 * x * x; }) - (-1.75 + at)) > 1e-3);
  }
  CHECK_THROWS(affineStencil(0.0));
  CHECK_THROWS(polynomialStencil(0, 1.0));
  CHECK_THROWS(polynomialStencil(2, 0.0));
  CHECK_THROWS(trigonometricStencil(0));
}

}  // namespace mcopt
