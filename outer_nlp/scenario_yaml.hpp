// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A scenario already parsed as YAML (a study's case after its fields are changed,
// docs/reference/studies.md; the Python module's Scenario). outer_nlp links yaml-cpp privately: this is
// its one header with yaml-cpp types, and a target including it links yaml-cpp itself
// (tests/header_boundaries.cmake).

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/robot_files.hpp"

namespace mcopt {

struct Scenario;             // outer_nlp/scenario.hpp
enum class InnerFeasibility;  // inner_qp/multi_contact_dynamics.hpp

/// The `throw` task (formulation.md §10; docs/reference/scenario-file.md, "Throw"; outer_nlp/throw_task.cpp):
/// `node` is tasks[i] with `kind: throw`; appends its two rows (BallFlightTask landing and
/// ThrowRelease) to s.tasks and sets s.ball. Needs the robot, the duration and the gravity read.
void readThrowTask(const std::filesystem::path& file, const YAML::Node& node, const std::string& field, Scenario& s);
/// What only the whole scenario decides: the release on a sample of the motion (and of every
/// continuation stage's grid), and the ball on a body that is not a contact's.
void checkThrowTask(const std::filesystem::path& file, const YAML::Node& node, const std::string& field, const Scenario& s);

/// The `contacts:` list (scenario_contacts.cpp): fills s.contacts, the reference contact
/// first, and the closure tasks of the environment contacts. Needs the robot, the reference
/// body and pose, the duration and the postures read.
void readContacts(const std::filesystem::path& file, const YAML::Node& list, const std::vector<ContactSurface>& surfaces,
                  Scenario& s);
/// The `solver:` mapping of Ipopt options (scenario_settings.cpp), typed as YAML reads them.
void readSolverOptions(const std::filesystem::path& file, const YAML::Node& node, Scenario& s);
/// The `inner:` settings (scenario_settings.cpp): solver, contact model, facets, tolerance,
/// polishing, KKT backend.
void readInnerSettings(const std::filesystem::path& file, const YAML::Node& node, Scenario& s);
/// An inner-feasibility row's name (`slack` or `margin`) at `node`: `inner.feasibility` or a
/// continuation stage's `feasibility`, named `field` in the error.
InnerFeasibility readInnerFeasibility(const std::filesystem::path& file, const YAML::Node& node, const std::string& field);

/// loadScenario(file) for `root`, read from `file` and maybe changed since: `file` names it in
/// messages, and its folder is where relative side-file paths start.
Scenario loadScenario(const YAML::Node& root, const std::filesystem::path& file,
                      std::optional<std::string> contactForces = std::nullopt, bool allowNonPhysicalInertia = false);

}  // namespace mcopt
