// SPDX-License-Identifier: BSD-3-Clause
#include "outer_nlp/contact_admissibility.hpp"

#include <limits>

#include "inner_qp/multi_contact_dynamics.hpp"

namespace mcopt {

ContactAdmissibilityRows::ContactAdmissibilityRows(const ContactSurface& surface, const RigidTransform& pose,
                                                   double weight, const ContactProblemSettings& model)
    : surface_(surface), smoothCone_(model.model == ContactModel::Report), scale_(1.0 / (weight * weight)) {
  // f_C = R_Cᵀ f, m_C = R_Cᵀ (m − p_C × f).
  toContact_.setZero();
  toContact_.topLeftCorner<3, 3>() = pose.rotation.transpose();
  toContact_.bottomRightCorner<3, 3>() = pose.rotation.transpose();
  toContact_.bottomLeftCorner<3, 3>() = -pose.rotation.transpose() * skew(pose.translation);
  if (smoothCone_) {
    names_ = {"f_z", "friction cone", "CoP x ≥ x_min", "CoP x ≤ x_max", "CoP y ≥ y_min", "CoP y ≤ y_max"};
    kinds_ = {ContactRowKind::NormalForce,      ContactRowKind::Friction,         ContactRowKind::CenterOfPressure,
              ContactRowKind::CenterOfPressure, ContactRowKind::CenterOfPressure, ContactRowKind::CenterOfPressure};
    return;
  }
  // The inner problem's rows with f_min = 0: row 0 is then f_z itself, bounded by f_min as
  // the report model's is.
  const ContactModelRows rows = contactModelRows(contactSpec(surface), model);
  linearByWrench_ = -rows.rows * toContact_;
  linearOffset_ = rows.bound;
  names_ = rows.names;
  kinds_ = rows.kinds;
}

void ContactAdmissibilityRows::evaluate(const Vector6& wrench, Eigen::Ref<Eigen::VectorXd> rows) const {
  if (!smoothCone_) {
    rows = linearOffset_;
    rows.noalias() += linearByWrench_.lazyProduct(wrench);
    return;
  }
  const Vector6 w = toContact_ * wrench;
  const double fx = w[0], fy = w[1], fz = w[2], mx = w[3], my = w[4];
  const double mu2 = surface_.friction * surface_.friction;
  rows << fz, (mu2 * fz * fz - fx * fx - fy * fy) * scale_, -my - surface_.xMin * fz, surface_.xMax * fz + my,
      mx - surface_.yMin * fz, surface_.yMax * fz - mx;
}

void ContactAdmissibilityRows::evaluate(const Vector6& wrench, Eigen::Ref<Eigen::VectorXd> rows,
                                        ContactRowsByWrench& rowsByWrench) const {
  evaluate(wrench, rows);
  if (!smoothCone_) {
    rowsByWrench = linearByWrench_;
    return;
  }
  const Vector6 w = toContact_ * wrench;
  const double mu2 = surface_.friction * surface_.friction;
  Eigen::Matrix<double, 6, 6> rowsByContactWrench = Eigen::Matrix<double, 6, 6>::Zero();
  rowsByContactWrench(0, 2) = 1.0;
  rowsByContactWrench.row(1).head<3>() << -2.0 * w[0] * scale_, -2.0 * w[1] * scale_, 2.0 * mu2 * w[2] * scale_;
  rowsByContactWrench(2, 2) = -surface_.xMin, rowsByContactWrench(2, 4) = -1.0;
  rowsByContactWrench(3, 2) = surface_.xMax, rowsByContactWrench(3, 4) = 1.0;
  rowsByContactWrench(4, 2) = -surface_.yMin, rowsByContactWrench(4, 3) = 1.0;
  rowsByContactWrench(5, 2) = surface_.yMax, rowsByContactWrench(5, 3) = -1.0;
  rowsByWrench.noalias() = rowsByContactWrench * toContact_;
}

Eigen::Matrix<double, 6, 6> ContactAdmissibilityRows::quadraticRowCurvature() const {
  Eigen::Matrix<double, 6, 6> curvature = Eigen::Matrix<double, 6, 6>::Zero();
  if (!smoothCone_) return curvature;
  // (μ² f_z² − f_x² − f_y²) / (m g)² in W_C = A W: Aᵀ diag(−2, −2, 2μ², 0, 0, 0) A / (m g)².
  Eigen::Matrix<double, 6, 1> diagonal = Eigen::Matrix<double, 6, 1>::Zero();
  diagonal << -2.0, -2.0, 2.0 * surface_.friction * surface_.friction, 0.0, 0.0, 0.0;
  curvature.noalias() = toContact_.transpose() * (scale_ * diagonal).asDiagonal() * toContact_;
  return curvature;
}

Eigen::Vector2d ContactAdmissibilityRows::centerOfPressure(const Vector6& wrench) const {
  const Vector6 w = toContact_ * wrench;
  if (w[2] <= 0.0) return Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  return {-w[4] / w[2], w[3] / w[2]};
}

}  // namespace mcopt
