// SPDX-License-Identifier: BSD-3-Clause
// URDF roll-pitch-yaw: rpyFromRotation inverts rotationFromRpy (the scenario and contact files
// mcopt writes, `robot init` and `robot check`, rely on it).
#include <catch2/catch.hpp>
#include <numbers>

#include "core/spatial.hpp"

using namespace mcopt;

TEST_CASE("rpy: rpyFromRotation inverts rotationFromRpy, and a half turn about z reads as yaw pi", "[core][spatial]") {
  for (const double roll : {-2.9, -0.7, 0.0, 0.4, 3.0})
    for (const double pitch : {-1.5, -0.3, 0.0, 0.8, 1.5})
      for (const double yaw : {-3.1, -1.0, 0.0, 0.2, 2.5}) {
        const Matrix3 R = rotationFromRpy(roll, pitch, yaw);
        const Vector3 rpy = rpyFromRotation(R);
        INFO(roll << " " << pitch << " " << yaw);
        CHECK((rotationFromRpy(rpy.x(), rpy.y(), rpy.z()) - R).cwiseAbs().maxCoeff() < 1e-12);
        CHECK(rpy.x() == Approx(roll).margin(1e-9));
        CHECK(rpy.y() == Approx(pitch).margin(1e-9));
        CHECK(rpy.z() == Approx(yaw).margin(1e-9));
      }
  const Vector3 half = rpyFromRotation(Matrix3(Eigen::AngleAxisd(std::numbers::pi, Vector3::UnitZ())));
  CHECK(std::abs(half.z()) == Approx(std::numbers::pi));
  CHECK(half.x() == Approx(0.0).margin(1e-12));
  CHECK(half.y() == Approx(0.0).margin(1e-12));
}
