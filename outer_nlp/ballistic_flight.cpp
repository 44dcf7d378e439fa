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

  // τ = (v_z + √D)/g: ∂τ/∂p_z = 1/√D, ∂τ/∂v_z = (1 + v_z/√D)/g. Below the apex (D ≤ 0)
  // the ball is taken at the apex, τ = v_z/g (the row apex ≥ 0 brings it back).
  const double root = std::sqrt(std::max(D, 0.0));
  f.flightTime = (v.z() + root) / g;
  f.flightTimeGradient.setZero();
  f.flightTimeGradient[5] = 1.0 / g;
  if (root > 0.0) {
    f.flightTimeGradient[2] = 1.0 / root;
    f.flightTimeGradient[5] += v.z() / (root * g);
  }

  // L = p_xy + v_xy τ.
  f.landing = p.head<2>() + v.head<2>() * f.flightTime;
  f.landingGradient.setZero();
  f.landingGradient(0, 0) = f.landingGradient(1, 1) = 1.0;
  f.landingGradient(0, 3) = f.landingGradient(1, 4) = f.flightTime;
  f.landingGradient.row(0) += v.x() * f.flightTimeGradient;
  f.landingGradient.row(1) += v.y() * f.flightTimeGradient;

  f.speed = v.norm();
  f.speedGradient.setZero();
  if (f.speed > 0.0) f.speedGradient.tail<3>() = v.transpose() / f.speed;

  // elevation = atan2(v_z, r), r = |v_xy|: ∂/∂v_z = r/|v|², ∂/∂v_xy = −v_z v_xy/(r |v|²).
  const double r = v.head<2>().norm(), speed2 = f.speed * f.speed;
  f.elevation = std::atan2(v.z(), r);
  f.elevationGradient.setZero();
  if (speed2 > 0.0) {
    f.elevationGradient[5] = r / speed2;
    if (r > 0.0) f.elevationGradient.segment<2>(3) = -v.z() * v.head<2>().transpose() / (r * speed2);
  }
  return f;
}

}  // namespace mcopt
