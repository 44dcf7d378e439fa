#include "sensitivity/multi_contact_gradient.hpp"

#include <omp.h>

#include <Eigen/KLUSupport>
#include <Eigen/SparseCore>
#include <Eigen/UmfPackSupport>

#include "core/errors.hpp"

namespace mcopt {

struct MultiContactGradientEvaluator::Workspace {
  Workspace(const DynamicsModel& model, const std::vector<ContactSurface>& contacts, const MultiContactSettings& s,
            const SensitivitySettings& sensitivitySettings)
      : data(model), derivatives(model), sample(model, contacts, s.problem), sensitivity(sensitivitySettings) {
    const int n = model.jointCount(), nc = static_cast<int>(contacts.size());
    solver = makeInnerSolver(s.solverName, s.solver);
    g.setZero(n), linearDv.setZero(n), linearDa.setZero(n);
    dJ1Fdq.setZero(n, n), dTorque.setZero(n, n);
    dBFdq.setZero(6, n), dWorld.setZero(6, n), dTorqueT.setZero(6, n), dWorldT.setZero(6, n);
    stationarity.setZero(6 * nc, 3 * n), balance.setZero(6, 3 * n), dF.setZero(6 * nc, 3 * n);
    dGammaDq.setZero(n, n), dGammaDv.setZero(n, n), dGammaDa.setZero(n, n), scaled.setZero(n, n);
    energyGradient.setZero(0), powerTorque.setZero(n), rowQ.setZero(n), rowV.setZero(n), rowA.setZero(n);
  }
  DynamicsData data;
  DynamicsDerivatives derivatives;
  SampleProblem sample;
  InnerSensitivity sensitivity;
  std::unique_ptr<InnerSolver> solver;
  Eigen::VectorXd g, linearDv, linearDa;
  Eigen::MatrixXd dJ1Fdq, dTorque;
  Eigen::Matrix<double, 6, Eigen::Dynamic> dBFdq, dWorld, dTorqueT, dWorldT;
  Eigen::MatrixXd stationarity, balance, dF;
  Eigen::MatrixXd dGammaDq, dGammaDv, dGammaDa, scaled;
  Eigen::VectorXd energyGradient, powerTorque, rowQ, rowV, rowA;
  double energyDT = 0.0;
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
  for (int t = 0; t < omp_get_max_threads(); ++t)
    workspaces_.push_back(std::make_unique<Workspace>(model, contacts_, settings_, sensitivitySettings_));
  previous_.resize(static_cast<std::size_t>(samples_.sampleCount()));
  store_.resize(static_cast<std::size_t>(samples_.sampleCount()));
  sampleKkt_.resize(static_cast<std::size_t>(samples_.sampleCount()));
  if (sensitivitySettings_.layout == KktLayout::AllSamples && sensitivitySettings_.backend == KktBackend::Dense)
    throw InputError("the all-samples KKT layout needs a sparse backend (klu or umfpack)");
}

MultiContactGradientEvaluator::~MultiContactGradientEvaluator() = default;

void MultiContactGradientEvaluator::prepareSample(Workspace& w, int s, double duration, MultiContactResult& r,
                                                  MultiContactGradient& grad) {
  const int n = model_.jointCount(), nc = static_cast<int>(contacts_.size());
  TrajectoryResult& motion = r.motion;
  motion.time[s] = samples_.time(s, duration);
  samples_.evaluate(s, controlPoints_, duration, motion.q.col(s), motion.v.col(s), motion.a.col(s));
  inverseDynamicsDerivatives(model_, w.data, w.derivatives, motion.q.col(s), motion.v.col(s), motion.a.col(s));
  const DynamicsDerivatives& d = w.derivatives;
  r.tau0.col(s) = w.data.tau;
  motion.referenceWrench.col(s) = referenceWrenchAtReferenceFrame(model_, w.data);
  w.sample.update(model_, w.data, actuators_, contacts_, motion.v.col(s), motion.a.col(s));
  InnerResult& inner = previous_[static_cast<std::size_t>(s)];
  w.solver->solve(w.sample.problem, inner);
  r.status[static_cast<std::size_t>(s)] = inner.status;
  r.iterations[s] = inner.iterations;
  r.kktResidual[s] = inner.kktResidual;
  r.wrenches.col(s) = inner.wrenches;
  r.balanceSlack.col(s) = inner.balanceSlack;
  const Eigen::MatrixXd& J1 = w.sample.wrenchToTorque;
  motion.tau.col(s) = w.data.tau;
  motion.tau.col(s).noalias() -= J1 * inner.wrenches;

  // ∂(J1 F)/∂q and ∂(B F)/∂q at the optimal wrenches.
  w.dJ1Fdq.setZero();
  w.dBFdq.setZero();
  for (int i = 0; i < nc; ++i) {
    const Vector6 wrench = inner.wrenches.segment<6>(6 * i);
    wrenchMapDerivatives(model_, w.data, w.sample.frames[static_cast<std::size_t>(i)], wrench, w.dWorld, w.dTorque);
    w.dJ1Fdq += w.dTorque;
    w.dBFdq += w.dWorld;
  }
  SampleStore& store = store_[static_cast<std::size_t>(s)];
  store.wrenchToTorque = J1;
  store.fixedWrenchQ = d.dtauDq - w.dJ1Fdq;
  store.fixedWrenchV = d.dtauDv;
  store.fixedWrenchA = d.dtauDa;
  store.dF.setZero(6 * nc, 3 * n);
  store.hasDerivative = inner.status == InnerStatus::Optimal;
  if (inner.status == InnerStatus::Optimal) {
    const SensitivityDiagnostics& diagnostics = w.sensitivity.factorize(w.sample.problem, inner);
    grad.diagnostics[static_cast<std::size_t>(s)] = diagnostics;
    w.degenerate += diagnostics.degenerate();
    const auto& weights = w.sample.weights;
    w.g = 2.0 * weights.cwiseProduct(motion.tau.col(s)) + w.sample.linear;
    innerObjectiveTermDerivatives(actuators_, motion.v.col(s), w.linearDv, w.linearDa);
    for (int i = 0; i < nc; ++i) {
      transposedWrenchMapDerivatives(model_, w.data, w.sample.frames[static_cast<std::size_t>(i)], w.g,
                                     inner.balanceMultipliers, w.dTorqueT, w.dWorldT);
      w.stationarity.block(6 * i, 0, 6, n) = w.dWorldT - w.dTorqueT;
    }
    // −J1ᵀ 2 diag(w) (∂Γ/∂x at fixed F) − J1ᵀ diag(∂l/∂x)
    // (scaled: 2 diag(w) times ∂Γ/∂x at fixed F, in a preallocated buffer: no temporaries)
    w.scaled.noalias() = 2.0 * weights.asDiagonal() * (d.dtauDq - w.dJ1Fdq);
    w.stationarity.leftCols(n).noalias() -= J1.transpose() * w.scaled;
    w.scaled.noalias() = 2.0 * weights.asDiagonal() * d.dtauDv;
    w.scaled.diagonal() += w.linearDv;
    w.stationarity.middleCols(n, n).noalias() = -J1.transpose() * w.scaled;
    w.scaled.noalias() = 2.0 * weights.asDiagonal() * d.dtauDa;
    w.scaled.diagonal() += w.linearDa;
    w.stationarity.rightCols(n).noalias() = -J1.transpose() * w.scaled;
    w.balance.leftCols(n) = w.dBFdq - d.dwrenchDq;
    w.balance.middleCols(n, n) = -d.dwrenchDv;
    w.balance.rightCols(n) = -d.dwrenchDa;
    if (sensitivitySettings_.layout == KktLayout::AllSamples) {
      sampleKkt_[static_cast<std::size_t>(s)] = w.sensitivity.kktMatrix();
      w.sensitivity.rightHandSide(w.stationarity, w.balance, store.rhs);
    } else {
      w.sensitivity.solve(w.stationarity, w.balance, store.dF);
    }
  } else {
    sampleKkt_[static_cast<std::size_t>(s)].resize(0, 0);
    grad.diagnostics[static_cast<std::size_t>(s)] = SensitivityDiagnostics{};
    ++w.withoutDerivative;
  }
}

void MultiContactGradientEvaluator::solveAllSamples() {
  // One block-diagonal matrix of every sample's KKT system, factorised once; the right-hand
  // sides share their 3n columns (the blocks do not interact).
  const int count = samples_.sampleCount(), n = model_.jointCount();
  std::vector<Eigen::Triplet<double>> entries;
  int size = 0;
  std::vector<int> offset(static_cast<std::size_t>(count), -1);
  for (int s = 0; s < count; ++s) {
    const Eigen::MatrixXd& K = sampleKkt_[static_cast<std::size_t>(s)];
    if (!store_[static_cast<std::size_t>(s)].hasDerivative || K.size() == 0) continue;
    offset[static_cast<std::size_t>(s)] = size;
    for (Eigen::Index c = 0; c < K.cols(); ++c)
      for (Eigen::Index r = 0; r < K.rows(); ++r)
        if (K(r, c) != 0.0) entries.emplace_back(size + static_cast<int>(r), size + static_cast<int>(c), K(r, c));
    size += static_cast<int>(K.rows());
  }
  if (size == 0) return;
  Eigen::SparseMatrix<double> blocks(size, size);
  blocks.setFromTriplets(entries.begin(), entries.end());
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(size, 3 * n);
  for (int s = 0; s < count; ++s)
    if (offset[static_cast<std::size_t>(s)] >= 0)
      rhs.middleRows(offset[static_cast<std::size_t>(s)], store_[static_cast<std::size_t>(s)].rhs.rows()) =
          store_[static_cast<std::size_t>(s)].rhs;
  Eigen::MatrixXd solution;
  if (sensitivitySettings_.backend == KktBackend::SparseUmfpack) {
    Eigen::UmfPackLU<Eigen::SparseMatrix<double>> lu(blocks);
    if (lu.info() != Eigen::Success) throw InputError("all-samples KKT factorisation (UMFPACK) failed");
    solution = lu.solve(rhs);
  } else {
    Eigen::KLU<Eigen::SparseMatrix<double>> lu(blocks);
    if (lu.info() != Eigen::Success) throw InputError("all-samples KKT factorisation (KLU) failed");
    solution = lu.solve(rhs);
  }
  const int nc = static_cast<int>(contacts_.size());
  for (int s = 0; s < count; ++s)
    if (offset[static_cast<std::size_t>(s)] >= 0)
      store_[static_cast<std::size_t>(s)].dF = solution.middleRows(offset[static_cast<std::size_t>(s)], 6 * nc);
}

void MultiContactGradientEvaluator::finishSample(Workspace& w, int s, double duration, MultiContactResult& r,
                                                 MultiContactGradient& grad) {
  const int n = model_.jointCount();
  const int count = samples_.sampleCount(), m = samples_.parametrization().parametersPerJoint();
  TrajectoryResult& motion = r.motion;
  const SampleStore& store = store_[static_cast<std::size_t>(s)];
  const Eigen::MatrixXd& J1 = store.wrenchToTorque;
  // dΓ/dx = dΓ0/dx − (∂J1/∂x) F − J1 dF/dx  (4.8)
  w.dGammaDq = store.fixedWrenchQ;
  w.dGammaDq.noalias() -= J1 * store.dF.leftCols(n);
  w.dGammaDv = store.fixedWrenchV;
  w.dGammaDv.noalias() -= J1 * store.dF.middleCols(n, n);
  w.dGammaDa = store.fixedWrenchA;
  w.dGammaDa.noalias() -= J1 * store.dF.rightCols(n);

  SampleTorqueJacobian& torqueBlock = grad.torqueAndEnergy.torque[static_cast<std::size_t>(s)];
  samples_.chainRule(s, duration, w.dGammaDq, w.dGammaDv, w.dGammaDa, torqueBlock.dtauDx, torqueBlock.parameters);
  SampledTrajectory::durationDerivative(duration, w.dGammaDv, w.dGammaDa, motion.v.col(s), motion.a.col(s),
                                        torqueBlock.dtauDT);
  SampleWrenchJacobian& wrenchBlock = grad.wrenches[static_cast<std::size_t>(s)];
  samples_.chainRule(s, duration, store.dF.leftCols(n), store.dF.middleCols(n, n), store.dF.rightCols(n),
                     wrenchBlock.dFdx, wrenchBlock.parameters);
  SampledTrajectory::durationDerivative(duration, store.dF.middleCols(n, n), store.dF.rightCols(n), motion.v.col(s),
                                        motion.a.col(s), wrenchBlock.dFdT);

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
  w.rowQ.noalias() = w.dGammaDq.transpose() * w.powerTorque;
  w.rowV.noalias() += w.dGammaDv.transpose() * w.powerTorque;
  w.rowA.noalias() += w.dGammaDa.transpose() * w.powerTorque;
  for (int j = 0; j < n; ++j)
    for (int l = 0; l < local.count; ++l)
      w.energyGradient[j * m + local.parameter[static_cast<std::size_t>(l)]] +=
          w.rowQ[j] * local.value[static_cast<std::size_t>(l)] +
          w.rowV[j] * local.d1[static_cast<std::size_t>(l)] / duration +
          w.rowA[j] * local.d2[static_cast<std::size_t>(l)] / (duration * duration);
  w.energyDT += sampleEnergy * weight / duration + directDT / duration + w.powerTorque.dot(torqueBlock.dtauDT);
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
  for (auto& w : workspaces_) {
    w->energyGradient.setZero(parameterCount);
    w->energyDT = 0.0;
    w->degenerate = w->withoutDerivative = 0;
  }
  const int threads = static_cast<int>(workspaces_.size());
#pragma omp parallel num_threads(threads)
  {
    const int t = omp_get_thread_num(), used = omp_get_num_threads();
    const int first = count * t / used, last = count * (t + 1) / used;
    Workspace& w = *workspaces_[static_cast<std::size_t>(t)];
    for (int s = first; s < last; ++s) {
      if (s > first && settings_.solver.warmStart) {  // warm start along the motion
        const InnerResult& before = previous_[static_cast<std::size_t>(s - 1)];
        InnerResult& current = previous_[static_cast<std::size_t>(s)];
        current.wrenches = before.wrenches;
        current.activeSet = before.activeSet;
        current.inequalityMultipliers = before.inequalityMultipliers;
        current.coneMultipliers = before.coneMultipliers;
      }
      prepareSample(w, s, duration, r, grad);
    }
  }
  if (sensitivitySettings_.layout == KktLayout::AllSamples) solveAllSamples();
#pragma omp parallel num_threads(threads)
  {
    const int t = omp_get_thread_num(), used = omp_get_num_threads();
    const int first = count * t / used, last = count * (t + 1) / used;
    Workspace& w = *workspaces_[static_cast<std::size_t>(t)];
    for (int s = first; s < last; ++s) finishSample(w, s, duration, r, grad);
  }
  r.innerTimeUs = 0.0;
  r.infeasibleSamples = r.failedSamples = 0;
  for (int s = 0; s < count; ++s) {
    r.innerTimeUs += previous_[static_cast<std::size_t>(s)].solveTimeUs;
    r.infeasibleSamples += r.status[static_cast<std::size_t>(s)] == InnerStatus::Infeasible;
    r.failedSamples += r.status[static_cast<std::size_t>(s)] == InnerStatus::Failed;
  }
  r.motion.energy = positiveEnergy(r.motion.power, r.motion.time);
  grad.torqueAndEnergy.energyGradient.setZero(parameterCount);
  grad.torqueAndEnergy.energyDT = 0.0;
  grad.degenerateSamples = grad.samplesWithoutDerivative = 0;
  for (const auto& w : workspaces_) {
    grad.torqueAndEnergy.energyGradient += w->energyGradient;
    grad.torqueAndEnergy.energyDT += w->energyDT;
    grad.degenerateSamples += w->degenerate;
    grad.samplesWithoutDerivative += w->withoutDerivative;
  }
}

}  // namespace mcopt
