// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Contacts held by construction (formulation.md §10, "Contacts that hold";
// docs/theory/outer-problem.md). Every environment contact closes a kinematic loop through the
// reference body. Six joints of that loop — the six nearest the contact's body — are not
// splines while the contact is active (over the whole motion, or over its window): at every
// such instant they are what keeps the contact frame at its world pose with zero velocity and
// zero acceleration, given the other joints:
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
// instant, between the samples too, whichever body is the reference. Outside its window a
// contact's closing joints are splines like the others; the outer problem makes the two meet
// at the window's ends (the frame at its pose, at rest: motion_problem.hpp).

#include <Eigen/Core>
#include <Eigen/LU>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/dynamics_data.hpp"
#include "core/dynamics_model.hpp"
#include "core/kinematics.hpp"
#include "core/motion_derivatives.hpp"
#include "core/spatial.hpp"
#include "outer_nlp/contact_force_parametrization.hpp"

namespace mcopt {

/// A contact to hold: the frame (RobotModel frame and placement), its world pose and its
/// window as fractions of the motion ([0, 1]: the whole motion).
struct HeldContact {
  std::string name;
  int frame = -1;
  RigidTransform placement, worldPose;
  std::array<double, 2> window{0.0, 1.0};
};

/// How far a contact's loop is stretched (docs/theory/outer-problem.md, "Closure by
/// construction"): the distance between the origins of its outermost and innermost closing
/// joints (a hip and an ankle, a shoulder and a wrist). Its longest, the loop fully stretched,
/// is where the closure folds: there the closing joints' Jacobian is singular — the closing
/// angles' derivatives grow without bound as the loop nears it — and beyond it the contact's
/// pose is out of reach.
struct LoopReach {
  int outer = -1, inner = -1;  ///< tree positions of the outermost and innermost closing joints' bodies
  Vector3 outerPoint = Vector3::Zero(), innerPoint = Vector3::Zero();  ///< their joint origins, in those bodies' frames
  /// [m]: the largest distance over the four closing joints between them (the outermost and
  /// innermost joints turn about the two points and do not change it), found by coordinate
  /// ascent from the start posture, each revolute joint to its exact maximum (free of its
  /// limits: the closure is); a prismatic joint to the better end of its range (infinite when
  /// it has none).
  double longest = 0.0;
};

/// Which contacts are closed at an instant: bit i for contact i.
using ClosureSet = std::uint32_t;

/// How much of the state ClosedChains::close closes: the pose alone, the pose and the
/// velocities, or all three. A task reads q and q̇ alone (a position task q alone), and its
/// closing joints' q and q̇ (and their map's rows) do not depend on what q̈ is.
enum class ClosureOrder { Positions, Velocities, Accelerations };

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
  /// At most 32 contacts (ClosureSet's bits).
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
  /// Every contact.
  ClosureSet all() const { return contacts_.size() >= 32 ? ~ClosureSet{0} : (ClosureSet{1} << contacts_.size()) - 1; }
  /// The contacts closed at u (a fraction of the motion) on a side of it (insideWindow): those
  /// held over the whole motion, and those whose window holds u there.
  ClosureSet closedAt(double u, int side) const;
  /// The contacts closed on both sides of u: at a window's end, not that window's (there the
  /// state is the splines', which meet the closure).
  ClosureSet closedAround(double u) const { return closedAt(u, -1) & closedAt(u, +1); }
  bool wholeMotion(int contact) const;
  /// q's joints closing a contact of `set` from `angles` (one per closing joint, in their
  /// order), where finite: a Newton start.
  void placeAngles(const Eigen::VectorXd& angles, ClosureSet set, Eigen::Ref<Eigen::VectorXd> q) const;
  /// `angles` of q's joints closing a contact of `set`; the others' left as they are.
  void readAngles(const Eigen::VectorXd& q, ClosureSet set, Eigen::Ref<Eigen::VectorXd> angles) const;
  /// Whether a joint closes a contact of `set`.
  bool closesIn(int joint, ClosureSet set) const {
    const int c = contactOf_[static_cast<std::size_t>(joint)];
    return c >= 0 && ((set >> c) & 1U);
  }

  /// Replaces the entries of (q, v, a) of the joints closing the contacts of `set` by the
  /// closure's, Newton's method (its step halved while it does not reduce the residual)
  /// starting from q's own, then, if that fails, from the start posture's; the other joints,
  /// the other contacts' closing joints included, stay as given. With `map` (3c × 3n, written):
  /// ∂(q_C, q̇_C, q̈_C)/∂(q, q̇, q̈), zero in the closed joints' columns and in the rows of the
  /// joints of contacts outside `set`. Returns false, with the closed entries NaN, when Newton's
  /// method does not reach the pose (a loop that cannot close: a step too far for Ipopt).
  /// Below ClosureOrder::Accelerations, the entries past `order` (q̈, or q̇ and q̈) stay as given
  /// and the map's rows for them are zero; the others are what the whole closure gives, to the bit.
  bool close(const DynamicsModel& model, ClosedChainData& d, Eigen::Ref<Eigen::VectorXd> q, Eigen::Ref<Eigen::VectorXd> v,
             Eigen::Ref<Eigen::VectorXd> a, Eigen::MatrixXd* map, ClosureSet set,
             ClosureOrder order = ClosureOrder::Accelerations) const;

  /// Contact i's loop: its two joint origins and its longest reach (LoopReach).
  const LoopReach& reach(int contact) const { return reaches_[static_cast<std::size_t>(contact)]; }
  /// "the loop of r_sole (RLEG_JOINT0 to RLEG_JOINT5)": the contact and the outermost and
  /// innermost closing joints, for messages and row names.
  std::string loopName(const RobotModel& robot, int contact) const;
  /// Contact i's loop's reach as a fraction of its longest at the pose in `data` (forward
  /// kinematics done), closed or not.
  double reachRatio(const DynamicsData& data, int contact) const;
  /// The same, and its derivative in q (1 × n: the joints between the two origins; the others'
  /// entries are not written — the caller zeroes the row).
  double reachRatio(const DynamicsModel& model, const DynamicsData& data, int contact,
                    Eigen::Ref<Eigen::RowVectorXd, 0, Eigen::InnerStride<>> gradient) const;

  /// The largest distance [m] and angle [rad] of a frame of `set` from its world pose at q.
  std::pair<double, double> poseError(const DynamicsModel& model, ClosedChainData& d, const Eigen::VectorXd& q,
                                      ClosureSet set) const;

 private:
  /// e(q): per contact of `set` (p − p*, log(R R*ᵀ)), world axes, zero for the others; frame
  /// poses from d.data (forward kinematics done).
  void poseResidual(const DynamicsModel& model, ClosedChainData& d, ClosureSet set) const;
  /// In d.closing and d.residual: a contact outside `set` keeps its closing joints, its rows
  /// the identity on their columns with a zero right-hand side (their step is zero).
  void keepOpen(ClosedChainData& d, ClosureSet set) const;
  /// close's `map` at the closed state (q, v, a), its rows up to `order`, the others zero.
  void writeMap(const DynamicsModel& model, ClosedChainData& d, const Eigen::Ref<const Eigen::VectorXd>& q,
                const Eigen::Ref<const Eigen::VectorXd>& v, const Eigen::Ref<const Eigen::VectorXd>& a, Eigen::MatrixXd& map,
                ClosureSet set, ClosureOrder order) const;
  std::vector<HeldContact> contacts_;
  Eigen::VectorXd posture_;  ///< the start posture: Newton's second start
  std::vector<int> closing_, contactOf_;
  std::vector<bool> closes_;
  std::vector<LoopReach> reaches_;
};

}  // namespace mcopt
