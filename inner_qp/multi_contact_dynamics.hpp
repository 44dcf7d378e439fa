// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The multi-contact "dynamic model" of the report's Figure 5.2: a whole motion, splines →
// (q, q̇, q̈) → Newton–Euler at the fixed reference body (Γ0, W0) → at every sample the inner
// problem picks the contact wrenches (formulation.md §5, §7) → Γ = Γ0 − J1 F → motor power →
// energy. The samples run in the fixed chunks of core/sample_chunks.hpp, as in the motion
// problem: each sample's inner solve starts from its own result of the previous evaluation or,
// on the first, from its predecessor's in the chunk; the results do not depend on the thread
// count. Allocation-free after construction.

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "core/actuators.hpp"
#include "core/bspline.hpp"
#include "core/contact_maps.hpp"
#include "core/robot_files.hpp"
#include "core/trajectory_evaluation.hpp"
#include "inner_qp/inner_solver.hpp"

namespace mcopt {

/// What the bilevel outer problem holds at each sample so that its inner problem has an
/// admissible wrench (sensitivity/bilevel_sample.hpp, docs/theory/outer-problem.md):
///   Slack   φ = ‖s‖²/(m g)² ≤ 0, s the least balance slack (zero on the admissible side);
///   Margin  the admissibility margin m_ε ≥ 0 (inner_qp/admissibility_margin.hpp), signed and
///           with a gradient on the boundary; linear contact models only.
enum class InnerFeasibility { Slack, Margin };
const char* toString(InnerFeasibility feasibility);

struct MultiContactSettings {
  ContactProblemSettings problem;
  InnerSettings solver;
  std::string solverName = "active-set";  ///< a registered inner solver (innerSolverNames())
  InnerFeasibility feasibility = InnerFeasibility::Slack;
};

/// A robot's contact surface as an inner-problem contact (f_min = 0), at `pose` in the world
/// (the identity until the sample sets it).
ContactSpec contactSpec(const ContactSurface& surface, const RigidTransform& pose = RigidTransform{});

/// One sample's inner problem, built from a Newton–Euler pass (formulation.md §5, §7): the
/// contact frames, wrenchToTorque J1 (n × the problem's variables: six columns a contact, three
/// for a force alone), the objective's per-joint terms, the balance
/// at W0. Sized once; update() allocates nothing.
struct SampleProblem {
  SampleProblem(const DynamicsModel& model, const std::vector<ContactSurface>& contacts,
                const ContactProblemSettings& settings);
  /// `data` holds the inverse dynamics of (q, v, a) (Γ0, W0 and the kinematics).
  void update(const DynamicsModel& model, const DynamicsData& data, const ActuatorSet& actuators,
              const std::vector<ContactSurface>& contacts, const Eigen::Ref<const Eigen::VectorXd>& v,
              const Eigen::Ref<const Eigen::VectorXd>& a);

  ContactProblem problem;
  Eigen::MatrixXd wrenchToTorque;      ///< J1
  std::vector<ContactFrame> frames;    ///< the contacts' frames at this sample
  Eigen::VectorXd weights, linear;     ///< w, l of the objective
 private:
  WrenchToTorque block_;
};

struct MultiContactResult {
  TrajectoryResult motion;           ///< time, q, q̇, q̈; tau = Γ with the chosen wrenches; power and energy from it
  Eigen::MatrixXd tau0;              ///< Γ0: torques with the reference body alone carrying the robot, n × N
  Eigen::MatrixXd wrenches;          ///< F, 6 nc × N, each contact's wrench in its own frame
  Eigen::Matrix<double, 6, Eigen::Dynamic> balanceSlack;  ///< per sample (zero unless infeasible)
  std::vector<InnerStatus> status;   ///< per sample
  Eigen::VectorXi iterations;        ///< inner iterations per sample
  Eigen::VectorXd kktResidual;       ///< inner KKT residual per sample (inner_solver.hpp)
  double innerTimeUs = 0.0;          ///< summed inner solve times
  int infeasibleSamples = 0, failedSamples = 0;
};

class MultiContactEvaluator {
 public:
  /// contacts: the surfaces in contact during the whole motion (the reference body's among
  /// them, usually). Throws InputError if an actuator's resistance is not positive (the
  /// inner objective's weights R / (K N)² must be) or sizes disagree.
  MultiContactEvaluator(const DynamicsModel& model, ActuatorSet actuators, SampledTrajectory samples,
                        std::vector<ContactSurface> contacts, MultiContactSettings settings = {});
  ~MultiContactEvaluator();

  const SampledTrajectory& samples() const { return samples_; }
  int contactCount() const { return static_cast<int>(contacts_.size()); }

  /// parameters: samples().parametrization().parameterCount(); duration T > 0.
  void evaluate(const Eigen::Ref<const Eigen::VectorXd>& parameters, double duration, MultiContactResult& result);

  /// The same evaluation, also copying out every sample's inner problem (allocates: for
  /// benchmarks, tests and exporting problems to `mcopt inner`).
  void evaluate(const Eigen::Ref<const Eigen::VectorXd>& parameters, double duration, MultiContactResult& result,
                std::vector<ContactProblem>& sampleProblems);

 private:
  struct Workspace;
  void evaluateSample(Workspace& w, int sample, double duration, MultiContactResult& r);

  const DynamicsModel& model_;
  ActuatorSet actuators_;
  SampledTrajectory samples_;
  std::vector<ContactSurface> contacts_;
  MultiContactSettings settings_;
  Eigen::MatrixXd controlPoints_;
  std::vector<std::unique_ptr<Workspace>> workspaces_;  ///< one per thread
  std::vector<InnerResult> previous_;                   ///< per sample: the warm start of the next evaluation
  bool sized_ = false;  ///< an evaluation has run: the inner solvers' buffers are sized (NoMallocScope)
  std::vector<ContactProblem>* capture_ = nullptr;
};

/// The inner objective's per-joint terms at one state (formulation.md §7): with
/// a = I_m N q̈ + Γ_fric(N q̇), the power's Γ-dependent part is w Γ² + l Γ with
/// w = R / (K N)², l = q̇ + 2 R a / (K² N).
void innerObjectiveTerms(const ActuatorSet& actuators, const Eigen::Ref<const Eigen::VectorXd>& velocity,
                         const Eigen::Ref<const Eigen::VectorXd>& acceleration, Eigen::Ref<Eigen::VectorXd> weights,
                         Eigen::Ref<Eigen::VectorXd> linear);
/// ∂l/∂q̇ = 1 + 2 R Γ_fric'(N q̇) / K² and ∂l/∂q̈ = 2 R I_m / K², per joint (w is constant).
void innerObjectiveTermDerivatives(const ActuatorSet& actuators, const Eigen::Ref<const Eigen::VectorXd>& velocity,
                                   Eigen::Ref<Eigen::VectorXd> linearDv, Eigen::Ref<Eigen::VectorXd> linearDa);

}  // namespace mcopt
