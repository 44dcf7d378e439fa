// SPDX-License-Identifier: BSD-3-Clause
// mcopt.Scenario: a scenario file (docs/reference/scenario-file.md) whose fields can be read and changed by
// field path (the sweep's paths, docs/reference/studies.md), and run like `mcopt run` with a progress
// callback, the GIL released while it runs and Ctrl-C ending it with its last iterate.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>
#include <yaml-cpp/yaml.h>

#include <optional>
#include <stdexcept>

#include "apps/run_output.hpp"
#include "apps/verification_output.hpp"
#include "core/atomic_file.hpp"
#include "core/errors.hpp"
#include "core/yaml_fields.hpp"
#include "outer_nlp/motion_problem.hpp"
#include "outer_nlp/scenario.hpp"
#include "outer_nlp/scenario_yaml.hpp"
#include "outer_nlp/scenario_run.hpp"
#include "outer_nlp/task.hpp"
#include "python/bindings.hpp"
#include "python/robot_handle.hpp"
#include "study/field_path.hpp"
#include "study/scenario_tree.hpp"
#include "outer_nlp/formulation_registry.hpp"

namespace mcopt::python {

namespace {

struct ScenarioHandle {
  std::filesystem::path file;
  YAML::Node root;  ///< the scenario's fields as read and changed; side files relative to `file`
  /// The formulation chosen when it was opened, over the file's: as `mcopt run --contact-forces`,
  /// it is the one the file's checks see (a bilevel file with `hessian: exact` opens for splines).
  std::optional<std::string> contactForces;
  Scenario scenario;
};

std::optional<std::string> formulationArgument(const std::optional<std::string>& name) {
  if (!name) return std::nullopt;
  return contactForceFormulation(*name).name;
}

/// A YAML scalar as the Python value it reads as: int, float, bool, None or str.
py::object scalarToPython(const YAML::Node& node) {
  const std::string& text = node.Scalar();
  if (node.Tag() != "!") {  // unquoted: may be a number, a boolean or null
    long long integer = 0;
    if (YAML::convert<long long>::decode(node, integer)) return py::int_(integer);
    double number = 0.0;
    if (YAML::convert<double>::decode(node, number)) return py::float_(number);
    bool flag = false;
    if (YAML::convert<bool>::decode(node, flag)) return py::bool_(flag);
    if (text == "~" || text == "null" || text == "Null" || text == "NULL") return py::none();
  }
  return py::str(text);
}

py::object yamlToPython(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Scalar: return scalarToPython(node);
    case YAML::NodeType::Sequence: {
      py::list out;
      for (const YAML::Node& e : node) out.append(yamlToPython(e));
      return out;
    }
    case YAML::NodeType::Map: {
      py::dict out;
      for (const auto& kv : node) out[yamlToPython(kv.first)] = yamlToPython(kv.second);
      return out;
    }
    default: return py::none();
  }
}

YAML::Node pythonToYaml(const py::handle& value, const std::string& field) {
  if (value.is_none()) return YAML::Node(YAML::NodeType::Null);
  if (py::isinstance<py::bool_>(value)) return YAML::Node(value.cast<bool>());
  if (py::isinstance<py::int_>(value)) return YAML::Node(value.cast<long long>());
  if (py::isinstance<py::float_>(value)) return YAML::Node(value.cast<double>());
  if (py::isinstance<py::str>(value)) return YAML::Node(value.cast<std::string>());
  if (py::hasattr(value, "tolist") && !py::isinstance<py::str>(value))  // numpy arrays and scalars
    return pythonToYaml(value.attr("tolist")(), field);
  if (py::isinstance<py::dict>(value)) {
    YAML::Node out(YAML::NodeType::Map);
    for (const auto& [k, v] : value.cast<py::dict>()) {
      if (!py::isinstance<py::str>(k)) throw py::value_error(field + ": keys must be strings");
      const std::string key = k.cast<std::string>();
      out[key] = pythonToYaml(v, field + "." + key);
    }
    return out;
  }
  if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
    YAML::Node out(YAML::NodeType::Sequence);
    std::size_t i = 0;
    for (const py::handle e : value) out.push_back(pythonToYaml(e, field + "[" + std::to_string(i++) + "]"));
    return out;
  }
  throw py::value_error(field + ": cannot be written to a scenario: " +
                        std::string(py::str(py::type::of(value).attr("__name__"))));
}

study::FieldPath pathArgument(const std::string& text) {
  try {
    return study::parseFieldPath(text);
  } catch (const std::invalid_argument& e) {
    throw py::key_error(text + ": " + e.what());
  }
}

/// A refused value, said as a sweep says it (docs/reference/studies.md): the value set from Python has
/// no line in the file, so the loader's location is replaced by the field and its value.
std::string refusal(const std::string& message, const std::filesystem::path& file, const std::string& path,
                    const YAML::Node& value) {
  std::string reason = message;
  const std::string head = file.string() + ":";
  if (reason.compare(0, head.size(), head) == 0) {
    const std::size_t colon = reason.find(": ", head.size());
    if (colon != std::string::npos) reason = reason.substr(colon + 2);
  }
  YAML::Emitter text;
  text << YAML::Flow << value;
  return file.string() + ": " + path + " = " + text.c_str() + ": the scenario refuses it: " + reason;
}

py::dict iterationDict(const IterationRecord& h, const MotionProblem& problem) {
  py::dict d;
  d["stage"] = h.stage, d["iteration"] = h.iteration, d["objective"] = h.objective;
  d["violation"] = h.violation, d["dual_infeasibility"] = h.dualInfeasibility;
  d["step_size"] = h.stepSize, d["elapsed_seconds"] = h.elapsedSeconds;
  if (problem.bilevel()) d["infeasible_samples"] = h.inner.infeasible;
  return d;
}

py::dict run(const ScenarioHandle& s, const py::object& progress, const std::optional<std::filesystem::path>& out,
             const std::optional<int>& maxIterations, const std::optional<std::string>& contactForces,
             const std::optional<bool>& configurationOptimisation, const std::optional<std::string>& hessian,
             const std::optional<int>& refine) {
  // Another formulation than the one it was opened with is checked against the file as the
  // command line's is (loadScenario's contactForces): the file's checks see the run's formulation.
  const std::optional<std::string> forces = formulationArgument(contactForces);
  Scenario scenario = forces && forces != s.contactForces ? loadScenario(s.root, s.file, forces) : s.scenario;
  ScenarioOverrides overrides;
  overrides.maxIterations = maxIterations;
  overrides.contactForces = forces;
  overrides.configurationOptimisation = configurationOptimisation;
  overrides.refineRounds = refine;
  if (hessian) {
    try {
      overrides.hessian = parseHessianOption(*hessian);
    } catch (const InputError& e) {
      throw InputError(std::string("hessian: ") + e.what());
    }
  }
  applyOverrides(scenario, overrides);
  MotionProblem problem(scenario);

  // Python runs only with the GIL: every callback takes it back for its time.
  std::optional<py::error_already_set> failure;  // raised by the callback: re-raised after the run
  ScenarioRunEvents events;
  auto interruption = [&](py::error_already_set& e) {
    if (e.matches(PyExc_KeyboardInterrupt)) return false;  // Ctrl-C: an interrupted run, not an error
    failure.emplace(std::move(e));
    return false;
  };
  events.onIteration = [&](const RunRecord& sofar, const MotionProblem& current, const IterationReport&) {
    if (progress.is_none()) return true;
    py::gil_scoped_acquire gil;
    try {
      const py::object answer = progress(iterationDict(sofar.history.back(), current));
      return answer.is_none() || answer.cast<bool>();
    } catch (py::error_already_set& e) {
      return interruption(e);
    }
  };
  events.keepRunning = [&] {
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() == 0) return true;  // runs Python's signal handlers (main thread)
    py::error_already_set e;
    return interruption(e);
  };
  RunRecord record;
  std::optional<RefinedRun> refined;  // its last round's scenario and problem, when refined
  {
    py::gil_scoped_release release;
    const std::lock_guard<std::mutex> oneIpoptAtATime(ipoptMutex());
    record = runScenario(scenario, problem, events);
    if (scenario.solve.refineRounds > 0 && record.status == OuterStatus::Optimal && !failure) {
      refined = refineRun(scenario, problem, std::move(record), scenario.solve.refineRounds, VerificationSettings{}, events);
      record = std::move(refined->record);
    }
  }
  if (failure) throw *failure;
  const cli::RunFiles files = cli::makeRunFiles(refined && refined->problem ? *refined->problem : problem, record);
  if (out) cli::writeRunFiles(*out, files);
  py::dict result = toPython(files.result);
  result["x"] = vectorToNumpy(record.x);
  return result;
}

}  // namespace

void bindScenario(py::module_& m) {
  m.def(
      "contact_force_formulations",
      [] {
        py::dict out;
        for (const ContactForceFormulationEntry& e : contactForceFormulations()) out[py::str(e.name)] = e.description;
        return out;
      },
      "The registered contact-force formulations (a scenario's contact_forces), name → what it is, in the order the "
      "documents list them.");
  py::class_<ScenarioHandle, std::shared_ptr<ScenarioHandle>>(m, "Scenario", R"doc(
A motion-optimisation scenario (docs/reference/scenario-file.md). Fields are read and changed by field path,
as a sweep names them (docs/reference/studies.md): `s["samples"] = 40`, `s["tasks[kick].target[0]"]`,
`s["inner.solver"] = "slsqp"`. Every change is validated by the scenario loader at once; a
refused value raises mcopt.InputError with the loader's message and leaves the scenario as it
was. `run()` optimises it as `mcopt run` does.)doc")
      .def(py::init([](const std::filesystem::path& file, const std::optional<std::string>& contactForces) {
             auto s = std::make_shared<ScenarioHandle>();
             s->file = file;
             s->contactForces = formulationArgument(contactForces);
             s->root = yaml::loadFile(file);
             s->scenario = loadScenario(s->root, file, s->contactForces);
             return s;
           }),
           py::arg("file"), py::arg("contact_forces") = py::none(),
           "Reads and validates a scenario file (errors as `mcopt run` reports them). `contact_forces`: "
           "a name of mcopt.contact_force_formulations() over the file's, as `mcopt run --contact-forces`, "
           "before the file's checks (a bilevel file with `hessian: exact` opens with 'splines').")
      .def_property_readonly("file", [](const ScenarioHandle& s) { return s.file; }, "the scenario file (side files are relative to it)")
      .def_property_readonly("robot", [](const ScenarioHandle& s) {
        return std::make_shared<RobotHandle>(s.scenario.robot, s.scenario.actuators,
                                             loadContactSurfaces(s.scenario.contactSurfacesFile, s.scenario.robot));
      }, "The scenario's robot with its actuators and contact surfaces (a mcopt.Robot).")
      .def_property_readonly("joint_names", [](const ScenarioHandle& s) { return s.scenario.robot.jointNames(); }, "joints in the order of every joint array of a result")
      .def_property_readonly("contact_forces", [](const ScenarioHandle& s) { return s.scenario.contactForces; }, "the contact-force formulation: a name of mcopt.contact_force_formulations()")
      .def(
          "__getitem__",
          [](const ScenarioHandle& s, const std::string& path) {
            try {
              return yamlToPython(study::getField(s.root, pathArgument(path)));
            } catch (const std::invalid_argument& e) {
              throw py::key_error(path + ": " + e.what());
            }
          },
          py::arg("path"), "The value of a field (KeyError when it is not set).")
      .def(
          "__setitem__",
          [](ScenarioHandle& s, const std::string& path, const py::object& value) {
            YAML::Node changed = YAML::Clone(s.root);
            const YAML::Node node = pythonToYaml(value, path);
            try {
              study::setField(changed, pathArgument(path), node);
            } catch (const std::invalid_argument& e) {
              throw py::key_error(path + ": " + e.what());
            }
            try {
              s.scenario = loadScenario(changed, s.file, s.contactForces);
            } catch (const InputError& e) {
              throw InputError(refusal(e.what(), s.file, path, node));
            }
            s.root = changed;
          },
          py::arg("path"), py::arg("value"), "Sets a field; the scenario loader validates the result.")
      .def(
          "to_dict", [](const ScenarioHandle& s) { return yamlToPython(s.root); },
          "The scenario's fields as dicts and lists.")
      .def(
          "save",
          [](const ScenarioHandle& s, const std::filesystem::path& path) {
            YAML::Emitter out;
            out << study::withAbsoluteSideFiles(s.root, s.file);
            writeFileAtomically(path, std::string(out.c_str()) + "\n");
          },
          py::arg("path"),
          "Writes the scenario (side-file paths made absolute, so it loads from anywhere), atomically.")
      .def("run", &run, py::arg("progress") = py::none(), py::arg("out") = py::none(),
           py::arg("max_iterations") = py::none(), py::arg("contact_forces") = py::none(),
           py::arg("configuration_optimisation") = py::none(), py::arg("hessian") = py::none(), py::arg("refine") = py::none(),
           R"doc(Optimises the motion as `mcopt run` does and returns result.json's content as a dict
(lists of numbers as numpy arrays: 'time' (N,), 'q', 'v', 'a', 'torques', 'power' (N, n), …)
with 'x', the outer problem's variables. `out`: also write the run's files there.
`progress(d)` is called after every Ipopt iteration with {'stage', 'iteration', 'objective',
'violation', 'dual_infeasibility', 'step_size', 'elapsed_seconds'} (and
'infeasible_samples' for the bilevel formulation); returning False stops the run. The GIL
is released while it runs (runs from several threads take turns: one Ipopt at a time, its
linear solver MUMPS not being thread-safe); Ctrl-C (KeyboardInterrupt) stops it at the end of the current
iteration and the result has status 'interrupted' with the last iterate. An exception
raised by `progress` stops the run and is raised again. The overrides are those of
`mcopt run`: --max-iterations, --contact-forces, --configuration-optimisation, --hessian,
--refine (rounds; the result's 'refinement' says what each found, docs/reference/verify.md).)doc")
      .def("__repr__", [](const ScenarioHandle& s) { return "<mcopt.Scenario " + s.file.string() + ">"; });

  m.def(
      "task_kinds",
      [] {
        py::dict out;
        for (const TaskKindEntry& e : taskKinds()) out[py::str(e.kind)] = e.description;
        out["throw"] = "a ball's release and its flight to a target (two rows of three, and the ball's load)";
        return out;
      },
      "The task kinds scenario files name, kind → what it bounds, in the order the documents list them.");
  m.def(
      "verify",
      [](const std::filesystem::path& result, int fine, const std::optional<std::filesystem::path>& scenario,
         double energyTolerance, const std::optional<std::filesystem::path>& out) {
        if (fine < 1) throw InputError("fine: " + std::to_string(fine) + ": expected an integer ≥ 1 (instants per sample interval)");
        if (!(energyTolerance >= 0.0)) throw InputError("energy_tolerance: expected a relative tolerance ≥ 0");
        cli::ResultVerification v;
        {
          py::gil_scoped_release release;
          VerificationSettings settings;
          settings.instantsPerInterval = fine;
          settings.energyTolerance = energyTolerance;
          v = cli::verifyResult(result, scenario.value_or(std::filesystem::path{}), settings);
        }
        const auto json = cli::verificationJson(v);
        if (out) writeFileAtomically(*out, json.dump(1) + "\n");
        return toPython(json);
      },
      py::arg("result"), py::arg("fine") = 10, py::arg("scenario") = py::none(),
      py::arg("energy_tolerance") = VerificationSettings{}.energyTolerance, py::arg("out") = py::none(),
      R"doc(Verifies a result's motion between its samples as `mcopt verify` does
(docs/reference/verify.md) and returns verify.json's content as a dict: 'passed',
'failed_checks', and 'checks', one dict per kind with 'worst', 'tolerance', 'where', 'time',
'between_samples' and 'failing_times'. `result`: a result folder (or its result.json);
`fine`: instants per sample interval; `scenario`: check against this file instead of the
result's own; `out`: also write verify.json there. Bad input raises mcopt.InputError.)doc");
}

}  // namespace mcopt::python
