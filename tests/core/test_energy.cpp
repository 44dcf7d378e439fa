// SPDX-License-Identifier: BSD-3-Clause
// Electrical power and energy (formulation.md §6).
#include <catch2/catch.hpp>
#include <numbers>

#include "core/actuators.hpp"
#include "core/trajectory_evaluation.hpp"

using namespace mcopt;

TEST_CASE("motor power follows (2.9) with gear ratio, rotor inertia and friction", "[energy]") {
  ActuatorParameters m;
  m.gearRatio = 100;
  m.torqueConstant = 0.03;
  m.resistance = 0.3;
  m.rotorInertia = 1e-5;
  m.viscousFriction = 2e-6;
  m.dryFriction = 0.01;
  const double nu = 50, torque = 12.0, velocity = 0.7, acceleration = -3.0;
  const double omega = 100 * velocity;
  const double friction = 2e-6 * omega + 0.01 * (2 / std::numbers::pi) * std::atan(nu * omega);
  const double motorTorque = torque / 100 + 1e-5 * 100 * acceleration + friction;
  const MotorPower p = motorPower(m, nu, torque, velocity, acceleration);
  CHECK(p.motorTorque == Approx(motorTorque).epsilon(1e-14));
  CHECK(p.power == Approx(motorTorque * omega + 0.3 / (0.03 * 0.03) * motorTorque * motorTorque).epsilon(1e-14));
  // Friction is odd in the speed and approaches Γ_d sign(Ω) as ν grows (the report's (3.8) slip).
  CHECK(frictionTorque(m, -5.0, nu) == Approx(-frictionTorque(m, 5.0, nu)));
  ActuatorParameters dry;
  dry.dryFriction = 0.2;
  CHECK(frictionTorque(dry, 0.1, 1e6) == Approx(0.2).epsilon(1e-4));
  CHECK(frictionTorque(dry, 0.1, 1.0) < 0.02);
}

TEST_CASE("energy integrates max(P, 0) with the trapezoid rule", "[energy]") {
  Eigen::VectorXd time = Eigen::VectorXd::LinSpaced(11, 0.0, 2.0);
  Eigen::MatrixXd power(2, 11);
  power.row(0).setConstant(3.0);   // 3 W for 2 s
  power.row(1).setConstant(-5.0);  // regeneration the supply cannot take
  CHECK(positiveEnergy(power, time) == Approx(6.0).epsilon(1e-14));
  power.row(1) = Eigen::RowVectorXd::LinSpaced(11, 0.0, 10.0);  // ramp: exact under the trapezoid rule
  CHECK(positiveEnergy(power, time) == Approx(6.0 + 10.0).epsilon(1e-14));
}
