// SPDX-License-Identifier: BSD-3-Clause
// mcopt.Robot: a URDF with its side files (formulation.md §2, docs/reference/robot-files.md).
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "apps/robot_info_json.hpp"
#include "core/robot_files.hpp"
#include "python/bindings.hpp"
#include "python/robot_handle.hpp"

namespace mcopt::python {

RobotHandle::RobotHandle(const std::filesystem::path& urdf, const std::optional<std::filesystem::path>& actuatorFile,
                         const std::optional<std::filesystem::path>& contactSurfaceFile, bool allowNonPhysicalInertia)
    : model(std::make_shared<const RobotModel>(loadUrdfFile(urdf, {allowNonPhysicalInertia}))),
      actuators(actuatorFile ? loadActuators(*actuatorFile, *model) : defaultActuators(*model)) {
  if (contactSurfaceFile) surfaces = loadContactSurfaces(*contactSurfaceFile, *model);
}

const ContactSurface& RobotHandle::surface(const std::string& name) const {
  for (const ContactSurface& s : surfaces)
    if (s.name == name) return s;
  std::string known;
  for (const ContactSurface& s : surfaces) known += (known.empty() ? "" : ", ") + s.name;
  throw py::value_error("unknown contact surface '" + name + "'" +
                        (surfaces.empty() ? std::string(" (the robot was loaded without contact_surfaces)")
                                          : " (known: " + known + ")"));
}

namespace {

/// The `name` of each element (bodies, frames, contact surfaces), in order.
template <class Named>
std::vector<std::string> namesOf(const std::vector<Named>& elements) {
  std::vector<std::string> names;
  for (const Named& e : elements) names.push_back(e.name);
  return names;
}

}  // namespace

void bindRobot(py::module_& m) {
  py::class_<RobotHandle, std::shared_ptr<RobotHandle>>(m, "Robot", R"doc(
A robot model: a URDF (fixed joints merged, joints in URDF order) with its actuator file and
contact surfaces (docs/reference/robot-files.md). Errors in any file raise mcopt.InputError with the
command line's message (file, line or element, field).)doc")
      .def(py::init<const std::filesystem::path&, const std::optional<std::filesystem::path>&,
                    const std::optional<std::filesystem::path>&, bool>(),
           py::arg("urdf"), py::arg("actuators") = py::none(), py::arg("contact_surfaces") = py::none(),
           py::arg("allow_nonphysical_inertia") = false,
           R"doc(Loads `urdf`; `actuators` (YAML) overrides the URDF's limits and sets the motors'
gear ratios, torque constants and resistances; `contact_surfaces` (YAML) names the
rectangles a contact can use. `allow_nonphysical_inertia` turns invalid inertias into warnings.)doc")
      .def_property_readonly("name", [](const RobotHandle& r) { return r.model->name; }, "the URDF's robot name")
      .def_property_readonly("source", [](const RobotHandle& r) { return r.model->source; }, "the file it was read from")
      .def_property_readonly("joint_names", [](const RobotHandle& r) { return r.model->jointNames(); },
                             "actuated joints in URDF order (the order of every joint array)")
      .def_property_readonly("joint_count", [](const RobotHandle& r) { return r.model->jointCount(); }, "number of actuated joints n")
      .def_property_readonly(
          "body_names",
          [](const RobotHandle& r) { return namesOf(r.model->bodies); },
          "bodies after merging fixed joints")
      .def_property_readonly(
          "frame_names",
          [](const RobotHandle& r) { return namesOf(r.model->frames); },
          "every URDF link, merged ones included: what reference_body and frame arguments accept")
      .def_property_readonly("total_mass", [](const RobotHandle& r) { return r.model->totalMass(); }, "[kg]")
      .def_property_readonly("warnings", [](const RobotHandle& r) { return r.model->warnings; }, "what loading accepted with a warning (allow_nonphysical_inertia)")
      .def_property_readonly(
          "contact_surfaces",
          [](const RobotHandle& r) { return namesOf(r.surfaces); },
          "names of the contact surfaces loaded with the robot")
      .def(
          "joint_limits",
          [](const RobotHandle& r) {
            const int n = r.model->jointCount();
            Eigen::VectorXd lower(n), upper(n), velocity(n), effort(n);
            for (int j = 0; j < n; ++j) {
              lower[j] = r.model->joints[static_cast<std::size_t>(j)].limits.lower;
              upper[j] = r.model->joints[static_cast<std::size_t>(j)].limits.upper;
              velocity[j] = r.actuators.joints[static_cast<std::size_t>(j)].velocityLimit;
              effort[j] = r.actuators.joints[static_cast<std::size_t>(j)].torqueLimit;
            }
            py::dict out;
            out["lower"] = vectorToNumpy(lower), out["upper"] = vectorToNumpy(upper);
            out["velocity"] = vectorToNumpy(velocity), out["effort"] = vectorToNumpy(effort);
            return out;
          },
          "Position, velocity and torque limits per joint (the actuator file over the URDF; inf where unbounded).")
      .def(
          "info", [](const RobotHandle& r) { return toPython(cli::robotInfoJson(*r.model, r.actuators)); },
          "What `mcopt robot info --json` prints for this robot, as a dict.")
      .def(
          "postures",
          [](const RobotHandle& r, const std::filesystem::path& file) {
            py::dict out;
            for (const auto& [name, q] : loadPostures(file, *r.model)) out[py::str(name)] = vectorToNumpy(q);
            return out;
          },
          py::arg("file"), "The named postures of a postures file (docs/reference/robot-files.md), joint arrays in URDF order.")
      .def("__repr__", [](const RobotHandle& r) {
        return "<mcopt.Robot " + r.model->name + ": " + std::to_string(r.model->jointCount()) + " joints>";
      });
}

}  // namespace mcopt::python
