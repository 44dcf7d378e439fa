// SPDX-License-Identifier: BSD-3-Clause
#include "inner_qp/multi_contact_dynamics.hpp"

#include <omp.h>

#include "core/no_malloc_scope.hpp"
#include "core/sample_chunks.hpp"

#include "core/errors.hpp"
#include "core/inverse_dynamics.hpp"

namespace mcopt {

const char* toString(InnerFeasibility feasibility) {
  return feasibility == InnerFeasibility::Margin ? "margin" : "slack";
}

void innerObjectiveTerms(const ActuatorSet& actuators, const Eigen::Ref<const Eigen::VectorXd>& velocity,
                         const Eigen::Ref<const Eigen::VectorXd>& acceleration, Eigen::Ref<Eigen::VectorXd> weights,
                         Eigen::Ref<Eigen::VectorXd> linear) {
  for (Eigen::Index j = 0; j < velocity.size(); ++j) {
    const ActuatorParameters& m = actuators.joints[static_cast<std::size_t>(j)];
    const double N = m.gearRatio, K = m.torqueConstant, R = m.resistance;
    const double other = m.rotorInertia * N * acceleration[j] +
                         frictionTorque(m, N * velocity[j], actuators.frictionSharpness);  // Γem − Γ/N
    weights[j] = R / (K * K * N * N);
    linear[j] = velocity[j] + 2.0 * R * other / (K * K * N);
  }
}

void innerObjectiveTermDerivatives(const ActuatorSet& actuators, const Eigen::Ref<const Eigen::VectorXd>& velocity,
                                   Eigen::Ref<Eigen::VectorXd> linearDv, Eigen::Ref<Eigen::VectorXd> linearDa) {
  for (Eigen::Index j = 0; j < velocity.size(); ++j) {
    const ActuatorParameters& m = actuators.joints[static_cast<std::size_t>(j)];
    const double N = m.gearRatio, K = m.torqueConstant, R = m.resistance;
    linearDv[j] = 1.0 + 2.0 * R * frictionTorqueSlope(m, N * velocity[j], actuators.frictionSharpness) / (K * K);
    linearDa[j] = 2.0 * R * m.rotorInertia / (K * K);
  }
}

ContactSpec contactSpec(const ContactSurface& s, const RigidTransform& pose) {
  return {s.name, pose, s.friction, s.xMin, s.xMax, s.yMin, s.yMax, 0.0, nullptr};
}

SampleProblem::SampleProblem(const DynamicsModel& model, const std::vector<ContactSurface>& contacts,
                             const ContactProblemSettings& settings) {
  const int n = model.jointCount(), nc = static_cast<int>(contacts.size());
  std::vector<ContactSpec> specs;
  for (const ContactSurface& s : contacts) specs.push_back(contactSpec(s));
  const int columns = contactColumns(specs, settings).back();
  problem = assembleContactProblem(specs, Eigen::MatrixXd::Zero(n, columns), Eigen::VectorXd::Zero(n), Vector6::Zero(),
                                   Eigen::VectorXd::Ones(n), Eigen::VectorXd::Zero(n), settings);
  wrenchToTorque.setZero(n, columns);
  frames.resize(static_cast<std::size_t>(nc));
  weights.setZero(n);
  linear.setZero(n);
  block_.setZero(n, 6);
}

void SampleProblem::update(const DynamicsModel& model, const DynamicsData& data, const ActuatorSet& actuators,
                           const std::vector<ContactSurface>& contacts, const Eigen::Ref<const Eigen::VectorXd>& v,
                           const Eigen::Ref<const Eigen::VectorXd>& a) {
  for (std::size_t i = 0; i < contacts.size(); ++i) {
    const auto at = static_cast<int>(i);
    frames[i] = contactFrame(model, data, contacts[i].frame, contacts[i].placement);
    mcopt::wrenchToTorque(model, data, frames[i], block_);
    // The wrench map's columns of the contact's variables: all six, or the force's three.
    const int size = problem.wrenchSize(at);
    wrenchToTorque.middleCols(problem.contactColumn[i], size) = block_.leftCols(size);
    setContactPose(problem, at, frames[i].contactPose);
  }
  innerObjectiveTerms(actuators, v, a, weights, linear);
  updateObjective(problem, wrenchToTorque, data.tau, weights, linear);
  problem.balanceTarget = data.referenceWrench;
}

struct MultiContactEvaluator::Workspace {
  DynamicsData data;
  SampleProblem sample;
  std::unique_ptr<InnerSolver> solver;
  Workspace(const DynamicsModel& model, const std::vector<ContactSurface>& contacts, const ContactProblemSettings& s)
      : data(model), sample(model, contacts, s) {}
};

MultiContactEvaluator::MultiContactEvaluator(const DynamicsModel& model, ActuatorSet actuators,
                                             SampledTrajectory samples, std::vector<ContactSurface> contacts,
                                             MultiContactSettings settings)
    : model_(model),
      actuators_(std::move(actuators)),
      samples_(std::move(samples)),
      contacts_(std::move(contacts)),
      settings_(std::move(settings)) {
  const int n = model.jointCount();
  if (static_cast<int>(actuators_.joints.size()) != n)
    throw InputError("actuator set has " + std::to_string(actuators_.joints.size()) + " joints, the robot " +
                     std::to_string(n));
  if (samples_.parametrization().jointCount() != n)
    throw InputError("trajectory has " + std::to_string(samples_.parametrization().jointCount()) +
                     " joints, the robot " + std::to_string(n));
  if (contacts_.empty()) throw InputError("multi-contact evaluation: no contact surface given");
  for (std::size_t j = 0; j < actuators_.joints.size(); ++j)
    if (!(actuators_.joints[j].resistance > 0.0))
      throw InputError("actuator of joint " + std::to_string(j) +
                       ": winding resistance must be positive for the inner objective (formulation.md §7)");
  for (int t = 0; t < omp_get_max_threads(); ++t) {
    auto w = std::make_unique<Workspace>(model, contacts_, settings_.problem);
    w->solver = makeInnerSolver(settings_.solverName, settings_.solver);
    workspaces_.push_back(std::move(w));
  }
  previous_.resize(static_cast<std::size_t>(samples_.sampleCount()));
  // Room for the largest active set, so that copying warm starts never allocates.
  const ContactProblem& sized = workspaces_.front()->sample.problem;
  for (InnerResult& r : previous_)
    r.activeSet.reserve(static_cast<std::size_t>(sized.inequality.rows()) + sized.cones.size());
}

MultiContactEvaluator::~MultiContactEvaluator() = default;

void MultiContactEvaluator::evaluateSample(Workspace& w, int s, double duration, MultiContactResult& r) {
  TrajectoryResult& m = r.motion;
  m.time[s] = samples_.time(s, duration);
  samples_.evaluate(s, controlPoints_, duration, m.q.col(s), m.v.col(s), m.a.col(s));
  inverseDynamics(model_, w.data, m.q.col(s), m.v.col(s), m.a.col(s));
  r.tau0.col(s) = w.data.tau;
  m.referenceWrench.col(s) = referenceWrenchAtReferenceFrame(model_, w.data);
  // The inner problem of this sample (formulation.md §5, §7): J1, the contact poses, W0.
  w.sample.update(model_, w.data, actuators_, contacts_, m.v.col(s), m.a.col(s));
  if (capture_ != nullptr) (*capture_)[static_cast<std::size_t>(s)] = w.sample.problem;
  InnerResult& result = previous_[static_cast<std::size_t>(s)];
  w.solver->solve(w.sample.problem, result);
  r.status[static_cast<std::size_t>(s)] = result.status;
  r.iterations[s] = result.iterations;
  r.kktResidual[s] = result.kktResidual;
  for (int i = 0; i < w.sample.problem.contactCount; ++i)
    r.wrenches.col(s).segment<6>(6 * i) = w.sample.problem.contactWrench(result.wrenches, i);
  r.balanceSlack.col(s) = result.balanceSlack;
  // Γ = Γ0 − J1 F (4.8), then the motors' power with it.
  m.tau.col(s) = w.data.tau;
  m.tau.col(s).noalias() -= w.sample.wrenchToTorque * result.wrenches;
  for (int j = 0; j < model_.jointCount(); ++j)
    m.power(j, s) = motorPower(actuators_.joints[static_cast<std::size_t>(j)], actuators_.frictionSharpness,
                               m.tau(j, s), m.v(j, s), m.a(j, s))
                        .power;
}

void MultiContactEvaluator::evaluate(const Eigen::Ref<const Eigen::VectorXd>& parameters, double duration,
                                     MultiContactResult& result, std::vector<ContactProblem>& sampleProblems) {
  sampleProblems.resize(static_cast<std::size_t>(samples_.sampleCount()));
  capture_ = &sampleProblems;
  try {
    evaluate(parameters, duration, result);
  } catch (...) {
    capture_ = nullptr;
    throw;
  }
  capture_ = nullptr;
}

void MultiContactEvaluator::evaluate(const Eigen::Ref<const Eigen::VectorXd>& parameters, double duration,
                                     MultiContactResult& r) {
  const int n = model_.jointCount(), count = samples_.sampleCount(), nc = contactCount();
  prepareTrajectoryResult(samples_, n, parameters, duration, r.motion);
  if (r.tau0.rows() != n || r.tau0.cols() != count) {
    r.tau0.resize(n, count);
    r.wrenches.resize(6 * nc, count);
    r.balanceSlack.resize(6, count);
    r.status.assign(static_cast<std::size_t>(count), InnerStatus::Failed);
    r.iterations.resize(count);
    r.kktResidual.resize(count);
  }
  samples_.parametrization().controlPoints(parameters, controlPoints_);
  const int threads = static_cast<int>(workspaces_.size());
  // The inner solvers size their buffers on their first problem: checked from the second
  // evaluation on (the contact set is fixed, so the shapes are).
  const NoMallocScope perSample("inner solves", sized_ && capture_ == nullptr);  // copying problems out allocates
#pragma omp parallel num_threads(threads)
  {
    Workspace& w = *workspaces_[static_cast<std::size_t>(omp_get_thread_num())];
    // The samples in fixed chunks (core/sample_chunks.hpp): a sample starts from its own result
    // of the previous evaluation or, without one, from its predecessor's in the chunk.
    forEachSampleInChunks(count, [&](int s, int predecessor) {
      InnerResult& current = previous_[static_cast<std::size_t>(s)];
      if (predecessor >= 0 && settings_.solver.warmStart && current.wrenches.size() == 0) {
        const InnerResult& before = previous_[static_cast<std::size_t>(predecessor)];
        current.wrenches = before.wrenches;
        current.activeSet = before.activeSet;
        current.inequalityMultipliers = before.inequalityMultipliers;
        current.coneMultipliers = before.coneMultipliers;
      }
      evaluateSample(w, s, duration, r);
    });
  }
  r.innerTimeUs = 0.0;
  r.infeasibleSamples = r.failedSamples = 0;
  for (int s = 0; s < count; ++s) {
    r.innerTimeUs += previous_[static_cast<std::size_t>(s)].solveTimeUs;
    r.infeasibleSamples += r.status[static_cast<std::size_t>(s)] == InnerStatus::Infeasible;
    r.failedSamples += r.status[static_cast<std::size_t>(s)] == InnerStatus::Failed;
  }
  r.motion.energy = positiveEnergy(r.motion.power, r.motion.time);
  sized_ = true;
}

}  // namespace mcopt
