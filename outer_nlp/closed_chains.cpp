// SPDX-License-Identifier: BSD-3-Clause
#include "outer_nlp/closed_chains.hpp"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/errors.hpp"
#include "core/inverse_dynamics.hpp"

namespace mcopt {
namespace {

constexpr int kNewtonIterations = 50;
/// Newton's method runs to the rounding floor — the closure's value must be smooth to well
/// below what a difference quotient of the outer problem resolves —: converged below 1e-14
/// [m, rad], or below 1e-9 once a step no longer halves the residual.
constexpr double kPoseTolerance = 1e-14, kPoseFloor = 1e-9;

Vector3 worldPoint(const DynamicsData& data, int position, const Vector3& local) {
  return data.position[static_cast<std::size_t>(position)] + data.rotation[static_cast<std::size_t>(position)] * local;
}

/// LoopReach of six closing joints (nearest the contact first) by coordinate ascent from
/// `posture`. Along one revolute joint's angle the squared distance is c + A cos δ + B sin δ
/// (the inner origin turns about the joint's axis, the outer one stays): its maximum is at
/// δ = atan2(B, A). Each sweep raises the distance; sweeps stop when no joint moves.
LoopReach measureReach(const DynamicsModel& model, const std::vector<int>& chain, const Eigen::VectorXd& posture,
                       DynamicsData& data) {
  const auto& edges = model.treeJoints();
  LoopReach r;
  r.inner = model.positionOfJoint(chain.front());
  r.outer = model.positionOfJoint(chain.back());
  // The joint frame is the body's frame times `after`⁻¹: its origin in the body's frame.
  r.innerPoint = edges[static_cast<std::size_t>(r.inner)].after.inverse().translation;
  r.outerPoint = edges[static_cast<std::size_t>(r.outer)].after.inverse().translation;
  Eigen::VectorXd q = posture;
  auto distance = [&] {
    forwardKinematics(model, data, q);
    return (worldPoint(data, r.inner, r.innerPoint) - worldPoint(data, r.outer, r.outerPoint)).norm();
  };
  for (int sweep = 0; sweep < 1000; ++sweep) {
    double moved = 0.0;
    for (std::size_t k = 1; k + 1 < chain.size(); ++k) {
      const int j = chain[k], b = model.positionOfJoint(j);
      if (edges[static_cast<std::size_t>(b)].prismatic) {
        const JointLimits& limits = model.robot().joints[static_cast<std::size_t>(j)].limits;
        if (!std::isfinite(limits.lower) || !std::isfinite(limits.upper)) {  // no longest reach (the motion problem says so)
          r.longest = std::numeric_limits<double>::infinity();
          return r;
        }
        const double before = q[j];
        q[j] = limits.lower;
        const double atLower = distance();
        q[j] = limits.upper;
        if (distance() < atLower) q[j] = limits.lower;
        moved = std::max(moved, std::abs(q[j] - before));
        continue;
      }
      forwardKinematics(model, data, q);
      const Vector3 axis = data.jointAxis[static_cast<std::size_t>(b)].normalized();
      const Vector3 onAxis = axis.cross(data.jointMoment[static_cast<std::size_t>(b)]);  // a × (o × a): a point of the axis
      const Vector3 arm = worldPoint(data, r.inner, r.innerPoint) - onAxis;
      const Vector3 across = arm - axis * axis.dot(arm);
      const Vector3 toAxis = onAxis - worldPoint(data, r.outer, r.outerPoint);
      const double turn = std::atan2(toAxis.dot(axis.cross(across)), toAxis.dot(across));
      q[j] += turn;
      moved = std::max(moved, std::abs(turn));
    }
    if (moved < 1e-13) break;
  }
  r.longest = distance();
  return r;
}

}  // namespace

ClosedChainData::ClosedChainData(const DynamicsModel& model, int contacts)
    : data(model), lu(6 * contacts) {
  const int n = model.jointCount(), rows = 6 * contacts;
  jacobian.setZero(6, n);
  for (MotionDerivative* m : {&twistDq, &twistDv, &accelerationDq, &accelerationDv, &accelerationDa}) m->setZero(6, n);
  for (Eigen::MatrixXd* m : {&spatial, &twistByAngle, &accelerationByAngle, &accelerationByVelocity}) m->setZero(rows, n);
  closing.setZero(rows, rows);
  residual.setZero(rows), step.setZero(rows), zeroAcceleration.setZero(n);
  rhs.setZero(rows, 3 * n);
}

ClosedChains::ClosedChains(const DynamicsModel& model, std::vector<HeldContact> contacts, const Eigen::VectorXd& posture)
    : contacts_(std::move(contacts)), posture_(posture) {
  const int n = model.jointCount();
  if (contacts_.size() > 32) throw InputError("more than 32 contacts to hold by construction");
  closes_.assign(static_cast<std::size_t>(n), false);
  contactOf_.assign(static_cast<std::size_t>(n), -1);
  for (std::size_t i = 0; i < contacts_.size(); ++i) {
    const HeldContact& c = contacts_[i];
    const int body = model.framePosition(c.frame);
    std::vector<int> path;
    for (int j = 0; j < n; ++j)
      if (model.supports(j, body) && !closes_[static_cast<std::size_t>(j)]) path.push_back(j);
    // The joints nearest the contact's body first (deepest in the tree rooted at the reference body).
    std::sort(path.begin(), path.end(), [&](int a, int b) { return model.positionOfJoint(a) > model.positionOfJoint(b); });
    if (path.size() < 6)
      throw InputError("contact '" + c.name + "': its loop through the reference body has " + std::to_string(path.size()) +
                       " joints free to close it; holding it takes six");
    for (int k = 0; k < 6; ++k) {
      closing_.push_back(path[static_cast<std::size_t>(k)]);
      closes_[static_cast<std::size_t>(path[static_cast<std::size_t>(k)])] = true;
      contactOf_[static_cast<std::size_t>(path[static_cast<std::size_t>(k)])] = static_cast<int>(i);
    }
  }
  if (contacts_.empty()) return;
  // The six joints must move the frame in every direction at the start posture.
  ClosedChainData d(model, contactCount());
  forwardKinematics(model, d.data, posture);
  for (int i = 0; i < contactCount(); ++i) {
    const HeldContact& c = contacts_[static_cast<std::size_t>(i)];
    const RigidTransform pose = framePose(model, d.data, c.frame) * c.placement;
    frameJacobian(model, d.data, model.framePosition(c.frame), pose.translation, d.jacobian);
    Eigen::Matrix<double, 6, 6> J;
    for (int k = 0; k < 6; ++k) J.col(k) = d.jacobian.col(closing_[static_cast<std::size_t>(6 * i + k)]);
    const Eigen::JacobiSVD<Eigen::Matrix<double, 6, 6>> svd(J);
    const double ratio = svd.singularValues()(5) / svd.singularValues()(0);
    if (!(ratio > 1e-6)) {
      std::string names;
      for (int k = 0; k < 6; ++k)
        names += (k ? ", " : "") + model.robot().joints[static_cast<std::size_t>(closing_[static_cast<std::size_t>(6 * i + k)])].name;
      throw InputError("contact '" + c.name + "': its closing joints (" + names +
                       ") cannot move its frame in every direction at the start posture (singular)");
    }
  }
  for (int i = 0; i < contactCount(); ++i) {
    const std::vector<int> chain(closing_.begin() + 6 * i, closing_.begin() + 6 * i + 6);
    reaches_.push_back(measureReach(model, chain, posture, d.data));
  }
}

std::string ClosedChains::loopName(const RobotModel& robot, int contact) const {
  const auto joint = [&](int k) { return robot.joints[static_cast<std::size_t>(closing_[static_cast<std::size_t>(6 * contact + k)])].name; };
  return "the loop of " + contacts_[static_cast<std::size_t>(contact)].name + " (" + joint(5) + " to " + joint(0) + ")";
}

double ClosedChains::reachRatio(const DynamicsData& data, int contact) const {
  const LoopReach& r = reach(contact);
  return (worldPoint(data, r.inner, r.innerPoint) - worldPoint(data, r.outer, r.outerPoint)).norm() / r.longest;
}

double ClosedChains::reachRatio(const DynamicsModel& model, const DynamicsData& data, int contact,
                                Eigen::Ref<Eigen::RowVectorXd, 0, Eigen::InnerStride<>> gradient) const {
  // d(|e|)/dq_j = eᵀ ∂p_inner/∂q_j / |e| for the joints from the inner body up to the outer
  // one; those at and above it move both origins rigidly (their column is ⟂ e).
  const LoopReach& r = reach(contact);
  const Vector3 inner = worldPoint(data, r.inner, r.innerPoint);
  const Vector3 e = inner - worldPoint(data, r.outer, r.outerPoint);
  const double d = e.norm();
  const Vector3 u = e / (d * r.longest);
  const auto& edges = model.treeJoints();
  for (int i = r.inner; i != r.outer && i > 0; i = edges[static_cast<std::size_t>(i)].parent) {
    const TreeJoint& edge = edges[static_cast<std::size_t>(i)];
    const Vector3& moment = data.jointMoment[static_cast<std::size_t>(i)];
    gradient[edge.joint] = edge.prismatic ? u.dot(moment) : u.dot(moment + data.jointAxis[static_cast<std::size_t>(i)].cross(inner));
  }
  return d / r.longest;
}

ClosureSet ClosedChains::closedAt(double u, int side) const {
  ClosureSet set = 0;
  for (int i = 0; i < contactCount(); ++i)
    if (wholeMotion(i) || insideWindow(u, contacts_[static_cast<std::size_t>(i)].window, side)) set |= ClosureSet{1} << i;
  return set;
}

void ClosedChains::placeAngles(const Eigen::VectorXd& angles, ClosureSet set, Eigen::Ref<Eigen::VectorXd> q) const {
  for (int k = 0; k < closingCount(); ++k) {
    const int j = closing_[static_cast<std::size_t>(k)];
    if (closesIn(j, set) && std::isfinite(angles[k])) q[j] = angles[k];
  }
}

void ClosedChains::readAngles(const Eigen::VectorXd& q, ClosureSet set, Eigen::Ref<Eigen::VectorXd> angles) const {
  for (int k = 0; k < closingCount(); ++k) {
    const int j = closing_[static_cast<std::size_t>(k)];
    if (closesIn(j, set)) angles[k] = q[j];
  }
}

bool ClosedChains::wholeMotion(int contact) const {
  const std::array<double, 2>& w = contacts_[static_cast<std::size_t>(contact)].window;
  return w[0] <= 0.0 && w[1] >= 1.0;
}

void ClosedChains::keepOpen(ClosedChainData& d, ClosureSet set) const {
  for (int i = 0; i < contactCount(); ++i) {
    if ((set >> i) & 1U) continue;
    d.closing.middleRows<6>(6 * i).setZero();
    d.closing.block<6, 6>(6 * i, 6 * i).setIdentity();
    d.residual.segment<6>(6 * i).setZero();
  }
}

void ClosedChains::poseResidual(const DynamicsModel& model, ClosedChainData& d, ClosureSet set) const {
  for (int i = 0; i < contactCount(); ++i) {
    if (!((set >> i) & 1U)) {
      d.residual.segment<6>(6 * i).setZero();
      continue;
    }
    const HeldContact& c = contacts_[static_cast<std::size_t>(i)];
    const RigidTransform pose = framePose(model, d.data, c.frame) * c.placement;
    d.residual.segment<3>(6 * i) = pose.translation - c.worldPose.translation;
    const Eigen::AngleAxisd error(Matrix3(pose.rotation * c.worldPose.rotation.transpose()));
    d.residual.segment<3>(6 * i + 3) = error.angle() * error.axis();
  }
}

std::pair<double, double> ClosedChains::poseError(const DynamicsModel& model, ClosedChainData& d, const Eigen::VectorXd& q,
                                                  ClosureSet set) const {
  forwardKinematics(model, d.data, q);
  poseResidual(model, d, set);
  double distance = 0.0, angle = 0.0;
  for (int i = 0; i < contactCount(); ++i)
    distance = std::max(distance, d.residual.segment<3>(6 * i).norm()), angle = std::max(angle, d.residual.segment<3>(6 * i + 3).norm());
  return {distance, angle};
}

bool ClosedChains::close(const DynamicsModel& model, ClosedChainData& d, Eigen::Ref<Eigen::VectorXd> q,
                         Eigen::Ref<Eigen::VectorXd> v, Eigen::Ref<Eigen::VectorXd> a, Eigen::MatrixXd* map,
                         ClosureSet set, ClosureOrder order) const {
  set &= all();
  if (set == 0) {
    if (map) map->setZero();
    return true;
  }
  const int c = closingCount();
  auto closed = [&](int k) { return closesIn(closing_[static_cast<std::size_t>(k)], set); };
  // The closing joints' point-form Jacobian columns at the pose in d.data: (linear velocity of
  // the frame origin, angular velocity), world axes — e's derivative at e = 0.
  auto closingJacobian = [&](bool full) {
    for (int i = 0; i < contactCount(); ++i) {
      const HeldContact& contact = contacts_[static_cast<std::size_t>(i)];
      const RigidTransform pose = framePose(model, d.data, contact.frame) * contact.placement;
      frameJacobian(model, d.data, model.framePosition(contact.frame), pose.translation, d.jacobian);
      for (int k = 0; k < c; ++k) d.closing.block<6, 1>(6 * i, k) = d.jacobian.col(closing_[static_cast<std::size_t>(k)]);
      if (full) d.spatial.middleRows<6>(6 * i) = d.jacobian;
    }
  };
  // Newton's method on the pose, its step halved while it does not reduce the residual (far
  // from the closure, a full step may overshoot); from q's closing angles, then, if that fails,
  // from the start posture's.
  auto newton = [&]() {
    double previous = std::numeric_limits<double>::infinity();
    forwardKinematics(model, d.data, q);
    poseResidual(model, d, set);
    for (int iteration = 0; iteration < kNewtonIterations; ++iteration) {
      if (!d.residual.allFinite()) return false;
      const double size = d.residual.lpNorm<Eigen::Infinity>();
      if (size < kPoseTolerance || (size < kPoseFloor && size > 0.5 * previous)) return true;
      previous = size;
      closingJacobian(false);
      keepOpen(d, set);
      d.lu.compute(d.closing);
      d.step.noalias() = d.lu.solve(d.residual);
      double scale = 1.0;
      for (int halving = 0; halving < 12; ++halving, scale *= 0.5) {
        for (int k = 0; k < c; ++k) q[closing_[static_cast<std::size_t>(k)]] -= scale * d.step[k];
        forwardKinematics(model, d.data, q);
        poseResidual(model, d, set);
        if (d.residual.allFinite() && (d.residual.lpNorm<Eigen::Infinity>() < size || size < kPoseFloor)) break;
        for (int k = 0; k < c; ++k) q[closing_[static_cast<std::size_t>(k)]] += scale * d.step[k];
        if (halving == 11) {  // no decrease along the step: leave the residual of q as it is
          forwardKinematics(model, d.data, q);
          poseResidual(model, d, set);
          return d.residual.lpNorm<Eigen::Infinity>() < kPoseFloor;
        }
      }
    }
    return false;
  };
  bool converged = newton();
  if (!converged) {
    for (int k = 0; k < c; ++k)
      if (closed(k)) q[closing_[static_cast<std::size_t>(k)]] = posture_[closing_[static_cast<std::size_t>(k)]];
    converged = newton();
  }
  if (!converged) {
    for (int k = 0; k < c; ++k)
      if (closed(k)) {
        const int j = closing_[static_cast<std::size_t>(k)];
        q[j] = v[j] = a[j] = std::numeric_limits<double>::quiet_NaN();
      }
    if (map) map->setConstant(std::numeric_limits<double>::quiet_NaN());
    return false;
  }
  // Past `order`, the entries stay as given (the map reads the velocity Jacobian at the closed
  // pose, q alone, and its q̇ rows the twist's q derivative, q and q̇ alone).
  if (order != ClosureOrder::Positions) {
    // Velocities: J (q̇ with q̇_C = 0) + J_C q̇_C = 0.
    closingJacobian(true);
    for (int k = 0; k < c; ++k)
      if (closed(k)) v[closing_[static_cast<std::size_t>(k)]] = 0.0;
    d.residual.noalias() = d.spatial * v;
    keepOpen(d, set);
    d.lu.compute(d.closing);
    d.step.noalias() = d.lu.solve(d.residual);
    for (int k = 0; k < c; ++k)
      if (closed(k)) v[closing_[static_cast<std::size_t>(k)]] = -d.step[k];
  }
  if (order == ClosureOrder::Accelerations) {
    // Accelerations: the spatial acceleration with q̈_C = 0, against the fixed world's (the
    // reference body's, gravity folded in), then S_C q̈_C cancels the difference. S is the frame
    // Jacobian about the world origin.
    for (int k = 0; k < c; ++k)
      if (closed(k)) a[closing_[static_cast<std::size_t>(k)]] = 0.0;
    inverseDynamics(model, d.data, q, v, a);
    for (int i = 0; i < contactCount(); ++i) {
      const int body = model.framePosition(contacts_[static_cast<std::size_t>(i)].frame);
      d.residual.segment<3>(6 * i) = d.data.linearAcceleration[static_cast<std::size_t>(body)] - d.data.linearAcceleration[0];
      d.residual.segment<3>(6 * i + 3) = d.data.angularAcceleration[static_cast<std::size_t>(body)] - d.data.angularAcceleration[0];
      frameJacobian(model, d.data, body, Vector3::Zero(), d.jacobian);
      d.spatial.middleRows<6>(6 * i) = d.jacobian;
    }
    for (int k = 0; k < c; ++k) d.closing.col(k) = d.spatial.col(closing_[static_cast<std::size_t>(k)]);
    keepOpen(d, set);
    d.lu.compute(d.closing);
    d.step.noalias() = d.lu.solve(d.residual);
    for (int k = 0; k < c; ++k)
      if (closed(k)) a[closing_[static_cast<std::size_t>(k)]] = -d.step[k];
  }
  if (map) writeMap(model, d, q, v, a, *map, set, order);
  return true;
}

void ClosedChains::writeMap(const DynamicsModel& model, ClosedChainData& d, const Eigen::Ref<const Eigen::VectorXd>& q,
                            const Eigen::Ref<const Eigen::VectorXd>& v, const Eigen::Ref<const Eigen::VectorXd>& a,
                            Eigen::MatrixXd& M, ClosureSet set, ClosureOrder order) const {
  const int c = closingCount(), n = model.jointCount();
  auto closed = [&](int k) { return closesIn(closing_[static_cast<std::size_t>(k)], set); };
  // ∂(q_C, q̇_C, q̈_C)/∂(q, q̇, q̈) by the implicit function theorem, at the closed state.
  inverseDynamics(model, d.data, q, v, a);
  for (int i = 0; i < contactCount(); ++i) {
    bodyMotionDerivatives(model, d.data, model.framePosition(contacts_[static_cast<std::size_t>(i)].frame), d.twistDq, d.twistDv,
                          d.accelerationDq, d.accelerationDv, d.accelerationDa);
    d.spatial.middleRows<6>(6 * i) = d.twistDv;
    d.twistByAngle.middleRows<6>(6 * i) = d.twistDq;
    d.accelerationByAngle.middleRows<6>(6 * i) = d.accelerationDq;
    d.accelerationByVelocity.middleRows<6>(6 * i) = d.accelerationDv;
  }
  for (int k = 0; k < c; ++k) d.closing.col(k) = d.spatial.col(closing_[static_cast<std::size_t>(k)]);
  keepOpen(d, set);
  d.lu.compute(d.closing);
  auto Mq = M.topRows(c), Mv = M.middleRows(c, c), Ma = M.bottomRows(c);
  // Right-hand sides in the other joints' columns (the closed joints' zeroed), then the
  // closed joints' own terms through the rows already solved; an open contact's rows zero
  // (its rows of the system are the identity: its joints are not the closure's).
  auto withoutClosing = [&](Eigen::Ref<Eigen::MatrixXd> block) {
    for (int k = 0; k < c; ++k)
      if (closed(k)) block.col(closing_[static_cast<std::size_t>(k)]).setZero();
  };
  auto openRowsZero = [&]() {
    for (int i = 0; i < contactCount(); ++i)
      if (!((set >> i) & 1U)) d.rhs.middleRows<6>(6 * i).setZero();
  };
  // M is block lower triangular: M_q reads q alone, M_v q and q̇. Each block is solved for its
  // own columns only (the solve is column by column: the same values as over all 3n) and the
  // columns right of them are zero.
  d.rhs.leftCols(n) = d.spatial;
  withoutClosing(d.rhs.leftCols(n));
  openRowsZero();
  Mq.leftCols(n) = d.lu.solve(d.rhs.leftCols(n));
  Mq.leftCols(n) *= -1.0;
  Mq.rightCols(2 * n).setZero();
  if (order == ClosureOrder::Positions) {
    Mv.setZero(), Ma.setZero();
    return;
  }

  d.rhs.leftCols(n) = d.twistByAngle;
  d.rhs.middleCols(n, n) = d.spatial;
  withoutClosing(d.rhs.leftCols(n));
  withoutClosing(d.rhs.middleCols(n, n));
  for (int k = 0; k < c; ++k)
    if (closed(k)) d.rhs.leftCols(n).noalias() += d.twistByAngle.col(closing_[static_cast<std::size_t>(k)]) * Mq.row(k).head(n);
  openRowsZero();
  Mv.leftCols(2 * n) = d.lu.solve(d.rhs.leftCols(2 * n));
  Mv.leftCols(2 * n) *= -1.0;
  Mv.rightCols(n).setZero();
  if (order == ClosureOrder::Velocities) {
    Ma.setZero();
    return;
  }

  d.rhs.leftCols(n) = d.accelerationByAngle;
  d.rhs.middleCols(n, n) = d.accelerationByVelocity;
  d.rhs.rightCols(n) = d.spatial;
  withoutClosing(d.rhs.leftCols(n));
  withoutClosing(d.rhs.middleCols(n, n));
  withoutClosing(d.rhs.rightCols(n));
  for (int k = 0; k < c; ++k) {
    if (!closed(k)) continue;
    const int j = closing_[static_cast<std::size_t>(k)];
    d.rhs.leftCols(n).noalias() += d.accelerationByAngle.col(j) * Mq.row(k).head(n);
    d.rhs.leftCols(2 * n).noalias() += d.accelerationByVelocity.col(j) * Mv.row(k).head(2 * n);
  }
  openRowsZero();
  Ma = d.lu.solve(d.rhs);
  Ma *= -1.0;
}

}  // namespace mcopt
