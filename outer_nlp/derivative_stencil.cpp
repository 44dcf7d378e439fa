// SPDX-License-Identifier: BSD-3-Clause
// Derivative stencils exact on polynomials and trigonometric polynomials of a given degree
// (derivative_stencil.hpp). Both are antisymmetric, d_{−m} = −d_m: the even part of f
// contributes nothing, and the weights solve the K × K system for the odd basis functions.
#include "outer_nlp/derivative_stencil.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <stdexcept>

namespace mcopt {

namespace {

/// Offsets ±o_m and weights ±d_m from the positive offsets o and the half weights d.
DerivativeStencil antisymmetric(const Eigen::VectorXd& offsets, const Eigen::VectorXd& halfWeights) {
  DerivativeStencil s;
  for (Eigen::Index m = 0; m < offsets.size(); ++m) {
    s.offsets.push_back(offsets[m]), s.weights.push_back(halfWeights[m]);
    s.offsets.push_back(-offsets[m]), s.weights.push_back(-halfWeights[m]);
  }
  return s;
}

}  // namespace

DerivativeStencil polynomialStencil(int degree, double step) {
  if (degree < 1) throw std::invalid_argument("polynomialStencil: degree must be at least 1");
  if (!(step > 0.0)) throw std::invalid_argument("polynomialStencil: step must be positive");
  const int M = (degree + 1) / 2;
  // Σ_m 2 d_m (m h)^p = [p = 1] for the odd powers p = 1, 3, …, 2M − 1.
  Eigen::MatrixXd A(M, M);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(M), offsets(M);
  for (int m = 0; m < M; ++m) offsets[m] = (m + 1) * step;
  for (int r = 0; r < M; ++r)
    for (int m = 0; m < M; ++m) A(r, m) = 2.0 * std::pow(offsets[m], 2 * r + 1);
  rhs[0] = 1.0;
  return antisymmetric(offsets, A.fullPivLu().solve(rhs));
}

DerivativeStencil affineStencil(double step) {
  if (!(step > 0.0)) throw std::invalid_argument("affineStencil: step must be positive");
  DerivativeStencil s;
  s.offsets = {step}, s.weights = {1.0 / step}, s.centre = -1.0 / step;
  return s;
}

DerivativeStencil trigonometricStencil(int degree) {
  if (degree < 1) throw std::invalid_argument("trigonometricStencil: degree must be at least 1");
  const int K = degree;
  const double h = 2.0 * std::acos(-1.0) / (2 * K + 1);
  // Σ_m 2 d_m sin(k m h) = k for k = 1 … K (the cosines are even: they vanish).
  Eigen::MatrixXd A(K, K);
  Eigen::VectorXd rhs(K), offsets(K);
  for (int m = 0; m < K; ++m) offsets[m] = (m + 1) * h;
  for (int k = 1; k <= K; ++k) {
    rhs[k - 1] = k;
    for (int m = 0; m < K; ++m) A(k - 1, m) = 2.0 * std::sin(k * offsets[m]);
  }
  return antisymmetric(offsets, A.fullPivLu().solve(rhs));
}

}  // namespace mcopt
