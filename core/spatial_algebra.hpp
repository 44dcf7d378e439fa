#pragma once
// 6-D spatial algebra at the world origin (formulation.md §4): motion vectors (v_O, ω),
// force vectors (f, n_O), both linear part first.

#include "core/spatial.hpp"

namespace mcopt {

using Matrix6 = Eigen::Matrix<double, 6, 6>;

// The products below run thousands of times a sample; GCC otherwise keeps some out of line
// (measured: 13 % of the gradient's instructions were call overhead).
#define MCOPT_ALWAYS_INLINE [[gnu::always_inline]] inline

/// Motion cross product: (v, ω) × (u, η) = (ω × u + v × η, ω × η).
MCOPT_ALWAYS_INLINE Vector6 motionCross(const Vector6& m, const Vector6& x) {
  Vector6 out;
  out.head<3>() = m.tail<3>().cross(x.head<3>()) + m.head<3>().cross(x.tail<3>());
  out.tail<3>() = m.tail<3>().cross(x.tail<3>());
  return out;
}

/// Force cross product: (v, ω) ×* (f, n) = (ω × f, v × f + ω × n).
MCOPT_ALWAYS_INLINE Vector6 forceCross(const Vector6& m, const Vector6& f) {
  Vector6 out;
  out.head<3>() = m.tail<3>().cross(f.head<3>());
  out.tail<3>() = m.head<3>().cross(f.head<3>()) + m.tail<3>().cross(f.tail<3>());
  return out;
}

/// crm(m): the matrix of x ↦ m × x (motion cross product).
inline Matrix6 motionCrossMatrix(const Vector6& m) {
  Matrix6 out = Matrix6::Zero();
  out.topLeftCorner<3, 3>() = skew(m.tail<3>());
  out.topRightCorner<3, 3>() = skew(m.head<3>());
  out.bottomRightCorner<3, 3>() = skew(m.tail<3>());
  return out;
}

/// crf(m) = −crm(m)ᵀ: the matrix of f ↦ m ×* f.
inline Matrix6 forceCrossMatrix(const Vector6& m) {
  Matrix6 out = Matrix6::Zero();
  out.topLeftCorner<3, 3>() = skew(m.tail<3>());
  out.bottomLeftCorner<3, 3>() = skew(m.head<3>());
  out.bottomRightCorner<3, 3>() = skew(m.tail<3>());
  return out;
}

/// B(h): the matrix of x ↦ x ×* h for a fixed force h = (f, n): [[0, −f×], [−f×, −n×]].
inline Matrix6 forceCrossByMatrix(const Vector6& h) {
  Matrix6 out = Matrix6::Zero();
  out.topRightCorner<3, 3>() = -skew(h.head<3>());
  out.bottomLeftCorner<3, 3>() = -skew(h.head<3>());
  out.bottomRightCorner<3, 3>() = -skew(h.tail<3>());
  return out;
}

/// Spatial inertia at the world origin of a body of mass m, com c (world) and rotational
/// inertia about the com in world axes: maps (a_O, α) to (f, n_O).
inline Matrix6 spatialInertia(double mass, const Vector3& com, const Matrix3& inertiaAboutCom) {
  const Matrix3 c = skew(com);
  Matrix6 inertia;
  inertia.topLeftCorner<3, 3>() = mass * Matrix3::Identity();
  inertia.topRightCorner<3, 3>() = -mass * c;
  inertia.bottomLeftCorner<3, 3>() = mass * c;
  inertia.bottomRightCorner<3, 3>() = inertiaAboutCom - mass * c * c;
  return inertia;
}

/// Wrench (f, n) about point p moved to the world origin: (f, n + p × f).
inline Vector6 wrenchAtOrigin(const Vector6& wrenchAtPoint, const Vector3& point) {
  Vector6 out = wrenchAtPoint;
  out.tail<3>() += point.cross(wrenchAtPoint.head<3>());
  return out;
}

}  // namespace mcopt
