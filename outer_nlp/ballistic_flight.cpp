// SPDX-License-Identifier: BSD-3-Clause
#include "outer_nlp/ballistic_flight.hpp"

#include <algorithm>
#include <cmath>

namespace mcopt {

BallisticFlight ballisticFlight(const Vector3& p, const Vector3& v, double targetHeight, double g) {
  BallisticFlight f;
  const double D = v.z() * v.z() + 2.0 * g * (p.z() - targetHeight);
  f.apexAboveTarget = D / (2.0 * g);
  f.apexGradient.setZero();
  f.apexGradient[2] = 1.0, f.apexGradient[5] = v.z() / g;
  f.apexHessian.setZero();
  f.apexHessian(5, 5) = 1.0 / g;

  // τ = (v_z + √D)/g: ∂τ/∂p_z = 1/√D, ∂τ/∂v_z = (1 + v_z/√D)/g. Below the apex (D ≤ 0)
  // the ball is taken at the apex, τ = v_z/g (the row apex ≥ 0 brings it back).
  const double root = std::sqrt(std::max(D, 0.0));
  f.flightTime = (v.z() + root) / g;
  f.flightTimeGradient.setZero();
  f.flightTimeGradient[5] = 1.0 / g;
  // ∇²τ = ∇²√D / g = (∇²D / (2√D) − ∇D ∇Dᵀ / (4 D^{3/2})) / g, ∇D = (0, 0, 2g, 0, 0, 2v_z),
  // ∇²D = 2 e_vz e_vzᵀ; at the apex τ is linear.
  f.flightTimeHessian.setZero();
  if (root > 0.0) {
    f.flightTimeGradient[2] = 1.0 / root;
    f.flightTimeGradient[5] += v.z() / (root * g);
    Vector6 dD = Vector6::Zero();
    dD[2] = 2.0 * g, dD[5] = 2.0 * v.z();
    f.flightTimeHessian = -dD * dD.transpose() / (4.0 * D * root * g);
    f.flightTimeHessian(5, 5) += 1.0 / (root * g);
  }

  // L = p_xy + v_xy τ.
  f.landing = p.head<2>() + v.head<2>() * f.flightTime;
  f.landingGradient.setZero();
  f.landingGradient(0, 0) = f.landingGradient(1, 1) = 1.0;
  f.landingGradient(0, 3) = f.landingGradient(1, 4) = f.flightTime;
  f.landingGradient.row(0) += v.x() * f.flightTimeGradient;
  f.landingGradient.row(1) += v.y() * f.flightTimeGradient;
  // ∇²L_i = e_vi ∇τᵀ + ∇τ e_viᵀ + v_i ∇²τ.
  for (int i = 0; i < 2; ++i) {
    Matrix6& h = f.landingHessian[static_cast<std::size_t>(i)];
    h = v[i] * f.flightTimeHessian;
    h.row(3 + i) += f.flightTimeGradient;
    h.col(3 + i) += f.flightTimeGradient.transpose();
  }

  f.speed = v.norm();
  f.speedGradient.setZero();
  f.speedHessian.setZero();
  if (f.speed > 0.0) {
    f.speedGradient.tail<3>() = v.transpose() / f.speed;
    // ∇²|v| = (I − v̂ v̂ᵀ) / |v|.
    f.speedHessian.bottomRightCorner<3, 3>() =
        (Matrix3::Identity() - v * v.transpose() / (f.speed * f.speed)) / f.speed;
  }

  // elevation = atan2(v_z, r), r = |v_xy|: ∂/∂v_z = r/|v|², ∂/∂v_xy = −v_z v_xy/(r |v|²).
  const double r = v.head<2>().norm(), speed2 = f.speed * f.speed;
  f.elevation = std::atan2(v.z(), r);
  f.elevationGradient.setZero();
  f.elevationHessian.setZero();
  if (speed2 > 0.0) {
    f.elevationGradient[5] = r / speed2;
    f.elevationHessian(5, 5) = -2.0 * r * v.z() / (speed2 * speed2);
    if (r > 0.0) {
      f.elevationGradient.segment<2>(3) = -v.z() * v.head<2>().transpose() / (r * speed2);
      // Through r: ∂²φ/∂r² = 2 r v_z/|v|⁴, ∂²φ/∂r∂v_z = (v_z² − r²)/|v|⁴, ∂φ/∂r = −v_z/|v|²,
      // with ∇r = v_xy / r and ∇²r = (I − r̂ r̂ᵀ) / r.
      const Eigen::Vector2d dr = v.head<2>() / r;
      f.elevationHessian.block<2, 2>(3, 3) = 2.0 * r * v.z() / (speed2 * speed2) * dr * dr.transpose() -
                                             v.z() / speed2 * (Eigen::Matrix2d::Identity() - dr * dr.transpose()) / r;
      f.elevationHessian.block<2, 1>(3, 5) = (v.z() * v.z() - r * r) / (speed2 * speed2) * dr;
      f.elevationHessian.block<1, 2>(5, 3) = f.elevationHessian.block<2, 1>(3, 5).transpose();
    }
  }
  return f;
}

}  // namespace mcopt
