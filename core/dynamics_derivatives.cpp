#include "core/dynamics_derivatives.hpp"

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
  inertia.assign(nb, Matrix6::Zero());
  compositeInertia.assign(nb, Matrix6::Zero());
  for (auto* v : {&motion, &twist, &acceleration, &momentum, &inertiaTimesAcceleration, &compositeWrench, &accumulated})
    v->assign(nb, Vector6::Zero());
}

namespace {

// Γ derivative columns for one direction once the subtree sums G of ∂F are in `acc`:
// inside the subtree ∂Γ_i = (S_j × S_i)·F^c_i (position only) + S_i·G_i; on the path to the
// root ∂Γ_a = S_a·G_j (S_a does not move); W0 takes G_j.
template <bool kPositionDerivative>
void scatterDirection(const DynamicsModel& model, const DynamicsDerivatives& d, int pj, Eigen::MatrixXd& dtau,
                      Eigen::Matrix<double, 6, Eigen::Dynamic>& dwrench) {
  const auto& edges = model.treeJoints();
  const int column = edges[pj].joint;
  const Vector6& sj = d.motion[pj];
  const int end = model.subtreeEnd(pj);
  for (int i = pj; i < end; ++i) {
    double value = d.motion[i].dot(d.accumulated[i]);
    if (kPositionDerivative && i != pj) value += motionCross(sj, d.motion[i]).dot(d.compositeWrench[i]);
    dtau(edges[i].joint, column) = value;
  }
  for (int p = edges[pj].parent; p > 0; p = edges[p].parent)
    dtau(edges[p].joint, column) = d.motion[p].dot(d.accumulated[pj]);
  dwrench.col(column) = d.accumulated[pj];
}

// Sums `accumulated` over the subtree of pj, in place (children follow parents in pre-order).
void accumulateSubtree(const DynamicsModel& model, DynamicsDerivatives& d, int pj) {
  const auto& edges = model.treeJoints();
  for (int i = model.subtreeEnd(pj) - 1; i > pj; --i) d.accumulated[edges[i].parent] += d.accumulated[i];
}

}  // namespace

void inverseDynamicsDerivatives(const DynamicsModel& model, DynamicsData& data, DynamicsDerivatives& d,
                                const ConstVectorRef& q, const ConstVectorRef& v, const ConstVectorRef& a) {
  inverseDynamics(model, data, q, v, a);
  const auto& edges = model.treeJoints();
  const auto& inertias = model.inertias();
  const int nb = model.bodyCount();

  // World-frame spatial quantities of every body.
  for (int i = 0; i < nb; ++i) {
    const Matrix3& R = data.rotation[i];
    d.inertia[i] = spatialInertia(inertias[i].mass, data.comPosition[i], R * inertias[i].inertiaAboutCom * R.transpose());
    d.twist[i] << data.linearVelocity[i], data.angularVelocity[i];
    d.acceleration[i] << data.linearAcceleration[i], data.angularAcceleration[i];
    if (i > 0) {
      d.motion[i].head<3>() = data.jointMoment[i];
      d.motion[i].tail<3>() = edges[i].prismatic ? Vector3::Zero() : data.jointAxis[i];
    } else {
      d.motion[i].setZero();
    }
    d.momentum[i].noalias() = d.inertia[i] * d.twist[i];
    d.inertiaTimesAcceleration[i].noalias() = d.inertia[i] * d.acceleration[i];
    d.compositeWrench[i] = d.inertiaTimesAcceleration[i] + forceCross(d.twist[i], d.momentum[i]);
    d.compositeInertia[i] = d.inertia[i];
  }
  for (int i = nb - 1; i > 0; --i) {
    d.compositeWrench[edges[i].parent] += d.compositeWrench[i];
    d.compositeInertia[edges[i].parent] += d.compositeInertia[i];
  }

  for (int pj = 1; pj < nb; ++pj) {
    const Vector6& sj = d.motion[pj];
    const Vector6& vj = d.twist[pj];
    const Vector6& aj = d.acceleration[pj];
    const Vector6& vParent = d.twist[edges[pj].parent];
    const Vector6 sjCrossVj = motionCross(sj, vj);
    const int end = model.subtreeEnd(pj);

    // ∂/∂q_j. With c = S_j × V_j the products regroup as
    //   ∂(I A) = S ×* (I A) + I ((V_i − V_j) × c − S × A_j),   ∂(I V) = S ×* (I V) − I c
    // so each body costs two 6 × 6 products.
    const Vector6 sjCrossAj = motionCross(sj, aj);
    for (int i = pj; i < end; ++i) {
      const Matrix6& I = d.inertia[i];
      const Vector6& vi = d.twist[i];
      const Vector6 dV = motionCross(sj, vi - vj);
      const Vector6 dMomentum = forceCross(sj, d.momentum[i]) - I * sjCrossVj;
      d.accumulated[i] = forceCross(sj, d.inertiaTimesAcceleration[i]) +
                         I * (motionCross(vi - vj, sjCrossVj) - sjCrossAj) + forceCross(dV, d.momentum[i]) +
                         forceCross(vi, dMomentum);
    }
    accumulateSubtree(model, d, pj);
    scatterDirection<true>(model, d, pj, d.dtauDq, d.dwrenchDq);

    // ∂/∂q̇_j
    for (int i = pj; i < end; ++i) {
      const Matrix6& I = d.inertia[i];
      const Vector6& vi = d.twist[i];
      const Vector6 dA = motionCross(sj, vi - vj - vParent);
      d.accumulated[i] = I * dA + forceCross(sj, d.momentum[i]) + forceCross(vi, I * sj);
    }
    accumulateSubtree(model, d, pj);
    scatterDirection<false>(model, d, pj, d.dtauDv, d.dwrenchDv);

    // ∂/∂q̈_j: the mass matrix, CRBA-style. F = I^c_j S_j; M(a, j) = M(j, a) = S_a · F for
    // j and each joint a between j and the reference body; W0 takes F.
    const Vector6 force = d.compositeInertia[pj] * sj;
    const int column = edges[pj].joint;
    for (int p = pj; p > 0; p = edges[p].parent) {
      const double value = d.motion[p].dot(force);
      d.dtauDa(edges[p].joint, column) = value;
      d.dtauDa(column, edges[p].joint) = value;
    }
    d.dwrenchDa.col(column) = force;
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
