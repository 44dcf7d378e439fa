// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// How a scenario's problem is solved, apart from what it asks (docs/reference/scenario-file.md):
// the Hessian model the outer solver's Newton steps use, the continuation stages solved before
// the problem, the torque-limit screening, the configuration optimisation of the end postures,
// the refinement rounds and the outer solver's own options. A Scenario holds the problem and
// one of these (Scenario::solve); the motion problem is built from the problem and a Hessian
// model (MotionProblemOptions), and the run (scenario_run.hpp, motion_solve.hpp) reads the rest.
#include <algorithm>
#include <optional>
#include <string>
#include <vector>

namespace mcopt {

/// The bilevel inner-feasibility row (inner_qp/multi_contact_dynamics.hpp), declared here so that
/// a stage can name one without this header pulling in the inner problem.
enum class InnerFeasibility;

/// The form of the energy's max(P, 0) (formulation.md §6): the problem's (Scenario::energyForm)
/// or a continuation stage's.
enum class EnergyForm {
  SmoothMaximum,  ///< P⁺ ≈ (P + sqrt(P² + ε²)) / 2 (formulation.md §6)
  Epigraph,       ///< slack s ≥ P, s ≥ 0 per joint and sample; minimise the trapezoid sum of s
};

/// What Ipopt's Newton steps use as the Lagrangian's Hessian (docs/theory/outer-problem.md, "Hessian
/// and convergence").
enum class HessianOption {
  LimitedMemory,      ///< Ipopt's quasi-Newton (L-BFGS) approximation, as the report
  FiniteDifferences,  ///< forward differences of the exact gradient, one whole evaluation per variable
  SampleDifferences,  ///< Σ_s B_sᵀ H_s B_s, H_s by differences of each sample's exact gradient in its state
  /// The same with each H_s (and each task instant's) projected onto the positive
  /// semidefinite cone (negative eigenvalues set to zero): a convex model, no inertia correction.
  ConvexSampleDifferences,
  /// Σ_s B_sᵀ H_s B_s with H_s assembled from each sample's exact first derivatives (no
  /// extra evaluation): the exact curvature of the energy and epigraph terms in the sample's
  /// outputs (P in Γ, q̇, q̈; the smooth maximum in P) chained through the outputs' exact
  /// Jacobian, the outputs' own curvature (∇²Γ, of the dynamics and the inner optimum)
  /// left out — a Gauss–Newton model. Task instants as sample-differences.
  GaussNewton,
  /// The Lagrangian's Hessian itself: each H_s is the gauss-newton terms plus the outputs' own
  /// curvature Σ_o w_o ∇²y_o, differentiated along each state component by a stencil that is
  /// exact on how the dynamics depend on it (polynomial in q̇, q̈ and the force variables,
  /// trigonometric in a revolute joint's angle: outer_nlp/derivative_stencil.hpp); task
  /// instants the same; the duration's row and column by the chain rule. Exact up to
  /// rounding. Not for what is not of that form (exactHessianRefusal).
  Exact,
};
const char* toString(HessianOption hessian);
/// "limited-memory", "finite-differences", "sample-differences", "convex-sample-differences",
/// "gauss-newton" or "exact";
/// throws InputError otherwise.
HessianOption parseHessianOption(const std::string& name);
/// Every option's name, in the order above (the choices of `mcopt run --hessian`).
const std::vector<std::string>& hessianOptionNames();

/// An outer-solver (Ipopt) option as written in the scenario's `solver:` (type decided by the YAML scalar).
struct SolverOption {
  enum class Type { Integer, Number, Text } type = Type::Text;
  std::string name, text, origin;
  double number = 0.0;
  int integer = 0;
};

/// A problem solved before the scenario's own, from the previous one's result (the first from
/// the initial motion), with a smoother friction model and/or smooth maximum: the dry
/// friction's steep atan(ν N q̇) makes the kick's Lagrangian indefinite at every joint that
/// is nearly still, and Newton's steps need hundreds of iterations there
/// (docs/theory/outer-problem.md, "Hessian options"). The scenario's own problem is solved last.
struct ContinuationStage {
  double frictionSharpness = 0.0;  ///< ν [s/rad]
  double smoothing = 0.0;          ///< ε [W]
  int samples = 0;                 ///< N: a coarser grid, the same spline parameters
  HessianOption hessian = HessianOption::SampleDifferences;  ///< the scenario's unless the stage names one
  int maxIterations = -1;          ///< Ipopt's max_iter for the stage; -1: the scenario's
  /// The stage's energy form: a smooth-maximum stage before the exact epigraph form, whose
  /// slack variables the next stage sets at max(P, 0) of the motion reached (MotionProblem::
  /// pointFrom; docs/theory/outer-problem.md, "Continuation").
  EnergyForm energyForm = EnergyForm::SmoothMaximum;
  /// The contact-force formulations the stage runs with (`for_contact_forces`); empty: every
  /// one. A hand-over stage that helps one formulation may hinder another (measured on the
  /// weight shift: Gauss–Newton first makes the bilevel run converge in seconds and keeps the
  /// `variables` one from converging; docs/theory/outer-problem.md, "Multi-contact"), and
  /// `mcopt run --contact-forces` chooses the formulation after the file is read.
  std::vector<std::string> forContactForces;
  /// The bilevel inner solver of the stage (`inner_solver`, a registered name); empty: the
  /// scenario's. The exact optima of the active-set method in a Gauss–Newton stage, then the
  /// barrier solver's smooth central path for the scenario's own problem, whose stationarity
  /// test the exact optima's kinks can keep from passing (docs/theory/outer-problem.md,
  /// "Continuation").
  std::string innerSolver;
  /// The bilevel outer row that keeps each sample's inner problem feasible in this stage
  /// (`feasibility`); unset: the scenario's `inner.feasibility`. The slack row has no gradient
  /// where it becomes active, so a stage whose optimum holds a sample's wrenches at the edge of
  /// admissibility can end without a constraint qualification; the margin row has one there
  /// (docs/theory/outer-problem.md, "Inner feasibility").
  std::optional<InnerFeasibility> feasibility;
  /// The contact-force formulation the stage itself is solved in (`contact_forces`); empty: the
  /// run's. The next stage starts from its motion, with its own force variables fitted to the
  /// inner problem's wrenches along it (MotionProblem::pointFrom), as `mcopt run --start-from`
  /// does: a bilevel Gauss–Newton stage hands the single-level formulations a motion whose
  /// wrenches are admissible at every sample (measured on the weight shift: `variables` then
  /// optimal after 22 iterations at 61.73 J, against 333 at 65.77 J from the interpolated motion;
  /// docs/developers/lab-notes/neighbours-and-stage-one.md).
  std::string contactForces;
  /// Whether the stage runs with that formulation.
  bool runsWith(const std::string& forces) const {
    return forContactForces.empty() ||
           std::find(forContactForces.begin(), forContactForces.end(), forces) != forContactForces.end();
  }
};

/// How the scenario's problem is solved (the fields of a scenario file that say it:
/// `hessian`, `continuation`, `limits.torque_screening`, `initialisation`, `refine`, `solver`).
struct SolveSettings {
  HessianOption hessian = HessianOption::SampleDifferences;  ///< the best measured (docs/theory/outer-problem.md)
  /// The stages solved before the scenario's problem, each from the previous one's result (the
  /// first from the initial motion), in their order.
  std::vector<ContinuationStage> continuation;
  /// Torque-limit rows whose |Γ| stays below this fraction of the limit are left out of the
  /// NLP and checked after the solve; rows that reach it join and the problem is solved
  /// again (docs/theory/outer-problem.md, "Torque-limit screening"). 0: every row in the NLP.
  double torqueScreening = 0.5;
  /// The same for the position and velocity rows of the joints that close a contact (the
  /// closing_joint_limit rows, one per joint and sample): a row whose value stays within this
  /// fraction of its range about the range's middle (|q − mid| < f · half-range, |q̇| < f · limit)
  /// is left out and checked after the solve (docs/theory/outer-problem.md, "Torque-limit
  /// screening"). 0 (the default): every row in the NLP.
  double closingScreening = 0.0;
  /// Configuration optimisation of the end postures before the motion (report §3.5), and its
  /// iteration cap (`initialisation:`).
  bool configurationOptimisation = true;
  int configurationIterations = 500;
  /// Refinement rounds after the optimum (`refine`, `mcopt run --refine`; scenario_run.hpp
  /// refineRun): while its motion does not verify between the samples, solve again on twice the
  /// sample intervals. 0: none.
  int refineRounds = 0;
  /// The outer solver's own options (`solver:`), passed as they are.
  std::vector<SolverOption> solverOptions;
};

}  // namespace mcopt
