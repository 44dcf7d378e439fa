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
              const ContactProblemSettings& settings, int columns) {
  const Eigen::Index n = tau0.size();
  if (contacts.empty()) throw InputError("contacts: at least one contact is needed");
  if (wrenchToTorque.rows() != n || wrenchToTorque.cols() != columns)
    throw InputError("wrench_to_torque: expected " + std::to_string(n) + " × " + std::to_string(columns) + ", got " +
                     std::to_string(wrenchToTorque.rows()) + " × " + std::to_string(wrenchToTorque.cols()));
  if (weights.size() != n || linear.size() != n)
    throw InputError("torque_weights, torque_linear: expected " + std::to_string(n) + " values each");
  if (!wrenchToTorque.allFinite() || !tau0.allFinite() || !balanceWrench.allFinite() || !weights.allFinite() ||
      !linear.allFinite())
    throw InputError("inner problem data contain NaN or infinity");
  if ((weights.array() <= 0.0).any()) throw InputError("torque_weights: must all be positive");
  if (!(settings.tikhonov >= 0.0)) throw InputError("tikhonov: must be non-negative");
  for (const ContactSpec& c : contacts) {
    const std::string where = "contact '" + c.name + "': ";
    if (!(c.friction > 0.0) || !std::isfinite(c.friction)) throw InputError(where + "mu must be positive");
    if (contactModelOf(c, settings).hasRectangle() && !(c.xMin < c.xMax && c.yMin < c.yMax))
      throw InputError(where + "rectangle must be [x_min, x_max, y_min, y_max] with x_min < x_max, y_min < y_max");
    if (!(c.minNormalForce >= 0.0)) throw InputError(where + "minimum normal force must be non-negative");
    if (!c.pose.rotation.allFinite() || !c.pose.translation.allFinite())
      throw InputError(where + "pose is not finite");
  }
}

/// Contact i's balance columns: the wrench map's first `size` columns.
void writeBalanceColumns(ContactProblem& p, int contact, const RigidTransform& pose) {
  Eigen::Matrix<double, 6, 6> toWorld;
  wrenchToWorld(pose, toWorld);
  const int size = p.wrenchSize(contact);
  p.balance.middleCols(p.contactColumn[static_cast<std::size_t>(contact)], size) = toWorld.leftCols(size);
}

}  // namespace

const ContactModel& contactModelOf(const ContactSpec& c, const ContactProblemSettings& settings) {
  if (c.model) return *c.model;
  if (const auto own = settings.byContact.find(c.name); own != settings.byContact.end() && own->second)
    return *own->second;
  if (!settings.model) throw InputError("inner problem: no contact model");
  return *settings.model;
}

std::vector<int> contactColumns(const std::vector<ContactSpec>& contacts, const ContactProblemSettings& settings) {
  std::vector<int> columns{0};
  for (const ContactSpec& c : contacts) columns.push_back(columns.back() + contactModelOf(c, settings).wrenchSize());
  return columns;
}

ContactProblem assembleContactProblem(const std::vector<ContactSpec>& contacts,
                                      const Eigen::Ref<const Eigen::MatrixXd>& J1,
                                      const Eigen::Ref<const Eigen::VectorXd>& tau0, const Vector6& balanceWrench,
                                      const Eigen::Ref<const Eigen::VectorXd>& weights,
                                      const Eigen::Ref<const Eigen::VectorXd>& linear,
                                      const ContactProblemSettings& settings) {
  ContactProblem p;
  p.contactColumn = contactColumns(contacts, settings);
  const int m = p.contactColumn.back();
  const int nc = static_cast<int>(contacts.size());
  // The whole wrench maps (six columns a contact) are accepted too: a force alone takes the
  // first three of its contact's.
  const bool whole = J1.cols() == 6 * nc && m != 6 * nc;
  validate(contacts, J1, tau0, balanceWrench, weights, linear, settings, whole ? 6 * nc : m);
  p.contactCount = nc;
  p.tikhonov = settings.tikhonov;
  p.hessian.resize(m, m);
  p.gradient.resize(m);
  p.weightedWrenchToTorque.resize(J1.rows(), m);
  if (whole) {
    Eigen::MatrixXd columns(J1.rows(), m);
    for (int i = 0; i < nc; ++i)
      columns.middleCols(p.contactColumn[static_cast<std::size_t>(i)], p.wrenchSize(i)) =
          J1.middleCols(6 * i, p.wrenchSize(i));
    updateObjective(p, columns, tau0, weights, linear);
  } else {
    updateObjective(p, J1, tau0, weights, linear);
  }

  // Balance (§5): the contact wrenches moved to the world origin add up to W.
  p.balance.resize(6, m);
  for (int i = 0; i < nc; ++i) writeBalanceColumns(p, i, contacts[static_cast<std::size_t>(i)].pose);
  p.balanceTarget = balanceWrench;

  // Each contact's rows, as its model writes them (over the six wrench components; a model
  // whose wrench is the force alone writes none on the moment).
  int rowCount = 0;
  for (const ContactSpec& c : contacts) rowCount += contactModelOf(c, settings).rowCount();
  p.inequality.setZero(rowCount, m);
  p.inequalityBound.resize(rowCount);
  int start = 0;
  for (int i = 0; i < nc; ++i) {
    const ContactSpec& c = contacts[static_cast<std::size_t>(i)];
    const ContactModel& model = contactModelOf(c, settings);
    const ContactModelRows rows = model.rows(c);
    const int count = model.rowCount(), size = model.wrenchSize(), column = p.contactColumn[static_cast<std::size_t>(i)];
    if (size < 6 && rows.rows.rightCols(6 - size).cwiseAbs().maxCoeff() != 0.0)
      throw std::logic_error("contact model '" + model.name() + "': a row bounds a wrench component that is not a variable");
    p.contactRowStart.push_back(start);
    p.contactNames.push_back(c.name);
    p.inequality.block(start, column, count, size) = rows.rows.leftCols(size);
    p.inequalityBound.segment(start, count) = rows.bound;
    for (const std::string& name : rows.names) p.rowNames.push_back(c.name + "." + name);
    p.rowKinds.insert(p.rowKinds.end(), rows.kinds.begin(), rows.kinds.end());
    p.contactCone.push_back(model.hasSecondOrderCone() ? static_cast<int>(p.cones.size()) : -1);
    if (model.hasSecondOrderCone()) p.cones.push_back({column, c.friction, i});
    start += count;
  }
  p.contactRowStart.push_back(start);
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
  writeBalanceColumns(p, contact, pose);
}

Eigen::MatrixXd ContactProblem::wrenchRows(const Eigen::Ref<const Eigen::MatrixXd>& variableRows) const {
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(6 * contactCount, variableRows.cols());
  for (int i = 0; i < contactCount; ++i)
    out.middleRows(6 * i, wrenchSize(i)) = variableRows.middleRows(contactColumn[static_cast<std::size_t>(i)], wrenchSize(i));
  return out;
}

Vector6 ContactProblem::contactWrench(const Eigen::Ref<const Eigen::VectorXd>& wrenches, int contact) const {
  Vector6 wrench = Vector6::Zero();
  const int size = wrenchSize(contact);
  wrench.head(size) = wrenches.segment(contactColumn[static_cast<std::size_t>(contact)], size);
  return wrench;
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
