// SPDX-License-Identifier: BSD-3-Clause
#include "core/inverse_dynamics.hpp"

#include <cmath>

#include "core/hot_path_checks.hpp"
#include "core/spatial_algebra.hpp"

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
MCOPT_ALWAYS_INLINE void rotateAboutCoordinateAxis(Matrix3& rotation, int k, double s, double c) {
  const int i = (k + 1) % 3, j = (k + 2) % 3;  // Rot(e_k) turns e_i toward e_j
  const Vector3 ci = rotation.col(i), cj = rotation.col(j);
  rotation.col(i) = c * ci + s * cj;
  rotation.col(j) = c * cj - s * ci;
}

// Pose of the body at `i` from its parent's (formulation.md (3.2)–(3.5)). Placements that
// are pure translations (most of them) skip the rotation products; joints about a
// coordinate axis rotate two columns: this halves the cost of a sample (measured).
MCOPT_ALWAYS_INLINE void placeBody(const TreeJoint& edge, double qj, DynamicsData& d, int i) {
  const Matrix3& parentRotation = d.rotation[edge.parent];
  Matrix3& rotation = d.rotation[i];  // built in place: the joint frame's, then the body's
  Vector3 jointOrigin = d.position[edge.parent];
  if (edge.beforeIsIdentity) {
    rotation = parentRotation;
  } else {
    jointOrigin.noalias() += parentRotation * edge.before.translation;
    if (edge.beforeIsTranslation)
      rotation = parentRotation;
    else
      rotation.noalias() = parentRotation * edge.before.rotation;
  }
  const Vector3 axis =
      edge.axisIndex >= 0 ? Vector3(edge.axisSign * rotation.col(edge.axisIndex)) : Vector3(rotation * edge.axis);
  d.jointAxis[i] = axis;
  if (edge.prismatic) {
    jointOrigin += qj * axis;
    d.jointMoment[i] = axis;
  } else {
    d.jointMoment[i] = cross3(jointOrigin, axis);
    if (edge.axisIndex >= 0) {
      double sine = 0.0, cosine = 1.0;
      ::sincos(qj, &sine, &cosine);  // one call for both (GCC merges sin and cos only without errno)
      rotateAboutCoordinateAxis(rotation, edge.axisIndex, edge.axisSign * sine, cosine);
    } else {
      rotation = rotation * rotationAboutAxis(edge.axis, qj);
    }
  }
  if (edge.afterIsIdentity) {
    d.position[i] = jointOrigin;
  } else {
    d.position[i].noalias() = rotation * edge.after.translation;
    d.position[i] += jointOrigin;
    if (!edge.afterIsTranslation) rotation = rotation * edge.after.rotation;
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
      const Vector3 sAng = edge.prismatic ? Vector3::Zero() : d.jointAxis[i];
      const Vector3 lin = d.linearVelocity[p] + qd * sLin;
      const Vector3 ang = d.angularVelocity[p] + qd * sAng;
      d.linearVelocity[i] = lin;
      d.angularVelocity[i] = ang;
      d.linearAcceleration[i] = d.linearAcceleration[p] + qdd * sLin + qd * (cross3(ang, sLin) + cross3(lin, sAng));
      d.angularAcceleration[i] = d.angularAcceleration[p] + qdd * sAng + qd * cross3(ang, sAng);
    }
    // Body wrench, Newton–Euler about the com, moved to the world origin.
    const BodyInertia& inertia = inertias[i];
    const Matrix3& R = d.rotation[i];
    const Vector3 com = d.position[i] + R * inertia.com;
    d.comPosition[i] = com;
    const Vector3& w = d.angularVelocity[i];
    const Vector3& dw = d.angularAcceleration[i];
    const Vector3 comVelocity = d.linearVelocity[i] + cross3(w, com);
    const Vector3 comAcceleration = d.linearAcceleration[i] + cross3(dw, com) + cross3(w, comVelocity);
    const Vector3 wLocal = R.transpose() * w;
    const Vector3 dwLocal = R.transpose() * dw;
    const Vector3 torqueLocal = inertia.inertiaAboutCom * dwLocal + cross3(wLocal, Vector3(inertia.inertiaAboutCom * wLocal));
    d.force[i] = inertia.mass * comAcceleration;
    d.moment[i] = R * torqueLocal + cross3(com, d.force[i]);
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
