#pragma once
// The support contact's admissibility as six smooth rows ≥ 0 (formulation.md §5, §10;
// report (2.18)–(2.20) with the slip of (2.20) corrected): with the reference body's
// wrench W0 moved to the contact frame C, W_C = (f, m) at C's origin in C's axes,
//   f_z − f_min                       unilaterality
//   (μ² f_z² − f_x² − f_y²) / (m g)²  friction cone (scaled to the robot's weight)
//   −m_y − x_min f_z,  x_max f_z + m_y centre of pressure x = −m_y / f_z in [x_min, x_max]
//   m_x − y_min f_z,   y_max f_z − m_x centre of pressure y =  m_x / f_z in [y_min, y_max]
// The contact frame is fixed (it is on the reference body), so W_C = A W0 with A constant.

#include <Eigen/Core>

#include "core/robot_files.hpp"
#include "core/spatial.hpp"

namespace mcopt {

class SupportContactRows {
 public:
  /// contactPose: world pose of C; weight: m g [N]. With the identity pose the wrench given to
  /// evaluate() is taken as already in C (a contact whose wrench is a variable of its own).
  SupportContactRows(const ContactSurface& surface, const RigidTransform& contactPose, double weight);

  /// W0: world axes, about the world origin. rows: the six values (unilaterality without f_min).
  void evaluate(const Vector6& referenceWrench, Eigen::Ref<Vector6> rows) const;
  /// Also ∂rows/∂W0 (6 × 6).
  void evaluate(const Vector6& referenceWrench, Eigen::Ref<Vector6> rows, Eigen::Matrix<double, 6, 6>& rowsByWrench) const;
  /// "f_z", "friction cone", "CoP x ≥ x_min", … for row 0 … 5.
  static const char* rowName(int row);
  /// W_C from W0.
  Vector6 contactWrench(const Vector6& referenceWrench) const { return toContact_ * referenceWrench; }
  /// Centre of pressure (x, y) in C; NaN when f_z ≤ 0.
  Eigen::Vector2d centerOfPressure(const Vector6& referenceWrench) const;

 private:
  ContactSurface surface_;
  Eigen::Matrix<double, 6, 6> toContact_;
  double scale_;
};

}  // namespace mcopt
