// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Actuator side file and the electrical power model (formulation.md §2, §4, §6).
//
// Per joint: gear ratio N, torque constant K, winding resistance R, rotor inertia I_m,
// viscous and dry friction on the motor side (μ_v, Γ_d), torque and velocity limits.
// With Ω = N q̇ and a joint torque Γ:
//   Γ_fric = μ_v Ω + Γ_d (2/π) atan(ν Ω)          (3.8), smooth stand-in for Γ_d sign(Ω)
//   Γem    = Γ / N + I_m N q̈ + Γ_fric              motor (electromagnetic) torque
//   P      = Γem Ω + (R / K²) Γem²                 (2.9)

#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/robot_model.hpp"

namespace mcopt {

struct ActuatorParameters {
  double gearRatio = 1.0;          ///< N (joint speed × N = motor speed)
  double torqueConstant = 1.0;     ///< K [N m / A]
  double resistance = 0.0;         ///< R [Ω]
  double rotorInertia = 0.0;       ///< I_m, motor side [kg m²]; reflected as N² I_m on the joint
  double viscousFriction = 0.0;    ///< μ_v, motor side [N m s / rad]
  double dryFriction = 0.0;        ///< Γ_d, motor side [N m]
  double torqueLimit = std::numeric_limits<double>::infinity();    ///< |Γ| on the joint [N m]
  double velocityLimit = std::numeric_limits<double>::infinity();  ///< |q̇| [rad/s]
};

/// Where each value of one joint's ActuatorParameters came from: "default" (the model's
/// neutral value: N = K = 1, R = I_m = 0, no limit), "URDF <limit effort>", "URDF <limit
/// velocity>", "URDF <dynamics damping>", "URDF <dynamics friction>" (joint side, read as motor
/// side), "actuator file defaults" or "actuator file joints.NAME".
struct ActuatorSources {
  std::string gearRatio = "default", torqueConstant = "default", resistance = "default", rotorInertia = "default",
              viscousFriction = "default", dryFriction = "default", torqueLimit = "default", velocityLimit = "default";
};

struct ActuatorSet {
  std::vector<ActuatorParameters> joints;  ///< URDF joint order
  std::vector<ActuatorSources> sources;    ///< the same order: where each value came from
  double frictionSharpness = 100.0;        ///< ν in (3.8) [s/rad]; larger is closer to sign(Ω)
};

/// Defaults from the URDF alone: N = K = 1, R = 0, URDF <limit> effort/velocity,
/// URDF <dynamics> damping/friction (joint side, equal to motor side when N = 1).
ActuatorSet defaultActuators(const RobotModel& robot);

/// One sentence per kind of friction taken from the URDF's <dynamics> (damping, friction) and
/// not set by an actuator file: which joints, and that the URDF's joint-side values are read as
/// motor-side friction (equal only with N = 1). Empty when no value comes from there.
std::vector<std::string> urdfFrictionNotes(const ActuatorSet& actuators, const RobotModel& robot);

/// Reads an actuator YAML file (docs/reference/robot-files.md); values not given keep the URDF
/// defaults. Throws InputError naming file, line and field for unknown joints or keys,
/// wrong types and impossible numbers.
ActuatorSet loadActuators(const std::filesystem::path& path, const RobotModel& robot);

/// Motor-side friction torque Γ_fric at motor speed Ω (3.8).
double frictionTorque(const ActuatorParameters& actuator, double motorSpeed, double sharpness);
/// dΓ_fric/dΩ at motor speed Ω.
double frictionTorqueSlope(const ActuatorParameters& actuator, double motorSpeed, double sharpness);
/// d²Γ_fric/dΩ² (the dry friction's arctan alone: the viscous part is linear).
double frictionTorqueCurvature(const ActuatorParameters& actuator, double motorSpeed, double sharpness);

struct MotorPower {
  double motorTorque = 0.0;  ///< Γem [N m], motor side
  double power = 0.0;        ///< P [W], may be negative (regeneration that the supply cannot take)
};

/// Electrical power of one joint's motor for joint torque Γ, velocity q̇ and acceleration q̈.
MotorPower motorPower(const ActuatorParameters& actuator, double sharpness, double torque, double velocity,
                      double acceleration);

struct MotorPowerDerivatives {
  double power = 0.0;
  double dTorque = 0.0;        ///< ∂P/∂Γ = (Ω + 2 R Γem / K²) / N
  double dVelocity = 0.0;      ///< ∂P/∂q̇ = N Γem + (Ω + 2 R Γem / K²) N Γ_fric'(Ω)
  double dAcceleration = 0.0;  ///< ∂P/∂q̈ = (Ω + 2 R Γem / K²) I_m N
};

MotorPowerDerivatives motorPowerDerivatives(const ActuatorParameters& actuator, double sharpness, double torque,
                                            double velocity, double acceleration);

/// Second derivatives of P in (Γ, q̇, q̈), symmetric 3 × 3, exact (formulation.md §6 with
/// Γem = Γ/N + I_m N q̈ + Γ_fric(N q̇), Ω = N q̇, P = Γem Ω + (R/K²) Γem²):
///   ∇²P = g eΩᵀ + eΩ gᵀ + 2 (R/K²) g gᵀ + (∂P/∂Γem) N² Γ_fric''(Ω) e_q̇ e_q̇ᵀ,
/// with g = ∇Γem = (1/N, N Γ_fric'(Ω), I_m N) and eΩ = ∇Ω = (0, N, 0).
Eigen::Matrix3d motorPowerHessian(const ActuatorParameters& actuator, double sharpness, double torque, double velocity,
                                  double acceleration);

}  // namespace mcopt
