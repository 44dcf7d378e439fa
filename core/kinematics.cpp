// SPDX-License-Identifier: BSD-3-Clause
#include "core/kinematics.hpp"

#include "core/hot_path_checks.hpp"

namespace mcopt {

RigidTransform framePose(const DynamicsModel& model, const DynamicsData& data, int frame) {
  MCOPT_HOT_PATH_CHECK(frame >= 0 && frame < static_cast<int>(model.robot().frames.size()), "framePose: no such frame");
  const int position = model.framePosition(frame);
  const RigidTransform body{data.rotation[position], data.position[position]};
  return body * model.framePlacement(frame);
}

Vector3 centerOfMass(const DynamicsModel& model, const DynamicsData& data) {
  Vector3 weighted = Vector3::Zero();
  double mass = 0.0;
  for (int i = 0; i < model.bodyCount(); ++i) {
    weighted += model.inertias()[i].mass * data.comPosition[i];
    mass += model.inertias()[i].mass;
  }
  return weighted / mass;
}

double kineticEnergy(const DynamicsModel& model, const DynamicsData& data) {
  double energy = 0.0;
  for (int i = 0; i < model.bodyCount(); ++i) {
    const BodyInertia& inertia = model.inertias()[i];
    const Vector3& w = data.angularVelocity[i];
    // linearVelocity is the velocity of the body point at the world origin.
    const Vector3 comVelocity = data.linearVelocity[i] + w.cross(data.comPosition[i]);
    const Vector3 wLocal = data.rotation[i].transpose() * w;
    energy += 0.5 * inertia.mass * comVelocity.squaredNorm() + 0.5 * wLocal.dot(inertia.inertiaAboutCom * wLocal);
  }
  return energy;
}

double potentialEnergy(const DynamicsModel& model, const DynamicsData& data) {
  double energy = 0.0;
  for (int i = 0; i < model.bodyCount(); ++i) energy -= model.inertias()[i].mass * model.gravity().dot(data.comPosition[i]);
  return energy;
}

Vector6 pointTwist(const DynamicsData& data, int bodyPosition, const Vector3& pointInWorld) {
  Vector6 twist;
  const Vector3& w = data.angularVelocity[static_cast<std::size_t>(bodyPosition)];
  twist.head<3>() = data.linearVelocity[static_cast<std::size_t>(bodyPosition)] + w.cross(pointInWorld);
  twist.tail<3>() = w;
  return twist;
}

void frameJacobian(const DynamicsModel& model, const DynamicsData& data, int bodyPosition, const Vector3& point,
                   FrameJacobian& jacobian) {
  MCOPT_HOT_PATH_CHECK(bodyPosition >= 0 && bodyPosition < model.bodyCount(), "frameJacobian: no such body");
  jacobian.setZero(6, model.jointCount());
  const auto& edges = model.treeJoints();
  for (int i = bodyPosition; i > 0; i = edges[i].parent) {
    // Motion subspace (sv, sw) at the world origin, moved to the point: v = sv + sw × x.
    const int j = edges[i].joint;
    if (edges[i].prismatic) {
      jacobian.col(j).head<3>() = data.jointMoment[i];
    } else {
      jacobian.col(j).head<3>() = data.jointMoment[i] + data.jointAxis[i].cross(point);
      jacobian.col(j).tail<3>() = data.jointAxis[i];
    }
  }
}

void centerOfMassJacobian(const DynamicsModel& model, const DynamicsData& data, Eigen::Matrix3Xd& jacobian) {
  jacobian.setZero(3, model.jointCount());
  double totalMass = 0.0;
  const auto& edges = model.treeJoints();
  for (int b = 0; b < model.bodyCount(); ++b) {
    const double mass = model.inertias()[b].mass;
    totalMass += mass;
    if (mass == 0.0) continue;
    for (int i = b; i > 0; i = edges[i].parent) {
      const int j = edges[i].joint;
      Vector3 column = data.jointMoment[i];
      if (!edges[i].prismatic) column += data.jointAxis[i].cross(data.comPosition[b]);
      jacobian.col(j) += mass * column;
    }
  }
  jacobian /= totalMass;
}

}  // namespace mcopt
