// SPDX-License-Identifier: BSD-3-Clause
#include "core/dynamics_model.hpp"

#include <algorithm>

#include "core/errors.hpp"

namespace mcopt {

DynamicsModel::DynamicsModel(RobotModel robot, const std::string& referenceFrame,
                             const RigidTransform& referencePose, const Vector3& gravity)
    : robot_(std::move(robot)), referencePose_(referencePose), gravity_(gravity) {
  if (!gravity_.allFinite()) throw InputError("gravity must be finite");
  if (!referencePose_.rotation.allFinite() || !referencePose_.translation.allFinite())
    throw InputError("reference pose must be finite");
  referenceFrame_ = robot_.frameIndex(referenceFrame);
  const Frame& reference = robot_.frames[referenceFrame_];
  rootPose_ = referencePose_ * reference.placement.inverse();

  const int nb = robot_.bodyCount();
  // Bodies adjacent through each joint, either direction.
  std::vector<std::vector<int>> jointsAtBody(nb);
  for (int j = 0; j < robot_.jointCount(); ++j) {
    jointsAtBody[robot_.joints[j].parentBody].push_back(j);
    jointsAtBody[robot_.joints[j].childBody].push_back(j);
  }
  treeJoints_.assign(1, TreeJoint{});
  bodyAtPosition_.assign(1, reference.body);
  positionOfBody_.assign(nb, -1);
  positionOfJoint_.assign(robot_.jointCount(), -1);
  positionOfBody_[reference.body] = 0;

  // Pre-order depth-first traversal from the reference body, joints in URDF order: every
  // subtree is then the contiguous range [position, subtreeEnd(position)).
  std::vector<std::pair<int, int>> stack{{reference.body, -1}};  // (body, joint reached through)
  while (!stack.empty()) {
    const auto [body, via] = stack.back();
    stack.pop_back();
    if (via >= 0) {
      const Joint& joint = robot_.joints[via];
      const bool reversed = joint.childBody != body;
      TreeJoint edge;
      edge.joint = via;
      edge.parent = positionOfBody_[reversed ? joint.childBody : joint.parentBody];
      edge.prismatic = joint.type == JointType::Prismatic;
      edge.reversed = reversed;
      if (reversed) {
        edge.axis = -joint.axis;
        edge.after = joint.placement.inverse();
      } else {
        edge.axis = joint.axis;
        edge.before = joint.placement;
      }
      edge.beforeIsIdentity = edge.before.isIdentity();
      edge.afterIsIdentity = edge.after.isIdentity();
      edge.beforeIsTranslation = edge.before.rotation == Matrix3::Identity();
      edge.afterIsTranslation = edge.after.rotation == Matrix3::Identity();
      for (int k = 0; k < 3; ++k)
        if (std::abs(std::abs(edge.axis[k]) - 1.0) < 1e-15) {
          edge.axisIndex = k;
          edge.axisSign = edge.axis[k] > 0 ? 1.0 : -1.0;
        }
      positionOfBody_[body] = static_cast<int>(bodyAtPosition_.size());
      positionOfJoint_[via] = positionOfBody_[body];
      bodyAtPosition_.push_back(body);
      treeJoints_.push_back(edge);
    }
    // Push in reverse so that joints pop in URDF order.
    for (auto it = jointsAtBody[body].rbegin(); it != jointsAtBody[body].rend(); ++it) {
      const Joint& joint = robot_.joints[*it];
      const int next = joint.childBody == body ? joint.parentBody : joint.childBody;
      if (*it == via) continue;  // the edge we came through
      stack.emplace_back(next, *it);
    }
  }
  subtreeEnd_.assign(nb, 0);
  for (int position = nb - 1; position >= 0; --position) {
    subtreeEnd_[position] = std::max(subtreeEnd_[position], position + 1);
    if (position > 0) {
      const int parent = treeJoints_[position].parent;
      subtreeEnd_[parent] = std::max(subtreeEnd_[parent], subtreeEnd_[position]);
    }
  }
  inertias_.resize(nb);
  for (int position = 0; position < nb; ++position) inertias_[position] = robot_.bodies[bodyAtPosition_[position]].inertia;
  jointAtPosition_.assign(nb, -1);
  for (int position = 1; position < nb; ++position) jointAtPosition_[position] = treeJoints_[position].joint;
}

bool DynamicsModel::supports(int joint, int position) const {
  const int jointPosition = positionOfJoint_[joint];
  return jointPosition <= position && position < subtreeEnd_[jointPosition];
}

}  // namespace mcopt
