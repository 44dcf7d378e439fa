// SPDX-License-Identifier: BSD-3-Clause
#include "inner_qp/admissibility_margin.hpp"

#include <cmath>
#include <string>

#include "core/errors.hpp"
#include "inner_qp/dual_active_set_qp.hpp"

namespace mcopt {

AdmissibilityMargin::AdmissibilityMargin(const ContactProblem& layout, MarginSettings settings)
    : settings_(settings), qp_(std::make_unique<inner_detail::DualActiveSetQp>()) {
  if (!(settings_.weight > 0.0) || !(settings_.length > 0.0) || !(settings_.regularisation > 0.0) || settings_.maxIterations < 1)
    throw InputError("admissibility margin: weight, length, regularisation and iterations must be positive");
  if (!layout.cones.empty())
    throw InputError("admissibility margin: contact '" + layout.contactNames[static_cast<std::size_t>(layout.cones.front().contact)] +
                     "' has a second-order friction cone; the margin shifts linear rows only (pyramid, wrench-cone)");
  for (int i = 0; i < layout.contactCount; ++i)
    if (layout.wrenchSize(i) != 6)
      throw InputError("admissibility margin: contact '" + layout.contactNames[static_cast<std::size_t>(i)] +
                       "' holds a force alone; the margin needs six wrench variables a contact");
  variables_ = layout.variableCount();
  rows_ = static_cast<int>(layout.inequality.rows());
  scale_.resize(variables_);
  for (int i = 0; i < layout.contactCount; ++i) {
    const int column = layout.contactColumn[static_cast<std::size_t>(i)];
    scale_.segment(column, 3).setConstant(settings_.weight);
    scale_.segment(column + 3, 3).setConstant(settings_.weight * settings_.length);
  }
  const int n = variables_ + 1;  // (F̃, t)
  qp_->resize(n, 6, rows_);
  qp_->hessian.setZero(n, n);
  qp_->hessian.diagonal().setConstant(settings_.regularisation);
  qp_->gradient.setZero(n);
  qp_->gradient[variables_] = -1.0;
  qp_->inequalityCount = rows_;
  // Each row over the scaled variables, divided by its normal's norm: t is a distance. The
  // contact models' rows are in the contacts' own frames, fixed for a contact set: built once.
  for (int i = 0; i < rows_; ++i) {
    auto row = qp_->inequality.row(i);
    row.head(variables_) = layout.inequality.row(i).cwiseProduct(scale_.transpose());
    const double norm = row.head(variables_).norm();
    const double inverse = norm > 0.0 ? 1.0 / norm : 1.0;
    row.head(variables_) *= inverse;
    row[variables_] = 1.0;
    qp_->inequalityBound[i] = layout.inequalityBound[i] * inverse;
  }
}

AdmissibilityMargin::~AdmissibilityMargin() = default;
AdmissibilityMargin::AdmissibilityMargin(AdmissibilityMargin&&) noexcept = default;
AdmissibilityMargin& AdmissibilityMargin::operator=(AdmissibilityMargin&&) noexcept = default;

void AdmissibilityMargin::solve(const ContactProblem& p, MarginResult& r) {
  if (p.variableCount() != variables_ || p.inequality.rows() != rows_)
    throw InputError("admissibility margin: a problem of " + std::to_string(p.variableCount()) + " variables and " +
                     std::to_string(p.inequality.rows()) + " rows, sized for " + std::to_string(variables_) + " and " +
                     std::to_string(rows_));
  const double w = settings_.weight, wl = settings_.weight * settings_.length;
  // Balance rows in units of m g (forces) and m g ℓ (moments), over the scaled variables.
  for (int k = 0; k < 6; ++k) {
    const double rowScale = k < 3 ? w : wl;
    qp_->equality.row(k).head(variables_) = p.balance.row(k).cwiseProduct(scale_.transpose()) / rowScale;
    qp_->equality(k, variables_) = 0.0;
    qp_->equalityTarget[k] = p.balanceTarget[k] / rowScale;
  }
  const auto status = qp_->solve(r.activeSet, settings_.maxIterations, 1e-13);
  r.iterations = qp_->iterations;
  r.solved = status == inner_detail::DualActiveSetQp::Status::Optimal;
  r.activeSet = qp_->activeSet;
  const auto x = qp_->x.head(variables_);
  const double t = qp_->x[variables_];
  r.margin = t - 0.5 * settings_.regularisation * (x.squaredNorm() + t * t);
  r.wrenches = x.cwiseProduct(scale_);
  // m_ε = −V; V's derivative with respect to the scaled target is −λ̃ (stationarity
  // H x + g + Eᵀ λ̃ + Cᵀ μ = 0), so ∂m_ε/∂W_k = λ̃_k / (row scale).
  for (int k = 0; k < 6; ++k) r.balanceGradient[k] = qp_->equalityMultipliers[k] / (k < 3 ? w : wl);
}

}  // namespace mcopt
