// SPDX-License-Identifier: BSD-3-Clause
#include "core/contact_maps.hpp"

#include "core/kinematics.hpp"

namespace mcopt {

namespace {

inline Vector6 motionSubspace(const DynamicsModel& model, const DynamicsData& data, int position) {
  Vector6 s;
  s.head<3>() = data.jointMoment[position];
  s.tail<3>() = model.treeJoints()[position].prismatic ? Vector3::Zero() : data.jointAxis[position];
  return s;
}

}  // namespace

ContactFrame contactFrame(const DynamicsModel& model, const DynamicsData& data, int frame,
                          const RigidTransform& placement) {
  return {model.framePosition(frame), framePose(model, data, frame) * placement};
}

void wrenchToWorld(const RigidTransform& contactPose, Eigen::Ref<Eigen::Matrix<double, 6, 6>> toWorld) {
  const Matrix3& R = contactPose.rotation;
  toWorld.setZero();
  toWorld.topLeftCorner<3, 3>() = R;
  toWorld.bottomLeftCorner<3, 3>() = skew(contactPose.translation) * R;
  toWorld.bottomRightCorner<3, 3>() = R;
}

void wrenchToWorld(const ContactFrame& contact, Matrix6& toWorld) { wrenchToWorld(contact.contactPose, toWorld); }

void wrenchToTorque(const DynamicsModel& model, const DynamicsData& data, const ContactFrame& contact,
                    WrenchToTorque& toTorque) {
  Matrix6 toWorld;
  wrenchToWorld(contact, toWorld);
  toTorque.setZero(model.jointCount(), 6);
  const auto& edges = model.treeJoints();
  for (int i = contact.bodyPosition; i > 0; i = edges[i].parent)
    toTorque.row(edges[i].joint).noalias() = motionSubspace(model, data, i).transpose() * toWorld;
}

void wrenchMapDerivatives(const DynamicsModel& model, const DynamicsData& data, const ContactFrame& contact,
                          const Vector6& wrench, Eigen::Matrix<double, 6, Eigen::Dynamic>& dWorld,
                          Eigen::MatrixXd& dTorque) {
  Matrix6 toWorld;
  wrenchToWorld(contact, toWorld);
  const Vector6 world = toWorld * wrench;
  dWorld.setZero(6, model.jointCount());
  dTorque.setZero(model.jointCount(), model.jointCount());
  const auto& edges = model.treeJoints();
  for (int j = contact.bodyPosition; j > 0; j = edges[j].parent) {
    const Vector6 moved = forceCross(motionSubspace(model, data, j), world);
    dWorld.col(edges[j].joint) = moved;
    for (int i = edges[j].parent; i > 0; i = edges[i].parent)
      dTorque(edges[i].joint, edges[j].joint) = motionSubspace(model, data, i).dot(moved);
  }
}

void transposedWrenchMapDerivatives(const DynamicsModel& model, const DynamicsData& data, const ContactFrame& contact,
                                    const Eigen::Ref<const Eigen::VectorXd>& g, const Vector6& lambda,
                                    Eigen::Matrix<double, 6, Eigen::Dynamic>& dTorqueTransposed,
                                    Eigen::Matrix<double, 6, Eigen::Dynamic>& dWorldTransposed) {
  Matrix6 toWorld;
  wrenchToWorld(contact, toWorld);
  dTorqueTransposed.setZero(6, model.jointCount());
  dWorldTransposed.setZero(6, model.jointCount());
  const auto& edges = model.treeJoints();
  // Σ over the whole path, then walked outboard → inboard: the part "k or inboard" is the
  // total minus what was passed.
  Vector6 total = Vector6::Zero();
  for (int j = contact.bodyPosition; j > 0; j = edges[j].parent) total += g[edges[j].joint] * motionSubspace(model, data, j);
  Vector6 outboard = Vector6::Zero();
  for (int k = contact.bodyPosition; k > 0; k = edges[k].parent) {
    const Vector6 axis = motionSubspace(model, data, k);
    dTorqueTransposed.col(edges[k].joint).noalias() = -toWorld.transpose() * motionCross(axis, total - outboard);
    dWorldTransposed.col(edges[k].joint).noalias() = -toWorld.transpose() * motionCross(axis, lambda);
    outboard += g[edges[k].joint] * axis;
  }
}

}  // namespace mcopt
