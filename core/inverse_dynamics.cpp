// SPDX-License-Identifier: BSD-3-Clause
#include "core/inverse_dynamics.hpp"

#include "core/hot_path_checks.hpp"

namespace mcopt {

DynamicsData::DynamicsData(const DynamicsModel& model) {
  const auto nb = static_cast<std::size_t>(model.bodyCount());
  rotation.assign(nb, Matrix3::Identity());
  for (auto* v : {&position, &jointAxis, &jointMoment, &linearVelocity, &angularVelocity, &linearAcceleration,
                  &angularAcceleration, &comPosition, &force, &moment})
    v->assign(nb, Vector3::Zero());
  tau = Eigen::VectorXd::Zero(model.jointCount());
  referenceWrench.setZero();
}

namespace {

// rotation ← rotation · Rot(e_k, angle) for a coordinate axis: two columns mix.
inline void rotateAboutCoordinateAxis(Matrix3& rotation, int k, double s, double c) {
  const int i = (k + 1) % 3, j = (k + 2) % 3;  // Rot(e_k) turns e_i toward e_j
  const Vector3 ci = rotation.col(i), cj = rotation.col(j);
  rotation.col(i) = c * ci + s * cj;
  rotation.col(j) = c * cj - s * ci;
}

// Pose of the body at `i` from its parent's (formulation.md (3.2)–(3.5)). Placements that
// are pure translations (most of them) skip the rotation products; joints about a
// coordinate axis rotate two columns: this halves the cost of a sample (measured).
inline void placeBody(const TreeJoint& edge, double qj, DynamicsData& d, int i) {
  const int p = edge.parent;
  Matrix3 jointRotation = d.rotation[p];
  Vector3 jointOrigin = d.position[p];
  if (!edge.beforeIsIdentity) {
    jointOrigin.noalias() += d.rotation[p] * edge.before.translation;
    if (!edge.beforeIsTranslation) jointRotation = d.rotation[p] * edge.before.rotation;
  }
  const Vector3 axis =
      edge.axisIndex >= 0 ? Vector3(edge.axisSign * jointRotation.col(edge.axisIndex)) : Vector3(jointRotation * edge.axis);
  d.jointAxis[i] = axis;
  if (edge.prismatic) {
    jointOrigin += qj * axis;
    d.jointMoment[i] = axis;
  } else {
    d.jointMoment[i] = jointOrigin.cross(axis);
    if (edge.axisIndex >= 0) {
      rotateAboutCoordinateAxis(jointRotation, edge.axisIndex, edge.axisSign * std::sin(qj), std::cos(qj));
    } else {
      jointRotation = jointRotation * rotationAboutAxis(edge.axis, qj);
    }
  }
  if (edge.afterIsIdentity) {
    d.rotation[i] = jointRotation;
    d.position[i] = jointOrigin;
  } else {
    d.position[i].noalias() = jointRotation * edge.after.translation;
    d.position[i] += jointOrigin;
    if (edge.afterIsTranslation)
      d.rotation[i] = jointRotation;
    else
      d.rotation[i].noalias() = jointRotation * edge.after.rotation;
  }
}

inline void placeRoot(const DynamicsModel& model, DynamicsData& d) {
  d.rotation[0] = model.rootPose().rotation;
  d.position[0] = model.rootPose().translation;
  d.jointAxis[0].setZero();
  d.jointMoment[0].setZero();
}

}  // namespace

void forwardKinematics(const DynamicsModel& model, DynamicsData& data, const ConstVectorRef& q) {
  MCOPT_HOT_PATH_CHECK(q.size() == model.jointCount(), "forwardKinematics: q must have jointCount() entries");
  MCOPT_HOT_PATH_CHECK(static_cast<int>(data.rotation.size()) == model.bodyCount(),
                       "forwardKinematics: data was made for another model");
  placeRoot(model, data);
  const auto& edges = model.treeJoints();
  const auto& inertias = model.inertias();
  data.comPosition[0] = data.position[0] + data.rotation[0] * inertias[0].com;
  for (int i = 1; i < model.bodyCount(); ++i) {
    placeBody(edges[i], q[edges[i].joint], data, i);
    data.comPosition[i] = data.position[i] + data.rotation[i] * inertias[i].com;
  }
}

void inverseDynamics(const DynamicsModel& model, DynamicsData& d, const ConstVectorRef& q, const ConstVectorRef& v,
                     const ConstVectorRef& a) {
  MCOPT_HOT_PATH_CHECK(q.size() == model.jointCount() && v.size() == model.jointCount() && a.size() == model.jointCount(),
                       "inverseDynamics: q, v and a must have jointCount() entries");
  MCOPT_HOT_PATH_CHECK(static_cast<int>(d.rotation.size()) == model.bodyCount() && d.tau.size() == model.jointCount(),
                       "inverseDynamics: data was made for another model");
  const auto& edges = model.treeJoints();
  const auto& inertias = model.inertias();
  const int nb = model.bodyCount();

  placeRoot(model, d);
  d.linearVelocity[0] = d.rootTwist.head<3>();
  d.angularVelocity[0] = d.rootTwist.tail<3>();
  // Gravity as a fictitious upward acceleration of the reference body.
  d.linearAcceleration[0] = d.rootAcceleration.head<3>() - model.gravity();
  d.angularAcceleration[0] = d.rootAcceleration.tail<3>();

  for (int i = 0; i < nb; ++i) {
    if (i > 0) {
      // Forward recursion: V_i = V_λ + S q̇,  A_i = A_λ + S q̈ + V_i × S q̇ (spatial, at the world origin).
      const TreeJoint& edge = edges[i];
      const int p = edge.parent;
      const double qd = v[edge.joint];
      const double qdd = a[edge.joint];
      placeBody(edge, q[edge.joint], d, i);
      const Vector3 sLin = d.jointMoment[i];
      Vector3 sAng = d.jointAxis[i];
      if (edge.prismatic) sAng.setZero();
      d.linearVelocity[i] = d.linearVelocity[p] + qd * sLin;
      d.angularVelocity[i] = d.angularVelocity[p] + qd * sAng;
      d.linearAcceleration[i] = d.linearAcceleration[p] + qdd * sLin +
                                qd * (d.angularVelocity[i].cross(sLin) + d.linearVelocity[i].cross(sAng));
      d.angularAcceleration[i] = d.angularAcceleration[p] + qdd * sAng + qd * d.angularVelocity[i].cross(sAng);
    }
    // Body wrench, Newton–Euler about the com, moved to the world origin.
    const BodyInertia& inertia = inertias[i];
    const Matrix3& R = d.rotation[i];
    const Vector3 com = d.position[i] + R * inertia.com;
    d.comPosition[i] = com;
    const Vector3& w = d.angularVelocity[i];
    const Vector3& dw = d.angularAcceleration[i];
    const Vector3 comVelocity = d.linearVelocity[i] + w.cross(com);
    const Vector3 comAcceleration = d.linearAcceleration[i] + dw.cross(com) + w.cross(comVelocity);
    const Vector3 wLocal = R.transpose() * w;
    const Vector3 dwLocal = R.transpose() * dw;
    const Vector3 torqueLocal = inertia.inertiaAboutCom * dwLocal + wLocal.cross(inertia.inertiaAboutCom * wLocal);
    d.force[i] = inertia.mass * comAcceleration;
    d.moment[i] = R * torqueLocal + com.cross(d.force[i]);
  }

  // Backward recursion: accumulate toward the reference body; Γ_j = sv·F + sw·M (3.6).
  for (int i = nb - 1; i > 0; --i) {
    const TreeJoint& edge = edges[i];
    const double sAngDotMoment = edge.prismatic ? 0.0 : d.jointAxis[i].dot(d.moment[i]);
    d.tau[edge.joint] = d.jointMoment[i].dot(d.force[i]) + sAngDotMoment;
    d.force[edge.parent] += d.force[i];
    d.moment[edge.parent] += d.moment[i];
  }
  d.referenceWrench.head<3>() = d.force[0];
  d.referenceWrench.tail<3>() = d.moment[0];
}

Vector6 referenceWrenchAtReferenceFrame(const DynamicsModel& model, const DynamicsData& data) {
  Vector6 wrench = data.referenceWrench;
  wrench.tail<3>() -= model.referencePose().translation.cross(data.referenceWrench.head<3>());
  return wrench;
}

}  // namespace mcopt
