// SPDX-License-Identifier: BSD-3-Clause
#include "sensitivity/sparse_kkt_factor.hpp"

#include <klu.h>
#include <umfpack.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace mcopt {

namespace {

/// Below this fraction of the reciprocal pivot growth of the last factorisation with pivoting,
/// a refactorisation on the kept pivot order (klu_refactor) is not trusted and KLU pivots
/// again: the values moved too far from those the order was chosen for.
constexpr double kPivotGrowthDrop = 1e-3;

}  // namespace

struct SparseKktFactor::Impl {
  Library library;
  // The pattern in compressed columns (int indices: KLU's and UMFPACK's `di` interfaces).
  int size = 0, leading = 0;
  std::vector<int> columnStart, rowIndex;
  std::vector<double> values;
  bool reused = false;
  double reciprocalCondition = 0.0, pivotRatio = 0.0;
  // KLU
  klu_common common{};
  klu_symbolic* symbolic = nullptr;
  klu_numeric* numeric = nullptr;
  double pivotGrowthAtFactor = 0.0;
  // UMFPACK
  void* umfSymbolic = nullptr;
  void* umfNumeric = nullptr;
  double control[UMFPACK_CONTROL] = {};
  double info[UMFPACK_INFO] = {};
  std::vector<int> solveIndexWork;
  std::vector<double> solveWork, column, contiguous;

  explicit Impl(Library l) : library(l) {
    klu_defaults(&common);
    umfpack_di_defaults(control);
    // No iterative refinement: it made each of the 3n right-hand sides cost several solves
    // (BilevelGradient/TwoContacts100/hrp2/umfpack 23.0 → 8.3 ms, docs/theory/sensitivity.md), and the
    // dense and KLU paths, equally accurate here (the tests' 1e-9 agreement), refine nothing;
    // ill-conditioned systems go to the least-norm solve instead.
    control[UMFPACK_IRSTEP] = 0;
  }
  ~Impl() { release(); }
  void releaseNumeric() {
    if (numeric != nullptr) klu_free_numeric(&numeric, &common);
    if (umfNumeric != nullptr) umfpack_di_free_numeric(&umfNumeric);
  }
  void release() {
    releaseNumeric();
    if (symbolic != nullptr) klu_free_symbolic(&symbolic, &common);
    if (umfSymbolic != nullptr) umfpack_di_free_symbolic(&umfSymbolic);
  }

  /// Writes the values of `k` into the kept pattern; false when a nonzero lies outside it.
  bool fillKeptPattern(const Eigen::Ref<const Eigen::MatrixXd>& k, int denseLeading) {
    if (k.rows() != size || denseLeading != leading || (symbolic == nullptr && umfSymbolic == nullptr)) return false;
    for (int c = 0; c < size; ++c) {
      int next = columnStart[static_cast<std::size_t>(c)];
      const int end = columnStart[static_cast<std::size_t>(c) + 1];
      for (int r = 0; r < size; ++r) {
        const double value = k(r, c);
        if (next < end && rowIndex[static_cast<std::size_t>(next)] == r) {
          values[static_cast<std::size_t>(next++)] = value;
        } else if (value != 0.0) {
          return false;
        }
      }
    }
    return true;
  }

  void takePattern(const Eigen::Ref<const Eigen::MatrixXd>& k, int denseLeading) {
    size = static_cast<int>(k.rows());
    leading = denseLeading;
    columnStart.assign(static_cast<std::size_t>(size) + 1, 0);
    rowIndex.clear();
    values.clear();
    for (int c = 0; c < size; ++c) {
      for (int r = 0; r < size; ++r)
        if (k(r, c) != 0.0 || (r < leading && c < leading)) rowIndex.push_back(r), values.push_back(k(r, c));
      columnStart[static_cast<std::size_t>(c) + 1] = static_cast<int>(rowIndex.size());
    }
    sizeSolveWorkspace();
  }

  void sizeSolveWorkspace() {
    solveIndexWork.resize(static_cast<std::size_t>(size));
    solveWork.resize(5 * static_cast<std::size_t>(size));
    column.resize(static_cast<std::size_t>(size));
  }

  bool factorNumeric() {
    reciprocalCondition = pivotRatio = 0.0;
    if (library == Library::Klu) {
      if (!factorKlu(reused)) return false;
      if (klu_condest(columnStart.data(), values.data(), symbolic, numeric, &common) == 0) return false;
      reciprocalCondition = 1.0 / common.condest;
      if (klu_rcond(symbolic, numeric, &common) == 0) return false;
      pivotRatio = common.rcond;
    } else {
      if (!factorUmfpack()) return false;
      reciprocalCondition = pivotRatio = info[UMFPACK_RCOND];
    }
    if (!std::isfinite(reciprocalCondition)) reciprocalCondition = 0.0;
    if (!std::isfinite(pivotRatio)) pivotRatio = 0.0;
    return true;
  }

  bool analyse() {
    release();
    if (library == Library::Klu) {
      symbolic = klu_analyze(size, columnStart.data(), rowIndex.data(), &common);
      return symbolic != nullptr;
    }
    return umfpack_di_symbolic(size, size, columnStart.data(), rowIndex.data(), values.data(), &umfSymbolic, control,
                               info) == UMFPACK_OK;
  }

  bool factorKlu(bool keepPivotOrder) {
    if (keepPivotOrder && numeric != nullptr &&
        klu_refactor(columnStart.data(), rowIndex.data(), values.data(), symbolic, numeric, &common) != 0 &&
        klu_rgrowth(columnStart.data(), rowIndex.data(), values.data(), symbolic, numeric, &common) != 0 &&
        common.rgrowth >= kPivotGrowthDrop * pivotGrowthAtFactor && common.status == KLU_OK)
      return true;
    releaseNumeric();
    numeric = klu_factor(columnStart.data(), rowIndex.data(), values.data(), symbolic, &common);
    if (numeric == nullptr || common.status != KLU_OK) return false;
    klu_rgrowth(columnStart.data(), rowIndex.data(), values.data(), symbolic, numeric, &common);
    pivotGrowthAtFactor = common.rgrowth;
    return true;
  }

  bool factorUmfpack() {
    releaseNumeric();
    const int status =
        umfpack_di_numeric(columnStart.data(), rowIndex.data(), values.data(), umfSymbolic, &umfNumeric, control, info);
    return status == UMFPACK_OK;
  }
};

SparseKktFactor::SparseKktFactor(Library library) : impl_(std::make_unique<Impl>(library)) {}
SparseKktFactor::~SparseKktFactor() = default;
SparseKktFactor::SparseKktFactor(SparseKktFactor&&) noexcept = default;
SparseKktFactor& SparseKktFactor::operator=(SparseKktFactor&&) noexcept = default;

bool SparseKktFactor::factorize(const Eigen::Ref<const Eigen::MatrixXd>& system, int denseLeading) {
  Impl& m = *impl_;
  if (system.rows() != system.cols() || denseLeading < 0 || denseLeading > system.rows())
    throw std::invalid_argument("SparseKktFactor: a square system, and a leading block inside it");
  m.reused = m.fillKeptPattern(system, denseLeading);
  if (!m.reused) {
    m.takePattern(system, denseLeading);
    if (!m.analyse()) return false;
  }
  return m.factorNumeric();
}

bool SparseKktFactor::factorize(const Eigen::SparseMatrix<double>& system) {
  Impl& m = *impl_;
  if (system.rows() != system.cols() || !system.isCompressed())
    throw std::invalid_argument("SparseKktFactor: a square system in compressed columns");
  const auto n = static_cast<int>(system.rows());
  const auto nonzeros = static_cast<std::size_t>(system.nonZeros());
  m.reused = (m.symbolic != nullptr || m.umfSymbolic != nullptr) && m.size == n && m.leading == -1 &&
             m.rowIndex.size() == nonzeros &&
             std::equal(m.columnStart.begin(), m.columnStart.end(), system.outerIndexPtr()) &&
             std::equal(m.rowIndex.begin(), m.rowIndex.end(), system.innerIndexPtr());
  if (m.reused) {
    std::copy(system.valuePtr(), system.valuePtr() + nonzeros, m.values.begin());
  } else {
    m.size = n, m.leading = -1;
    m.columnStart.assign(system.outerIndexPtr(), system.outerIndexPtr() + n + 1);
    m.rowIndex.assign(system.innerIndexPtr(), system.innerIndexPtr() + nonzeros);
    m.values.assign(system.valuePtr(), system.valuePtr() + nonzeros);
    m.sizeSolveWorkspace();
    if (!m.analyse()) return false;
  }
  return m.factorNumeric();
}

bool SparseKktFactor::reusedAnalysis() const { return impl_->reused; }
double SparseKktFactor::reciprocalCondition() const { return impl_->reciprocalCondition; }
double SparseKktFactor::pivotRatio() const { return impl_->pivotRatio; }

void SparseKktFactor::solveInPlace(Eigen::Ref<Eigen::MatrixXd> x) {
  Impl& m = *impl_;
  if (x.rows() != m.size) throw std::invalid_argument("SparseKktFactor: right-hand sides of the wrong size");
  if (m.library == Library::Klu) {
    // KLU solves all columns in one call (four at a time inside), in place, with the leading
    // dimension given; a block of a taller matrix goes through contiguous workspace, which
    // grows to the largest right-hand side once.
    if (x.outerStride() == x.rows()) {
      klu_solve(m.symbolic, m.numeric, m.size, static_cast<int>(x.cols()), x.data(), &m.common);
      return;
    }
    const std::size_t needed = static_cast<std::size_t>(x.rows() * x.cols());
    if (m.contiguous.size() < needed) m.contiguous.resize(needed);
    Eigen::Map<Eigen::MatrixXd> work(m.contiguous.data(), x.rows(), x.cols());
    work = x;
    klu_solve(m.symbolic, m.numeric, m.size, static_cast<int>(x.cols()), work.data(), &m.common);
    x = work;
    return;
  }
  // UMFPACK solves one column at a time, out of place, in workspace given (wsolve: no allocation).
  for (Eigen::Index c = 0; c < x.cols(); ++c) {
    Eigen::Map<Eigen::VectorXd>(m.column.data(), m.size) = x.col(c);
    umfpack_di_wsolve(UMFPACK_A, m.columnStart.data(), m.rowIndex.data(), m.values.data(), x.col(c).data(),
                      m.column.data(), m.umfNumeric, m.control, m.info, m.solveIndexWork.data(), m.solveWork.data());
  }
}

}  // namespace mcopt
