// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// One task of every kind a scenario may state (but the throw's), on the HRP-2 kick's robot,
// with bounds on some components and windows and instants inside its 1.6 s: for tests of
// the outer problem's derivatives.
#include <cmath>
#include <limits>
#include <vector>

#include "core/spatial.hpp"
#include "outer_nlp/scenario.hpp"

namespace mcopt::test {

inline std::vector<TaskSpec> everyTaskKind(const Scenario& scenario) {
  const double inf = std::numeric_limits<double>::infinity();
  auto frame = [&](const char* body) { return scenario.robot.frameIndex(body); };
  auto task = [&](std::shared_ptr<const Task> kind, const char* name, double start, double end) {
    TaskSpec t;
    t.task = std::move(kind), t.name = name, t.start = start, t.end = end, t.window = end > start;
    t.lower = Eigen::Vector3d(-0.3, -inf, -1.0), t.upper = Eigen::Vector3d(0.3, 0.5, inf);
    return t;
  };
  TaskSpec angle = task(makeOrientationAngleTask(frame("LARM_LINK6"), rotationFromRpy(0.2, 0.1, -0.3)), "LARM_LINK6",
                        0.3, 1.2);
  angle.lower.setConstant(1, -inf), angle.upper.setConstant(1, 1.0 - std::cos(0.4));
  return {task(makeOrientationTask(frame("r_sole"), rotationFromRpy(0.1, -0.2, 0.3)), "r_sole", 0.2, 0.9),
          task(makePositionTask(frame("RARM_LINK5"), Vector3(0.02, -0.03, 0.1)), "RARM_LINK5", 1.1, 1.1),
          task(makeLinearVelocityTask(frame("HEAD_LINK1"), Vector3(0.1, 0.0, 0.05)), "HEAD_LINK1", 0.7, 0.7),
          task(makeAngularVelocityTask(frame("CHEST_LINK1")), "CHEST_LINK1", 0.5, 0.5),
          task(makeCenterOfMassTask(), "", 0.0, 1.6),
          angle};
}

}  // namespace mcopt::test
