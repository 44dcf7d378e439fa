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
// Each contact's constraints come from the contact model (inner_qp/contact_model.hpp):
// report, pyramid or wrench-cone; the problem records which rows and which cone belong to
// which contact, so that nothing downstream assumes a layout.

#include <Eigen/Core>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/spatial.hpp"
#include "inner_qp/contact_model.hpp"

namespace mcopt {

struct ContactProblemSettings {
  std::shared_ptr<const ContactModel> model = makeReportContactModel();
  /// Contacts whose model is not `model`, by contact name (a scenario's `contacts[k].model`);
  /// a ContactSpec's own `model` comes first.
  std::map<std::string, std::shared_ptr<const ContactModel>> byContact;
  double tikhonov = 1e-9;   ///< ε added to H's diagonal; not part of the reported objective
};

/// A second-order cone ‖(F[index], F[index + 1])‖ ≤ μ F[index + 2] (a model with
/// hasSecondOrderCone(), e.g. the report's).
struct FrictionCone {
  int index = 0;
  double friction = 0.0;
  int contact = 0;  ///< the contact it belongs to
};

/// Problem data, sized once per contact set and overwritten per sample.
/// Fc stacks each contact's wrench variables: (f, m), or f alone for a model whose wrenchSize()
/// is 3 (contactColumn); m = Σ of those sizes, 6nc when every contact has six.
struct ContactProblem {
  int contactCount = 0;
  Eigen::MatrixXd hessian;                           ///< H, m × m, with ε
  Eigen::VectorXd gradient;                          ///< c, m
  double constant = 0.0;                             ///< Σ w τ0² + l τ0: objective at Fc = 0
  double tikhonov = 0.0;
  Eigen::Matrix<double, 6, Eigen::Dynamic> balance;  ///< wrenchToWorld, 6 × m
  Vector6 balanceTarget = Vector6::Zero();           ///< W: world axes, about the world origin
  Eigen::MatrixXd inequality;                        ///< G, rows × m: G Fc ≤ bound
  Eigen::VectorXd inequalityBound;
  std::vector<FrictionCone> cones;                   ///< models with hasSecondOrderCone()
  /// Name of each linear row, "<contact>.<row>": fz_min, cop_x_max, cop_x_min, cop_y_max,
  /// cop_y_min, then facet_<k> (pyramid) or fx_max, fx_min, fy_max, fy_min, yaw_<k> (wrench cone).
  std::vector<std::string> rowNames;
  std::vector<ContactRowKind> rowKinds;              ///< what each linear row bounds
  std::vector<std::string> contactNames;
  /// Contact i's linear rows are [contactRowStart[i], contactRowStart[i + 1]); its first is
  /// its normal force's fz ≥ f_min. contactCount + 1 values.
  std::vector<int> contactRowStart;
  std::vector<int> contactCone;                      ///< contact i's cone in `cones`, or -1
  /// Contact i's wrench variables are Fc[contactColumn[i], contactColumn[i + 1]): its wrench
  /// (f, m) or its force f alone. contactCount + 1 values.
  std::vector<int> contactColumn;
  Eigen::MatrixXd weightedWrenchToTorque;            ///< scratch of updateObjective, n × m

  int variableCount() const { return static_cast<int>(gradient.size()); }
  int wrenchSize(int contact) const {
    return contactColumn[static_cast<std::size_t>(contact) + 1] - contactColumn[static_cast<std::size_t>(contact)];
  }
  /// Contact i's wrench (f, m) in its frame from the stacked variables (m = 0 for a force alone).
  Vector6 contactWrench(const Eigen::Ref<const Eigen::VectorXd>& wrenches, int contact) const;
  /// Rows over the variables (a derivative of Fc) as rows over every contact's six wrench
  /// components, zero for a moment that is not a variable.
  Eigen::MatrixXd wrenchRows(const Eigen::Ref<const Eigen::MatrixXd>& variableRows) const;

  /// Σ w Γ² + l Γ at Fc, without the Tikhonov term (what results report).
  double objective(const Eigen::Ref<const Eigen::VectorXd>& wrenches) const;
  int normalForceRow(int contact) const { return contactRowStart[static_cast<std::size_t>(contact)]; }
  /// Scale of the data for relative tolerances: 1 + ‖H‖∞ + ‖c‖∞ + ‖W‖∞.
  double dataScale() const;
  /// Largest violation of the balance, the linear rows and the cones (0 when feasible).
  double constraintViolation(const Eigen::Ref<const Eigen::VectorXd>& wrenches) const;
};

/// The model a contact has under the settings: its own, the settings' for its name, or the
/// settings' default. Throws InputError when none is given.
const ContactModel& contactModelOf(const ContactSpec& contact, const ContactProblemSettings& settings);

/// Columns of a contact set (contactColumn): each contact's wrench size under its model, or
/// the default one. Throws InputError for a contact set without a model.
std::vector<int> contactColumns(const std::vector<ContactSpec>& contacts, const ContactProblemSettings& settings);

/// Assembles the problem. wrenchToTorque: n × m (each contact's columns: the wrench map's six,
/// or its first three for a force alone), or the whole maps, n × 6nc; tau0, torqueWeights (> 0), torqueLinear:
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
