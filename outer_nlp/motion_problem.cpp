#include "outer_nlp/motion_problem.hpp"

#include <omp.h>

#include <cmath>
#include <sstream>

#include "core/errors.hpp"
#include "core/inverse_dynamics.hpp"
#include "core/spatial.hpp"

namespace mcopt {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

std::vector<double> taskInstants(const Scenario& s, std::vector<int>& taskOfInstant) {
  // Instants are fractions of the motion: with a free duration a task keeps its phase.
  std::vector<double> u;
  const double T = s.duration.initial;
  for (std::size_t t = 0; t < s.tasks.size(); ++t) {
    const TaskSpec& task = s.tasks[t];
    if (!task.window) {
      u.push_back(std::min(1.0, task.start / T));
      taskOfInstant.push_back(static_cast<int>(t));
      continue;
    }
    // A window holds at every regular sample inside it, and at its two ends.
    std::vector<double> inside{std::min(1.0, task.start / T)};
    for (int k = 0; k < s.samples; ++k) {
      const double uk = static_cast<double>(k) / (s.samples - 1);
      if (uk * T > task.start + 1e-9 && uk * T < task.end - 1e-9) inside.push_back(uk);
    }
    inside.push_back(std::min(1.0, task.end / T));
    for (const double value : inside) {
      u.push_back(value);
      taskOfInstant.push_back(static_cast<int>(t));
    }
  }
  return u;
}

/// P⁺ ≈ (P + sqrt(P² + ε²)) / 2 and its derivative (formulation.md §6).
inline double smoothMaximum(double p, double epsilon) { return 0.5 * (p + std::sqrt(p * p + epsilon * epsilon)); }
inline double smoothMaximumSlope(double p, double epsilon) {
  return 0.5 * (1.0 + p / std::sqrt(p * p + epsilon * epsilon));
}

/// The support contact is on the reference body: its frame never moves.
RigidTransform supportPose(const DynamicsModel& model, const ContactSurface& surface) {
  DynamicsData data(model);
  forwardKinematics(model, data, Eigen::VectorXd::Zero(model.jointCount()));
  return framePose(model, data, surface.frame) * surface.placement;
}

}  // namespace

const char* constraintKindName(ConstraintKind kind) {
  switch (kind) {
    case ConstraintKind::VelocityLimit: return "velocity_limit";
    case ConstraintKind::TorqueLimit: return "torque_limit";
    case ConstraintKind::ContactUnilateral: return "contact_unilateral";
    case ConstraintKind::ContactFriction: return "contact_friction";
    case ConstraintKind::ContactCop: return "contact_cop";
    case ConstraintKind::Task: return "task";
    case ConstraintKind::Epigraph: return "energy_epigraph";
  }
  return "?";
}

MotionProblem::MotionProblem(const Scenario& scenario)
    : scenario_(scenario),
      model_(scenario.robot, scenario.referenceBody, scenario.referencePose, scenario.gravity),
      parametrization_(scenario.robot.jointCount(), scenario.controlPoints),
      samples_(parametrization_, scenario.samples),
      taskSamples_(parametrization_, taskInstants(scenario, taskOfInstant_)),
      support_(scenario.support, supportPose(model_, scenario.support), scenario.robot.totalMass() * scenario.gravity.norm()) {
  jointCount_ = model_.jointCount();
  parameterCount_ = parametrization_.parameterCount();
  slackStart_ = parameterCount_ + (durationIsFree() ? 1 : 0);
  variableCount_ = slackStart_ + (scenario_.energyForm == EnergyForm::Epigraph ? jointCount_ * scenario_.samples : 0);
  for (int j = 0; j < jointCount_; ++j)
    if (scenario_.torqueLimits && std::isfinite(scenario_.actuators.joints[static_cast<std::size_t>(j)].torqueLimit))
      torqueJoints_.push_back(j);
  const auto& knots = parametrization_.basis().knots();
  const int m = parametrization_.parametersPerJoint();
  for (int j = 0; j < jointCount_ && scenario_.velocityLimits; ++j) {
    if (!std::isfinite(scenario_.actuators.joints[static_cast<std::size_t>(j)].velocityLimit)) continue;
    for (int k = 0; k + 1 < parametrization_.controlPointCount(); ++k) {
      const int first = parametrization_.parameterOfControlPoint(k), second = parametrization_.parameterOfControlPoint(k + 1);
      if (first == second) continue;  // the clamped ends: identically zero
      velocityRows_.push_back({j, j * m + first, j * m + second,
                               3.0 / (knots[static_cast<std::size_t>(k) + 4] - knots[static_cast<std::size_t>(k) + 1])});
    }
  }
  contactRowCount_ = scenario_.contactConstraints ? 6 : 0;

  workspaces_.assign(static_cast<std::size_t>(omp_get_max_threads()), ThreadWorkspace(model_));
  for (ThreadWorkspace& w : workspaces_) w.q.setZero(jointCount_), w.v.setZero(jointCount_), w.a.setZero(jointCount_);
  const int outputs = 2 * jointCount_ + 6;
  blocks_.resize(static_cast<std::size_t>(samples_.sampleCount()));
  for (SampleBlock& b : blocks_) {
    b.y.setZero(outputs), b.dyDT.setZero(outputs);
    b.dyDq.setZero(outputs, jointCount_), b.dyDv.setZero(outputs, jointCount_), b.dyDa.setZero(outputs, jointCount_);
  }
  taskBlocks_.resize(taskOfInstant_.size());
  for (SampleBlock& b : taskBlocks_) {
    b.y.setZero(3), b.dyDT.setZero(3);
    b.dyDq.setZero(3, jointCount_), b.dyDv.setZero(3, jointCount_), b.dyDa.setZero(3, jointCount_);
  }
  // Local parameters of every sample (the chain rule's column order), fixed for good.
  for (int s = 0; s < samples_.sampleCount(); ++s) {
    SampleBlock& b = blocks_[static_cast<std::size_t>(s)];
    samples_.chainRule(s, 1.0, b.dyDq, b.dyDv, b.dyDa, b.dyDx, b.parameters);
  }
  for (std::size_t i = 0; i < taskBlocks_.size(); ++i) {
    SampleBlock& b = taskBlocks_[i];
    taskSamples_.chainRule(static_cast<int>(i), 1.0, b.dyDq, b.dyDv, b.dyDa, b.dyDx, b.parameters);
  }
  // Sparsity within a sample: Γ_i (and P_i) depends on q_j, q̇_j, q̈_j only when one of the
  // two joints carries the other (the tree rooted at the reference body); W0 on every joint;
  // a body's pose and twist on the joints between it and the reference body.
  relatedJoints_.resize(static_cast<std::size_t>(jointCount_));
  for (int i = 0; i < jointCount_; ++i) {
    allJoints_.push_back(i);
    for (int j = 0; j < jointCount_; ++j)
      if (model_.supports(i, model_.positionOfJoint(j)) || model_.supports(j, model_.positionOfJoint(i)))
        relatedJoints_[static_cast<std::size_t>(i)].push_back(j);
  }
  for (const int t : taskOfInstant_) {
    const TaskSpec& task = scenario_.tasks[static_cast<std::size_t>(t)];
    if (task.kind == TaskKind::CenterOfMass) {
      taskJoints_.push_back(allJoints_);
      continue;
    }
    std::vector<int> path;
    for (int j = 0; j < jointCount_; ++j)
      if (model_.supports(j, model_.framePosition(task.frame))) path.push_back(j);
    taskJoints_.push_back(path);
  }
  buildStructure();
}

void MotionProblem::buildStructure() {
  std::vector<int> rows, columns;
  const bool freeT = durationIsFree();
  int row = 0;
  auto addRow = [&](ConstraintKind kind, int detail, int sample) {
    rowKind_.push_back(kind), rowDetail_.push_back(detail), rowSample_.push_back(sample);
  };
  for (const VelocityRow& v : velocityRows_) {
    addRow(ConstraintKind::VelocityLimit, v.joint, -1);
    for (const int c : {v.first, v.second}) rows.push_back(row), columns.push_back(c);
    if (freeT) rows.push_back(row), columns.push_back(parameterCount_);
    ++row;
  }
  // Only the local parameters of the joints the row depends on (dependsOn lists them).
  auto sampleColumns = [&](const SampleBlock& b, const std::vector<int>& dependsOn) {
    const int k = static_cast<int>(b.parameters.size()) / jointCount_;
    for (const int j : dependsOn)
      for (int l = 0; l < k; ++l) rows.push_back(row), columns.push_back(b.parameters[j * k + l]);
    if (freeT) rows.push_back(row), columns.push_back(parameterCount_);
  };
  for (int s = 0; s < samples_.sampleCount(); ++s) {
    const SampleBlock& b = blocks_[static_cast<std::size_t>(s)];
    for (const int j : torqueJoints_) {
      addRow(ConstraintKind::TorqueLimit, j, s);
      sampleColumns(b, relatedJoints_[static_cast<std::size_t>(j)]);
      ++row;
    }
    for (int c = 0; c < contactRowCount_; ++c) {
      addRow(c == 0 ? ConstraintKind::ContactUnilateral : c == 1 ? ConstraintKind::ContactFriction : ConstraintKind::ContactCop,
             c, s);
      sampleColumns(b, allJoints_);
      ++row;
    }
    if (scenario_.energyForm == EnergyForm::Epigraph)
      for (int j = 0; j < jointCount_; ++j) {
        addRow(ConstraintKind::Epigraph, j, s);
        sampleColumns(b, relatedJoints_[static_cast<std::size_t>(j)]);
        rows.push_back(row), columns.push_back(slackStart_ + s * jointCount_ + j);
        ++row;
      }
  }
  for (std::size_t i = 0; i < taskBlocks_.size(); ++i) {
    const TaskSpec& task = scenario_.tasks[static_cast<std::size_t>(taskOfInstant_[i])];
    for (int c = 0; c < 3; ++c) {
      if (!std::isfinite(task.lower[c]) && !std::isfinite(task.upper[c])) continue;
      addRow(ConstraintKind::Task, c, static_cast<int>(i));
      sampleColumns(taskBlocks_[i], taskJoints_[i]);
      ++row;
    }
  }
  jacobianRows_ = Eigen::Map<Eigen::VectorXi>(rows.data(), static_cast<Eigen::Index>(rows.size()));
  jacobianColumns_ = Eigen::Map<Eigen::VectorXi>(columns.data(), static_cast<Eigen::Index>(columns.size()));
}

std::string MotionProblem::rowName(int row) const {
  const std::size_t r = static_cast<std::size_t>(row);
  const ConstraintKind kind = rowKind_[r];
  const int detail = rowDetail_[r], sample = rowSample_[r];
  std::ostringstream name;
  switch (kind) {
    case ConstraintKind::VelocityLimit:
      name << "velocity limit of " << scenario_.robot.joints[static_cast<std::size_t>(detail)].name << " (control points)";
      return name.str();
    case ConstraintKind::TorqueLimit:
      name << "torque limit of " << scenario_.robot.joints[static_cast<std::size_t>(detail)].name;
      break;
    case ConstraintKind::ContactUnilateral:
    case ConstraintKind::ContactFriction:
    case ConstraintKind::ContactCop: name << scenario_.support.name << " " << SupportContactRows::rowName(detail); break;
    case ConstraintKind::Epigraph:
      name << "energy epigraph of " << scenario_.robot.joints[static_cast<std::size_t>(detail)].name;
      break;
    case ConstraintKind::Task: {
      const TaskSpec& task = scenario_.tasks[static_cast<std::size_t>(taskOfInstant_[static_cast<std::size_t>(sample)])];
      name << "task '" << task.name << "' component " << "xyz"[detail] << " at u = "
           << taskSamples_.time(sample, 1.0) << " of the motion";
      return name.str();
    }
  }
  name << " at sample " << sample;
  return name.str();
}

void MotionProblem::variableBounds(Eigen::VectorXd& lower, Eigen::VectorXd& upper) const {
  lower.setConstant(variableCount_, -kInf);
  upper.setConstant(variableCount_, kInf);
  const int m = parametrization_.parametersPerJoint();
  for (int j = 0; j < jointCount_; ++j) {
    const JointLimits& limit = scenario_.robot.joints[static_cast<std::size_t>(j)].limits;
    if (scenario_.positionLimits) {
      lower.segment(j * m, m).setConstant(limit.lower);
      upper.segment(j * m, m).setConstant(limit.upper);
    }
    if (scenario_.fixStart) lower[j * m] = upper[j * m] = scenario_.start[j];
    if (scenario_.fixEnd) lower[j * m + m - 1] = upper[j * m + m - 1] = scenario_.end[j];
  }
  if (durationIsFree()) lower[parameterCount_] = scenario_.duration.lower, upper[parameterCount_] = scenario_.duration.upper;
  lower.tail(variableCount_ - slackStart_).setZero();
}

void MotionProblem::constraintBounds(Eigen::VectorXd& lower, Eigen::VectorXd& upper) const {
  lower.resize(constraintCount());
  upper.resize(constraintCount());
  for (int r = 0; r < constraintCount(); ++r) {
    const std::size_t i = static_cast<std::size_t>(r);
    const int detail = rowDetail_[i];
    switch (rowKind_[i]) {
      case ConstraintKind::VelocityLimit: {
        const double limit = scenario_.actuators.joints[static_cast<std::size_t>(detail)].velocityLimit;
        lower[r] = -limit, upper[r] = limit;
        break;
      }
      case ConstraintKind::TorqueLimit: {
        const double limit = scenario_.actuators.joints[static_cast<std::size_t>(detail)].torqueLimit;
        lower[r] = -limit, upper[r] = limit;
        break;
      }
      case ConstraintKind::ContactUnilateral: lower[r] = scenario_.minimumNormalForce, upper[r] = kInf; break;
      case ConstraintKind::ContactFriction:
      case ConstraintKind::ContactCop:
      case ConstraintKind::Epigraph: lower[r] = 0.0, upper[r] = kInf; break;
      case ConstraintKind::Task: {
        const TaskSpec& task =
            scenario_.tasks[static_cast<std::size_t>(taskOfInstant_[static_cast<std::size_t>(rowSample_[i])])];
        lower[r] = task.lower[detail], upper[r] = task.upper[detail];
        break;
      }
    }
  }
}

Eigen::VectorXd MotionProblem::initialPoint(const Eigen::VectorXd& start, const Eigen::VectorXd& end) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(variableCount_);
  x.head(parameterCount_) = parametrization_.interpolatedMotion(start, end);
  if (durationIsFree()) x[parameterCount_] = scenario_.duration.initial;
  if (scenario_.energyForm == EnergyForm::Epigraph) {
    evaluate(x, false);
    for (int s = 0; s < samples_.sampleCount(); ++s)
      for (int j = 0; j < jointCount_; ++j)
        x[slackStart_ + s * jointCount_ + j] = std::max(0.0, blocks_[static_cast<std::size_t>(s)].y[jointCount_ + 6 + j]);
  }
  return x;
}

void MotionProblem::evaluateSample(int s, double T, bool derivatives, ThreadWorkspace& w) {
  SampleBlock& b = blocks_[static_cast<std::size_t>(s)];
  const int n = jointCount_;
  samples_.evaluate(s, controlPoints_, T, w.q, w.v, w.a);
  if (derivatives)
    inverseDynamicsDerivatives(model_, w.data, w.derivatives, w.q, w.v, w.a);
  else
    inverseDynamics(model_, w.data, w.q, w.v, w.a);
  b.y.head(n) = w.data.tau;
  b.acceleration = w.a;

  Eigen::Matrix<double, 6, 6> rowsByW0;
  if (derivatives)
    support_.evaluate(w.data.referenceWrench, b.y.segment<6>(n), rowsByW0);
  else
    support_.evaluate(w.data.referenceWrench, b.y.segment<6>(n));

  for (int j = 0; j < n; ++j) {
    const MotorPowerDerivatives p = motorPowerDerivatives(scenario_.actuators.joints[static_cast<std::size_t>(j)],
                                                          scenario_.actuators.frictionSharpness, w.data.tau[j], w.v[j],
                                                          w.a[j]);
    b.y[n + 6 + j] = p.power;
    if (!derivatives) continue;
    const DynamicsDerivatives& d = w.derivatives;
    b.dyDq.row(n + 6 + j) = p.dTorque * d.dtauDq.row(j);
    b.dyDv.row(n + 6 + j) = p.dTorque * d.dtauDv.row(j);
    b.dyDa.row(n + 6 + j) = p.dTorque * d.dtauDa.row(j);
    b.dyDv(n + 6 + j, j) += p.dVelocity;
    b.dyDa(n + 6 + j, j) += p.dAcceleration;
  }
  if (!derivatives) return;
  const DynamicsDerivatives& d = w.derivatives;
  b.dyDq.topRows(n) = d.dtauDq;
  b.dyDv.topRows(n) = d.dtauDv;
  b.dyDa.topRows(n) = d.dtauDa;
  b.dyDq.middleRows<6>(n).noalias() = rowsByW0 * d.dwrenchDq;
  b.dyDv.middleRows<6>(n).noalias() = rowsByW0 * d.dwrenchDv;
  b.dyDa.middleRows<6>(n).noalias() = rowsByW0 * d.dwrenchDa;
  samples_.chainRule(s, T, b.dyDq, b.dyDv, b.dyDa, b.dyDx, b.parameters);
  SampledTrajectory::durationDerivative(T, b.dyDv, b.dyDa, w.v, w.a, b.dyDT);
}

void MotionProblem::evaluateTaskInstant(int i, double T, bool derivatives, ThreadWorkspace& w) {
  SampleBlock& b = taskBlocks_[static_cast<std::size_t>(i)];
  const TaskSpec& task = scenario_.tasks[static_cast<std::size_t>(taskOfInstant_[static_cast<std::size_t>(i)])];
  taskSamples_.evaluate(i, controlPoints_, T, w.q, w.v, w.a);
  inverseDynamics(model_, w.data, w.q, w.v, w.a);
  Vector3 value;
  evaluateTask(model_, w.data, task, derivatives, w.task, value, b.dyDq, b.dyDv);
  b.y = value;
  if (!derivatives) return;
  taskSamples_.chainRule(i, T, b.dyDq, b.dyDv, Eigen::MatrixXd(), b.dyDx, b.parameters);
  SampledTrajectory::durationDerivative(T, b.dyDv, b.dyDa, w.v, w.a, b.dyDT);
}

void MotionProblem::evaluate(const Eigen::VectorXd& x, bool derivatives) {
  if (x.size() != variableCount_) throw InputError("motion problem: wrong number of variables");
  if (cacheValid_ && (cachedDerivatives_ || !derivatives) && x == cachedX_) return;
  if (!x.allFinite()) throw InputError("motion problem: non-finite variables");
  const double T = duration(x);
  parametrization_.controlPoints(x.head(parameterCount_), controlPoints_);
  const int count = samples_.sampleCount(), taskCount = static_cast<int>(taskBlocks_.size());
#pragma omp parallel
  {
    ThreadWorkspace& w = workspaces_[static_cast<std::size_t>(omp_get_thread_num())];
#pragma omp for schedule(static) nowait
    for (int s = 0; s < count; ++s) evaluateSample(s, T, derivatives, w);
#pragma omp for schedule(static)
    for (int i = 0; i < taskCount; ++i) evaluateTaskInstant(i, T, derivatives, w);
  }
  cachedX_ = x;
  cachedDerivatives_ = derivatives;
  cacheValid_ = true;
}

double MotionProblem::objective(const Eigen::VectorXd& x) {
  evaluate(x, false);
  const int N = samples_.sampleCount(), n = jointCount_;
  const double dt = duration(x) / (N - 1);
  double energy = 0.0;
  for (int s = 0; s < N; ++s) {
    const double weight = (s == 0 || s == N - 1) ? 0.5 * dt : dt;
    double sum = 0.0;
    if (scenario_.energyForm == EnergyForm::Epigraph)
      sum = x.segment(slackStart_ + s * n, n).sum();
    else
      for (int j = 0; j < n; ++j) sum += smoothMaximum(blocks_[static_cast<std::size_t>(s)].y[n + 6 + j], scenario_.smoothing);
    if (scenario_.accelerationWeight > 0.0)
      sum += scenario_.accelerationWeight * blocks_[static_cast<std::size_t>(s)].acceleration.squaredNorm();
    energy += weight * sum;
  }
  return energy;
}

void MotionProblem::objectiveGradient(const Eigen::VectorXd& x, Eigen::VectorXd& gradient) {
  const bool epigraph = scenario_.energyForm == EnergyForm::Epigraph;
  if (!epigraph)
    evaluate(x, true);
  else if (scenario_.accelerationWeight > 0.0)
    evaluate(x, false);
  const int N = samples_.sampleCount(), n = jointCount_;
  const double T = duration(x), dt = T / (N - 1);
  gradient.setZero(variableCount_);
  double dT = 0.0;
  for (int s = 0; s < N; ++s) {
    const double weight = (s == 0 || s == N - 1) ? 0.5 * dt : dt;
    const SampleBlock& b = blocks_[static_cast<std::size_t>(s)];
    if (scenario_.accelerationWeight > 0.0) {
      // ∂q̈_j/∂x_{j,l} = w''_l / T², ∂q̈/∂T = −2 q̈ / T; the weight Δt ∝ T.
      const LocalParameterWeights& local = samples_.weights(s);
      const double scale = weight * scenario_.accelerationWeight;
      const int m = parametrization_.parametersPerJoint();
      for (int j = 0; j < n; ++j)
        for (int l = 0; l < local.count; ++l)
          gradient[j * m + local.parameter[l]] += scale * 2.0 * b.acceleration[j] * local.d2[l] / (T * T);
      dT += scale * (b.acceleration.squaredNorm() / T - 4.0 * b.acceleration.squaredNorm() / T);
    }
    if (epigraph) {
      gradient.segment(slackStart_ + s * n, n).array() += weight;
      dT += weight / T * x.segment(slackStart_ + s * n, n).sum();
      continue;
    }
    for (int j = 0; j < n; ++j) {
      const double p = b.y[n + 6 + j], slope = weight * smoothMaximumSlope(p, scenario_.smoothing);
      for (Eigen::Index c = 0; c < b.parameters.size(); ++c) gradient[b.parameters[c]] += slope * b.dyDx(n + 6 + j, c);
      dT += slope * b.dyDT[n + 6 + j] + weight / T * smoothMaximum(p, scenario_.smoothing);
    }
  }
  if (durationIsFree()) gradient[parameterCount_] = dT;
}

void MotionProblem::constraints(const Eigen::VectorXd& x, Eigen::VectorXd& values) {
  evaluate(x, false);
  const double T = duration(x);
  const int n = jointCount_;
  values.resize(constraintCount());
  int row = 0;
  for (const VelocityRow& v : velocityRows_) values[row++] = v.scale * (x[v.second] - x[v.first]) / T;
  for (int s = 0; s < samples_.sampleCount(); ++s) {
    const SampleBlock& b = blocks_[static_cast<std::size_t>(s)];
    for (const int j : torqueJoints_) values[row++] = b.y[j];
    for (int c = 0; c < contactRowCount_; ++c) values[row++] = b.y[n + c];
    if (scenario_.energyForm == EnergyForm::Epigraph)
      for (int j = 0; j < n; ++j) values[row++] = x[slackStart_ + s * n + j] - b.y[n + 6 + j];
  }
  for (std::size_t i = 0; i < taskBlocks_.size(); ++i) {
    const TaskSpec& task = scenario_.tasks[static_cast<std::size_t>(taskOfInstant_[i])];
    for (int c = 0; c < 3; ++c)
      if (std::isfinite(task.lower[c]) || std::isfinite(task.upper[c])) values[row++] = taskBlocks_[i].y[c];
  }
}

void MotionProblem::jacobianValues(const Eigen::VectorXd& x, Eigen::VectorXd& values) {
  evaluate(x, true);
  const double T = duration(x);
  const bool freeT = durationIsFree();
  const int n = jointCount_;
  values.resize(jacobianNonZeros());
  Eigen::Index k = 0;
  for (const VelocityRow& v : velocityRows_) {
    values[k++] = -v.scale / T;
    values[k++] = v.scale / T;
    if (freeT) values[k++] = -v.scale * (x[v.second] - x[v.first]) / (T * T);
  }
  auto sampleRow = [&](const SampleBlock& b, int output, double sign, const std::vector<int>& dependsOn) {
    const int local = static_cast<int>(b.parameters.size()) / n;
    for (const int j : dependsOn)
      for (int l = 0; l < local; ++l) values[k++] = sign * b.dyDx(output, j * local + l);
    if (freeT) values[k++] = sign * b.dyDT[output];
  };
  for (int s = 0; s < samples_.sampleCount(); ++s) {
    const SampleBlock& b = blocks_[static_cast<std::size_t>(s)];
    for (const int j : torqueJoints_) sampleRow(b, j, 1.0, relatedJoints_[static_cast<std::size_t>(j)]);
    for (int c = 0; c < contactRowCount_; ++c) sampleRow(b, n + c, 1.0, allJoints_);
    if (scenario_.energyForm == EnergyForm::Epigraph)
      for (int j = 0; j < n; ++j) {
        sampleRow(b, n + 6 + j, -1.0, relatedJoints_[static_cast<std::size_t>(j)]);
        values[k++] = 1.0;
      }
  }
  for (std::size_t i = 0; i < taskBlocks_.size(); ++i) {
    const TaskSpec& task = scenario_.tasks[static_cast<std::size_t>(taskOfInstant_[i])];
    for (int c = 0; c < 3; ++c)
      if (std::isfinite(task.lower[c]) || std::isfinite(task.upper[c])) sampleRow(taskBlocks_[i], c, 1.0, taskJoints_[i]);
  }
}

MotionProblem::Violations MotionProblem::violations(const Eigen::VectorXd& x) {
  Violations v;
  Eigen::VectorXd lower, upper, g, gl, gu;
  variableBounds(lower, upper);
  for (Eigen::Index i = 0; i < x.size(); ++i)
    v.positionLimit = std::max({v.positionLimit, lower[i] - x[i], x[i] - upper[i]});
  v.overall = v.positionLimit;
  constraints(x, g);
  constraintBounds(gl, gu);
  for (int r = 0; r < constraintCount(); ++r) {
    const double violation = std::max({0.0, gl[r] - g[r], g[r] - gu[r]});
    double& kind = v.byKind[static_cast<std::size_t>(rowKind(r))];
    kind = std::max(kind, violation);
    if (violation > v.overall) v.overall = violation, v.worstRow = r;
  }
  return v;
}

}  // namespace mcopt
