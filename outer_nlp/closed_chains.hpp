// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Contacts held over the whole motion, by construction (formulation.md §10, "Contacts that
// hold"; docs/theory/outer-problem.md). Every environment contact without a window closes a
// kinematic loop through the reference body. Six joints of that loop — the six nearest the
// contact's body — are not splines: at every instant they are what keeps the contact frame at
// its world pose with zero velocity and zero acceleration, given the other joints:
//   pose      e(q) = 0                       (frame origin and orientation, world axes)
//   velocity  V(q, q̇) = S q̇ = 0               (the body's spatial twist)
//   acceleration A(q, q̇, q̈) − A_ref = 0        (its spatial acceleration, the reference body's
//                                              being the fixed world's, gravity folded in)
// solved for the closing joints' (q_C, q̇_C, q̈_C): the pose by Newton's method, the other two
// linearly. Their derivatives in the other joints' state follow from the implicit function
// theorem, block-triangular in (q, q̇, q̈):
//   M_q = −S_C⁻¹ [S_F 0 0]
//   M_v = −S_C⁻¹ ([V_q,F S_F 0] + V_q,C M_q)
//   M_a = −S_C⁻¹ ([A_q,F A_v,F S_F] + A_q,C M_q + A_v,C M_v)
// where S is the spatial Jacobian, V_q = ∂V/∂q, A_q, A_v = ∂A/∂q, ∂A/∂q̇ (core/motion_derivatives.hpp),
// F the other joints' columns, C the closing joints'. The contact then holds exactly at every
// instant, between the samples too, whichever body is the reference.

#include <Eigen/Core>
#include <Eigen/LU>
#include <string>
#include <vector>

#include "core/dynamics_data.hpp"
#include "core/dynamics_model.hpp"
#include "core/kinematics.hpp"
#include "core/motion_derivatives.hpp"
#include "core/spatial.hpp"

namespace mcopt {

/// A contact to hold: the frame (RobotModel frame and placement) and its world pose.
struct HeldContact {
  std::string name;
  int frame = -1;
  RigidTransform placement, worldPose;
};

/// Per-thread buffers of ClosedChains::close, sized once (no allocation afterwards).
struct ClosedChainData {
  ClosedChainData(const DynamicsModel& model, int contacts);
  DynamicsData data;
  FrameJacobian jacobian;
  MotionDerivative twistDq, twistDv, accelerationDq, accelerationDv, accelerationDa;
  Eigen::MatrixXd spatial, twistByAngle, accelerationByAngle, accelerationByVelocity;  ///< 6k × n, stacked
  Eigen::MatrixXd closing;                     ///< S_C or J_C, 6k × 6k
  Eigen::PartialPivLU<Eigen::MatrixXd> lu;
  Eigen::VectorXd residual, step, zeroAcceleration;
  Eigen::MatrixXd rhs;                         ///< 6k × 3n
};

class ClosedChains {
 public:
  /// Chooses each contact's six closing joints: the nearest its body on the path from the
  /// reference body, not already closing another contact. Throws InputError naming the
  /// contact when its loop has fewer than six free joints, or when they cannot move its frame
  /// in all six directions at `posture` (a singular choice).
  ClosedChains(const DynamicsModel& model, std::vector<HeldContact> contacts, const Eigen::VectorXd& posture);

  bool empty() const { return contacts_.empty(); }
  int contactCount() const { return static_cast<int>(contacts_.size()); }
  const std::vector<HeldContact>& contacts() const { return contacts_; }
  /// The closing joints, six a contact in contact order.
  const std::vector<int>& closingJoints() const { return closing_; }
  int closingCount() const { return static_cast<int>(closing_.size()); }
  bool closes(int joint) const { return closes_[static_cast<std::size_t>(joint)]; }
  /// The contact a closing joint holds.
  int contactOf(int joint) const { return contactOf_[static_cast<std::size_t>(joint)]; }

  /// Replaces the closing joints' entries of (q, v, a) by the closure's, Newton's method (its
  /// step halved while it does not reduce the residual) starting from q's own, then, if that
  /// fails, from the start posture's. With `map` (3c × 3n, written): ∂(q_C, q̇_C, q̈_C)/∂(q, q̇, q̈), zero
  /// in the closing joints' columns. Returns false, with those entries NaN, when Newton's
  /// method does not reach the pose (a loop that cannot close: a step too far for Ipopt).
  bool close(const DynamicsModel& model, ClosedChainData& d, Eigen::Ref<Eigen::VectorXd> q, Eigen::Ref<Eigen::VectorXd> v,
             Eigen::Ref<Eigen::VectorXd> a, Eigen::MatrixXd* map) const;

  /// The largest distance [m] and angle [rad] of a held frame from its world pose at q.
  std::pair<double, double> poseError(const DynamicsModel& model, ClosedChainData& d, const Eigen::VectorXd& q) const;

 private:
  /// e(q): per contact (p − p*, log(R R*ᵀ)), world axes; frame poses from d.data (forward kinematics done).
  void poseResidual(const DynamicsModel& model, ClosedChainData& d) const;
  std::vector<HeldContact> contacts_;
  Eigen::VectorXd posture_;  ///< the start posture: Newton's second start
  std::vector<int> closing_, contactOf_;
  std::vector<bool> closes_;
};

}  // namespace mcopt
