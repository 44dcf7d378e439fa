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
  for (auto* v : {&motion, &twist, &acceleration, &momentum, &inertiaTimesAcceleration, &wrench}) v->assign(nb, Vector6::Zero());
  rowFactors.setZero(18, model.bodyCount());
  columnFactors.setZero(18, model.bodyCount());
  subtreeWrench.setZero(18, model.bodyCount());
}

namespace {

using Terms = DynamicsDerivatives::BodyTerms;

MCOPT_ALWAYS_INLINE Vector6 inertiaTimes(const Terms& t, const Vector6& x) {
  Vector6 out;
  out.head<3>() = t.mass * x.head<3>() - cross3(t.massCom, x.tail<3>());
  out.tail<3>().noalias() = t.rotational * x.tail<3>();
  out.tail<3>() += cross3(t.massCom, x.head<3>());
  return out;
}

// Y x with Y = [[0, [f]×], [−[f]×, E]]; f is the linear momentum of the same bodies.
MCOPT_ALWAYS_INLINE Vector6 velocityCouplingTimes(const Terms& t, const Vector3& linearMomentum, const Vector6& x) {
  Vector6 out;
  out.head<3>() = cross3(linearMomentum, x.tail<3>());
  out.tail<3>().noalias() = t.velocityBlock * x.tail<3>();
  out.tail<3>() -= cross3(linearMomentum, x.head<3>());
  return out;
}

// Z x with Z = [[0, [z₁]×], [[z₁]×, [z₂]×]].
MCOPT_ALWAYS_INLINE Vector6 momentumCouplingTimes(const Terms& t, const Vector6& x) {
  Vector6 out;
  out.head<3>() = cross3(t.z1, x.tail<3>());
  out.tail<3>() = cross3(t.z1, x.head<3>()) + cross3(t.z2, x.tail<3>());
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
    const Vector3& lin = data.linearVelocity[i];
    const Vector3& ang = data.angularVelocity[i];
    const Vector3 f = d.momentum[i].head<3>(), n = d.momentum[i].tail<3>();
    const Matrix3 jw = t.rotational * skew(ang);
    t.velocityBlock = lin * t.massCom.transpose() + t.massCom * lin.transpose() -
                      2.0 * t.massCom.dot(lin) * Matrix3::Identity() + jw + jw.transpose();
    t.z1 = cross3(f, ang);
    t.z2 = cross3(f, lin) + cross3(n, ang);
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
  // Per joint j: its row factors (α, β, γ), its column factors and G_j; the diagonal entries.
  for (int j = 1; j < nb; ++j) {
    const Vector6& sj = d.motion[j];
    const Vector6& vj = d.twist[j];
    const Terms& t = d.terms[j];
    const Vector6& h = d.momentum[j];
    const Vector6& pj = d.inertiaTimesAcceleration[j];
    const Vector3 linearMomentum = h.head<3>();
    const Vector6 ys = velocityCouplingTimes(t, linearMomentum, sj);  // Y S
    const Vector6 zs = momentumCouplingTimes(t, sj);                  // Z S
    const Vector6 sh = forceCross(sj, h);                             // S ×* h
    const Vector6 is = inertiaTimes(t, sj);                           // I S
    const Vector6 alpha = forceCross(sj, d.wrench[j] - pj) - zs;
    const Vector6 gamma = ys + sh;
    const Vector6 cj = motionCross(sj, vj);
    const Vector6 uj = motionCross(sj, d.acceleration[j]) + motionCross(vj, cj);
    const Vector6 ej = motionCross(sj, vj + d.twist[edges[j].parent]);
    auto rows = d.rowFactors.col(j);
    rows.segment<6>(0) = alpha;
    rows.segment<6>(6) = -is;
    rows.segment<6>(12) = gamma;
    auto factors = d.columnFactors.col(j);
    factors.segment<6>(0) = uj;
    factors.segment<6>(6) = cj;
    factors.segment<6>(12) = ej;
    // Between j and the reference body: S_a · G_j, and W0 takes G_j.
    auto g = d.subtreeWrench.col(j);
    g.segment<6>(0) = forceCross(sj, pj) - inertiaTimes(t, uj) + velocityCouplingTimes(t, linearMomentum, cj) + zs -
                      forceCross(cj, h);
    g.segment<6>(6) = sh - ys - inertiaTimes(t, ej);
    g.segment<6>(12) = is;  // ∂/∂q̈_j: the mass matrix, CRBA-style: M(a, j) = S_a · Iᶜ_j S_j
    const int column = model.jointAtPosition(j);
    d.dtauDq(column, column) = sj.dot(alpha) + uj.dot(rows.segment<6>(6)) + cj.dot(gamma);
    d.dtauDv(column, column) = ej.dot(rows.segment<6>(6)) - sj.dot(gamma);
    d.dtauDa(column, column) = sj.dot(is);
    d.dwrenchDq.col(column) = g.segment<6>(0);
    d.dwrenchDv.col(column) = g.segment<6>(6);
    d.dwrenchDa.col(column) = is;
  }
  // Each pair of a joint j and a joint k it carries (k in the subtree of j, k ≠ j): the
  // subtree's rows, ∂Γ_k/∂q_j = S_j·α_k + u_j·β_k + c_j·γ_k and ∂Γ_k/∂q̇_j = e_j·β_k − S_j·γ_k,
  // and the other way, ∂Γ_j/∂(q_k, q̇_k, q̈_k) = S_j · G_k (the mass matrix's both entries).
  for (int j = 1; j < nb; ++j) {
    const int column = model.jointAtPosition(j);
    const Vector6 sj = d.motion[j];
    const Vector6 uj = d.columnFactors.col(j).segment<6>(0);
    const Vector6 cj = d.columnFactors.col(j).segment<6>(6);
    const Vector6 ej = d.columnFactors.col(j).segment<6>(12);
    for (int k = j + 1; k < model.subtreeEnd(j); ++k) {
      const int row = model.jointAtPosition(k);
      const auto rows = d.rowFactors.col(k);
      const auto g = d.subtreeWrench.col(k);
      d.dtauDq(row, column) = sj.dot(rows.segment<6>(0)) + uj.dot(rows.segment<6>(6)) + cj.dot(rows.segment<6>(12));
      d.dtauDv(row, column) = ej.dot(rows.segment<6>(6)) - sj.dot(rows.segment<6>(12));
      d.dtauDq(column, row) = sj.dot(g.segment<6>(0));
      d.dtauDv(column, row) = sj.dot(g.segment<6>(6));
      const double mass = sj.dot(g.segment<6>(12));
      d.dtauDa(column, row) = mass;
      d.dtauDa(row, column) = mass;
    }
  }
}

void wrenchDerivativeAtReferenceFrame(const DynamicsModel& model,
                                      const Eigen::Matrix<double, 6, Eigen::Dynamic>& atOrigin,
                                      Eigen::Matrix<double, 6, Eigen::Dynamic>& out) {
  out = atOrigin;
  const Vector3& p = model.referencePose().translation;
  for (Eigen::Index c = 0; c < out.cols(); ++c) out.col(c).tail<3>() -= cross3(p, Vector3(atOrigin.col(c).head<3>()));
}

}  // namespace mcopt
