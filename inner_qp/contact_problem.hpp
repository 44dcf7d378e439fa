// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The inner problem of one time sample (formulation.md §5, §7): the contact wrenches
// Fc = (F_1 … F_nc), each F_i = (f, m) in its own contact frame C_i, that minimise the
// motors' power terms that depend on Fc,
//     Σ_j w_j Γ_j² + l_j Γ_j,   Γ = τ0 − wrenchToTorque · Fc,
// subject to the balance  wrenchToWorld · Fc = W  and, per contact, the constraints of the
// chosen contact model. As a QP:  ½ Fcᵀ H Fc + cᵀ Fc (+ constant),
//     H = 2 J1ᵀ diag(w) J1 + ε 1,   c = −J1ᵀ (2 diag(w) τ0 + l),
// with the documented Tikhonov term ε (H is singular along wrench directions that move no
// joint, e.g. every wrench on the reference body).
//
// Contact models, all in C_i with fz along the surface normal into the robot:
//   report       fz ≥ f_min; fx² + fy² ≤ μ² fz² (a second-order cone, kept separate);
//                centre of pressure in [x_min, x_max] × [y_min, y_max]:
//                x_min fz ≤ −m_y ≤ x_max fz,  y_min fz ≤ m_x ≤ y_max fz      (2.21, with (2.20) corrected)
//   pyramid      the cone replaced by k facets inscribed in it: cos θ_i fx + sin θ_i fy ≤ μ cos(π/k) fz
//   wrench-cone  Caron, Pham, Nakamura (ICRA 2015) for the rectangle, taken about its centre,
//                with the inscribed friction pyramid μ̃ = μ/√2 (their inner approximation):
//                |fx|, |fy| ≤ μ̃ fz; centre of pressure as above; and the yaw bounds
//                −μ̃(X+Y) fz + |Y fx − μ̃ m_x| + |X fy − μ̃ m_y| ≤ m_z ≤ μ̃(X+Y) fz − |Y fx + μ̃ m_x| − |X fy + μ̃ m_y|
//                (X, Y half-sizes), each absolute value expanded into linear rows. Every
//                wrench it admits, the report model admits; it forbids the yaw slip besides.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/spatial.hpp"

namespace mcopt {

enum class ContactModel { Report, Pyramid, WrenchCone };

/// One contact of an inner problem: frame C in the world (z = normal into the robot),
/// friction μ > 0, rectangle [xMin, xMax] × [yMin, yMax] in C.
struct ContactSpec {
  std::string name;
  RigidTransform pose;
  double friction = 0.7;
  double xMin = 0, xMax = 0, yMin = 0, yMax = 0;
  double minNormalForce = 0.0;  ///< f_min ≥ 0
};

struct ContactProblemSettings {
  ContactModel model = ContactModel::Report;
  int pyramidFacets = 8;    ///< k ≥ 3
  double tikhonov = 1e-9;   ///< ε added to H's diagonal; not part of the reported objective
};

/// A second-order cone ‖(F[index], F[index + 1])‖ ≤ μ F[index + 2] (report model).
struct FrictionCone {
  int index = 0;
  double friction = 0.0;
};

/// What a contact-model row bounds (results group violations by it).
enum class ContactRowKind { NormalForce, CenterOfPressure, Friction, Yaw };

/// One contact's linear rows in its own frame, rows · F ≤ bound with F = (f, m) in C: the
/// model's rows of assembleContactProblem (the report model's friction cone, a second-order
/// cone, is not among them). The single-level outer formulations hold the same rows on
/// their wrench variables (outer_nlp/contact_admissibility.hpp).
struct ContactModelRows {
  Eigen::Matrix<double, Eigen::Dynamic, 6> rows;
  Eigen::VectorXd bound;
  std::vector<std::string> names;     ///< fz_min, cop_x_max, …, facet_<k> or fx_max, …, yaw_min_3
  std::vector<ContactRowKind> kinds;
};
/// Rows a contact has under the model: 5 (report), 5 + facets (pyramid), 17 (wrench cone).
int contactModelRowCount(const ContactProblemSettings& settings);
/// Throws InputError for fewer than 3 pyramid facets.
ContactModelRows contactModelRows(const ContactSpec& contact, const ContactProblemSettings& settings);

/// Problem data, sized once per contact set and overwritten per sample.
struct ContactProblem {
  int contactCount = 0;
  Eigen::MatrixXd hessian;                           ///< H, 6nc × 6nc, with ε
  Eigen::VectorXd gradient;                          ///< c, 6nc
  double constant = 0.0;                             ///< Σ w τ0² + l τ0: objective at Fc = 0
  double tikhonov = 0.0;
  Eigen::Matrix<double, 6, Eigen::Dynamic> balance;  ///< wrenchToWorld, 6 × 6nc
  Vector6 balanceTarget = Vector6::Zero();           ///< W: world axes, about the world origin
  Eigen::MatrixXd inequality;                        ///< G, rows × 6nc: G Fc ≤ bound
  Eigen::VectorXd inequalityBound;
  std::vector<FrictionCone> cones;                   ///< report model only
  /// Name of each linear row, "<contact>.<row>": fz_min, cop_x_max, cop_x_min, cop_y_max,
  /// cop_y_min, then facet_<k> (pyramid) or fx_max, fx_min, fy_max, fy_min, yaw_<k> (wrench cone).
  std::vector<std::string> rowNames;
  std::vector<std::string> contactNames;
  Eigen::MatrixXd weightedWrenchToTorque;            ///< scratch of updateObjective, n × 6nc

  /// Σ w Γ² + l Γ at Fc, without the Tikhonov term (what results report).
  double objective(const Eigen::Ref<const Eigen::VectorXd>& wrenches) const;
  /// Largest violation of the balance, the linear rows and the cones (0 when feasible).
  double constraintViolation(const Eigen::Ref<const Eigen::VectorXd>& wrenches) const;
};

/// Assembles the problem. wrenchToTorque: n × 6nc; tau0, torqueWeights (> 0), torqueLinear:
/// n; balanceWrench: world axes about the world origin. Throws InputError naming the
/// contact and field for sizes that disagree, μ ≤ 0, an empty rectangle or a non-finite value.
ContactProblem assembleContactProblem(const std::vector<ContactSpec>& contacts,
                                      const Eigen::Ref<const Eigen::MatrixXd>& wrenchToTorque,
                                      const Eigen::Ref<const Eigen::VectorXd>& tau0, const Vector6& balanceWrench,
                                      const Eigen::Ref<const Eigen::VectorXd>& torqueWeights,
                                      const Eigen::Ref<const Eigen::VectorXd>& torqueLinear,
                                      const ContactProblemSettings& settings);

/// Overwrites the objective (hessian, gradient, constant) for a new sample of a problem
/// assembled with the same contact set and joint count; the contact rows are unchanged.
/// Allocation-free (the per-sample path of the bilevel loop). Sizes and finiteness as for
/// assembleContactProblem; a size mismatch throws InputError.
void updateObjective(ContactProblem& problem, const Eigen::Ref<const Eigen::MatrixXd>& wrenchToTorque,
                     const Eigen::Ref<const Eigen::VectorXd>& tau0, const Eigen::Ref<const Eigen::VectorXd>& torqueWeights,
                     const Eigen::Ref<const Eigen::VectorXd>& torqueLinear);

/// Moves contact i to a new world pose (its balance columns); allocation-free.
void setContactPose(ContactProblem& problem, int contact, const RigidTransform& pose);

}  // namespace mcopt
