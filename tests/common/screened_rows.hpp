// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Row screening's tests (torque-limit and closing-row screening): every row of a screened motion
// problem found in the full one by its name (and which of the rows of that name it is: a
// joint's velocity-limit rows share one), with the same value, bounds and Jacobian row at x.
#include <catch2/catch.hpp>

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "common/nlp_jacobian.hpp"
#include "outer_nlp/motion_problem.hpp"

namespace mcopt::test {

/// Checks every row of `screened` against its row in `full` at x, then calls
/// visit(screened row, full row) for it.
inline void checkScreenedRows(MotionProblem& full, MotionProblem& screened, const Eigen::VectorXd& x,
                              const std::function<void(int, int)>& visit) {
  const auto keys = [](const MotionProblem& problem) {
    std::vector<std::string> key;
    std::map<std::string, int> seen;
    for (int r = 0; r < problem.constraintCount(); ++r) {
      const std::string name = problem.rowName(r);
      key.push_back(name + "#" + std::to_string(seen[name]++));
    }
    return key;
  };
  const std::vector<std::string> fullKeys = keys(full), screenedKeys = keys(screened);
  std::map<std::string, int> fullRows;
  for (int r = 0; r < full.constraintCount(); ++r) fullRows[fullKeys[static_cast<std::size_t>(r)]] = r;
  Eigen::VectorXd gFull, gScreened, lowerFull, upperFull, lowerScreened, upperScreened;
  full.constraints(x, gFull);
  screened.constraints(x, gScreened);
  full.constraintBounds(lowerFull, upperFull);
  screened.constraintBounds(lowerScreened, upperScreened);
  const Eigen::MatrixXd jacobianFull = denseJacobian(full, x), jacobianScreened = denseJacobian(screened, x);
  for (int r = 0; r < screened.constraintCount(); ++r) {
    const auto found = fullRows.find(screenedKeys[static_cast<std::size_t>(r)]);
    REQUIRE(found != fullRows.end());
    const int f = found->second;
    CHECK(gScreened[r] == gFull[f]);
    CHECK(lowerScreened[r] == lowerFull[f]);
    CHECK(upperScreened[r] == upperFull[f]);
    CHECK((jacobianScreened.row(r) - jacobianFull.row(f)).cwiseAbs().maxCoeff() == 0.0);
    visit(r, f);
  }
}

}  // namespace mcopt::test
