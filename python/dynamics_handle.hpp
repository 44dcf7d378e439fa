// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// What a mcopt.Dynamics holds: the robot re-rooted at its reference body (formulation.md
// §4), with the per-call workspace. A Dynamics is used under the GIL, one call at a time.

#include <memory>

#include "core/dynamics_data.hpp"
#include "core/dynamics_derivatives.hpp"
#include "core/dynamics_model.hpp"
#include "python/robot_handle.hpp"

namespace mcopt::python {

struct DynamicsHandle {
  DynamicsHandle(std::shared_ptr<RobotHandle> robotHandle, const DynamicsModel& dynamicsModel)
      : robot(std::move(robotHandle)), model(dynamicsModel), data(model), derivatives(model) {}
  std::shared_ptr<RobotHandle> robot;
  const DynamicsModel model;
  DynamicsData data;
  DynamicsDerivatives derivatives;
};

}  // namespace mcopt::python
