// SPDX-License-Identifier: BSD-3-Clause
#include "outer_nlp/task.hpp"

#include <cmath>
#include <limits>

#include "core/spatial.hpp"

namespace mcopt {

// Each kind's reader, in its own file.
ReadTask readPositionTask(const TaskFields& fields);
ReadTask readOrientationTask(const TaskFields& fields);
ReadTask readOrientationAngleTask(const TaskFields& fields);
ReadTask readLinearVelocityTask(const TaskFields& fields);
ReadTask readAngularVelocityTask(const TaskFields& fields);
ReadTask readCenterOfMassTask(const TaskFields& fields);

const std::vector<TaskKindEntry>& taskKinds() {
  static const std::vector<TaskKindEntry> kinds = {
      {"position", "a point of a body, world frame [m]", {"body", "point", "target", "tolerance", "lower", "upper"},
       readPositionTask},
      {"orientation", "a body's orientation error from a target, sin θ times the axis, per component",
       {"body", "target", "tolerance"}, readOrientationTask},
      {"orientation_angle", "a body's orientation within an angle of a target (one row, 1 − cos θ)",
       {"body", "target", "tolerance"}, readOrientationAngleTask},
      {"linear_velocity", "a point's velocity, world frame [m/s], at an instant",
       {"body", "point", "target", "tolerance", "lower", "upper"}, readLinearVelocityTask},
      {"angular_velocity", "a body's angular velocity, world frame [rad/s], at an instant",
       {"body", "target", "tolerance", "lower", "upper"}, readAngularVelocityTask},
      {"center_of_mass", "the centre of mass, world frame [m]", {"target", "tolerance", "lower", "upper"},
       readCenterOfMassTask},
  };
  return kinds;
}

const TaskKindEntry* findTaskKind(const std::string& kind) {
  for (const TaskKindEntry& e : taskKinds())
    if (e.kind == kind) return &e;
  return nullptr;
}

std::string taskKindList() {
  std::string out;
  for (const TaskKindEntry& e : taskKinds()) out += e.kind + ", ";
  return out + "or throw";
}

std::string Task::componentName(int i) const {
  static const char* const names[] = {"x", "y", "z", "rx", "ry", "rz"};
  return i >= 0 && i < kMaxTaskDimension ? names[i] : std::to_string(i);
}

bool Task::readsVelocity() const {
  const TaskQuantity q = reads();
  return q == TaskQuantity::LinearVelocity || q == TaskQuantity::AngularVelocity || q == TaskQuantity::Ball;
}

TaskWorkspace::TaskWorkspace(const DynamicsModel& model)
    : jacobian(6, model.jointCount()),
      dTwistDq(6, model.jointCount()),
      dTwistDv(6, model.jointCount()),
      dAccelerationDq(6, model.jointCount()),
      dAccelerationDv(6, model.jointCount()),
      dAccelerationDa(6, model.jointCount()),
      comJacobian(3, model.jointCount()),
      velocityDq(3, model.jointCount()),
      ballJacobian(6, 2 * model.jointCount()),
      weightedBallJacobian(6, 2 * model.jointCount()) {}

Matrix3 readTargetRotation(const TaskFields& fields) {
  if (!fields.has("target")) fields.fail("target", "missing required field (rpy of the target)");
  const std::vector<double> r = fields.numbers("target", 3);
  return rotationFromRpy(r[0], r[1], r[2]);
}

void readTargetOrBounds(const TaskFields& fields, int dimension, ReadTask& out) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  out.lower.setConstant(dimension, -kInf);
  out.upper.setConstant(dimension, kInf);
  if (fields.has("target")) {
    if (fields.has("lower") || fields.has("upper"))
      fields.fail("target", "give either target (and tolerance) or lower/upper");
    const std::vector<double> target = fields.bounds("target", dimension, kInf);
    double tolerance = 0.0;
    if (fields.has("tolerance")) {
      tolerance = fields.number("tolerance");
      if (!(tolerance >= 0.0)) fields.fail("tolerance", "expected a number ≥ 0");
    }
    for (int i = 0; i < dimension; ++i) {
      const double t = target[static_cast<std::size_t>(i)];
      if (std::isfinite(t)) out.lower[i] = t - tolerance, out.upper[i] = t + tolerance;
    }
  } else {
    if (fields.has("tolerance")) fields.fail("tolerance", "a tolerance goes with a target");
    if (fields.has("lower")) {
      const std::vector<double> v = fields.bounds("lower", dimension, -kInf);
      for (int i = 0; i < dimension; ++i) out.lower[i] = v[static_cast<std::size_t>(i)];
    }
    if (fields.has("upper")) {
      const std::vector<double> v = fields.bounds("upper", dimension, kInf);
      for (int i = 0; i < dimension; ++i) out.upper[i] = v[static_cast<std::size_t>(i)];
    }
    for (int i = 0; i < dimension; ++i)
      if (out.lower[i] > out.upper[i]) fields.fail("upper", "upper bound below lower bound");
  }
}

}  // namespace mcopt
