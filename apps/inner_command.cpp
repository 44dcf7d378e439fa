// SPDX-License-Identifier: BSD-3-Clause
// `mcopt inner`: solve inner contact-force problems given as data (formulation.md §7), one
// per time sample, with a chosen solver and contact model. Formats: docs/theory/inner-problem.md.
#include <cmath>
#include <iostream>
#include <optional>
#include <map>

#include "apps/commands.hpp"
#include "apps/json_io.hpp"
#include "core/atomic_file.hpp"
#include "inner_qp/inner_solver.hpp"
#include "apps/inner_json.hpp"
#include "sensitivity/inner_sensitivity.hpp"

namespace mcopt::cli {

namespace {

struct InnerOptions {
  std::string problems, out, solver = "active-set", contactModel = "report", kktBackend = "dense";
  bool sensitivity = false;
  std::optional<int> pyramidFacets;
  double tikhonov = 1e-9;
  bool cold = false;
  bool polish = false;
  std::optional<double> barrier;
};

using json_io::Json;
using json_io::allowKeys;
using json_io::required;

int runInner(const InnerOptions& o) {
  const std::filesystem::path file = o.problems;
  const Json input = json_io::readFile(file);
  allowKeys(file, input, "(top level)", {"problems"});
  const Json& problems = required(file, input, "(top level)", "problems");
  if (!problems.is_array()) throw InputError(file.string() + ": problems: expected a list");
  ContactProblemSettings settings;
  settings.model = parseContactModel(o.contactModel, o.pyramidFacets);
  settings.tikhonov = o.tikhonov;
  InnerSettings solverSettings;
  solverSettings.warmStart = !o.cold;
  solverSettings.polish = o.polish;
  if (o.barrier) {
    if (o.solver != "barrier")
      throw InputError("--barrier: only the barrier inner solver has a barrier parameter (the solver is " + o.solver + ")");
    if (!(*o.barrier > 0.0) || !std::isfinite(*o.barrier))
      throw InputError("--barrier: must be a positive number, got " + std::to_string(*o.barrier));
    solverSettings.barrier = *o.barrier;
  }
  auto solver = makeInnerSolver(o.solver, solverSettings);
  SensitivitySettings sensitivitySettings;
  sensitivitySettings.backend = parseKktBackend(o.kktBackend);

  Json results = Json::array();
  std::map<std::string, int> statusCounts;
  double totalTime = 0.0;
  long totalIterations = 0;
  InnerResult previous;  // consecutive problems are consecutive samples: the warm start
  for (std::size_t k = 0; k < problems.size(); ++k) {
    const std::string field = "problems[" + std::to_string(k) + "]";
    const InnerProblemData d = readInnerProblem(file, problems[k], field);
    ContactProblem p;
    try {
      p = assembleContactProblem(d.contacts, d.wrenchToTorque, d.tau0, d.balance, d.weights, d.linear, settings);
    } catch (const InputError& e) {
      throw InputError(file.string() + ": " + field + ": " + e.what());
    }
    if (previous.wrenches.size() != p.variableCount()) previous = InnerResult{};
    solver->solve(p, previous);
    Json result = innerResultToJson(p, previous);
    if (o.sensitivity) addInnerSensitivity(p, previous, sensitivitySettings, result);
    results.push_back(result);
    ++statusCounts[toString(previous.status)];
    totalTime += previous.solveTimeUs;
    totalIterations += previous.iterations;
  }
  Json output;
  output["solver"] = solver->name();
  output["contact_model"] = o.contactModel;
  output["results"] = results;
  const std::string text = output.dump(2) + "\n";
  if (o.out.empty())
    std::cout << text;
  else
    writeFileAtomically(o.out, text);
  std::cerr << "mcopt inner: " << problems.size() << " problems with " << solver->name() << " (" << o.contactModel
            << "):";
  for (const auto& [status, count] : statusCounts) std::cerr << " " << status << " " << count;
  if (!problems.empty())
    std::cerr << "; mean " << totalTime / static_cast<double>(problems.size()) << " µs and "
              << static_cast<double>(totalIterations) / static_cast<double>(problems.size()) << " iterations a problem";
  std::cerr << "\n";
  // Non-zero when any problem failed (infeasible is an answer, not a failure).
  return statusCounts.count("failed") ? 1 : 0;
}

}  // namespace

Runner addInner(CLI::App& app) {
  auto o = std::make_shared<InnerOptions>();
  app.add_option("--problems", o->problems, "inner problems (JSON, docs/theory/inner-problem.md)")->required();
  std::string solvers;
  for (const InnerSolverEntry& e : innerSolvers()) solvers += "; " + e.name + ": " + e.description;
  app.add_option("--solver", o->solver, "the inner solver, default active-set" + solvers);
  std::string models;
  for (const ContactModelEntry& e : contactModels()) models += "; " + e.name + ": " + e.description;
  app.add_option("--contact-model", o->contactModel, "the contact model, default report" + models);
  app.add_option("--pyramid-facets", o->pyramidFacets, "facets of the pyramid model (default 8; only with --contact-model pyramid)");
  app.add_option("--tikhonov", o->tikhonov, "ε added to the objective's Hessian diagonal (default 1e-9)");
  app.add_flag("--cold", o->cold, "do not warm-start each problem from the previous one's result");
  app.add_flag("--polish", o->polish,
               "slsqp, ipopt: polish each answer on its own active set (linear contact models; docs/theory/inner-problem.md)");
  app.add_option("--barrier", o->barrier,
                 "barrier: the central-path parameter μ in W (default 1e-3); each objective lies at most rows × μ above "
                 "its exact minimum (docs/theory/inner-problem.md)");
  app.add_flag("--sensitivity", o->sensitivity,
               "add dwrenches_dtau0 and dwrenches_dbalance (formulation.md §8) to each optimal result");
  app.add_option("--kkt-backend", o->kktBackend, "factorisation of the sensitivity's KKT system: dense (default), klu, umfpack");
  app.add_option("--out", o->out, "write the results there (atomically) instead of standard output");
  return [o] { return runInner(*o); };
}

}  // namespace mcopt::cli
