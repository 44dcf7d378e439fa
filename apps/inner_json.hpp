// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Inner problems and their results as JSON (docs/theory/inner-problem.md): the one reader of a
// problem and the one writer of a result, for `mcopt inner` and the Python module alike.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "apps/json_io.hpp"
#include "inner_qp/contact_problem.hpp"
#include "inner_qp/inner_solver.hpp"
#include "sensitivity/inner_sensitivity.hpp"

namespace mcopt::cli {

/// One problem's data as read, before assembly (assembleContactProblem checks sizes).
struct InnerProblemData {
  std::vector<ContactSpec> contacts;
  Eigen::MatrixXd wrenchToTorque;
  Eigen::VectorXd tau0, weights, linear;
  Vector6 balance = Vector6::Zero();
};

/// Reads one problem object; errors name `file` and `field` (e.g. problems[3].tau0).
InnerProblemData readInnerProblem(const std::filesystem::path& file, const json_io::Json& node, const std::string& field);

/// A registered contact model (contactModels()) by name, with the pyramid's facets when given;
/// InputError naming --contact-model and the registered ones otherwise, or facets given to
/// another model.
std::shared_ptr<const ContactModel> parseContactModel(const std::string& name, std::optional<int> pyramidFacets = {});

/// status, wrenches, objective, multipliers (balance, named rows, cones), active_set (row
/// names), iterations, kkt_residual, solve_time_us, balance_slack, message.
json_io::Json innerResultToJson(const ContactProblem& problem, const InnerResult& result);

/// Adds dwrenches_dtau0 and dwrenches_dbalance (formulation.md §8) to `out`; null with the
/// reason where the result is not optimal.
void addInnerSensitivity(const ContactProblem& problem, const InnerResult& result, const SensitivitySettings& settings,
                         json_io::Json& out);

}  // namespace mcopt::cli
