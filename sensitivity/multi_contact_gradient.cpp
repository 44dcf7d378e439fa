// SPDX-License-Identifier: BSD-3-Clause
#include "sensitivity/multi_contact_gradient.hpp"

#include <omp.h>

#include <Eigen/SparseCore>
#include <optional>

#include "core/errors.hpp"
#include "core/no_malloc_scope.hpp"
#include "core/sample_chunks.hpp"
#include "sensitivity/sparse_kkt_factor.hpp"

namespace mcopt {

struct MultiContactGradientEvaluator::Workspace {
  explicit Workspace(const DynamicsModel& model) : data(model), derivatives(model) {
    const int n = model.jointCount();
    powerTorque.setZero(n), rowQ.setZero(n), rowV.setZero(n), rowA.setZero(n);
  }
  DynamicsData data;
  DynamicsDerivatives derivatives;
  Eigen::VectorXd powerTorque, rowQ, rowV, rowA;
  int degenerate = 0, withoutDerivative = 0;
};

MultiContactGradientEvaluator::MultiContactGradientEvaluator(const DynamicsModel& model, ActuatorSet actuators,
                                                             SampledTrajectory samples,
                                                             std::vector<ContactSurface> contacts,
                                                             MultiContactSettings settings,
                                                             SensitivitySettings sensitivity)
    : model_(model),
      actuators_(std::move(actuators)),
      samples_(std::move(samples)),
      contacts_(std::move(contacts)),
      settings_(std::move(settings)),
      sensitivitySettings_(sensitivity) {
  const int n = model.jointCount();
  if (static_cast<int>(actuators_.joints.size()) != n || samples_.parametrization().jointCount() != n)
    throw InputError("multi-contact gradient: actuators, trajectory and robot disagree on the joint count");
  if (contacts_.empty()) throw InputError("multi-contact gradient: no contact surface given");
  for (std::size_t j = 0; j < actuators_.joints.size(); ++j)
    if (!(actuators_.joints[j].resistance > 0.0))
      throw InputError("actuator of joint " + std::to_string(j) +
                       ": winding resistance must be positive for the inner objective (formulation.md §7)");
  if (sensitivitySettings_.layout == KktLayout::AllSamples && sensitivitySettings_.backend == KktBackend::Dense)
    throw InputError("the all-samples KKT layout needs a sparse backend (klu or umfpack)");
  for (int t = 0; t < omp_get_max_threads(); ++t) workspaces_.push_back(std::make_unique<Workspace>(model));
  // φ's scale (m g) does not matter here: this evaluator reports the slack, not φ.
  for (int s = 0; s < samples_.sampleCount(); ++s)
    bilevel_.emplace_back(model, contacts_, settings_, sensitivitySettings_, 1.0);
}

MultiContactGradientEvaluator::~MultiContactGradientEvaluator() = default;

void MultiContactGradientEvaluator::prepareSample(Workspace& w, int s, double duration, MultiContactResult& r,
                                                  MultiContactGradient& grad) {
  TrajectoryResult& motion = r.motion;
  motion.time[s] = samples_.time(s, duration);
  samples_.evaluate(s, controlPoints_, duration, motion.q.col(s), motion.v.col(s), motion.a.col(s));
  inverseDynamicsDerivatives(model_, w.data, w.derivatives, motion.q.col(s), motion.v.col(s), motion.a.col(s));
  r.tau0.col(s) = w.data.tau;
  motion.referenceWrench.col(s) = referenceWrenchAtReferenceFrame(model_, w.data);
  BilevelSample& sample = bilevel_[static_cast<std::size_t>(s)];
  sample.evaluate(model_, w.data, &w.derivatives, actuators_, motion.v.col(s), motion.a.col(s), true,
                  sensitivitySettings_.layout == KktLayout::PerSample);
  const InnerResult& inner = sample.innerResult();
  r.status[static_cast<std::size_t>(s)] = inner.status;
  r.iterations[s] = inner.iterations;
  r.kktResidual[s] = inner.kktResidual;
  for (int i = 0; i < sample.contactCount(); ++i)
    r.wrenches.col(s).segment<6>(6 * i) = sample.problem().problem.contactWrench(inner.wrenches, i);
  r.balanceSlack.col(s) = inner.balanceSlack;
  motion.tau.col(s) = sample.torque();
  grad.diagnostics[static_cast<std::size_t>(s)] = sample.diagnostics();
  if (sample.hasWrenchDerivative())
    w.degenerate += sample.diagnostics().degenerate();
  else
    ++w.withoutDerivative;
}

void MultiContactGradientEvaluator::solveAllSamples() {
  // One block-diagonal matrix of every sample's KKT system, factorised once; the right-hand
  // sides share their 3n columns (the blocks do not interact).
  const int count = samples_.sampleCount(), n = model_.jointCount();
  std::vector<Eigen::Triplet<double>> entries;
  std::vector<Eigen::MatrixXd> rhs(static_cast<std::size_t>(count));
  int size = 0;
  std::vector<int> offset(static_cast<std::size_t>(count), -1);
  for (int s = 0; s < count; ++s) {
    const BilevelSample& sample = bilevel_[static_cast<std::size_t>(s)];
    if (!sample.hasWrenchDerivative()) continue;
    const Eigen::MatrixXd& K = sample.kktMatrix();
    offset[static_cast<std::size_t>(s)] = size;
    for (Eigen::Index c = 0; c < K.cols(); ++c)
      for (Eigen::Index r = 0; r < K.rows(); ++r)
        if (K(r, c) != 0.0) entries.emplace_back(size + static_cast<int>(r), size + static_cast<int>(c), K(r, c));
    sample.kktRightHandSide(rhs[static_cast<std::size_t>(s)]);
    size += static_cast<int>(K.rows());
  }
  if (size == 0) return;
  Eigen::SparseMatrix<double> blocks(size, size);
  blocks.setFromTriplets(entries.begin(), entries.end());
  Eigen::MatrixXd stacked = Eigen::MatrixXd::Zero(size, 3 * n);
  for (int s = 0; s < count; ++s)
    if (offset[static_cast<std::size_t>(s)] >= 0)
      stacked.middleRows(offset[static_cast<std::size_t>(s)], rhs[static_cast<std::size_t>(s)].rows()) =
          rhs[static_cast<std::size_t>(s)];
  // Kept from call to call: the analysis of the whole pattern is reused while no sample's
  // active set or contact state changes.
  if (!allSamplesFactor_)
    allSamplesFactor_ = std::make_unique<SparseKktFactor>(sensitivitySettings_.backend == KktBackend::SparseUmfpack
                                                              ? SparseKktFactor::Library::Umfpack
                                                              : SparseKktFactor::Library::Klu);
  if (!allSamplesFactor_->factorize(blocks))
    throw InputError(std::string("all-samples KKT factorisation (") + toString(sensitivitySettings_.backend) + ") failed");
  Eigen::MatrixXd& solution = stacked;
  allSamplesFactor_->solveInPlace(solution);
  for (int s = 0; s < count; ++s)
    if (offset[static_cast<std::size_t>(s)] >= 0)
      bilevel_[static_cast<std::size_t>(s)].setWrenchDerivative(solution.middleRows(
          offset[static_cast<std::size_t>(s)], bilevel_[static_cast<std::size_t>(s)].problem().problem.variableCount()));
}

void MultiContactGradientEvaluator::finishSample(Workspace& w, int s, double duration, MultiContactResult& r,
                                                 MultiContactGradient& grad, ChunkedEnergyGradient::Sum& sum) {
  const int n = model_.jointCount();
  const int count = samples_.sampleCount(), m = samples_.parametrization().parametersPerJoint();
  TrajectoryResult& motion = r.motion;
  const BilevelSample& sample = bilevel_[static_cast<std::size_t>(s)];
  const Eigen::MatrixXd& dF = sample.wrenchesDstate();

  SampleTorqueJacobian& torqueBlock = grad.torqueAndEnergy.torque[static_cast<std::size_t>(s)];
  samples_.chainRule(s, duration, sample.torqueDq(), sample.torqueDv(), sample.torqueDa(), torqueBlock.dtauDx,
                     torqueBlock.parameters);
  SampledTrajectory::durationDerivative(duration, sample.torqueDv(), sample.torqueDa(), motion.v.col(s), motion.a.col(s),
                                        torqueBlock.dtauDT);
  SampleWrenchJacobian& wrenchBlock = grad.wrenches[static_cast<std::size_t>(s)];
  samples_.chainRule(s, duration, dF.leftCols(n), dF.middleCols(n, n), dF.rightCols(n), wrenchBlock.dFdx,
                     wrenchBlock.parameters);
  SampledTrajectory::durationDerivative(duration, dF.middleCols(n, n), dF.rightCols(n), motion.v.col(s), motion.a.col(s),
                                        wrenchBlock.dFdT);

  // Energy (as TrajectoryGradientEvaluator, with Γ and dΓ/dx of the chosen wrenches).
  const LocalParameterWeights& local = samples_.weights(s);
  const double dt = duration / (count - 1);
  const double weight = (s == 0 || s == count - 1) ? 0.5 * dt : dt;
  w.rowV.setZero();
  w.rowA.setZero();
  double sampleEnergy = 0.0, directDT = 0.0;
  for (int j = 0; j < n; ++j) {
    const MotorPowerDerivatives p = motorPowerDerivatives(actuators_.joints[static_cast<std::size_t>(j)],
                                                          actuators_.frictionSharpness, motion.tau(j, s),
                                                          motion.v(j, s), motion.a(j, s));
    motion.power(j, s) = p.power;
    const bool active = p.power > 0.0;
    sampleEnergy += active ? p.power : 0.0;
    w.powerTorque[j] = active ? weight * p.dTorque : 0.0;
    w.rowV[j] = active ? weight * p.dVelocity : 0.0;
    w.rowA[j] = active ? weight * p.dAcceleration : 0.0;
    directDT -= w.rowV[j] * motion.v(j, s) + 2.0 * w.rowA[j] * motion.a(j, s);
  }
  w.rowQ.noalias() = sample.torqueDq().transpose() * w.powerTorque;
  w.rowV.noalias() += sample.torqueDv().transpose() * w.powerTorque;
  w.rowA.noalias() += sample.torqueDa().transpose() * w.powerTorque;
  for (int j = 0; j < n; ++j)
    for (int l = 0; l < local.count; ++l)
      sum.energyGradient[j * m + local.parameter[static_cast<std::size_t>(l)]] +=
          w.rowQ[j] * local.value[static_cast<std::size_t>(l)] +
          w.rowV[j] * local.d1[static_cast<std::size_t>(l)] / duration +
          w.rowA[j] * local.d2[static_cast<std::size_t>(l)] / (duration * duration);
  sum.energyDT += sampleEnergy * weight / duration + directDT / duration + w.powerTorque.dot(torqueBlock.dtauDT);
}

void MultiContactGradientEvaluator::evaluate(const Eigen::Ref<const Eigen::VectorXd>& parameters, double duration,
                                             MultiContactResult& r, MultiContactGradient& grad) {
  const int n = model_.jointCount(), count = samples_.sampleCount(), nc = static_cast<int>(contacts_.size());
  const int parameterCount = samples_.parametrization().parameterCount();
  prepareTrajectoryResult(samples_, n, parameters, duration, r.motion);
  if (r.tau0.rows() != n || r.tau0.cols() != count) {
    r.tau0.resize(n, count);
    r.wrenches.resize(6 * nc, count);
    r.balanceSlack.resize(6, count);
    r.status.assign(static_cast<std::size_t>(count), InnerStatus::Failed);
    r.iterations.resize(count);
    r.kktResidual.resize(count);
  }
  grad.torqueAndEnergy.torque.resize(static_cast<std::size_t>(count));
  grad.wrenches.resize(static_cast<std::size_t>(count));
  grad.diagnostics.resize(static_cast<std::size_t>(count));
  samples_.parametrization().controlPoints(parameters, controlPoints_);
  for (auto& w : workspaces_) w->degenerate = w->withoutDerivative = 0;
  chunkSums_.reset(count, parameterCount);
  const int threads = static_cast<int>(workspaces_.size());
  // Once every sample's buffers are sized by a first evaluation, the per-sample path —
  // dynamics, inner solve, KKT assembly, factorisation and solve, chain rule — makes no Eigen
  // allocation (debug builds check; the all-samples layout's assembly allocates).
  // (The caller's output blocks too: a new MultiContactGradient is sized by its first use.)
  bool outputSized = true;
  for (int s = 0; s < count; ++s)
    outputSized = outputSized && grad.torqueAndEnergy.torque[static_cast<std::size_t>(s)].dtauDx.size() > 0 &&
                  grad.wrenches[static_cast<std::size_t>(s)].dFdx.size() > 0;
  const bool armed = sized_ && outputSized;
  const bool perSampleLayout = sensitivitySettings_.layout == KktLayout::PerSample;
  std::optional<NoMallocScope> perSample;
  perSample.emplace("sensitivity", armed && perSampleLayout);
#pragma omp parallel num_threads(threads)
  {
    // The samples in fixed chunks (core/sample_chunks.hpp): a sample without a result of its
    // own (the first evaluation) is warm-started from its predecessor in the chunk.
    Workspace& w = *workspaces_[static_cast<std::size_t>(omp_get_thread_num())];
    forEachSampleInChunks(count, [&](int s, int predecessor) {
      if (predecessor >= 0 && settings_.solver.warmStart && !bilevel_[static_cast<std::size_t>(s)].hasResult())
        bilevel_[static_cast<std::size_t>(s)].warmStartFrom(bilevel_[static_cast<std::size_t>(predecessor)]);
      prepareSample(w, s, duration, r, grad);
    });
  }
  if (!perSampleLayout) {
    perSample.reset();
    solveAllSamples();
    perSample.emplace("sensitivity", armed);
  }
#pragma omp parallel num_threads(threads)
  {
    // The energy's gradient is summed per chunk, then over the chunks in order: the same sums
    // in the same order for any thread count.
    Workspace& w = *workspaces_[static_cast<std::size_t>(omp_get_thread_num())];
    forEachSampleInChunks(count, [&](int s, int) {
      finishSample(w, s, duration, r, grad, chunkSums_.of(s));
    });
  }
  perSample.reset();
  sized_ = true;
  r.innerTimeUs = 0.0;
  r.infeasibleSamples = r.failedSamples = 0;
  for (int s = 0; s < count; ++s) {
    r.innerTimeUs += bilevel_[static_cast<std::size_t>(s)].innerResult().solveTimeUs;
    r.infeasibleSamples += r.status[static_cast<std::size_t>(s)] == InnerStatus::Infeasible;
    r.failedSamples += r.status[static_cast<std::size_t>(s)] == InnerStatus::Failed;
  }
  r.motion.energy = positiveEnergy(r.motion.power, r.motion.time);
  grad.degenerateSamples = grad.samplesWithoutDerivative = 0;
  chunkSums_.total(grad.torqueAndEnergy.energyGradient, grad.torqueAndEnergy.energyDT);
  for (const auto& w : workspaces_) {
    grad.degenerateSamples += w->degenerate;
    grad.samplesWithoutDerivative += w->withoutDerivative;
  }
}

}  // namespace mcopt
