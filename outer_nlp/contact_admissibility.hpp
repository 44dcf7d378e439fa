// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A contact's admissibility as rows ≥ 0 on its wrench (formulation.md §5, §10), for the
// formulations whose wrenches the outer NLP holds itself: the reference contact's W0 whenever
// it is the only contact or the others' wrenches are variables (`splines`, `variables`), and
// each environment contact's own wrench there. W_C = (f, m) is the wrench at the contact
// frame C's origin in C's axes; C is fixed to the wrench's frame, so W_C = A W with A constant.
//
// The rows are the scenario's contact model's (`inner.contact_model`,
// ContactModel::admissibilityRows, inner_qp/contact_model.hpp): affine in W_C, with at most
// one quadratic row, f_z first.
//   report       six smooth rows (report (2.18)–(2.20), the slip of (2.20) corrected): f_z;
//                (μ² f_z² − f_x² − f_y²) / (m g)², the friction cone scaled to the robot's
//                weight (the inner problem keeps it as a second-order cone); the four
//                centre-of-pressure rows.
//   pyramid,     the inner problem's linear rows G W_C ≤ b as b − G W_C ≥ 0, in N and N m:
//   wrench-cone  f_z first, the four centre-of-pressure rows, then the friction facets, or
//                |f_x|, |f_y| ≤ μ̃ f_z and the eight yaw-moment rows.

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
  bool hasQuadraticRows() const { return quadraticRow_ >= 0; }
  /// The quadratic row's index and its constant second derivative in W (6 × 6); -1 and zero
  /// for a model without one.
  int quadraticRow() const { return quadraticRow_; }
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
  Eigen::Matrix<double, 6, 6> toContact_;
  ContactRowsByWrench linearByWrench_;  ///< L A: the affine part's ∂/∂W
  Eigen::VectorXd offset_;
  int quadraticRow_ = -1;
  Eigen::Matrix<double, 6, 6> quadratic_;  ///< Q in C: the row's ½ W_Cᵀ Q W_C
  std::vector<std::string> names_;
  std::vector<ContactRowKind> kinds_;
};

}  // namespace mcopt
