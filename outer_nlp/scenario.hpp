// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// A motion-optimisation scenario (docs/reference/scenario-file.md): the problem — the robot and
// its side files, the reference body, the contacts, the duration and samples, the objective,
// the limits, the tasks, the start and end postures (formulation.md §10) — and how it is
// solved (Scenario::solve, solve_settings.hpp). loadScenario validates everything and names
// file, line and field in every error.

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/actuators.hpp"
#include "core/robot_files.hpp"
#include "core/robot_model.hpp"
#include "inner_qp/multi_contact_dynamics.hpp"
#include "outer_nlp/solve_settings.hpp"
#include "outer_nlp/task.hpp"
#include "sensitivity/inner_sensitivity.hpp"

namespace mcopt {

/// A task of the scenario: what it bounds (a Task, outer_nlp/task.hpp), where it came from,
/// when it holds, and its bounds; ±∞ where a component is free.
struct TaskSpec {
  std::string name;          ///< from the file, or "tasks[i]"
  std::string origin;        ///< "file:line" of the task, for messages
  std::shared_ptr<const Task> task;
  bool closure = false;      ///< made by a contact: its frame holds its world pose (formulation.md §10)
  /// A contact's closure over its window: the motion problem holds it exactly by construction
  /// (closed_chains.hpp) and has no rows for it; the configuration problem keeps it, within
  /// `closure_tolerance`, for the postures inside the window.
  bool heldByConstruction = false;
  double start = 0.0, end = 0.0;         ///< instant (start == end) or window [s], of the initial duration
  bool window = false;
  TaskVector lower, upper;               ///< task->dimension() entries each
  int dimension() const { return task->dimension(); }
};

/// The ball of a `throw` task (formulation.md §10): a point mass carried by a body until its
/// release, when its weight and inertial force stop loading that body.
struct ThrownBall {
  std::string origin;          ///< "file:line" of the throw task, for messages
  std::string body;            ///< URDF link that holds it
  int frame = -1;              ///< RobotModel frame of `body`
  Vector3 point = Vector3::Zero();  ///< the ball's centre in that frame [m]
  double mass = 0.0;           ///< [kg]
  double releaseTime = 0.0;    ///< t_r [s] of the initial duration; a sample (a fraction of a free duration)
  Vector3 target = Vector3::Zero();  ///< the throw's target point, world frame [m]
  double gravity = 9.81;             ///< gravity's magnitude (along −z) [m/s²]
};

/// A contact other than the reference body's: its surface is fixed in the world over the
/// whole motion or over a window, at a given world pose or the one it has in the start
/// posture (formulation.md §10).
struct EnvironmentContact {
  ContactSurface surface;
  std::string origin;          ///< "file:line" of the entry, for messages
  double start = 0.0, end = 0.0;  ///< window [s] of the initial duration; the whole motion unless given
  bool window = false;
  bool poseGiven = false;
  RigidTransform worldPose;    ///< of the contact frame
};

struct DurationSpec {
  double initial = 1.0;  ///< [s]
  double lower = 1.0, upper = 1.0;
  bool free() const { return lower < upper; }
};

/// The unit in which the outer solver sees the splines and variables formulations' force
/// variables (NlpProblem::variableUnits): newtons (and newton-metres), or the robot's weight m g.
enum class ForceUnits { Newton, Weight };
const char* toString(ForceUnits units);
/// "newton" or "weight"; throws InputError otherwise.
ForceUnits parseForceUnits(const std::string& name);
/// Both names, in the order above (the choices of `mcopt run --force-units`).
const std::vector<std::string>& forceUnitsNames();

struct Scenario {
  std::filesystem::path file;
  std::filesystem::path contactSurfacesFile;  ///< the side file the contacts were read from
  std::string description;
  RobotModel robot;
  bool allowNonPhysicalInertia = false;  ///< the robot's URDF loaded with UrdfOptions::allowNonPhysicalInertia
  ActuatorSet actuators;
  std::string referenceBody;
  RigidTransform referencePose;
  Vector3 gravity{0.0, 0.0, -9.81};
  ContactSurface support;          ///< the reference body's contact surface
  std::vector<EnvironmentContact> contacts;  ///< the other contacts, in the file's order
  /// Closure of the environment contacts as a box on the pose error at the samples: a spline
  /// motion stays on the closed chain's (non-polynomial) manifold only up to such a band
  /// (docs/theory/outer-problem.md, "Multi-contact").
  double closurePositionTolerance = 1e-3;     ///< [m]
  double closureOrientationTolerance = 1e-3;  ///< [rad], on sin θ of the error rotation
  /// `closure_reach_margin` m: each held contact's loop stays at most (1 − m) of its longest
  /// reach at the samples where it is closed, away from full stretch where the closure folds
  /// (closed_chains.hpp LoopReach; docs/theory/outer-problem.md). 0: no such rows.
  double closureReachMargin = 0.0;
  /// How the contact wrenches enter the outer problem (formulation.md §9): a registered
  /// formulation's name (formulation_registry.hpp).
  std::string contactForces = "bilevel";
  int forceControlPoints = 9;      ///< per wrench spline (splines formulation), over its contact's window
  /// `force_units`: the unit in which Ipopt sees the splines and variables formulations' force variables.
  ForceUnits forceUnits = ForceUnits::Weight;
  MultiContactSettings inner;      ///< bilevel: contact model and inner solver
  SensitivitySettings sensitivity; ///< bilevel: KKT backend
  bool contactConstraints = true;  ///< unilaterality, friction cone and CoP of W0 at the samples
  double minimumNormalForce = 0.0; ///< f_z ≥ this [N]

  DurationSpec duration;
  int samples = 100;
  int controlPoints = 9;
  int outputSamples = 500;         ///< fine resampling of the result (power per joint, energy check)

  EnergyForm energyForm = EnergyForm::SmoothMaximum;
  double smoothing = 1.0;          ///< ε of the smooth maximum [W]
  double accelerationWeight = 0.0; ///< w of the regularisation w ∫ Σ_j q̈_j² dt [J s⁴/rad²/s]

  bool positionLimits = true, velocityLimits = true, torqueLimits = true;
  std::vector<TaskSpec> tasks;
  /// A throw task's ball (at most one throw a scenario); its two rows are in `tasks`.
  std::optional<ThrownBall> ball;

  Eigen::VectorXd start, end;      ///< initial guesses for the start and end postures [rad]
  bool fixStart = false, fixEnd = false;
  /// `end: {same_as: start}`: one posture for both ends (MotionParametrization's periodic
  /// layout), so the motion returns exactly to where it started; end = start, fixEnd = fixStart.
  bool periodic = false;
  /// A given initial motion instead of the interpolation from start to end (`mcopt run
  /// --start-from`, outer_nlp/scenario_run.hpp `startFromMotion`).
  struct InitialMotion {
    Eigen::VectorXd parameters;  ///< spline parameters, joint by joint (MotionProblem's layout)
    double duration = 0.0;       ///< T [s]
  };
  std::optional<InitialMotion> initialMotion;

  /// How the problem above is solved: Hessian model, continuation, screening, configuration
  /// optimisation, refinement, the outer solver's options (solve_settings.hpp).
  SolveSettings solve;
};

/// The scenario with only the continuation stages that run with its contact-force
/// formulation (ContinuationStage::forContactForces), in their order.
Scenario withStagesForItsFormulation(const Scenario& scenario);
/// Stage k of the scenario's continuation (k = solve.continuation.size(): the scenario itself):
/// a copy with that stage's friction sharpness, smoothing, samples, Hessian option, energy form,
/// inner solver, inner-feasibility row and contact-force formulation.
Scenario continuationStage(const Scenario& scenario, std::size_t k);
/// Whether a stage (continuationStage's copy) poses the scenario's own problem: the same ν, ε,
/// samples, energy form, contact-force formulation and (where an inner problem picks the wrenches) inner solver and row,
/// differing at most in its Hessian option or iteration limit.
bool posesScenarioProblem(const Scenario& stage, const Scenario& scenario);
/// Why `hessian: exact` does not apply to the scenario (empty when it does): its stencils need
/// every sample output polynomial in q̇, q̈ and the force variables and trigonometric in the
/// joint angles, which a throw's flight, an inner optimum (bilevel with environment contacts)
/// and a prismatic joint are not; and the epigraph's slack × duration term lies outside the
/// Hessian's variables.
std::string exactHessianRefusal(const Scenario& scenario);
/// Why the scenario's contact models do not suit its inner solver (empty when they do): the
/// barrier solver smooths linear models only (inner.contact_model and every contacts[k].model).
std::string barrierModelRefusal(const Scenario& scenario);
/// Why the scenario's contact models do not suit inner.feasibility: margin (empty when they do):
/// the margin shifts linear rows, and a second-order cone has none.
std::string marginModelRefusal(const Scenario& scenario);


/// Reads and validates a scenario file (robot files are loaded relative to it). Throws
/// InputError "file:line: field: what" for unknown keys, wrong types, unknown bodies, joints
/// or postures, and impossible numbers. `contactForces`, when set, replaces the file's
/// `contact_forces` before the checks that depend on it (`mcopt run --contact-forces`: a file
/// whose `hessian: exact` the bilevel formulation refuses is accepted with `splines`).
/// `allowNonPhysicalInertia` (`--allow-nonphysical-inertia`) loads a URDF whose inertias a real
/// body cannot have, as the file's `allow_nonphysical_inertia: true` does, with a warning each.
Scenario loadScenario(const std::filesystem::path& file, std::optional<std::string> contactForces = std::nullopt,
                      bool allowNonPhysicalInertia = false);
/// (A scenario already parsed as YAML: outer_nlp/scenario_yaml.hpp.)

/// The fields that name side files, relative to the scenario's folder: a copy of the scenario
/// written elsewhere must make them absolute.
inline constexpr std::array<const char*, 4> kScenarioSideFileFields = {"robot", "actuators", "contact_surfaces", "postures"};

}  // namespace mcopt
