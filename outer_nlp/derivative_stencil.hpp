// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Derivative stencils that are exact — up to rounding, not up to a truncation error — on the
// functions the `exact` Hessian option differentiates (outer_nlp/motion_hessian.cpp;
// docs/theory/outer-problem.md, "Hessian options"): along one state component a sample's
// weighted output gradient is a polynomial of known degree in a velocity, an acceleration or
// a force variable, and a trigonometric polynomial of known degree in a revolute joint's angle
// (rigid motions are first-degree in cos q and sin q).
// f'(0) = centre f(0) + Σ_m weight_m f(offset_m).
#include <vector>

namespace mcopt {

struct DerivativeStencil {
  std::vector<double> offsets, weights;  ///< same size; offset 0 never appears (its weight is `centre`)
  /// The weight of f(0): zero for the central stencils. One f(0) serves every direction of a
  /// point, so a one-sided stencil costs one evaluation a direction where a central one costs two.
  double centre = 0.0;
  int size() const { return static_cast<int>(offsets.size()); }
};

/// The one-sided difference (f(h) − f(0)) / h: exact for every affine function. `step` h > 0;
/// throws std::invalid_argument for h ≤ 0.
DerivativeStencil affineStencil(double step);

/// Central differences at ±h, ±2h, … ±M h with M = ⌈degree / 2⌉ (at least 1): exact for every
/// polynomial of degree ≤ 2M. `step` h > 0 in the variable's unit; any h is exact in exact
/// arithmetic, a larger one loses fewer digits to cancellation. Throws std::invalid_argument
/// for degree < 1 or h ≤ 0.
DerivativeStencil polynomialStencil(int degree, double step);

/// Points at ±2πm/(2K + 1), m = 1 … K, K = degree ≥ 1: exact for every trigonometric polynomial
/// a0 + Σ_{k ≤ K} (a_k cos kθ + b_k sin kθ) (the periodic interpolant's derivative).
DerivativeStencil trigonometricStencil(int degree);

}  // namespace mcopt
