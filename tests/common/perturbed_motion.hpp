// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A motion problem's initial point with its spline parameters (± size) and force variables
// (± 20 size, newtons) perturbed at random: a generic point for the outer problems' tests.
#include <Eigen/Core>
#include <random>

#include "outer_nlp/motion_problem.hpp"

namespace mcopt::test {

inline Eigen::VectorXd perturbedMotion(MotionProblem& problem, double size, unsigned seed) {
  Eigen::VectorXd x = problem.initialPoint(problem.scenario().start, problem.scenario().end);
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> u(-size, size);
  for (int i = 0; i < problem.parametrization().parameterCount(); ++i) x[i] += u(random);
  for (int i = 0; i < problem.forceVariableCount(); ++i) x[problem.forceVariableStart() + i] += 20.0 * u(random);
  return x;
}

}  // namespace mcopt::test
