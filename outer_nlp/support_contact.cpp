#include "outer_nlp/support_contact.hpp"

#include <limits>

namespace mcopt {

SupportContactRows::SupportContactRows(const ContactSurface& surface, const RigidTransform& pose, double weight)
    : surface_(surface), scale_(1.0 / (weight * weight)) {
  // f_C = R_Cᵀ f, m_C = R_Cᵀ (m − p_C × f).
  toContact_.setZero();
  toContact_.topLeftCorner<3, 3>() = pose.rotation.transpose();
  toContact_.bottomRightCorner<3, 3>() = pose.rotation.transpose();
  toContact_.bottomLeftCorner<3, 3>() = -pose.rotation.transpose() * skew(pose.translation);
}

void SupportContactRows::evaluate(const Vector6& referenceWrench, Eigen::Ref<Vector6> rows) const {
  const Vector6 w = toContact_ * referenceWrench;
  const double fx = w[0], fy = w[1], fz = w[2], mx = w[3], my = w[4];
  const double mu2 = surface_.friction * surface_.friction;
  rows << fz, (mu2 * fz * fz - fx * fx - fy * fy) * scale_, -my - surface_.xMin * fz, surface_.xMax * fz + my,
      mx - surface_.yMin * fz, surface_.yMax * fz - mx;
}

void SupportContactRows::evaluate(const Vector6& referenceWrench, Eigen::Ref<Vector6> rows,
                                  Eigen::Matrix<double, 6, 6>& rowsByWrench) const {
  evaluate(referenceWrench, rows);
  const Vector6 w = toContact_ * referenceWrench;
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

const char* SupportContactRows::rowName(int row) {
  static const char* names[] = {"f_z", "friction cone", "CoP x ≥ x_min", "CoP x ≤ x_max", "CoP y ≥ y_min", "CoP y ≤ y_max"};
  return row >= 0 && row < 6 ? names[row] : "?";
}

Eigen::Vector2d SupportContactRows::centerOfPressure(const Vector6& referenceWrench) const {
  const Vector6 w = toContact_ * referenceWrench;
  if (w[2] <= 0.0) return Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  return {-w[4] / w[2], w[3] / w[2]};
}

}  // namespace mcopt
