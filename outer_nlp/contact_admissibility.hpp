// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A contact's admissibility as rows ≥ 0 on its wrench (formulation.md §5, §10), for the
// formulations whose wrenches the outer NLP holds itself: the reference contact's W0 whenever
// it is the only contact or the others' wrenches are variables (`splines`, `variables`), and
// each environment contact's own wrench there. W_C = (f, m) is the wrench at the contact
// frame C's origin in C's axes; C is fixed to the wrench's frame, so W_C = A W with A constant.
//
// The rows are the scenario's contact model (`inner.contact_model`), the same as the inner
// problem's (inner_qp/contact_problem.hpp):
//   report       six smooth rows (report (2.18)–(2.20), the slip of (2.20) corrected):
//                  f_z                               unilaterality (its lower bound is f_min)
//                  (μ² f_z² − f_x² − f_y²) / (m g)²  friction cone, scaled to the robot's weight
//                  −m_y − x_min f_z,  x_max f_z + m_y centre of pressure x = −m_y / f_z
//                  m_x − y_min f_z,   y_max f_z − m_x centre of pressure y =  m_x / f_z
//                the inner problem keeps the cone as a second-order cone; here it is one
//                smooth row.
//   pyramid,     the inner problem's linear rows G W_C ≤ b (contactModelRows) as b − G W_C ≥ 0,
//   wrench-cone  in N and N m: f_z first, the four centre-of-pressure rows, then the friction
//                facets, or |f_x|, |f_y| ≤ μ̃ f_z and the eight yaw-moment rows.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/robot_files.hpp"
#include "core/spatial.hpp"
#include "inner_qp/contact_problem.hpp"

namespace mcopt {

/// ∂rows/∂W, one row per admissibility row.
using ContactRowsByWrench = Eigen::Matrix<double, Eigen::Dynamic, 6>;

class ContactAdmissibilityRows {
 public:
  /// contactPose: world pose of C; weight: m g [N]. With the identity pose the wrench given to
  /// evaluate() is taken as already in C (a contact whose wrench is a variable of its own).
  ContactAdmissibilityRows(const ContactSurface& surface, const RigidTransform& contactPose, double weight,
                           const ContactProblemSettings& model);

  int rowCount() const { return static_cast<int>(kinds_.size()); }
  /// Row 0 is the normal force f_z (its lower bound is the scenario's f_min, the others' 0).
  ContactRowKind rowKind(int row) const { return kinds_[static_cast<std::size_t>(row)]; }
  /// "f_z", "friction cone", "CoP x ≥ x_min", … (report) or the inner problem's row names.
  const std::string& rowName(int row) const { return names_[static_cast<std::size_t>(row)]; }

  /// Whether a row is quadratic in W (the report model's friction cone); the others are linear.
  /// The exact Hessian's stencils take the degree from it (motion_hessian.cpp).
  bool hasQuadraticRows() const { return smoothCone_; }
  /// The quadratic row's index (the report model's friction cone) and its constant second
  /// derivative in W (6 × 6); -1 and zero for the linear models.
  int quadraticRow() const { return smoothCone_ ? 1 : -1; }
  Eigen::Matrix<double, 6, 6> quadraticRowCurvature() const;
  /// W: world axes, about the world origin (or C's own wrench with the identity pose).
  /// rows: rowCount() values; allocation-free.
  void evaluate(const Vector6& wrench, Eigen::Ref<Eigen::VectorXd> rows) const;
  /// Also ∂rows/∂W, rowCount() × 6, sized by the caller.
  void evaluate(const Vector6& wrench, Eigen::Ref<Eigen::VectorXd> rows, ContactRowsByWrench& rowsByWrench) const;
  /// W_C from W.
  Vector6 contactWrench(const Vector6& wrench) const { return toContact_ * wrench; }
  /// Centre of pressure (x, y) in C; NaN when f_z ≤ 0.
  Eigen::Vector2d centerOfPressure(const Vector6& wrench) const;

 private:
  ContactSurface surface_;
  bool smoothCone_ = true;  ///< the report model's six rows; otherwise linear rows
  Eigen::Matrix<double, 6, 6> toContact_;
  double scale_;
  ContactRowsByWrench linearByWrench_;  ///< −G A (linear models)
  Eigen::VectorXd linearOffset_;        ///< b
  std::vector<std::string> names_;
  std::vector<ContactRowKind> kinds_;
};

}  // namespace mcopt
