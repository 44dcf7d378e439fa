// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The smooth maximum P⁺ ≈ (P + sqrt(P² + ε²)) / 2 of the energy criterion its slope and its curvature
// (formulation.md §6): one definition for the objective, its gradient and its Hessian.
#include <cmath>

namespace mcopt {

inline double smoothMaximum(double p, double epsilon) { return 0.5 * (p + std::sqrt(p * p + epsilon * epsilon)); }
inline double smoothMaximumSlope(double p, double epsilon) {
  return 0.5 * (1.0 + p / std::sqrt(p * p + epsilon * epsilon));
}

inline double smoothMaximumCurvature(double p, double epsilon) {
  const double root = std::sqrt(p * p + epsilon * epsilon);
  return 0.5 * epsilon * epsilon / (root * root * root);
}

}  // namespace mcopt
