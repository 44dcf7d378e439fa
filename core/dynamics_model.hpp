// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// DynamicsModel: the robot's tree re-rooted at the reference body, which is held
// fixed at a known world pose (formulation.md §2, report §3.2). Immutable; the
// per-sample buffers live in DynamicsData.

#include <string>
#include <vector>

#include "core/robot_model.hpp"

namespace mcopt {

/// One edge of the re-rooted tree. The body's world pose is
///   pose(parent) * before * motion(axis, q) * after,
/// where motion is a rotation by q about `axis` (revolute) or a translation q·axis (prismatic).
/// A joint traversed against its URDF direction has before = 1, axis = −(URDF axis),
/// after = placement⁻¹: its coordinate and torque keep the URDF meaning (formulation.md §1–§2).
struct TreeJoint {
  int joint = -1;      ///< index in RobotModel::joints (URDF order): the coordinate q_joint
  int parent = -1;     ///< tree position of the parent body
  bool prismatic = false;
  bool reversed = false;
  RigidTransform before;
  Vector3 axis = Vector3::UnitZ();
  RigidTransform after;
  bool afterIsIdentity = true;
  bool beforeIsIdentity = true;
  bool beforeIsTranslation = true;  ///< before.rotation is the identity
  bool afterIsTranslation = true;   ///< after.rotation is the identity
  /// 0, 1, 2 when `axis` is ±x, ±y, ±z (then axisSign is that sign), −1 for a general axis.
  int axisIndex = -1;
  double axisSign = 1.0;
};

class DynamicsModel {
 public:
  /// `referenceFrame`: any URDF link name, including one attached by a fixed joint (a sole
  /// frame); its frame is held at `referencePose` in the world. Throws InputError for an
  /// unknown name.
  DynamicsModel(RobotModel robot, const std::string& referenceFrame,
                const RigidTransform& referencePose = RigidTransform::identity(),
                const Vector3& gravity = Vector3(0.0, 0.0, -9.81));

  const RobotModel& robot() const { return robot_; }
  int jointCount() const { return robot_.jointCount(); }
  int bodyCount() const { return robot_.bodyCount(); }

  /// Tree positions: 0 is the body holding the reference frame; a parent's position is
  /// always smaller than its children's. treeJoints()[0] is unused.
  const std::vector<TreeJoint>& treeJoints() const { return treeJoints_; }
  const std::vector<BodyInertia>& inertias() const { return inertias_; }  ///< by tree position
  int bodyAtPosition(int position) const { return bodyAtPosition_[position]; }
  int positionOfBody(int body) const { return positionOfBody_[body]; }
  /// Tree position of the body that joint j moves away from the reference body.
  int positionOfJoint(int joint) const { return positionOfJoint_[joint]; }
  /// The joint into the body at `position` (treeJoints()[position].joint, from a contiguous
  /// array for the per-sample loops); −1 at the reference body.
  int jointAtPosition(int position) const { return jointAtPosition_[position]; }

  int referenceFrame() const { return referenceFrame_; }
  const RigidTransform& referencePose() const { return referencePose_; }
  const RigidTransform& rootPose() const { return rootPose_; }  ///< world pose of the root body frame
  const Vector3& gravity() const { return gravity_; }

  /// Tree position of the body carrying frame f and the frame's placement in it.
  int framePosition(int frame) const { return positionOfBody_[robot_.frames[frame].body]; }
  const RigidTransform& framePlacement(int frame) const { return robot_.frames[frame].placement; }

  /// Tree positions are in depth-first pre-order: the subtree of `position` (the bodies it
  /// carries away from the reference body) is [position, subtreeEnd(position)).
  int subtreeEnd(int position) const { return subtreeEnd_[position]; }
  /// Whether joint j lies on the path from the reference body to the body at `position`.
  bool supports(int joint, int position) const;

 private:
  RobotModel robot_;
  std::vector<TreeJoint> treeJoints_;
  std::vector<BodyInertia> inertias_;
  std::vector<int> bodyAtPosition_, positionOfBody_, positionOfJoint_, jointAtPosition_, subtreeEnd_;
  int referenceFrame_ = 0;
  RigidTransform referencePose_, rootPose_;
  Vector3 gravity_;
};

}  // namespace mcopt
