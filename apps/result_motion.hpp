// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A result's motion read back (docs/reference/results.md): its spline parameters by joint, its
// duration and its contact-force variables — what the motion is, never its sampled arrays —
// and the scenario it is a motion of, with the formulation and inner solver it ran with.
// `mcopt verify`, `mcopt run --start-from` and the Python module read results through here.

#include <Eigen/Core>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "outer_nlp/motion_problem.hpp"
#include "outer_nlp/scenario.hpp"

namespace mcopt::cli {

/// result.json's `format`: 2 added `format`, `contact_force_variables` and an absolute `scenario`.
inline constexpr int kResultFormat = 2;

struct ResultMotion {
  std::filesystem::path file;      ///< the result.json read
  int format = 1;                  ///< 1: written before `format` existed
  std::filesystem::path scenario;  ///< the scenario file it is a result of
  std::string contactForces, innerSolver;  ///< as run (innerSolver: "" unless bilevel with contacts)
  std::vector<std::string> jointNames, contactNames;  ///< contactNames: the reference contact first
  std::map<std::string, std::vector<double>> parameters;  ///< spline parameters by joint
  double duration = 0.0;
  int samples = 0;                 ///< the grid it was optimised on (a refined run's, finer than its scenario's); 0: the scenario's
  Eigen::VectorXd forceVariables;  ///< the splines / variables formulations' z (empty otherwise)
};

/// Reads a result folder (or its result.json). Throws InputError naming the file and field for
/// what is missing or malformed; with `current`, also for a result written before this format
/// ("an older format"), whose force variables and scenario path cannot be trusted.
ResultMotion readResultMotion(const std::filesystem::path& folderOrFile, bool current);

/// The scenario of a result — its own file, or `scenarioFile` when not empty — with the result's
/// formulation and inner solver, and the result's motion as its initial motion. Throws InputError
/// when the scenario's joints or contacts are not the result's (naming the field).
Scenario scenarioOfResult(const ResultMotion& result, const std::filesystem::path& scenarioFile = {});

/// The result's point x of `problem` (built from scenarioOfResult's scenario): its spline
/// parameters and duration, its force variables (checked against the problem's count), the
/// epigraph's slacks at max(P, 0).
Eigen::VectorXd pointOfResult(MotionProblem& problem, const ResultMotion& result);

}  // namespace mcopt::cli
