// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A SuiteSparse LU of one sample's KKT system (formulation.md §8), through KLU's and
// UMFPACK's own interfaces. Analyse once, factorise many (style.md §10): the symbolic
// analysis of a sparsity pattern is kept while the next systems' nonzeros fit in it — the
// same active set and contact states, from outer iteration to outer iteration — and only the
// numeric factorisation is redone. The condition estimate is the library's own, so the
// sparse path runs no dense factorisation. (Eigen's KLUSupport / UmfPackSupport wrappers
// analyse again on every compute() and keep the estimates private.)
// Private to mcopt::sensitivity; no SuiteSparse header here.

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>

namespace mcopt {

class SparseKktFactor {
 public:
  enum class Library { Klu, Umfpack };
  explicit SparseKktFactor(Library library);
  ~SparseKktFactor();
  SparseKktFactor(SparseKktFactor&&) noexcept;
  SparseKktFactor& operator=(SparseKktFactor&&) noexcept;

  /// Factorises the square `system` (dense storage). Its pattern is the leading
  /// `denseLeading` rows and columns whole — the Hessian and the balance rows, whose entries
  /// vanish only by accident of the posture — and the nonzeros of the rest (contact rows and
  /// pins, fixed in the contact frames). Returns false when the library finds it singular (no
  /// solve then). Allocates only when the pattern changes (KLU; UMFPACK's numeric
  /// factorisation makes a new object each time).
  bool factorize(const Eigen::Ref<const Eigen::MatrixXd>& system, int denseLeading);
  /// The same for a system already in compressed columns (all samples' systems as one
  /// block-diagonal matrix): its stored entries are the pattern.
  bool factorize(const Eigen::SparseMatrix<double>& system);
  /// Whether the last factorize() reused the previous symbolic analysis.
  bool reusedAnalysis() const;
  /// Reciprocal condition of the last factorised system. KLU: 1/klu_condest, the
  /// Hager–Higham estimate of ‖K‖₁‖K⁻¹‖₁ (a lower bound of the condition number, so this is an
  /// upper bound of the reciprocal, as the dense path's). UMFPACK: its Info[UMFPACK_RCOND],
  /// min|U_ii| / max|U_ii| — a rough figure, the only one UMFPACK gives.
  double reciprocalCondition() const;
  /// min|U_ii| / max|U_ii| of the last factorisation (KLU: klu_rcond; UMFPACK: the same figure
  /// as reciprocalCondition()). Unlike the estimate it sees an exact dependency at once.
  double pivotRatio() const;
  /// x ← K⁻¹ x for every column of x (rows = the system's size), with no allocation.
  void solveInPlace(Eigen::Ref<Eigen::MatrixXd> x);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mcopt
