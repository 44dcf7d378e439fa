#include "core/dynamics_model.hpp"

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

  // Pre-order depth-first traversal from the reference body.
  std::vector<int> stack{reference.body};
  while (!stack.empty()) {
    const int body = stack.back();
    stack.pop_back();
    const int parentPosition = positionOfBody_[body];
    // Push in reverse so that joints are visited in URDF order.
    for (auto it = jointsAtBody[body].rbegin(); it != jointsAtBody[body].rend(); ++it) {
      const Joint& joint = robot_.joints[*it];
      const bool reversed = joint.childBody == body;
      const int next = reversed ? joint.parentBody : joint.childBody;
      if (positionOfBody_[next] >= 0) continue;  // the edge we came through
      TreeJoint edge;
      edge.joint = *it;
      edge.parent = parentPosition;
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
      positionOfBody_[next] = static_cast<int>(bodyAtPosition_.size());
      positionOfJoint_[*it] = positionOfBody_[next];
      bodyAtPosition_.push_back(next);
      treeJoints_.push_back(edge);
      stack.push_back(next);
    }
  }
  // Re-order depth-first pushes into a proper parent-before-child order is already
  // guaranteed: a body is numbered when first reached from its parent.
  inertias_.resize(nb);
  for (int position = 0; position < nb; ++position) inertias_[position] = robot_.bodies[bodyAtPosition_[position]].inertia;
}

bool DynamicsModel::supports(int joint, int position) const {
  const int jointPosition = positionOfJoint_[joint];
  for (int p = position; p > 0; p = treeJoints_[p].parent)
    if (p == jointPosition) return true;
  return false;
}

}  // namespace mcopt
