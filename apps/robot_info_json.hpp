// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A robot description as JSON (`mcopt robot info --json`, and `Robot.info()` in Python):
// name, source, mass, centre of mass at the zero posture, joints with their limits and
// actuator parameters (actuator file over URDF, formulation.md §2) with where each came from
// (`sources`), bodies, frames, warnings, and notes on friction read from the URDF.

#include "apps/json_io.hpp"
#include "core/actuators.hpp"
#include "core/robot_model.hpp"

namespace mcopt::cli {

json_io::Json robotInfoJson(const RobotModel& robot, const ActuatorSet& actuators);

}  // namespace mcopt::cli
