// SPDX-License-Identifier: BSD-3-Clause
// mcopt.InnerProblem, mcopt.InnerSolver, mcopt.InnerResult: the inner contact-force problem
// of one time sample (formulation.md §7) and its sensitivity (§8), what `mcopt inner` solves.
// A problem given as arrays goes through the reader of `mcopt inner`'s JSON problems, so it
// is checked, and refused, exactly as a problem file is (docs/theory/inner-problem.md).
#include <pybind11/stl.h>

#include "apps/inner_json.hpp"
#include "core/contact_maps.hpp"
#include "core/inverse_dynamics.hpp"
#include "inner_qp/multi_contact_dynamics.hpp"
#include "python/bindings.hpp"
#include "python/dynamics_handle.hpp"

namespace mcopt::python {

namespace {

using json_io::Json;

/// Where a problem built from Python says its errors come from (the CLI names the file).
constexpr const char* kOrigin = "mcopt.InnerProblem";

struct InnerProblemHandle {
  cli::InnerProblemData data;
  ContactProblemSettings settings;
  std::string modelName;
  ContactProblem problem;

  InnerProblemHandle(cli::InnerProblemData d, const std::string& contactModel, std::optional<int> facets, double tikhonov)
      : data(std::move(d)), modelName(contactModel) {
    settings.model = cli::parseContactModel(contactModel, facets);
    settings.tikhonov = tikhonov;
    problem = assembleContactProblem(data.contacts, data.wrenchToTorque, data.tau0, data.balance, data.weights,
                                     data.linear, settings);
  }

  /// The problem as an element of `mcopt inner`'s "problems" list.
  Json toJson() const {
    Json contacts = Json::array();
    for (const ContactSpec& c : data.contacts)
      contacts.push_back({{"name", c.name},
                          {"position", json_io::toJson(c.pose.translation)},
                          {"quaternion_xyzw", json_io::toJson(quaternionXyzwFromRotation(c.pose.rotation))},
                          {"mu", c.friction},
                          {"rectangle", {c.xMin, c.xMax, c.yMin, c.yMax}},
                          {"min_normal_force", c.minNormalForce}});
    return {{"contacts", contacts},
            {"wrench_to_torque", json_io::matrixToJson(data.wrenchToTorque)},
            {"tau0", json_io::toJson(data.tau0)},
            {"balance_wrench", json_io::toJson(data.balance)},
            {"torque_weights", json_io::toJson(data.weights)},
            {"torque_linear", json_io::toJson(data.linear)}};
  }
};

struct InnerResultHandle {
  std::shared_ptr<InnerProblemHandle> problem;
  InnerResult result;
  Json toJson() const { return cli::innerResultToJson(problem->problem, result); }
};

struct InnerSolverHandle {
  std::string name;
  std::unique_ptr<InnerSolver> solver;
};

/// Python values as JSON, through Python's own json module (numpy arrays as lists).
Json jsonOf(const py::object& value, const std::string& what) {
  const py::module_ json = py::module_::import("json");
  const py::object tolist = py::cpp_function([](const py::object& o) -> py::object {
    if (py::hasattr(o, "tolist")) return o.attr("tolist")();
    throw py::type_error("not a number or a list: " + std::string(py::str(py::type::of(o).attr("__name__"))));
  });
  try {
    const std::string text = py::str(json.attr("dumps")(value, py::arg("default") = tolist, py::arg("allow_nan") = false));
    return Json::parse(text);
  } catch (const py::error_already_set& e) {
    throw py::value_error(std::string(kOrigin) + ": " + what + ": " + std::string(py::str(e.value())));
  } catch (const Json::exception& e) {  // an integer beyond a double (10**400)
    throw py::value_error(std::string(kOrigin) + ": " + what + ": " + e.what());
  }
}

py::dict resultDict(const InnerResultHandle& r) { return toPython(r.toJson()); }

}  // namespace

void bindInner(py::module_& m) {
  m.def(
      "inner_solvers",
      [] {
        py::dict out;
        for (const InnerSolverEntry& e : innerSolvers()) out[py::str(e.name)] = e.description;
        return out;
      },
      "The registered inner solvers, name → what it is, in the order the documents list them.");
  m.def(
      "contact_models",
      [] {
        py::dict out;
        for (const ContactModelEntry& e : contactModels()) out[py::str(e.name)] = e.description;
        return out;
      },
      "The registered contact models, name → what it is, in the order the documents list them.");
  py::class_<InnerProblemHandle, std::shared_ptr<InnerProblemHandle>>(m, "InnerProblem", R"doc(
One sample's inner problem (formulation.md §7): the contact wrenches F_i (in each contact's
frame) that minimise Σ w Γ² + l Γ with Γ = tau0 − wrench_to_torque · F, subject to the balance
B F = W and each contact's model (report, pyramid, wrench-cone or point — a force alone, 3 variables; `pyramid_facets`, default 8,
only with the pyramid). Built from arrays (the
fields of a `mcopt inner` problem, docs/theory/inner-problem.md) or from a robot state and contact
surfaces (InnerProblem.from_state).)doc")
      .def(py::init([](const py::object& contacts, const py::object& wrenchToTorque, const py::object& tau0,
                       const py::object& balance, const py::object& weights, const py::object& linear,
                       const std::string& contactModel, std::optional<int> facets, double tikhonov) {
             Json node = {{"contacts", jsonOf(contacts, "contacts")},
                          {"wrench_to_torque", jsonOf(wrenchToTorque, "wrench_to_torque")},
                          {"tau0", jsonOf(tau0, "tau0")},
                          {"balance_wrench", jsonOf(balance, "balance_wrench")},
                          {"torque_weights", jsonOf(weights, "torque_weights")},
                          {"torque_linear", jsonOf(linear, "torque_linear")}};
             cli::InnerProblemData data = cli::readInnerProblem(kOrigin, node, "problem");
             try {
               return std::make_shared<InnerProblemHandle>(std::move(data), contactModel, facets, tikhonov);
             } catch (const InputError& e) {
               throw InputError(std::string(kOrigin) + ": problem: " + e.what());
             }
           }),
           py::arg("contacts"), py::arg("wrench_to_torque"), py::arg("tau0"), py::arg("balance_wrench"),
           py::arg("torque_weights"), py::arg("torque_linear"), py::arg("contact_model") = "report",
           py::arg("pyramid_facets") = py::none(), py::arg("tikhonov") = 1e-9,
           R"doc(`contacts`: a list of dicts {name, position (3), quaternion_xyzw (4), mu,
rectangle [x_min, x_max, y_min, y_max], min_normal_force}; `wrench_to_torque`: (n, 6 nc);
`tau0`, `torque_weights`, `torque_linear`: (n,); `balance_wrench`: (6,), world axes about the
world origin. Sizes, values and keys are checked as `mcopt inner` checks a problem file.)doc")
      .def_static(
          "from_state",
          [](const std::shared_ptr<DynamicsHandle>& dynamics, const py::object& q, const py::object& v,
             const py::object& a, const std::vector<std::string>& contacts, const std::string& contactModel,
             std::optional<int> facets, double tikhonov) {
            DynamicsHandle& d = *dynamics;
            const int n = d.model.jointCount();
            const Eigen::VectorXd qs = vectorArgument(q, "q", n);
            const Eigen::VectorXd vs = v.is_none() ? Eigen::VectorXd::Zero(n) : vectorArgument(v, "v", n);
            const Eigen::VectorXd as = a.is_none() ? Eigen::VectorXd::Zero(n) : vectorArgument(a, "a", n);
            if (contacts.empty()) throw py::value_error("contacts: expected the names of one or more contact surfaces");
            std::vector<ContactSurface> surfaces;
            for (const std::string& name : contacts) surfaces.push_back(d.robot->surface(name));
            // The bilevel formulation's own sample assembly (formulation.md §5, §7).
            inverseDynamics(d.model, d.data, qs, vs, as);
            ContactProblemSettings settings;
            settings.model = cli::parseContactModel(contactModel, facets);
            settings.tikhonov = tikhonov;
            SampleProblem sample(d.model, surfaces, settings);
            sample.update(d.model, d.data, d.robot->actuators, surfaces, vs, as);
            cli::InnerProblemData data;
            for (std::size_t i = 0; i < surfaces.size(); ++i) {
              const ContactSurface& s = surfaces[i];
              data.contacts.push_back({s.name, sample.frames[i].contactPose, s.friction, s.xMin, s.xMax, s.yMin, s.yMax, 0.0, nullptr});
            }
            data.wrenchToTorque = sample.wrenchToTorque;
            data.tau0 = d.data.tau;
            data.balance = d.data.referenceWrench;
            data.weights = sample.weights;
            data.linear = sample.linear;
            return std::make_shared<InnerProblemHandle>(std::move(data), contactModel, facets, tikhonov);
          },
          py::arg("dynamics"), py::arg("q"), py::arg("v") = py::none(), py::arg("a") = py::none(),
          py::arg("contacts"), py::arg("contact_model") = "report", py::arg("pyramid_facets") = py::none(),
          py::arg("tikhonov") = 1e-9,
          R"doc(The inner problem at state (q, v, a) with the named contact surfaces of the
dynamics' robot, as the bilevel formulation builds it at a sample: Γ0 and W0 from Newton–Euler,
J1 from the contact frames, w = R/(K N)² and l from the actuators (formulation.md §5–§7).)doc")
      .def_property_readonly("contact_count", [](const InnerProblemHandle& p) { return p.problem.contactCount; }, "number of contacts nc (6 nc wrench components)")
      .def_property_readonly("contact_names", [](const InnerProblemHandle& p) { return p.problem.contactNames; }, "the contacts, in the order of the stacked wrenches")
      .def_property_readonly("contact_model", [](const InnerProblemHandle& p) { return p.modelName; }, "the contact model's name (mcopt.contact_models())")
      .def_property_readonly("row_names", [](const InnerProblemHandle& p) { return p.problem.rowNames; },
                             "names of the linear rows G F ≤ g, '<contact>.<row>'")
      .def_property_readonly("variable_count", [](const InnerProblemHandle& p) { return p.problem.variableCount(); },
                             "m: the stacked wrench variables, 6 a contact (3 for a point contact: the force alone)")
      .def_property_readonly("hessian", [](const InnerProblemHandle& p) { return matrixToNumpy(p.problem.hessian); },
                             "H of ½ Fᵀ H F + cᵀ F, with the Tikhonov term")
      .def_property_readonly("gradient", [](const InnerProblemHandle& p) { return vectorToNumpy(p.problem.gradient); }, "c of ½ Fᵀ H F + cᵀ F")
      .def_property_readonly("balance", [](const InnerProblemHandle& p) { return matrixToNumpy(p.problem.balance); },
                             "B (6, m): the wrenches to the world, about its origin")
      .def_property_readonly("balance_target", [](const InnerProblemHandle& p) { return vectorToNumpy(p.problem.balanceTarget); }, "W (6,): the wrench the contacts must balance, world axes about the world origin")
      .def_property_readonly("inequality", [](const InnerProblemHandle& p) { return matrixToNumpy(p.problem.inequality); }, "G of the linear rows G F ≤ g (rows named by row_names)")
      .def_property_readonly("inequality_bound", [](const InnerProblemHandle& p) { return vectorToNumpy(p.problem.inequalityBound); }, "g of the linear rows G F ≤ g")
      .def(
          "objective",
          [](const InnerProblemHandle& p, const py::object& wrenches) {
            return p.problem.objective(vectorArgument(wrenches, "wrenches", p.problem.variableCount()));
          },
          py::arg("wrenches"),
          "Σ w Γ² + l Γ at the stacked wrench variables (variable_count,: 6 a contact, 3 for a point contact), "
          "without the Tikhonov term.")
      .def(
          "constraint_violation",
          [](const InnerProblemHandle& p, const py::object& wrenches) {
            return p.problem.constraintViolation(vectorArgument(wrenches, "wrenches", p.problem.variableCount()));
          },
          py::arg("wrenches"), "Largest violation of the balance, the linear rows and the cones (0 when feasible).")
      .def(
          "to_dict", [](const InnerProblemHandle& p) { return toPython(p.toJson()); },
          "The problem as an element of a `mcopt inner` problems file (docs/theory/inner-problem.md).");

  py::class_<InnerResultHandle, std::shared_ptr<InnerResultHandle>>(m, "InnerResult", R"doc(
An inner solver's result: status ('optimal', 'infeasible' with the least-norm balance slack, or
'failed'), wrenches, objective, multipliers, active set, iterations, KKT residual.)doc")
      .def_property_readonly("status", [](const InnerResultHandle& r) { return std::string(toString(r.result.status)); }, "'optimal', 'infeasible' or 'failed'")
      .def_property_readonly(
          "wrenches",
          [](const InnerResultHandle& r) {
            const int nc = r.problem->problem.contactCount;
            Eigen::MatrixXd w(nc, 6);
            for (int i = 0; i < nc; ++i) w.row(i) = r.problem->problem.contactWrench(r.result.wrenches, i).transpose();
            return matrixToNumpy(w);
          },
          "(nc, 6): each contact's (fx, fy, fz, mx, my, mz) in its own frame")
      .def_property_readonly("objective", [](const InnerResultHandle& r) { return r.result.objective; }, "Σ w Γ² + l Γ at the wrenches, without the Tikhonov term")
      .def_property_readonly("iterations", [](const InnerResultHandle& r) { return r.result.iterations; }, "the solver's iterations (its own count)")
      .def_property_readonly("kkt_residual", [](const InnerResultHandle& r) { return r.result.kktResidual; }, "largest of stationarity, feasibility and complementarity, relative to the data")
      .def_property_readonly("polished", [](const InnerResultHandle& r) { return r.result.polished; }, "whether the answer was polished on its active set (InnerSolver(polish=True))")
      .def_property_readonly("barrier", [](const InnerResultHandle& r) { return r.result.barrier; }, "0 for an exact optimum; μ for the barrier solver's central point")
      .def_property_readonly("balance_slack", [](const InnerResultHandle& r) { return vectorToNumpy(r.result.balanceSlack); }, "(6,): the least-norm balance slack when 'infeasible', zero otherwise")
      .def_property_readonly("active_set", [](const InnerResultHandle& r) -> py::object { const py::dict d = resultDict(r); return d["active_set"]; },
                             "names of the active rows (and '<contact>.cone' for active cones)")
      .def_property_readonly("multipliers", [](const InnerResultHandle& r) -> py::object { const py::dict d = resultDict(r); return d["multipliers"]; },
                             "{'balance': (6,), 'rows': {name: value} (non-zero ones), 'cones': {contact: (3,)}}")
      .def_property_readonly("message", [](const InnerResultHandle& r) { return r.result.message; }, "the underlying solver's own words")
      .def("to_dict", &resultDict, "The result as `mcopt inner` writes it (one element of its results list).")
      .def(
          "sensitivity",
          [](const InnerResultHandle& r, const std::string& backend) {
            SensitivitySettings settings;
            settings.backend = parseKktBackend(backend);
            Json out;
            cli::addInnerSensitivity(r.problem->problem, r.result, settings, out);
            return toPython(out);
          },
          py::arg("backend") = "dense",
          R"doc(dF/dτ0 (6 nc, n) and dF/dW (6 nc, 6) from the KKT system (formulation.md §8), with
the factorisation `backend` (dense, klu or umfpack): {'dwrenches_dtau0', 'dwrenches_dbalance',
'sensitivity': {'degenerate', 'diagnostics'}}; None with a note unless the result is optimal.)doc")
      .def("__repr__", [](const InnerResultHandle& r) {
        return std::string("<mcopt.InnerResult ") + toString(r.result.status) + ", objective " +
               std::to_string(r.result.objective) + ">";
      });

  py::class_<InnerSolverHandle, std::shared_ptr<InnerSolverHandle>>(m, "InnerSolver", R"doc(
An inner solver by its registered name (`mcopt.inner_solvers()`: name → what it is).)doc")
      .def(py::init([](const std::string& name, double tolerance, double kktTolerance, int maxIterations, bool warmStart,
                       bool polish, double barrier) {
             InnerSettings settings;
             settings.tolerance = tolerance, settings.kktTolerance = kktTolerance;
             settings.maxIterations = maxIterations, settings.warmStart = warmStart, settings.polish = polish;
             settings.barrier = barrier;
             auto handle = std::make_shared<InnerSolverHandle>();
             handle->solver = makeInnerSolver(name, settings);
             handle->name = handle->solver->name();
             return handle;
           }),
           py::arg("name") = "active-set", py::arg("tolerance") = 1e-9, py::arg("kkt_tolerance") = 1e-6,
           py::arg("max_iterations") = 500, py::arg("warm_start") = true, py::arg("polish") = false,
           py::arg("barrier") = InnerSettings{}.barrier,
           "Settings as in inner_solver.hpp; `warm_start` False is `mcopt inner --cold`, `polish` True is "
           "`mcopt inner --polish` (slsqp, ipopt: each answer polished on its own active set), `barrier` is "
           "`mcopt inner --barrier` (the barrier solver's μ in W; the others do not read it).")
      .def_property_readonly("name", [](const InnerSolverHandle& s) { return s.name; }, "its registered name")
      .def(
          "solve",
          [](InnerSolverHandle& s, const std::shared_ptr<InnerProblemHandle>& problem,
             const std::shared_ptr<InnerResultHandle>& previous) {
            auto out = std::make_shared<InnerResultHandle>();
            out->problem = problem;
            // Consecutive samples: the previous result is the starting point (as `mcopt inner`
            // does along its list), when it has this problem's size.
            if (previous && previous->result.wrenches.size() == problem->problem.variableCount())
              out->result = previous->result;
            if (s.name == "ipopt") {  // MUMPS: one Ipopt at a time in the process (bindings.hpp)
              py::gil_scoped_release release;
              const std::lock_guard<std::mutex> oneIpoptAtATime(ipoptMutex());
              s.solver->solve(problem->problem, out->result);
            } else {
              s.solver->solve(problem->problem, out->result);
            }
            return out;
          },
          py::arg("problem"), py::arg("previous") = nullptr,
          "Solves `problem`, warm-started from `previous` (an InnerResult of a problem of the same size).");
}

}  // namespace mcopt::python
