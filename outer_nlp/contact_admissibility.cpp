// SPDX-License-Identifier: BSD-3-Clause
#include "outer_nlp/contact_admissibility.hpp"

#include <limits>

#include "inner_qp/multi_contact_dynamics.hpp"

namespace mcopt {

ContactAdmissibilityRows::ContactAdmissibilityRows(const ContactSurface& surface, const RigidTransform& pose,
                                                   double weight, const ContactProblemSettings& model)
    : surface_(surface) {
  // f_C = R_Cᵀ f, m_C = R_Cᵀ (m − p_C × f).
  toContact_.setZero();
  toContact_.topLeftCorner<3, 3>() = pose.rotation.transpose();
  toContact_.bottomRightCorner<3, 3>() = pose.rotation.transpose();
  toContact_.bottomLeftCorner<3, 3>() = -pose.rotation.transpose() * skew(pose.translation);
  const ContactSpec spec = contactSpec(surface);
  AdmissibilityRows rows = contactModelOf(spec, model).admissibilityRows(spec, weight);
  linearByWrench_ = rows.linear * toContact_;
  offset_ = std::move(rows.offset);
  quadraticRow_ = rows.quadraticRow;
  quadratic_ = rows.quadratic;
  names_ = std::move(rows.names);
  kinds_ = std::move(rows.kinds);
}

void ContactAdmissibilityRows::evaluate(const Vector6& wrench, Eigen::Ref<Eigen::VectorXd> rows) const {
  rows = offset_;
  rows.noalias() += linearByWrench_.lazyProduct(wrench);
  if (quadraticRow_ >= 0) {
    const Vector6 w = toContact_ * wrench;
    rows[quadraticRow_] += 0.5 * w.dot(quadratic_ * w);
  }
}

void ContactAdmissibilityRows::evaluate(const Vector6& wrench, Eigen::Ref<Eigen::VectorXd> rows,
                                        ContactRowsByWrench& rowsByWrench) const {
  evaluate(wrench, rows);
  rowsByWrench = linearByWrench_;
  if (quadraticRow_ >= 0) {
    const Vector6 w = toContact_ * wrench;
    rowsByWrench.row(quadraticRow_).noalias() += (quadratic_ * w).transpose() * toContact_;
  }
}

Eigen::Matrix<double, 6, 6> ContactAdmissibilityRows::quadraticRowCurvature() const {
  Eigen::Matrix<double, 6, 6> curvature = Eigen::Matrix<double, 6, 6>::Zero();
  if (quadraticRow_ >= 0) curvature.noalias() = toContact_.transpose() * quadratic_ * toContact_;
  return curvature;
}

Eigen::Vector2d ContactAdmissibilityRows::centerOfPressure(const Vector6& wrench) const {
  const Vector6 w = toContact_ * wrench;
  if (w[2] <= 0.0) return Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  return {-w[4] / w[2], w[3] / w[2]};
}

}  // namespace mcopt
