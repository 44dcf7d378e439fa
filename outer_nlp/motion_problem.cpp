// SPDX-License-Identifier: BSD-3-Clause
#include "outer_nlp/motion_problem.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "core/errors.hpp"
#include "core/inverse_dynamics.hpp"
#include "core/kinematics.hpp"
#include "core/no_malloc_scope.hpp"
#include "core/sample_chunks.hpp"
#include "core/spatial.hpp"
#include "core/trajectory_evaluation.hpp"
#include "outer_nlp/contact_force_formulation.hpp"
#include "outer_nlp/motion_workspace.hpp"

namespace mcopt {

namespace {

std::vector<double> taskInstants(const Scenario& s, std::vector<int>& taskOfInstant) {
  // Instants are fractions of the motion: with a free duration a task keeps its phase.
  std::vector<double> u;
  const double T = s.duration.initial;
  for (std::size_t t = 0; t < s.tasks.size(); ++t) {
    const TaskSpec& task = s.tasks[t];
    if (task.heldByConstruction) continue;  // closed_chains.hpp
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

/// The NLP's samples (formulation.md §10): the regular u_s = s / (N − 1) and, where the physics
/// jumps, the instant twice, each side its own sample — a thrown ball's release (on the nearest
/// regular sample: loaded, then released) and each end of a contact's window inside the motion
/// (out of contact then in at its start, in then out at its end; inserted where no regular
/// sample is). `side`: −1 the twin before the instant, +1 after, 0 a single sample.
struct NlpSampleGrid {
  std::vector<double> u;
  std::vector<int> side;
  int releaseSample = -1;  ///< the loaded twin
};

NlpSampleGrid nlpSampleGrid(const Scenario& scenario) {
  const int N = scenario.samples;
  const double T = scenario.duration.initial, slack = 1e-9;
  std::vector<double> jumps;  // instants where the physics jumps
  double release = -1.0;
  if (scenario.ball) {
    release = static_cast<double>(std::lround(scenario.ball->releaseTime / T * (N - 1))) / (N - 1);
    jumps.push_back(release);
  }
  for (const EnvironmentContact& c : scenario.contacts)
    if (c.window)
      for (const double end : {c.start / T, std::min(1.0, c.end / T)})
        if (end > slack && end < 1.0 - slack) jumps.push_back(end);
  std::sort(jumps.begin(), jumps.end());
  NlpSampleGrid grid;
  auto add = [&](double u, int side) { grid.u.push_back(u), grid.side.push_back(side); };
  std::size_t next = 0;
  for (int k = 0; k < N; ++k) {
    const double u = static_cast<double>(k) / (N - 1);
    bool regularIsJump = false;
    while (next < jumps.size() && jumps[next] < u + slack) {
      const double jump = jumps[next];
      while (next < jumps.size() && jumps[next] < jump + slack) ++next;  // one pair for coinciding jumps
      regularIsJump = std::abs(jump - u) <= slack;
      const double at = regularIsJump ? u : jump;
      if (std::abs(at - release) <= slack) grid.releaseSample = static_cast<int>(grid.u.size());
      add(at, -1), add(at, +1);
    }
    if (!regularIsJump) add(u, 0);
  }
  return grid;
}

std::vector<double> nlpSampleTimes(const Scenario& scenario) { return nlpSampleGrid(scenario).u; }

/// The support contact is on the reference body: its frame never moves.
RigidTransform supportPose(const DynamicsModel& model, const ContactSurface& surface) {
  DynamicsData data(model);
  forwardKinematics(model, data, Eigen::VectorXd::Zero(model.jointCount()));
  return framePose(model, data, surface.frame) * surface.placement;
}

}  // namespace

MotionProblem::MotionProblem(const Scenario& scenario) : MotionProblem(scenario, {scenario.solve.hessian, {}}) {}

MotionProblem::MotionProblem(const Scenario& scenario, MotionProblemOptions options)
    : scenario_(scenario),
      model_(scenario.robot, scenario.referenceBody, scenario.referencePose, scenario.gravity),
      parametrization_(scenario.robot.jointCount(), scenario.controlPoints, scenario.periodic),
      samples_(parametrization_, nlpSampleTimes(scenario)),
      taskSamples_(parametrization_, taskInstants(scenario, taskOfInstant_)),
      support_(scenario.support, supportPose(model_, scenario.support), scenario.robot.totalMass() * scenario.gravity.norm(),
               scenario.inner.problem),
      weight_(scenario.robot.totalMass() * scenario.gravity.norm()) {
  hessian_ = options.hessian;
  derivativesLaidOut_ = options.derivatives;
  // The scenario file checks this with its line; a command-line override (--contact-forces)
  // or a hand-built scenario meets it here.
  if (hessian_ == HessianOption::Exact)
    if (const std::string why = exactHessianRefusal(scenario_); !why.empty()) throw InputError("hessian: exact: " + why);
  if (hessian_ == HessianOption::Exact) {
    // The degree of a weighted output gradient along one state component (docs/reference/scenario-file.md,
    // "Hessian options"; tests/core/test_dynamics_degree.cpp): Γ and the reference
    // wrench are trigonometric of degree 2 in each joint angle (a moved body's world-frame
    // inertia X* I X⁻¹ is second-degree in cos q, sin q; its velocity and acceleration
    // first-degree), quadratic in q̇, affine in q̈ and in the force variables. The report
    // model's friction-cone row, quadratic in the wrench, enters through the wrench
    // (motion_hessian.cpp), so these are the degrees for every contact model. Task
    // quantities (positions, orientations, the centre of mass, point velocities) are
    // first-degree in cos q, sin q and linear in q̇; their angle stencil takes degree 2, which
    // also holds for a product of two such factors.
    exactStencils_.angle = trigonometricStencil(2);
    exactStencils_.velocity = polynomialStencil(2, 1.0);
    // Affine directions take the one-sided difference from the point's own gradient, which
    // one evaluation gives for all of them: n + 1 evaluations for a kick sample's q̈ columns
    // instead of 2n (212 in all instead of 241).
    exactStencils_.acceleration = affineStencil(1.0);
    exactStencils_.force = affineStencil(1.0);
    exactStencils_.taskAngle = trigonometricStencil(2);
    exactStencils_.taskVelocity = polynomialStencil(1, 1.0);
  }
  jointCount_ = model_.jointCount();
  parameterCount_ = parametrization_.parameterCount();
  // Environment contacts: closed by construction over their windows (closed_chains.hpp; the
  // exact Hessian option refuses them: exactHessianRefusal, checked above).
  std::vector<HeldContact> held;
  for (const EnvironmentContact& c : scenario_.contacts) {
    HeldContact h{c.surface.name, c.surface.frame, c.surface.placement, c.worldPose};
    if (c.window) h.window = {c.start / scenario_.duration.initial, std::min(1.0, c.end / scenario_.duration.initial)};
    held.push_back(h);
  }
  if (!held.empty()) closure_ = std::make_unique<ClosedChains>(model_, std::move(held), scenario_.start);
  const int closing = closure_ ? closure_->closingCount() : 0;
  outputs_.closing = closing;
  if (closure_ && scenario_.closureReachMargin > 0.0) {
    outputs_.reaches = closure_->contactCount();
    checkLoopReaches();
  }
  // Trapezoid weights as fractions of T, (u_{s+1} − u_{s−1}) / 2: 1 / (N − 1) between regular
  // samples, halved at the ends and, where an instant is sampled twice (a throw's release, a
  // window's end: the power jumps there), each twin its side's half interval.
  const NlpSampleGrid grid = nlpSampleGrid(scenario_);
  sampleTimes_ = grid.u;
  sampleSides_ = grid.side;
  const int count = samples_.sampleCount();
  sampleWeights_.assign(static_cast<std::size_t>(count), 0.0);
  for (int s = 0; s < count; ++s)
    sampleWeights_[static_cast<std::size_t>(s)] =
        0.5 * (sampleTimes_[static_cast<std::size_t>(std::min(s + 1, count - 1))] - sampleTimes_[static_cast<std::size_t>(std::max(s - 1, 0))]);
  loaded_.assign(static_cast<std::size_t>(count), false);
  if (scenario_.ball) {
    const ThrownBall& ball = *scenario_.ball;
    loadedModel_ = std::make_unique<DynamicsModel>(withPointMass(scenario.robot, ball.frame, ball.point, ball.mass),
                                                   scenario.referenceBody, scenario.referencePose, scenario.gravity);
    releaseSample_ = grid.releaseSample;
    for (int s = 0; s <= releaseSample_; ++s) loaded_[static_cast<std::size_t>(s)] = true;
  }
  omittedTorqueRows_ = std::move(options.omittedTorqueRows);
  if (!omittedTorqueRows_.empty() && omittedTorqueRows_.size() != static_cast<std::size_t>(jointCount_ * count))
    throw InputError("motion problem: the torque-row screening mask has the wrong size");
  omittedClosingRows_ = std::move(options.omittedClosingRows);
  if (!omittedClosingRows_.empty() && omittedClosingRows_.size() != static_cast<std::size_t>(2 * closing * count))
    throw InputError("motion problem: the closing-joint-row screening mask has the wrong size");
  const int contacts = static_cast<int>(scenario_.contacts.size());
  outputs_.joints = jointCount_, outputs_.contacts = contacts;
  outputs_.contactRowStart = {0, support_.rowCount()};
  forceStart_ = parameterCount_ + (durationIsFree() ? 1 : 0);
  for (const EnvironmentContact& c : scenario_.contacts) {
    windows_.push_back({c.start / scenario_.duration.initial, std::min(1.0, c.end / scenario_.duration.initial)});
    // In contact at a sample inside the window; at a twin of a window's end, on the side within it.
    std::vector<bool> active(static_cast<std::size_t>(count));
    for (int s = 0; s < count; ++s)
      active[static_cast<std::size_t>(s)] =
          insideWindow(sampleTimes_[static_cast<std::size_t>(s)], windows_.back(), sampleSides_[static_cast<std::size_t>(s)]);
    active_.push_back(std::move(active));
    contactRows_.emplace_back(c.surface, RigidTransform{}, weight_, scenario_.inner.problem);
    outputs_.contactRowStart.push_back(outputs_.contactRowStart.back() + contactRows_.back().rowCount());
  }
  // How the environment contacts' wrenches are chosen (contact_force_formulation.hpp).
  FormulationContext formulation{scenario_, outputs_, support_,    contactRows_, windows_, sampleTimes_,
                                 active_,   forceStart_, weight_, {},           {}};
  for (int s = 0; s < count; ++s)
    formulation.sampleModels.push_back(&modelOf(s)), formulation.sampleSurfaces.push_back(surfacesInContact(s));
  formulation_ = makeContactForceFormulation(formulation);
  slackStart_ = forceStart_ + forceVariableCount();

  for (int j = 0; j < jointCount_; ++j)
    if (scenario_.torqueLimits && std::isfinite(scenario_.actuators.joints[static_cast<std::size_t>(j)].torqueLimit))
      torqueJoints_.push_back(j);
  const int m = parametrization_.parametersPerJoint();

  const int outputs = outputs_.size();
  // The task buffers' rows: the largest task dimension (3 unless every task has fewer, or one more).
  for (const int t : taskOfInstant_) taskRows_ = std::max(taskRows_, scenario_.tasks[static_cast<std::size_t>(t)].dimension());
  workspaces_.assign(static_cast<std::size_t>(omp_get_max_threads()),
                     ThreadWorkspace(model_, contactRowCounts(), closure_ ? closure_->contactCount() : 0,
                                     closing, outputs, taskRows_));
  blocks_.resize(static_cast<std::size_t>(samples_.sampleCount()));
  for (int s = 0; s < samples_.sampleCount(); ++s) {
    SampleBlock& b = blocks_[static_cast<std::size_t>(s)];
    b.y.setZero(outputs), b.wrenches.setZero(6 * (1 + contacts));
    formulation_->layOutForceColumns(s, b.forceTerms, b.forceColumns);
    b.closedAngles.setConstant(closing, std::numeric_limits<double>::quiet_NaN());
    // The contacts in contact here are closed (a window's end sampled once or on its side within).
    for (int i = 0; closure_ && i < contacts; ++i)
      if (contactActive(i, s)) b.closed |= ClosureSet{1} << i;
    b.startFromSplines = sampleSides_[static_cast<std::size_t>(s)] != 0;
    if (!derivativesLaidOut_) continue;  // values only: no derivative blocks
    b.dyDT.setZero(outputs);
    b.dyDq.setZero(outputs, jointCount_), b.dyDv.setZero(outputs, jointCount_), b.dyDa.setZero(outputs, jointCount_);
    b.dyDz.setZero(outputs, static_cast<Eigen::Index>(b.forceColumns.size()));
    b.closureMap.setZero(3 * closing, 3 * jointCount_);
    // Local parameters of every sample (the chain rule's column order), fixed for good.
    samples_.chainRule(s, 1.0, b.dyDq, b.dyDv, b.dyDa, b.dyDx, b.parameters);
  }
  taskBlocks_.resize(taskOfInstant_.size());
  for (std::size_t i = 0; i < taskBlocks_.size(); ++i) {
    SampleBlock& b = taskBlocks_[i];
    const int d = scenario_.tasks[static_cast<std::size_t>(taskOfInstant_[i])].dimension();
    b.y.setZero(d);
    b.closedAngles.setConstant(closing, std::numeric_limits<double>::quiet_NaN());
    // At a window's end the task reads the splines' state: there they meet the closure.
    if (closure_) b.closed = closure_->closedAround(taskSamples_.time(static_cast<int>(i), 1.0));
    if (!derivativesLaidOut_) continue;
    b.dyDT.setZero(d);
    b.dyDq.setZero(d, jointCount_), b.dyDv.setZero(d, jointCount_), b.dyDa.setZero(d, jointCount_);
    b.closureMap.setZero(3 * closing, 3 * jointCount_);
    taskSamples_.chainRule(static_cast<int>(i), 1.0, b.dyDq, b.dyDv, b.dyDa, b.dyDx, b.parameters);
  }
  // Sparsity within a sample: with forces fixed by the formulation's variables, Γ_i (and
  // P_i) depends on q_j, q̇_j, q̈_j only when one of the two joints carries the other (the
  // tree rooted at the reference body; J1's rows follow the same paths); W0 on every joint;
  // a body's pose and twist on the joints between it and the reference body. The bilevel
  // wrenches depend on the whole state: then every row depends on every joint.
  relatedJoints_.resize(static_cast<std::size_t>(jointCount_));
  for (int i = 0; i < jointCount_; ++i) {
    allJoints_.push_back(i);
    for (int j = 0; j < jointCount_; ++j)
      // Through a closure every output may depend on every joint (its map's columns).
      if (formulation_->innerProblem() || closure_ || model_.supports(i, model_.positionOfJoint(j)) || model_.supports(j, model_.positionOfJoint(i)))
        relatedJoints_[static_cast<std::size_t>(i)].push_back(j);
  }
  for (const int t : taskOfInstant_) {
    const TaskSpec& task = scenario_.tasks[static_cast<std::size_t>(t)];
    if (task.task->frame() < 0 || closure_) {
      taskJoints_.push_back(allJoints_);
      continue;
    }
    std::vector<int> path;
    for (int j = 0; j < jointCount_; ++j)
      if (model_.supports(j, model_.framePosition(task.task->frame()))) path.push_back(j);
    taskJoints_.push_back(path);
  }
  // A spline parameter is used when it reaches a sample or task instant where its joint is a
  // spline (every parameter of a joint closing nothing; a window's closing joint outside it).
  unusedParameter_.assign(static_cast<std::size_t>(parameterCount_), false);
  if (closure_) {
    std::vector<bool> used(static_cast<std::size_t>(parameterCount_), false);
    auto mark = [&](const SampledTrajectory& trajectory, const std::vector<SampleBlock>& blocks) {
      for (std::size_t s = 0; s < blocks.size(); ++s) {
        const LocalParameterWeights& local = trajectory.weights(static_cast<int>(s));
        for (int j = 0; j < jointCount_; ++j)
          if (!closure_->closesIn(j, blocks[s].closed))
            for (int l = 0; l < local.count; ++l) used[static_cast<std::size_t>(j * m + local.parameter[static_cast<std::size_t>(l)])] = true;
      }
    };
    mark(samples_, blocks_);
    mark(taskSamples_, taskBlocks_);
    for (int j = 0; j < jointCount_; ++j)
      for (int l = 0; l < m && closure_->closes(j); ++l)
        unusedParameter_[static_cast<std::size_t>(j * m + l)] = !used[static_cast<std::size_t>(j * m + l)];
  }
  terms_ = makeConstraintTerms(TermContext{scenario_, parametrization_, outputs_, closure_.get(), support_, contactRows_, formulation_->innerProblem(),
                                           relatedJoints_, allJoints_, taskJoints_, torqueJoints_, omittedTorqueRows_, omittedClosingRows_,
                                           taskOfInstant_});
  costs_ = makeCostTerms(CostContext{scenario_, outputs_, closure_.get(), parametrization_, samples_, slackStart_});
  // The cost terms' own variables (the epigraph's slacks) come last.
  variableCount_ = slackStart_;
  forEachCostVariableBlock([&](const CostTerm&, int, int, int size) { variableCount_ += size; });
  variableUnits(units_);
  buildStructure();
}

MotionProblem::~MotionProblem() = default;

bool MotionProblem::bilevel() const { return formulation_->innerProblem(); }

int MotionProblem::forceVariableCount() const { return formulation_->variableCount(); }

bool MotionProblem::contactActive(int contact, int sample) const {
  return active_[static_cast<std::size_t>(contact)][static_cast<std::size_t>(sample)];
}

std::vector<ContactSurface> MotionProblem::surfacesInContact(int sample) const {
  std::vector<ContactSurface> surfaces{scenario_.support};
  for (int i = 0; i < outputs_.contacts; ++i)
    if (contactActive(i, sample)) surfaces.push_back(scenario_.contacts[static_cast<std::size_t>(i)].surface);
  return surfaces;
}

std::vector<bool> MotionProblem::torquesBelow(const Eigen::VectorXd& x, double fraction) {
  evaluate(x, false);
  std::vector<bool> below(static_cast<std::size_t>(jointCount_ * samples_.sampleCount()), true);
  for (int s = 0; s < samples_.sampleCount(); ++s)
    for (const int j : torqueJoints_) {
      const double limit = scenario_.actuators.joints[static_cast<std::size_t>(j)].torqueLimit;
      below[static_cast<std::size_t>(s * jointCount_ + j)] =
          std::abs(blocks_[static_cast<std::size_t>(s)].y[outputs_.torque(j)]) < fraction * limit;
    }
  return below;
}

int MotionProblem::omittedTorqueRowCount() const {
  int count = 0;
  for (int s = 0; s < samples_.sampleCount() && !omittedTorqueRows_.empty(); ++s)
    for (const int j : torqueJoints_) count += omittedTorqueRows_[static_cast<std::size_t>(s * jointCount_ + j)];
  return count;
}

std::vector<bool> MotionProblem::closingLimitsBelow(const Eigen::VectorXd& x, double fraction) {
  evaluate(x, false);
  const int closing = outputs_.closing;
  std::vector<bool> below(static_cast<std::size_t>(2 * closing * samples_.sampleCount()), true);
  for (int s = 0; s < samples_.sampleCount(); ++s) {
    const SampleBlock& b = blocks_[static_cast<std::size_t>(s)];
    for (int k = 0; k < closing; ++k) {
      const int joint = closure_->closingJoints()[static_cast<std::size_t>(k)];
      if (!closure_->closesIn(joint, b.closed)) continue;  // no row: its spline's control points bound it
      const JointLimits& range = scenario_.robot.joints[static_cast<std::size_t>(joint)].limits;
      const double middle = 0.5 * (range.lower + range.upper), half = 0.5 * (range.upper - range.lower);
      const std::size_t at = static_cast<std::size_t>(s * 2 * closing + k);
      below[at] = std::abs(b.y[outputs_.closingPosition(k)] - middle) < fraction * half;  // false when unbounded (NaN)
      const double limit = scenario_.actuators.joints[static_cast<std::size_t>(joint)].velocityLimit;
      below[at + static_cast<std::size_t>(closing)] = std::abs(b.y[outputs_.closingVelocity(k)]) < fraction * limit;
    }
  }
  return below;
}

int MotionProblem::omittedClosingRowCount() const {
  int count = 0;
  for (int s = 0; s < samples_.sampleCount() && !omittedClosingRows_.empty(); ++s) {
    const ClosureSet closed = blocks_[static_cast<std::size_t>(s)].closed;
    for (int k = 0; k < 2 * outputs_.closing; ++k) {
      const int joint = closure_->closingJoints()[static_cast<std::size_t>(k % outputs_.closing)];
      const bool row = closure_->closesIn(joint, closed) &&
                       (k < outputs_.closing ? scenario_.positionLimits
                                             : scenario_.velocityLimits &&
                                                   std::isfinite(scenario_.actuators.joints[static_cast<std::size_t>(joint)].velocityLimit));
      count += row && omittedClosingRows_[static_cast<std::size_t>(s * 2 * outputs_.closing + k)];
    }
  }
  return count;
}

MotionProblem::InnerStatistics MotionProblem::innerStatistics() const {
  InnerStatistics statistics;
  int samples = 0;
  for (int s = 0; s < samples_.sampleCount(); ++s) {
    const InnerResult* inner = formulation_->innerResult(s);
    if (inner == nullptr) continue;
    const InnerResult& r = *inner;
    ++samples;
    statistics.optimal += r.status == InnerStatus::Optimal;
    statistics.infeasible += r.status == InnerStatus::Infeasible;
    statistics.failed += r.status == InnerStatus::Failed;
    statistics.polished += r.polished;
    statistics.meanIterations += r.iterations;
    statistics.solveSeconds += 1e-6 * r.solveTimeUs;
  }
  if (samples > 0) statistics.meanIterations /= static_cast<double>(samples);
  return statistics;
}

void MotionProblem::evaluate(const Eigen::VectorXd& x, bool derivatives) {
  if (x.size() != variableCount_) throw InputError("motion problem: wrong number of variables");
  if (derivatives && !derivativesLaidOut_)
    throw std::logic_error("motion problem: derivatives asked of a problem built without them (MotionProblemOptions::derivatives)");
  if (cacheValid_ && (cachedDerivatives_ || !derivatives) && x == cachedX_) return;
  if (!x.allFinite()) throw InputError("motion problem: non-finite variables");
  const double T = duration(x);
  parametrization_.controlPoints(x.head(parameterCount_), controlPoints_);
  if (closure_ && !closureStarted_) startClosureAlongTheMotion(controlPoints_, T);
  const int count = samples_.sampleCount(), taskCount = static_cast<int>(taskBlocks_.size());
  const int threads = static_cast<int>(workspaces_.size());
  {
    // After the first evaluation of its kind every buffer is sized: no Eigen allocation here
    // (debug builds check; tests/core/test_no_allocation.cpp counts every allocation).
    const NoMallocScope perSample("outer evaluation", derivatives ? sizedWithDerivatives_ : sizedValues_);
#pragma omp parallel num_threads(threads)
    {
      ThreadWorkspace& w = workspaces_[static_cast<std::size_t>(omp_get_thread_num())];
      // The samples in fixed chunks (core/sample_chunks.hpp): a bilevel sample without a result
      // of its own (the first evaluation) is warm-started from its predecessor in the chunk
      // (beforeSample), so the results are the same, to the bit, for any thread count
      // (docs/developers/determinism.md).
      forEachSampleInChunks(count, [&](int s, int predecessor) {
        formulation_->beforeSample(s, predecessor);
        evaluateSample(s, x, T, derivatives, w);
      });
#pragma omp for schedule(static)
      for (int i = 0; i < taskCount; ++i) evaluateTaskInstant(i, T, derivatives, w);
    }
  }
  (derivatives ? sizedWithDerivatives_ : sizedValues_) = true;
  cachedX_ = x;
  cachedDerivatives_ = derivatives;
  cacheValid_ = true;
}

double MotionProblem::objective(const Eigen::VectorXd& x) {
  evaluate(x, false);
  const int N = samples_.sampleCount();
  const double T = duration(x);
  double energy = 0.0;
  for (int s = 0; s < N; ++s) {
    const double weight = sampleWeights_[static_cast<std::size_t>(s)] * T;
    const CostSample sample = costSample(s, blocks_[static_cast<std::size_t>(s)]);
    double sum = 0.0;
    for (const auto& term : costs_) term->addValue(sample, x, sum);
    energy += weight * sum;
  }
  return energy;
}

void MotionProblem::objectiveGradient(const Eigen::VectorXd& x, Eigen::VectorXd& gradient) {
  CostNeeds needs = CostNeeds::Nothing;
  for (const auto& term : costs_) needs = std::max(needs, term->needs());
  if (needs == CostNeeds::Derivatives)
    evaluate(x, true);
  else if (needs == CostNeeds::Values)
    evaluate(x, false);
  const int N = samples_.sampleCount();
  const double T = duration(x);
  gradient.setZero(variableCount_);
  double dT = 0.0;
  for (int s = 0; s < N; ++s) {
    const double weight = sampleWeights_[static_cast<std::size_t>(s)] * T;
    const CostSample sample = costSample(s, blocks_[static_cast<std::size_t>(s)]);
    for (const auto& term : costs_) term->addGradient(sample, x, weight, T, gradient, dT);
  }
  if (durationIsFree()) gradient[parameterCount_] = dT;
}

double MotionProblem::rowValue(const Row& row, const Eigen::VectorXd& x, double T) const {
  switch (row.place) {
    case RowPlace::ControlPoints: return terms_[static_cast<std::size_t>(row.term)]->directValue(row.detail, x, T);
    case RowPlace::TaskInstant: return taskBlocks_[static_cast<std::size_t>(row.block)].y[row.output];
    case RowPlace::Sample: break;
  }
  const double y = row.sign * blocks_[static_cast<std::size_t>(row.block)].y[row.output];
  return row.slack >= 0 ? x[row.slack] + y : y;
}

void MotionProblem::constraints(const Eigen::VectorXd& x, Eigen::VectorXd& values) {
  evaluate(x, false);
  const double T = duration(x);
  values.resize(constraintCount());
  for (int r = 0; r < constraintCount(); ++r) values[r] = rowValue(rows_[static_cast<std::size_t>(r)], x, T);
}

void MotionProblem::jacobianValues(const Eigen::VectorXd& x, Eigen::VectorXd& values) {
  evaluate(x, true);
  const double T = duration(x);
  values.resize(jacobianNonZeros());
  using Source = JacobianEntry::Source;
  // A gather of every entry from the blocks (over a hundred thousand, most from blocks no
  // longer in cache): each value on its own, so the threads share them.
  const auto count = static_cast<std::ptrdiff_t>(entries_.size());
#pragma omp parallel for schedule(static) num_threads(static_cast<int>(workspaces_.size()))
  for (std::ptrdiff_t k = 0; k < count; ++k) {
    const JacobianEntry& e = entries_[static_cast<std::size_t>(k)];
    const auto block = static_cast<std::size_t>(e.block);
    const SampleBlock* b = e.block < 0 ? nullptr : e.task ? &taskBlocks_[block] : &blocks_[block];
    double value = 0.0;
    switch (e.source) {
      case Source::Parameter: value = b->dyDx(e.output, e.local); break;
      case Source::Duration: value = b->dyDT[e.output]; break;
      case Source::Force: value = b->dyDz(e.output, e.local); break;
      case Source::Slack: value = 1.0; break;
      case Source::Direct: {
        const Row& row = rows_[static_cast<std::size_t>(jacobianRows_[k])];
        value = terms_[static_cast<std::size_t>(row.term)]->directDerivative(row.detail, e.local, x, T);
        break;
      }
    }
    values[k] = e.sign * value;
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
  for (const ConstraintKindInfo& k : rowKinds()) v.byKind.emplace_back(std::string(k.name), 0.0);
  for (int r = 0; r < constraintCount(); ++r) {
    const double violation = std::max({0.0, gl[r] - g[r], g[r] - gu[r]});
    const std::string_view name = rowKind(r);
    double& kind = std::find_if(v.byKind.begin(), v.byKind.end(), [&](const auto& k) { return k.first == name; })->second;
    kind = std::max(kind, violation);
    if (violation > v.overall) v.overall = violation, v.worstRow = r;
  }
  return v;
}

}  // namespace mcopt
