// SPDX-License-Identifier: BSD-3-Clause
#include "outer_nlp/outer_solver.hpp"

#include <iterator>
#include <utility>

#include "core/errors.hpp"

namespace mcopt {

std::unique_ptr<OuterSolver> makeIpoptSolver();  // ipopt_driver.cpp

namespace {

/// Each OuterStatus's name in result.json, in the enum's order: the one place they are listed.
constexpr const char* kStatusNames[] = {
    "running",          "optimal",   "acceptable",         "maximum_iterations",        "maximum_cpu_time",
    "tiny_step",        "infeasible", "interrupted",       "feasible_point_found",      "diverging",
    "restoration_failed", "error_in_step_computation", "invalid_number", "too_few_degrees_of_freedom",
    "invalid_option",   "out_of_memory", "internal_error", "stalled"};
static_assert(std::size(kStatusNames) == static_cast<std::size_t>(OuterStatus::Stalled) + 1);

using OuterSolverFactory = std::unique_ptr<OuterSolver> (*)();

/// The outer solvers by name: one line each.
const std::vector<std::pair<std::string, OuterSolverFactory>>& outerSolvers() {
  static const std::vector<std::pair<std::string, OuterSolverFactory>> solvers = {
      {"ipopt", &makeIpoptSolver},
  };
  return solvers;
}

}  // namespace

const char* toString(OuterStatus status) { return kStatusNames[static_cast<std::size_t>(status)]; }

std::vector<std::string> outerSolverNames() {
  std::vector<std::string> names;
  for (const auto& [name, make] : outerSolvers()) names.push_back(name);
  return names;
}

std::unique_ptr<OuterSolver> makeOuterSolver(std::string_view name) {
  for (const auto& [known, make] : outerSolvers())
    if (known == name) return make();
  std::string list;
  for (const std::string& known : outerSolverNames()) list += (list.empty() ? "" : ", ") + known;
  throw InputError("outer solver: expected " + list + "; got '" + std::string(name) + "'");
}

OuterOutcome solveOuter(NlpProblem& problem, const Eigen::VectorXd& start, const OuterSolverSettings& settings,
                        const IterationCallback& onIteration) {
  return makeOuterSolver(settings.solver)->solve(problem, start, settings, onIteration);
}

}  // namespace mcopt
