// SPDX-License-Identifier: BSD-3-Clause
#include "inner_qp/dual_active_set_qp.hpp"

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>

namespace mcopt::inner_detail {

namespace {
// A transformed normal whose part outside range V is below this fraction of its length is
// dependent on the working set (Gram–Schmidt with one re-orthogonalisation is accurate to
// a few ulps times the condition of V, far below this).
constexpr double kDependence = 1e-10;
}  // namespace

void DualActiveSetQp::resize(int variables, int equalities, int inequalityCapacity) {
  n_ = variables;
  hessian.setZero(n_, n_);
  gradient.setZero(n_);
  equality.setZero(equalities, n_);
  equalityTarget.setZero(equalities);
  inequality.setZero(inequalityCapacity, n_);
  inequalityBound.setZero(inequalityCapacity);
  inequalityCount = 0;
  x.setZero(n_);
  equalityMultipliers.setZero(equalities);
  inequalityMultipliers.setZero(inequalityCapacity);
  activeSet.reserve(static_cast<std::size_t>(n_));
  factor_.setZero(n_, n_);
  transformed_.setZero(n_, n_);
  basis_.setZero(n_, n_);
  triangle_.setZero(n_, n_);
  entries_.assign(static_cast<std::size_t>(n_), Entry{});
  for (auto* v : {&multipliers_, &multiplierStep_, &projection_, &orthogonal_, &vector_, &rhs_, &residual_,
                  &correction_, &savedX_, &savedMultipliers_})
    v->setZero(n_);
  inWorkingSet_.assign(static_cast<std::size_t>(inequalityCapacity), 0);
  working_ = 0;
}

void DualActiveSetQp::transformedNormal(const Entry& e, Eigen::Ref<Eigen::VectorXd> v) const {
  v = normal(e).transpose();
  factor_.triangularView<Eigen::Lower>().solveInPlace(v);
}

double DualActiveSetQp::orthogonalise(const Eigen::Ref<const Eigen::VectorXd>& v) {
  const int w = working_;
  auto Q = basis_.leftCols(w);
  auto h = projection_.head(w);
  h.noalias() = Q.transpose() * v;
  orthogonal_ = v;
  orthogonal_.noalias() -= Q * h;
  // Twice is enough (Giraud et al. 2005): the second pass restores orthogonality lost to
  // cancellation when v is nearly in range Q.
  auto h2 = multiplierStep_.head(w);
  h2.noalias() = Q.transpose() * orthogonal_;
  orthogonal_.noalias() -= Q * h2;
  h += h2;
  return orthogonal_.norm();
}

bool DualActiveSetQp::append(const Entry& entry, const Eigen::Ref<const Eigen::VectorXd>& v, double multiplier) {
  if (working_ >= n_) return false;
  const double remainder = orthogonalise(v);
  if (!(remainder > kDependence * v.norm())) return false;
  const int w = working_;
  basis_.col(w) = orthogonal_ / remainder;
  triangle_.col(w).head(w) = projection_.head(w);
  triangle_(w, w) = remainder;
  transformed_.col(w) = v;
  entries_[static_cast<std::size_t>(w)] = entry;
  multipliers_[w] = multiplier;
  if (!entry.isEquality) inWorkingSet_[static_cast<std::size_t>(entry.row)] = 1;
  ++working_;
  return true;
}

void DualActiveSetQp::remove(int k) {
  const Entry gone = entries_[static_cast<std::size_t>(k)];
  if (!gone.isEquality) inWorkingSet_[static_cast<std::size_t>(gone.row)] = 0;
  const int w = working_;
  for (int j = k; j + 1 < w; ++j) {
    entries_[static_cast<std::size_t>(j)] = entries_[static_cast<std::size_t>(j + 1)];
    transformed_.col(j) = transformed_.col(j + 1);
    multipliers_[j] = multipliers_[j + 1];
  }
  // Columns before k keep their Q and R; the rest are orthogonalised again (independent
  // before, so they stay independent after a column is taken out).
  working_ = k;
  for (int j = k; j + 1 < w; ++j) {
    vector_ = transformed_.col(j);
    const double remainder = orthogonalise(vector_);
    basis_.col(j) = orthogonal_ / remainder;
    triangle_.col(j).head(j) = projection_.head(j);
    triangle_(j, j) = remainder;
    ++working_;
  }
}

void DualActiveSetQp::solveWorkingSet(const Eigen::Ref<const Eigen::VectorXd>& g,
                                      const Eigen::Ref<const Eigen::VectorXd>& b) {
  // y = Lᵀ x. Rows: Vᵀ y = b, so Qᵀ y = α = R⁻ᵀ b; stationarity y + L⁻¹ g + V u = 0 gives
  // u = −R⁻¹ (α + Qᵀ L⁻¹ g) and y = Q α − (L⁻¹ g − Q Qᵀ L⁻¹ g).
  const int w = working_;
  auto Q = basis_.leftCols(w);
  const auto R = triangle_.topLeftCorner(w, w).triangularView<Eigen::Upper>();
  Eigen::VectorXd& lg = vector_;  // L⁻¹ g
  lg = g;
  factor_.triangularView<Eigen::Lower>().solveInPlace(lg);
  auto alpha = projection_.head(w);
  alpha = b.head(w);
  R.transpose().solveInPlace(alpha);
  auto qlg = multiplierStep_.head(w);
  qlg.noalias() = Q.transpose() * lg;
  alpha += qlg;  // α + Qᵀ L⁻¹ g
  auto u = rhs_.head(w);
  u = -alpha;
  R.solveInPlace(u);
  // y into orthogonal_, then x = L⁻ᵀ y.
  orthogonal_ = -lg;
  orthogonal_.noalias() += Q * alpha;
  factor_.triangularView<Eigen::Lower>().transpose().solveInPlace(orthogonal_);
  x = orthogonal_;
  multipliers_.head(w) = u;
}

void DualActiveSetQp::refine() {
  // Residuals on the exact data, r = H x + g + N u and p = Nᵀ x − b; the correction solves
  // the working-set system with g := r and b := −p.
  const int w = working_;
  residual_.noalias() = hessian.selfadjointView<Eigen::Lower>() * x;
  residual_ += gradient;
  for (int j = 0; j < w; ++j) {
    const Entry& e = entries_[static_cast<std::size_t>(j)];
    residual_ += multipliers_[j] * normal(e).transpose();
    correction_[j] = bound(e) - normal(e).dot(x);
  }
  savedX_ = x;
  savedMultipliers_.head(w) = multipliers_.head(w);
  solveWorkingSet(residual_, correction_);
  x += savedX_;
  multipliers_.head(w) += savedMultipliers_.head(w);
}

DualActiveSetQp::Status DualActiveSetQp::solve(const std::vector<int>& initialWorkingSet, int maxIterations,
                                               double violationTolerance) {
  iterations = 0;
  activeSet.clear();
  inequalityMultipliers.setZero();
  equalityMultipliers.setZero();
  std::fill(inWorkingSet_.begin(), inWorkingSet_.end(), 0);
  working_ = 0;
  factor_ = hessian;
  Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>> cholesky(factor_);
  if (cholesky.info() != Eigen::Success) return Status::NotPositiveDefinite;

  // Working set: the equalities, then the warm-start rows that are independent of them.
  for (int k = 0; k < equality.rows(); ++k) {
    const Entry e{k, true};
    transformedNormal(e, vector_);
    append(e, vector_, 0.0);
  }
  for (int row : initialWorkingSet) {
    if (row < 0 || row >= inequalityCount || inWorkingSet_[static_cast<std::size_t>(row)]) continue;
    const Entry e{row, false};
    transformedNormal(e, vector_);
    append(e, vector_, 0.0);
  }
  // The minimiser over the working set; rows with negative multipliers leave, one at a time.
  for (;;) {
    for (int j = 0; j < working_; ++j) correction_[j] = bound(entries_[static_cast<std::size_t>(j)]);
    solveWorkingSet(gradient, correction_);
    int worst = -1;
    double mostNegative = 0.0;
    for (int j = 0; j < working_; ++j)
      if (!entries_[static_cast<std::size_t>(j)].isEquality && multipliers_[j] < mostNegative)
        mostNegative = multipliers_[j], worst = j;
    if (worst < 0) break;
    remove(worst);
    ++iterations;
  }

  for (;;) {
    // The most violated row outside the working set.
    const double scale = 1.0 + x.cwiseAbs().maxCoeff();
    int added = -1;
    double worstViolation = 0.0;
    for (int i = 0; i < inequalityCount; ++i) {
      if (inWorkingSet_[static_cast<std::size_t>(i)]) continue;
      const double rowScale = inequality.row(i).cwiseAbs().maxCoeff();
      const double violation = (inequality.row(i).dot(x) - inequalityBound[i]) / (scale * rowScale);
      if (violation > violationTolerance && violation > worstViolation) worstViolation = violation, added = i;
    }
    if (added < 0) break;
    if (iterations >= maxIterations) return Status::IterationLimit;

    const Entry p{added, false};
    double multiplierOfAdded = 0.0;
    for (;;) {
      ++iterations;
      if (iterations > maxIterations) return Status::IterationLimit;
      transformedNormal(p, vector_);
      const double remainder = orthogonalise(vector_);
      const int w = working_;
      // Multiplier step r = −R⁻¹ h (h = Qᵀ v, in projection_).
      auto step = multiplierStep_.head(w);
      step = -projection_.head(w);
      triangle_.topLeftCorner(w, w).triangularView<Eigen::Upper>().solveInPlace(step);
      const bool independent = remainder > kDependence * vector_.norm();
      const double slack = inequality.row(added).dot(x) - inequalityBound[added];
      const double fullStep = independent ? std::max(slack, 0.0) / (remainder * remainder)
                                          : std::numeric_limits<double>::infinity();
      double partialStep = std::numeric_limits<double>::infinity();
      int blocking = -1;
      for (int j = 0; j < w; ++j) {
        if (entries_[static_cast<std::size_t>(j)].isEquality || !(step[j] < 0.0)) continue;
        const double t = multipliers_[j] / -step[j];
        if (t < partialStep) partialStep = t, blocking = j;
      }
      if (!independent && blocking < 0) return Status::Infeasible;
      const double t = std::min(fullStep, partialStep);
      if (independent) {
        // Primal step z = −L⁻ᵀ (v's part orthogonal to range V).
        factor_.triangularView<Eigen::Lower>().transpose().solveInPlace(orthogonal_);
        x -= t * orthogonal_;
      }
      multipliers_.head(w) += t * step;
      multiplierOfAdded += t;
      if (t == fullStep) {
        transformedNormal(p, vector_);
        if (!append(p, vector_, multiplierOfAdded)) return Status::Infeasible;
        break;
      }
      remove(blocking);
    }
  }

  // Two refinement passes recover what the transformation lost on ill-conditioned H.
  refine();
  refine();
  for (int j = 0; j < working_; ++j) {
    const Entry& e = entries_[static_cast<std::size_t>(j)];
    if (e.isEquality) {
      equalityMultipliers[e.row] = multipliers_[j];
    } else {
      inequalityMultipliers[e.row] = std::max(multipliers_[j], 0.0);
      activeSet.push_back(e.row);
    }
  }
  return Status::Optimal;
}

}  // namespace mcopt::inner_detail
