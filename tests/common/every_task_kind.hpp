// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// One task of every kind a scenario may state (but the throw's), on the HRP-2 kick's robot,
// with bounds on some components and windows and instants inside its 1.6 s: for tests of
// the outer problem's derivatives.
#include <limits>
#include <vector>

#include "outer_nlp/scenario.hpp"

namespace mcopt::test {

inline std::vector<TaskSpec> everyTaskKind(const Scenario& scenario) {
  const double inf = std::numeric_limits<double>::infinity();
  auto task = [&](TaskKind kind, const char* body, double start, double end) {
    TaskSpec t;
    t.kind = kind, t.name = body, t.start = start, t.end = end, t.window = end > start;
    if (kind != TaskKind::CenterOfMass) t.body = body, t.frame = scenario.robot.frameIndex(body);
    t.lower = Eigen::Vector3d(-0.3, -inf, -1.0), t.upper = Eigen::Vector3d(0.3, 0.5, inf);
    return t;
  };
  TaskSpec orientation = task(TaskKind::Orientation, "r_sole", 0.2, 0.9);
  orientation.targetRotation = rotationFromRpy(0.1, -0.2, 0.3);
  TaskSpec point = task(TaskKind::Position, "RARM_LINK5", 1.1, 1.1);
  point.point = Vector3(0.02, -0.03, 0.1);
  TaskSpec velocity = task(TaskKind::LinearVelocity, "HEAD_LINK1", 0.7, 0.7);
  velocity.point = Vector3(0.1, 0.0, 0.05);
  return {orientation, point, velocity, task(TaskKind::AngularVelocity, "CHEST_LINK1", 0.5, 0.5),
          task(TaskKind::CenterOfMass, "", 0.0, 1.6)};
}

}  // namespace mcopt::test
