// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Rigid transforms and rotation helpers shared by the whole project.
// Rotations are matrices internally (formulation.md §1); files use quaternions
// written [x, y, z, w] or URDF roll-pitch-yaw, converted here.

#include <algorithm>
#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace mcopt {

using Vector3 = Eigen::Vector3d;
using Matrix3 = Eigen::Matrix3d;
using Vector6 = Eigen::Matrix<double, 6, 1>;

/// Pose of frame B in frame A: x_A = rotation * x_B + translation.
struct RigidTransform {
  Matrix3 rotation = Matrix3::Identity();
  Vector3 translation = Vector3::Zero();

  static RigidTransform identity() { return {}; }

  /// (A←B) * (B←C) = (A←C).
  RigidTransform operator*(const RigidTransform& other) const {
    return {rotation * other.rotation, rotation * other.translation + translation};
  }
  RigidTransform inverse() const {
    return {rotation.transpose(), -(rotation.transpose() * translation)};
  }
  Vector3 apply(const Vector3& point) const { return rotation * point + translation; }
  bool isIdentity(double tolerance = 0.0) const {
    return (rotation - Matrix3::Identity()).cwiseAbs().maxCoeff() <= tolerance &&
           translation.cwiseAbs().maxCoeff() <= tolerance;
  }
};

/// Rotation by `angle` about the unit vector `axis` (Rodrigues).
inline Matrix3 rotationAboutAxis(const Vector3& axis, double angle) {
  const double s = std::sin(angle);
  const double c = std::cos(angle);
  Matrix3 skew;
  skew << 0, -axis.z(), axis.y(), axis.z(), 0, -axis.x(), -axis.y(), axis.x(), 0;
  return Matrix3::Identity() + s * skew + (1.0 - c) * (skew * skew);
}

/// URDF roll-pitch-yaw: R = Rz(yaw) Ry(pitch) Rx(roll).
inline Matrix3 rotationFromRpy(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, Vector3::UnitZ()) * Eigen::AngleAxisd(pitch, Vector3::UnitY()) *
          Eigen::AngleAxisd(roll, Vector3::UnitX()))
      .toRotationMatrix();
}

/// The roll, pitch and yaw of `R` (rotationFromRpy's inverse; pitch in [−π/2, π/2]).
inline Vector3 rpyFromRotation(const Matrix3& R) {
  const double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  return Vector3(std::atan2(R(2, 1), R(2, 2)), pitch, std::atan2(R(1, 0), R(0, 0)));
}

/// Quaternion given as [x, y, z, w]; it is normalised (a zero quaternion is rejected by callers).
inline Matrix3 rotationFromQuaternionXyzw(double x, double y, double z, double w) {
  return Eigen::Quaterniond(w, x, y, z).normalized().toRotationMatrix();
}

inline Eigen::Vector4d quaternionXyzwFromRotation(const Matrix3& rotation) {
  const Eigen::Quaterniond q(rotation);
  return {q.x(), q.y(), q.z(), q.w()};
}

inline Matrix3 skew(const Vector3& v) {
  Matrix3 m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

}  // namespace mcopt
