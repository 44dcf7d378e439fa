// SPDX-License-Identifier: BSD-3-Clause
#include "apps/inner_json.hpp"

#include <algorithm>

#include "sensitivity/inner_sensitivity.hpp"

namespace mcopt::cli {

using json_io::Json;
using json_io::allowKeys;
using json_io::required;

InnerProblemData readInnerProblem(const std::filesystem::path& file, const Json& node, const std::string& field) {
  allowKeys(file, node, field,
            {"contacts", "wrench_to_torque", "tau0", "balance_wrench", "torque_weights", "torque_linear"});
  InnerProblemData d;
  const Json& contacts = required(file, node, field, "contacts");
  if (!contacts.is_array() || contacts.empty())
    throw InputError(file.string() + ": " + field + ".contacts: expected a non-empty list of contacts");
  for (std::size_t i = 0; i < contacts.size(); ++i) {
    const std::string where = field + ".contacts[" + std::to_string(i) + "]";
    const Json& c = contacts[i];
    allowKeys(file, c, where, {"name", "position", "quaternion_xyzw", "mu", "rectangle", "min_normal_force"});
    ContactSpec spec;
    spec.name = "contact" + std::to_string(i);
    if (c.contains("name")) {
      if (!c["name"].is_string()) throw InputError(file.string() + ": " + where + ".name: expected a string");
      spec.name = c["name"].get<std::string>();
    }
    spec.pose.translation = json_io::numbers(file, required(file, c, where, "position"), where + ".position", 3);
    const Eigen::VectorXd q =
        json_io::numbers(file, required(file, c, where, "quaternion_xyzw"), where + ".quaternion_xyzw", 4);
    if (q.norm() < 1e-9) throw InputError(file.string() + ": " + where + ".quaternion_xyzw: zero quaternion");
    spec.pose.rotation = rotationFromQuaternionXyzw(q[0], q[1], q[2], q[3]);
    const Json& mu = required(file, c, where, "mu");
    if (!mu.is_number()) throw InputError(file.string() + ": " + where + ".mu: expected a number");
    spec.friction = mu.get<double>();
    const Eigen::VectorXd rectangle = json_io::numbers(file, required(file, c, where, "rectangle"), where + ".rectangle", 4);
    spec.xMin = rectangle[0], spec.xMax = rectangle[1], spec.yMin = rectangle[2], spec.yMax = rectangle[3];
    if (c.contains("min_normal_force")) {
      if (!c["min_normal_force"].is_number())
        throw InputError(file.string() + ": " + where + ".min_normal_force: expected a number");
      spec.minNormalForce = c["min_normal_force"].get<double>();
    }
    d.contacts.push_back(spec);
  }
  const Json& map = required(file, node, field, "wrench_to_torque");
  const std::string mapField = field + ".wrench_to_torque";
  if (!map.is_array() || map.empty()) throw InputError(file.string() + ": " + mapField + ": expected a list of rows");
  const long columns = 6 * static_cast<long>(d.contacts.size());
  d.wrenchToTorque.resize(static_cast<Eigen::Index>(map.size()), columns);
  for (std::size_t r = 0; r < map.size(); ++r)
    d.wrenchToTorque.row(static_cast<Eigen::Index>(r)) =
        json_io::numbers(file, map[r], mapField + "[" + std::to_string(r) + "]", columns).transpose();
  const long joints = static_cast<long>(map.size());
  d.tau0 = json_io::numbers(file, required(file, node, field, "tau0"), field + ".tau0", joints);
  d.balance = json_io::numbers(file, required(file, node, field, "balance_wrench"), field + ".balance_wrench", 6);
  d.weights = json_io::numbers(file, required(file, node, field, "torque_weights"), field + ".torque_weights", joints);
  d.linear = json_io::numbers(file, required(file, node, field, "torque_linear"), field + ".torque_linear", joints);
  return d;
}

std::shared_ptr<const ContactModel> parseContactModel(const std::string& name, std::optional<int> pyramidFacets) {
  if (!isContactModelName(name))
    throw InputError("--contact-model: expected " + contactModelList() + "; got '" + name + "'");
  ContactModelOptions options;
  if (pyramidFacets) {
    if (name != "pyramid")
      throw InputError("pyramid facets: only the pyramid contact model has facets (the contact model is " + name + ")");
    options.pyramidFacets = *pyramidFacets;
  }
  return makeContactModel(name, options);
}

Json innerResultToJson(const ContactProblem& p, const InnerResult& r) {
  Json out;
  out["status"] = toString(r.status);
  Json wrenches = Json::array();
  for (int i = 0; i < p.contactCount; ++i) wrenches.push_back(json_io::toJson(p.contactWrench(r.wrenches, i)));
  out["wrenches"] = wrenches;
  out["objective"] = r.objective;
  Json multipliers;
  multipliers["balance"] = json_io::toJson(r.balanceMultipliers);
  Json rows = Json::object();
  for (Eigen::Index i = 0; i < r.inequalityMultipliers.size(); ++i)
    if (r.inequalityMultipliers[i] != 0.0) rows[p.rowNames[static_cast<std::size_t>(i)]] = r.inequalityMultipliers[i];
  multipliers["rows"] = rows;
  if (!p.cones.empty()) {
    Json cones = Json::object();
    for (std::size_t k = 0; k < p.cones.size(); ++k)
      cones[p.contactNames[static_cast<std::size_t>(p.cones[k].contact)]] =
          json_io::toJson(r.coneMultipliers.segment<3>(3 * static_cast<Eigen::Index>(k)));
    multipliers["cones"] = cones;
  }
  out["multipliers"] = multipliers;
  Json active = Json::array();
  const auto rowCount = static_cast<int>(p.inequality.rows());
  for (int a : r.activeSet)
    active.push_back(a < rowCount ? p.rowNames[static_cast<std::size_t>(a)]
                                  : p.contactNames[static_cast<std::size_t>(p.cones[static_cast<std::size_t>(a - rowCount)].contact)] +
                                        ".cone");
  out["active_set"] = active;
  out["iterations"] = r.iterations;
  out["kkt_residual"] = r.kktResidual;
  out["polished"] = r.polished;
  out["barrier"] = r.barrier;  // 0: an exact optimum; μ: the barrier solver's central point
  out["solve_time_us"] = r.solveTimeUs;
  out["balance_slack"] = json_io::toJson(r.balanceSlack);
  if (!r.message.empty()) out["message"] = r.message;
  return out;
}

/// dF/dτ0 and dF/dW (formulation.md §8), rows in the order of the stacked wrenches; null
/// with the reason where the result is not optimal.
void addInnerSensitivity(const ContactProblem& p, const InnerResult& r, const SensitivitySettings& settings, Json& out) {
  if (r.status != InnerStatus::Optimal) {
    out["dwrenches_dtau0"] = nullptr;
    out["dwrenches_dbalance"] = nullptr;
    out["sensitivity"] = {{"note", std::string("no derivative: the result is ") + toString(r.status)}};
    return;
  }
  InnerSensitivity sensitivity(settings);
  const SensitivityDiagnostics& d = sensitivity.factorize(p, r);
  Eigen::MatrixXd dTau0, dBalance;
  sensitivity.dataSensitivities(p, dTau0, dBalance);
  out["dwrenches_dtau0"] = json_io::matrixToJson(p.wrenchRows(dTau0));
  out["dwrenches_dbalance"] = json_io::matrixToJson(p.wrenchRows(dBalance));
  out["sensitivity"] = {{"degenerate", d.degenerate()}, {"diagnostics", d.describe()}};
}

}  // namespace mcopt::cli
