// SPDX-License-Identifier: BSD-3-Clause
#include "core/dynamics_derivatives.hpp"

#include "core/hot_path_checks.hpp"

namespace mcopt {

DynamicsDerivatives::DynamicsDerivatives(const DynamicsModel& model) {
  const int n = model.jointCount();
  const auto nb = static_cast<std::size_t>(model.bodyCount());
  dtauDq.setZero(n, n);
  dtauDv.setZero(n, n);
  dtauDa.setZero(n, n);
  dwrenchDq.setZero(6, n);
  dwrenchDv.setZero(6, n);
  dwrenchDa.setZero(6, n);
  terms.assign(nb, BodyTerms{});
  for (auto* v : {&motion, &twist, &acceleration, &momentum, &inertiaTimesAcceleration, &wrench, &alpha, &beta, &gamma})
    v->assign(nb, Vector6::Zero());
}

namespace {

using Terms = DynamicsDerivatives::BodyTerms;

MCOPT_ALWAYS_INLINE Vector6 inertiaTimes(const Terms& t, const Vector6& x) {
  Vector6 out;
  out.head<3>() = t.mass * x.head<3>() - t.massCom.cross(x.tail<3>());
  out.tail<3>().noalias() = t.rotational * x.tail<3>();
  out.tail<3>() += t.massCom.cross(x.head<3>());
  return out;
}

// Y x with Y = [[0, [f]×], [−[f]×, E]]; f is the linear momentum of the same bodies.
MCOPT_ALWAYS_INLINE Vector6 velocityCouplingTimes(const Terms& t, const Vector3& linearMomentum, const Vector6& x) {
  Vector6 out;
  out.head<3>() = linearMomentum.cross(x.tail<3>());
  out.tail<3>().noalias() = t.velocityBlock * x.tail<3>();
  out.tail<3>() -= linearMomentum.cross(x.head<3>());
  return out;
}

// Z x with Z = [[0, [z₁]×], [[z₁]×, [z₂]×]].
MCOPT_ALWAYS_INLINE Vector6 momentumCouplingTimes(const Terms& t, const Vector6& x) {
  Vector6 out;
  out.head<3>() = t.z1.cross(x.tail<3>());
  out.tail<3>() = t.z1.cross(x.head<3>()) + t.z2.cross(x.tail<3>());
  return out;
}

}  // namespace

void inverseDynamicsDerivatives(const DynamicsModel& model, DynamicsData& data, DynamicsDerivatives& d,
                                const ConstVectorRef& q, const ConstVectorRef& v, const ConstVectorRef& a) {
  MCOPT_HOT_PATH_CHECK(d.dtauDq.rows() == model.jointCount() && d.dtauDq.cols() == model.jointCount(),
                       "inverseDynamicsDerivatives: derivatives were made for another model");
  inverseDynamics(model, data, q, v, a);
  const auto& edges = model.treeJoints();
  const auto& inertias = model.inertias();
  const int nb = model.bodyCount();

  // Per body: I, V, A, h = I V, P = I A, F = P + V ×* h and the blocks of Y and Z.
  for (int i = 0; i < nb; ++i) {
    const Matrix3& R = data.rotation[i];
    Terms& t = d.terms[i];
    const Vector3& c = data.comPosition[i];
    t.mass = inertias[i].mass;
    t.massCom = t.mass * c;
    t.rotational.noalias() = R * inertias[i].inertiaAboutCom * R.transpose();
    t.rotational += t.mass * (c.squaredNorm() * Matrix3::Identity() - c * c.transpose());
    d.twist[i] << data.linearVelocity[i], data.angularVelocity[i];
    d.acceleration[i] << data.linearAcceleration[i], data.angularAcceleration[i];
    if (i > 0) {
      d.motion[i].head<3>() = data.jointMoment[i];
      d.motion[i].tail<3>() = edges[i].prismatic ? Vector3::Zero() : data.jointAxis[i];
    } else {
      d.motion[i].setZero();
    }
    d.momentum[i] = inertiaTimes(t, d.twist[i]);
    d.inertiaTimesAcceleration[i] = inertiaTimes(t, d.acceleration[i]);
    d.wrench[i] = d.inertiaTimesAcceleration[i] + forceCross(d.twist[i], d.momentum[i]);
    const Vector3 lin = d.twist[i].head<3>(), ang = d.twist[i].tail<3>();
    const Vector3 f = d.momentum[i].head<3>(), n = d.momentum[i].tail<3>();
    const Matrix3 jw = t.rotational * skew(ang);
    t.velocityBlock = lin * t.massCom.transpose() + t.massCom * lin.transpose() -
                      2.0 * t.massCom.dot(lin) * Matrix3::Identity() + jw + jw.transpose();
    t.z1 = f.cross(ang);
    t.z2 = f.cross(lin) + n.cross(ang);
  }
  // Subtree sums, children before parents (pre-order positions, read backwards).
  for (int i = nb - 1; i > 0; --i) {
    const int p = edges[i].parent;
    Terms& to = d.terms[p];
    const Terms& from = d.terms[i];
    to.mass += from.mass;
    to.massCom += from.massCom;
    to.rotational += from.rotational;
    to.velocityBlock += from.velocityBlock;
    to.z1 += from.z1;
    to.z2 += from.z2;
    d.momentum[p] += d.momentum[i];
    d.inertiaTimesAcceleration[p] += d.inertiaTimesAcceleration[i];
    d.wrench[p] += d.wrench[i];
  }
  for (int k = 1; k < nb; ++k) {
    const Vector6& sk = d.motion[k];
    const Terms& t = d.terms[k];
    d.alpha[k] = forceCross(sk, d.wrench[k] - d.inertiaTimesAcceleration[k]) - momentumCouplingTimes(t, sk);
    d.beta[k] = -inertiaTimes(t, sk);
    d.gamma[k] = velocityCouplingTimes(t, d.momentum[k].head<3>(), sk) + forceCross(sk, d.momentum[k]);
  }

  for (int pj = 1; pj < nb; ++pj) {
    const Vector6& sj = d.motion[pj];
    const Vector6& vj = d.twist[pj];
    const Terms& t = d.terms[pj];
    const Vector3 linearMomentum = d.momentum[pj].head<3>();
    const Vector6 cj = motionCross(sj, vj);
    const Vector6 uj = motionCross(sj, d.acceleration[pj]) + motionCross(vj, cj);
    const Vector6 ej = motionCross(sj, vj + d.twist[edges[pj].parent]);
    const int column = edges[pj].joint;
    // The subtree of j: three dot products a joint.
    for (int k = pj; k < model.subtreeEnd(pj); ++k) {
      const int row = edges[k].joint;
      d.dtauDq(row, column) = sj.dot(d.alpha[k]) + uj.dot(d.beta[k]) + cj.dot(d.gamma[k]);
      d.dtauDv(row, column) = ej.dot(d.beta[k]) - sj.dot(d.gamma[k]);
    }
    // Between j and the reference body: S_a · G_j, and W0 takes G_j.
    const Vector6 gq = forceCross(sj, d.inertiaTimesAcceleration[pj]) - inertiaTimes(t, uj) +
                       velocityCouplingTimes(t, linearMomentum, cj) + momentumCouplingTimes(t, sj) -
                       forceCross(cj, d.momentum[pj]);
    const Vector6 gv =
        forceCross(sj, d.momentum[pj]) - velocityCouplingTimes(t, linearMomentum, sj) - inertiaTimes(t, ej);
    // ∂/∂q̈_j: the mass matrix, CRBA-style: F = Iᶜ_j S_j, M(a, j) = M(j, a) = S_a · F.
    const Vector6 ga = -d.beta[pj];
    for (int p = edges[pj].parent; p > 0; p = edges[p].parent) {
      const int row = edges[p].joint;
      d.dtauDq(row, column) = d.motion[p].dot(gq);
      d.dtauDv(row, column) = d.motion[p].dot(gv);
      const double mass = d.motion[p].dot(ga);
      d.dtauDa(row, column) = mass;
      d.dtauDa(column, row) = mass;
    }
    d.dtauDa(column, column) = sj.dot(ga);
    d.dwrenchDq.col(column) = gq;
    d.dwrenchDv.col(column) = gv;
    d.dwrenchDa.col(column) = ga;
  }
}

void wrenchDerivativeAtReferenceFrame(const DynamicsModel& model,
                                      const Eigen::Matrix<double, 6, Eigen::Dynamic>& atOrigin,
                                      Eigen::Matrix<double, 6, Eigen::Dynamic>& out) {
  out = atOrigin;
  const Vector3& p = model.referencePose().translation;
  for (Eigen::Index c = 0; c < out.cols(); ++c) out.col(c).tail<3>() -= p.cross(Vector3(atOrigin.col(c).head<3>()));
}

}  // namespace mcopt
