// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Central differences for the derivative tests (style.md §4): each entry of x is perturbed
// by ±h in place, f() re-evaluated, and the entry restored to its exact original value.
#include <Eigen/Core>

namespace mcopt::test {

/// Columns k = (f(x + h e_k) − f(x − h e_k)) / 2h; f() reads x and returns a vector.
template <class Function>
Eigen::MatrixXd centralDifferences(Eigen::VectorXd& x, double h, Function&& f) {
  Eigen::MatrixXd columns;
  for (Eigen::Index k = 0; k < x.size(); ++k) {
    const double saved = x[k];
    x[k] = saved + h;
    const Eigen::VectorXd plus = f();
    x[k] = saved - h;
    const Eigen::VectorXd minus = f();
    x[k] = saved;
    if (k == 0) columns.resize(plus.size(), x.size());
    columns.col(k) = (plus - minus) / (2 * h);
  }
  return columns;
}

}  // namespace mcopt::test
