// SPDX-License-Identifier: BSD-3-Clause
#include "inner_qp/contact_problem.hpp"

#include <cmath>
#include <numbers>

#include "core/contact_maps.hpp"
#include "core/errors.hpp"

namespace mcopt {

namespace {

// Wrench components within one contact's 6 columns.
enum { Fx = 0, Fy, Fz, Mx, My, Mz };

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
  if (settings.model == ContactModel::Pyramid && settings.pyramidFacets < 3)
    throw InputError("pyramid facets: need at least 3, got " + std::to_string(settings.pyramidFacets));
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

/// Appends one row a·F ≤ bound over one contact's 6 wrench components.
struct RowWriter {
  ContactModelRows& out;
  Eigen::Index next = 0;
  void add(std::string name, ContactRowKind kind, std::initializer_list<std::pair<int, double>> terms,
           double bound = 0.0) {
    out.names[static_cast<std::size_t>(next)] = std::move(name);
    out.kinds[static_cast<std::size_t>(next)] = kind;
    out.rows.row(next).setZero();
    for (const auto& [component, value] : terms) out.rows(next, component) += value;
    out.bound[next] = bound;
    ++next;
  }
};

}  // namespace

int contactModelRowCount(const ContactProblemSettings& s) {
  switch (s.model) {
    case ContactModel::Report: return 5;                        // fz ≥ f_min, 4 CoP rows
    case ContactModel::Pyramid: return 5 + s.pyramidFacets;      // + facets
    case ContactModel::WrenchCone: return 5 + 4 + 8;             // + |fx|,|fy| ≤ μ fz, 8 yaw rows
  }
  return 0;
}

ContactModelRows contactModelRows(const ContactSpec& c, const ContactProblemSettings& settings) {
  if (settings.model == ContactModel::Pyramid && settings.pyramidFacets < 3)
    throw InputError("pyramid facets: need at least 3, got " + std::to_string(settings.pyramidFacets));
  const int count = contactModelRowCount(settings);
  ContactModelRows out;
  out.rows.resize(count, 6);
  out.bound.resize(count);
  out.names.resize(static_cast<std::size_t>(count));
  out.kinds.resize(static_cast<std::size_t>(count));
  RowWriter rows{out};
  using K = ContactRowKind;
  rows.add("fz_min", K::NormalForce, {{Fz, -1.0}}, -c.minNormalForce);  // fz ≥ f_min
  rows.add("cop_x_max", K::CenterOfPressure, {{My, -1.0}, {Fz, -c.xMax}});    // −m_y ≤ x_max fz
  rows.add("cop_x_min", K::CenterOfPressure, {{My, 1.0}, {Fz, c.xMin}});      // x_min fz ≤ −m_y
  rows.add("cop_y_max", K::CenterOfPressure, {{Mx, 1.0}, {Fz, -c.yMax}});     // m_x ≤ y_max fz
  rows.add("cop_y_min", K::CenterOfPressure, {{Mx, -1.0}, {Fz, c.yMin}});     // y_min fz ≤ m_x
  switch (settings.model) {
    case ContactModel::Report: break;  // the friction cone is a second-order cone, not a row
    case ContactModel::Pyramid: {
      const int k = settings.pyramidFacets;
      const double inscribed = c.friction * std::cos(std::numbers::pi / k);
      for (int f = 0; f < k; ++f) {
        const double theta = 2.0 * std::numbers::pi * f / k;
        rows.add("facet_" + std::to_string(f), K::Friction, {{Fx, std::cos(theta)}, {Fy, std::sin(theta)}, {Fz, -inscribed}});
      }
      break;
    }
    case ContactModel::WrenchCone: {
      // About the rectangle's centre (cx, cy): m'_x = m_x − cy fz, m'_y = m_y + cx fz,
      // m'_z = m_z − cx fy + cy fx. With μ̃ = μ/√2 the pyramid |fx|, |fy| ≤ μ̃ fz is
      // inscribed in the circular cone (Caron et al. §III), so the wrench cone admits
      // nothing the report model forbids and forbids, besides, the yaw slip.
      const double mu = c.friction / std::numbers::sqrt2;
      const double cx = 0.5 * (c.xMin + c.xMax), cy = 0.5 * (c.yMin + c.yMax);
      const double X = 0.5 * (c.xMax - c.xMin), Y = 0.5 * (c.yMax - c.yMin);
      rows.add("fx_max", K::Friction, {{Fx, 1.0}, {Fz, -mu}});
      rows.add("fx_min", K::Friction, {{Fx, -1.0}, {Fz, -mu}});
      rows.add("fy_max", K::Friction, {{Fy, 1.0}, {Fz, -mu}});
      rows.add("fy_min", K::Friction, {{Fy, -1.0}, {Fz, -mu}});
      int yaw = 0;
      for (double s1 : {-1.0, 1.0})
        for (double s2 : {-1.0, 1.0}) {
          // m'_z ≤ μ(X+Y) fz − s1 (Y fx + μ m'_x) − s2 (X fy + μ m'_y)
          rows.add("yaw_max_" + std::to_string(yaw), K::Yaw, {{Mz, 1.0}, {Fy, -cx}, {Fx, cy},
                       {Fz, -mu * (X + Y)}, {Fx, s1 * Y}, {Mx, s1 * mu}, {Fz, -s1 * mu * cy},
                       {Fy, s2 * X}, {My, s2 * mu}, {Fz, s2 * mu * cx}});
          // −m'_z ≤ μ(X+Y) fz − s1 (Y fx − μ m'_x) − s2 (X fy − μ m'_y)
          rows.add("yaw_min_" + std::to_string(yaw++), K::Yaw, {{Mz, -1.0}, {Fy, cx}, {Fx, -cy},
                       {Fz, -mu * (X + Y)}, {Fx, s1 * Y}, {Mx, -s1 * mu}, {Fz, s1 * mu * cy},
                       {Fy, s2 * X}, {My, -s2 * mu}, {Fz, -s2 * mu * cx}});
        }
      break;
    }
  }
  return out;
}

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

  const int perContact = contactModelRowCount(settings);
  p.inequality.setZero(perContact * nc, 6 * nc);
  p.inequalityBound.resize(perContact * nc);
  for (const ContactSpec& c : contacts) p.contactNames.push_back(c.name);
  for (int i = 0; i < nc; ++i) {
    const ContactSpec& c = contacts[static_cast<std::size_t>(i)];
    const ContactModelRows rows = contactModelRows(c, settings);
    p.inequality.block(perContact * i, 6 * i, perContact, 6) = rows.rows;
    p.inequalityBound.segment(perContact * i, perContact) = rows.bound;
    for (const std::string& name : rows.names) p.rowNames.push_back(c.name + "." + name);
    if (settings.model == ContactModel::Report) p.cones.push_back({6 * i, c.friction});
  }
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
