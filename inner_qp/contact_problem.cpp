// SPDX-License-Identifier: BSD-3-Clause
#include "inner_qp/contact_problem.hpp"

#include <cmath>

#include "core/contact_maps.hpp"
#include "core/errors.hpp"

namespace mcopt {

namespace {

void validate(const std::vector<ContactSpec>& contacts, const Eigen::Ref<const Eigen::MatrixXd>& wrenchToTorque,
              const Eigen::Ref<const Eigen::VectorXd>& tau0, const Vector6& balanceWrench,
              const Eigen::Ref<const Eigen::VectorXd>& weights, const Eigen::Ref<const Eigen::VectorXd>& linear,
              const ContactProblemSettings& settings) {
  const auto nc = static_cast<Eigen::Index>(contacts.size());
  const Eigen::Index n = tau0.size();
  if (nc == 0) throw InputError("contacts: at least one contact is needed");
  if (wrenchToTorque.rows() != n || wrenchToTorque.cols() != 6 * nc)
    throw InputError("wrench_to_torque: expected " + std::to_string(n) + " × " + std::to_string(6 * nc) + ", got " +
                     std::to_string(wrenchToTorque.rows()) + " × " + std::to_string(wrenchToTorque.cols()));
  if (weights.size() != n || linear.size() != n)
    throw InputError("torque_weights, torque_linear: expected " + std::to_string(n) + " values each");
  if (!wrenchToTorque.allFinite() || !tau0.allFinite() || !balanceWrench.allFinite() || !weights.allFinite() ||
      !linear.allFinite())
    throw InputError("inner problem data contain NaN or infinity");
  if ((weights.array() <= 0.0).any()) throw InputError("torque_weights: must all be positive");
  if (!settings.model) throw InputError("inner problem: no contact model");
  if (!(settings.tikhonov >= 0.0)) throw InputError("tikhonov: must be non-negative");
  for (const ContactSpec& c : contacts) {
    const std::string where = "contact '" + c.name + "': ";
    if (!(c.friction > 0.0) || !std::isfinite(c.friction)) throw InputError(where + "mu must be positive");
    if (!(c.xMin < c.xMax && c.yMin < c.yMax))
      throw InputError(where + "rectangle must be [x_min, x_max, y_min, y_max] with x_min < x_max, y_min < y_max");
    if (!(c.minNormalForce >= 0.0)) throw InputError(where + "minimum normal force must be non-negative");
    if (!c.pose.rotation.allFinite() || !c.pose.translation.allFinite())
      throw InputError(where + "pose is not finite");
  }
}

}  // namespace

ContactProblem assembleContactProblem(const std::vector<ContactSpec>& contacts,
                                      const Eigen::Ref<const Eigen::MatrixXd>& J1,
                                      const Eigen::Ref<const Eigen::VectorXd>& tau0, const Vector6& balanceWrench,
                                      const Eigen::Ref<const Eigen::VectorXd>& weights,
                                      const Eigen::Ref<const Eigen::VectorXd>& linear,
                                      const ContactProblemSettings& settings) {
  validate(contacts, J1, tau0, balanceWrench, weights, linear, settings);
  ContactProblem p;
  const int nc = static_cast<int>(contacts.size());
  p.contactCount = nc;
  p.tikhonov = settings.tikhonov;
  p.hessian.resize(6 * nc, 6 * nc);
  p.gradient.resize(6 * nc);
  p.weightedWrenchToTorque.resize(J1.rows(), 6 * nc);
  updateObjective(p, J1, tau0, weights, linear);

  // Balance (§5): the contact wrenches moved to the world origin add up to W.
  p.balance.resize(6, 6 * nc);
  for (int i = 0; i < nc; ++i) wrenchToWorld(contacts[i].pose, p.balance.middleCols<6>(6 * i));
  p.balanceTarget = balanceWrench;

  const ContactModel& model = *settings.model;
  const int perContact = model.rowCount();
  p.inequality.setZero(perContact * nc, 6 * nc);
  p.inequalityBound.resize(perContact * nc);
  for (int i = 0; i < nc; ++i) {
    const ContactSpec& c = contacts[static_cast<std::size_t>(i)];
    const ContactModelRows rows = model.rows(c);
    const int start = perContact * i;
    p.contactRowStart.push_back(start);
    p.contactNames.push_back(c.name);
    p.inequality.block(start, 6 * i, perContact, 6) = rows.rows;
    p.inequalityBound.segment(start, perContact) = rows.bound;
    for (const std::string& name : rows.names) p.rowNames.push_back(c.name + "." + name);
    p.rowKinds.insert(p.rowKinds.end(), rows.kinds.begin(), rows.kinds.end());
    p.contactCone.push_back(model.hasSecondOrderCone() ? static_cast<int>(p.cones.size()) : -1);
    if (model.hasSecondOrderCone()) p.cones.push_back({6 * i, c.friction, i});
  }
  p.contactRowStart.push_back(perContact * nc);
  return p;
}

void updateObjective(ContactProblem& p, const Eigen::Ref<const Eigen::MatrixXd>& J1,
                     const Eigen::Ref<const Eigen::VectorXd>& tau0, const Eigen::Ref<const Eigen::VectorXd>& weights,
                     const Eigen::Ref<const Eigen::VectorXd>& linear) {
  if (J1.rows() != p.weightedWrenchToTorque.rows() || J1.cols() != p.hessian.cols() || tau0.size() != J1.rows() ||
      weights.size() != J1.rows() || linear.size() != J1.rows())
    throw InputError("inner problem update: sizes differ from the assembled problem");
  // Objective (§7): Σ w Γ² + l Γ with Γ = τ0 − J1 F.
  p.weightedWrenchToTorque.noalias() = weights.asDiagonal() * J1;
  p.hessian.noalias() = 2.0 * J1.transpose() * p.weightedWrenchToTorque;
  p.hessian.diagonal().array() += p.tikhonov;
  p.gradient.noalias() = -2.0 * p.weightedWrenchToTorque.transpose() * tau0;
  p.gradient.noalias() -= J1.transpose() * linear;
  p.constant = 0.0;
  for (Eigen::Index j = 0; j < tau0.size(); ++j) p.constant += (weights[j] * tau0[j] + linear[j]) * tau0[j];
}

void setContactPose(ContactProblem& p, int contact, const RigidTransform& pose) {
  if (contact < 0 || contact >= p.contactCount) throw InputError("inner problem: no contact " + std::to_string(contact));
  wrenchToWorld(pose, p.balance.middleCols<6>(6 * contact));
}

double ContactProblem::objective(const Eigen::Ref<const Eigen::VectorXd>& F) const {
  // ½ Fᵀ H F + cᵀ F + constant − ½ ε ‖F‖², column by column: no temporaries (called in the
  // allocation-free inner solve).
  double value = constant;
  for (Eigen::Index j = 0; j < F.size(); ++j)
    value += F[j] * (0.5 * hessian.col(j).dot(F) + gradient[j] - 0.5 * tikhonov * F[j]);
  return value;
}

double ContactProblem::dataScale() const {
  return 1.0 + hessian.cwiseAbs().maxCoeff() + gradient.cwiseAbs().maxCoeff() + balanceTarget.cwiseAbs().maxCoeff();
}

double ContactProblem::constraintViolation(const Eigen::Ref<const Eigen::VectorXd>& F) const {
  double worst = 0.0;
  for (int k = 0; k < 6; ++k) worst = std::max(worst, std::abs(balance.row(k).dot(F) - balanceTarget[k]));
  for (Eigen::Index i = 0; i < inequality.rows(); ++i)
    worst = std::max(worst, inequality.row(i).dot(F) - inequalityBound[i]);
  for (const FrictionCone& cone : cones)
    worst = std::max(worst, std::hypot(F[cone.index], F[cone.index + 1]) - cone.friction * F[cone.index + 2]);
  return worst;
}

}  // namespace mcopt
