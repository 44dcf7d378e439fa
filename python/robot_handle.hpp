// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// What a mcopt.Robot holds: the model, shared with every Dynamics built on it, its actuators
// and its contact surfaces.

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/actuators.hpp"
#include "core/robot_files.hpp"
#include "core/robot_model.hpp"

namespace mcopt::python {

struct RobotHandle {
  RobotHandle(const std::filesystem::path& urdf, const std::optional<std::filesystem::path>& actuatorFile,
              const std::optional<std::filesystem::path>& contactSurfaceFile, bool allowNonPhysicalInertia);

  RobotHandle(RobotModel robot, ActuatorSet actuatorSet, std::vector<ContactSurface> contactSurfaces)
      : model(std::make_shared<const RobotModel>(std::move(robot))),
        actuators(std::move(actuatorSet)),
        surfaces(std::move(contactSurfaces)) {}

  /// Throws ValueError listing the known surfaces.
  const ContactSurface& surface(const std::string& name) const;

  std::shared_ptr<const RobotModel> model;
  ActuatorSet actuators;
  std::vector<ContactSurface> surfaces;
};

}  // namespace mcopt::python
