// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A dense, strictly convex QP solved by the dual active-set method of Goldfarb and Idnani
// (Math. Programming 27, 1983), the core of the in-house inner solver (formulation.md §7):
//
//     min ½ xᵀ H x + gᵀ x   s.t.   E x = e,   C x ≤ d,        H positive definite.
//
// Why dual: it needs no feasible starting point (the previous sample's solution is rarely
// feasible for the next sample's balance), every iterate is the minimiser over its working
// set, and a QP with no feasible point is detected, not wandered in.
//
// Everything is done in the space transformed by H = L Lᵀ: with V = L⁻¹ N (N: the working
// set's normals as columns) kept as V = Q R by Gram–Schmidt with re-orthogonalisation, the
// primal step of a new constraint is −L⁻ᵀ (its normal's part orthogonal to range V) and the
// multiplier step is −R⁻¹ Qᵀ L⁻¹ n. A constraint whose normal lies in range V (degenerate
// rows, such as the centre-of-pressure and friction rows of an unloaded contact, which are all
// active at f = 0) never enters: only a multiplier step is taken, as in the original method.
//
// Allocation-free after resize(): every buffer is sized for the largest working set (n).
// Stationarity convention: H x + g + Eᵀ λ + Cᵀ μ = 0, μ ≥ 0.

#include <Eigen/Core>
#include <vector>

namespace mcopt::inner_detail {

class DualActiveSetQp {
 public:
  enum class Status { Optimal, Infeasible, IterationLimit, NotPositiveDefinite };

  /// Sizes every buffer: n variables, the equality rows, room for `inequalityCapacity` rows.
  void resize(int variables, int equalities, int inequalityCapacity);

  // Problem data, written in place by the caller between resize() and solve().
  Eigen::MatrixXd hessian;           ///< H, n × n (lower triangle read)
  Eigen::VectorXd gradient;          ///< g, n
  Eigen::MatrixXd equality;          ///< E, equalities × n
  Eigen::VectorXd equalityTarget;    ///< e
  Eigen::MatrixXd inequality;        ///< C, capacity × n; the first inequalityCount rows are used
  Eigen::VectorXd inequalityBound;   ///< d
  int inequalityCount = 0;

  /// Solves from the working set `initialWorkingSet` (inequality indices; the equalities are
  /// always in it): rows that are dependent or whose multipliers come out negative are left
  /// out, so any list is a valid warm start. `violationTolerance`: a row with
  /// C_i x − d_i ≤ tolerance · (1 + ‖x‖∞) · ‖C_i‖∞ counts as satisfied.
  Status solve(const std::vector<int>& initialWorkingSet, int maxIterations, double violationTolerance);

  // Results of the last solve.
  Eigen::VectorXd x;
  Eigen::VectorXd equalityMultipliers;    ///< λ
  Eigen::VectorXd inequalityMultipliers;  ///< μ ≥ 0, capacity entries, zero off the working set
  std::vector<int> activeSet;             ///< inequality rows in the final working set
  int iterations = 0;                     ///< working-set changes (additions and drops)

 private:
  struct Entry {
    int row = 0;        ///< inequality row, or equality row when isEquality
    bool isEquality = false;
  };
  auto normal(const Entry& e) const {
    return e.isEquality ? equality.row(e.row) : inequality.row(e.row);
  }
  double bound(const Entry& e) const { return e.isEquality ? equalityTarget[e.row] : inequalityBound[e.row]; }

  /// Orthogonalises v against Q's first `working_` columns: coefficients into `projection_`,
  /// remainder into `orthogonal_`. Returns ‖remainder‖.
  double orthogonalise(const Eigen::Ref<const Eigen::VectorXd>& v);
  /// Appends a working entry whose transformed normal is v; false (nothing changed) when dependent.
  bool append(const Entry& entry, const Eigen::Ref<const Eigen::VectorXd>& v, double multiplier);
  /// Removes working entry k and rebuilds Q, R from there on.
  void remove(int k);
  /// Minimiser over the working set as equalities, with gradient `g` and right-hand sides `b`
  /// (the working rows' bounds): writes x and the working multipliers.
  void solveWorkingSet(const Eigen::Ref<const Eigen::VectorXd>& g, const Eigen::Ref<const Eigen::VectorXd>& b);
  /// One step of iterative refinement of the working-set solution on the exact data.
  void refine();
  void transformedNormal(const Entry& e, Eigen::Ref<Eigen::VectorXd> v) const;  ///< v = L⁻¹ nᵀ

  int n_ = 0;
  Eigen::MatrixXd factor_;         ///< L (lower) of H = L Lᵀ
  Eigen::MatrixXd transformed_;    ///< V = L⁻¹ N, n × n
  Eigen::MatrixXd basis_;          ///< Q, n × n (first working_ columns)
  Eigen::MatrixXd triangle_;       ///< R, n × n upper (leading working_ block)
  std::vector<Entry> entries_;     ///< the working set, capacity n
  Eigen::VectorXd multipliers_;    ///< of the working entries
  Eigen::VectorXd multiplierStep_, projection_, orthogonal_, vector_, rhs_, residual_, correction_,
      savedX_, savedMultipliers_;
  std::vector<char> inWorkingSet_;
  int working_ = 0;
};

}  // namespace mcopt::inner_detail
