// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// 6-D spatial algebra at the world origin (formulation.md §4): motion vectors (v_O, ω),
// force vectors (f, n_O), both linear part first.

#include "core/spatial.hpp"

namespace mcopt {

using Matrix6 = Eigen::Matrix<double, 6, 6>;

// The products below run thousands of times a sample; GCC otherwise keeps some out of line
// (measured: 13 % of the gradient's instructions were call overhead).
#define MCOPT_ALWAYS_INLINE [[gnu::always_inline]] inline

/// a × b written out. Eigen's cross() on blocks of 6-vectors is left out of line by GCC 12 at
/// -O3 (measured: a call per product, a fifth of the derivatives' instructions).
template <typename A, typename B>
MCOPT_ALWAYS_INLINE Vector3 cross3(const Eigen::MatrixBase<A>& a, const Eigen::MatrixBase<B>& b) {
  const double a0 = a.coeff(0), a1 = a.coeff(1), a2 = a.coeff(2);
  const double b0 = b.coeff(0), b1 = b.coeff(1), b2 = b.coeff(2);
  return Vector3(a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0);
}

/// Motion cross product: (v, ω) × (u, η) = (ω × u + v × η, ω × η).
MCOPT_ALWAYS_INLINE Vector6 motionCross(const Vector6& m, const Vector6& x) {
  Vector6 out;
  out.head<3>() = cross3(m.tail<3>(), x.head<3>()) + cross3(m.head<3>(), x.tail<3>());
  out.tail<3>() = cross3(m.tail<3>(), x.tail<3>());
  return out;
}

/// Force cross product: (v, ω) ×* (f, n) = (ω × f, v × f + ω × n).
MCOPT_ALWAYS_INLINE Vector6 forceCross(const Vector6& m, const Vector6& f) {
  Vector6 out;
  out.head<3>() = cross3(m.tail<3>(), f.head<3>());
  out.tail<3>() = cross3(m.head<3>(), f.head<3>()) + cross3(m.tail<3>(), f.tail<3>());
  return out;
}

/// Wrench (f, n) about point p moved to the world origin: (f, n + p × f).
inline Vector6 wrenchAtOrigin(const Vector6& wrenchAtPoint, const Vector3& point) {
  Vector6 out = wrenchAtPoint;
  out.tail<3>() += point.cross(wrenchAtPoint.head<3>());
  return out;
}

}  // namespace mcopt
