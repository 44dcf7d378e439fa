// SPDX-License-Identifier: BSD-3-Clause
#include "outer_nlp/fine_grid_motion.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/dynamics_data.hpp"
#include "core/inverse_dynamics.hpp"
#include "core/kinematics.hpp"
#include "core/spatial_algebra.hpp"
#include "inner_qp/contact_problem.hpp"
#include "inner_qp/dual_active_set_qp.hpp"
#include "inner_qp/multi_contact_dynamics.hpp"
#include "outer_nlp/contact_admissibility.hpp"
#include "outer_nlp/formulation_registry.hpp"

namespace mcopt {

namespace {

/// The registered single-level formulation whose variables are the wrenches at each sample:
/// the fine grid's way of carrying wrenches chosen instant by instant.
const std::string& perSampleFormulation() {
  for (const ContactForceFormulationEntry& e : contactForceFormulations())
    if (e.variablesPerSample && !e.innerProblem) return e.name;
  throw std::logic_error("no per-sample contact-force formulation is registered");
}

/// Each contact's rows (in its own frame) and what it needs of the QP.
struct ContactRows {
  ContactAdmissibilityRows rows;
  Eigen::MatrixXd linear;   ///< ∂rows/∂W_C, rowCount × 6
  Eigen::VectorXd offset;   ///< rows at W_C = 0
  Eigen::VectorXd bound;    ///< rows ≥ bound
  bool forceOnly = false;   ///< a model without moments (a point contact): m = 0
};

/// X such that the world wrench about the world origin is X W_C, for a frame at `pose`.
Matrix6 wrenchToWorld(const RigidTransform& pose) {
  Matrix6 X = Matrix6::Zero();
  X.topLeftCorner<3, 3>() = pose.rotation;
  X.bottomRightCorner<3, 3>() = pose.rotation;
  X.bottomLeftCorner<3, 3>() = skew(pose.translation) * pose.rotation;
  return X;
}

}  // namespace

Scenario fineGridScenario(const Scenario& scenario, int instantsPerInterval) {
  if (instantsPerInterval < 1) throw std::invalid_argument("fineGridScenario: instantsPerInterval must be at least 1");
  Scenario fine = scenario;
  fine.samples = instantsPerInterval * (scenario.samples - 1) + 1;
  if (fine.ball) {
    // The release where the scenario's grid has it (MotionProblem puts it on the nearest
    // sample): on the fine grid, that sample's instant, not its own nearest to the time asked.
    const int intervals = scenario.samples - 1;
    const long release = std::lround(scenario.ball->releaseTime / scenario.duration.initial * intervals);
    fine.ball->releaseTime = static_cast<double>(release) / intervals * scenario.duration.initial;
    for (TaskSpec& task : fine.tasks)
      if (task.task->reads() == TaskQuantity::Ball)
        task.start = task.end = fine.ball->releaseTime;
  }
  fine.solve.torqueScreening = 0.0;
  fine.solve.continuation.clear();
  return fine;
}

double scenarioConstraintTolerance(const Scenario& scenario) {
  for (const SolverOption& o : scenario.solve.solverOptions)
    if (o.name == "constr_viol_tol") return o.type == SolverOption::Type::Integer ? o.integer : o.number;
  return 1e-4;  // Ipopt's default
}

FineGridMotion::FineGridMotion(MotionProblem& problem, const Eigen::VectorXd& x, int instantsPerInterval, double rowTolerance)
    : scenario_(std::make_unique<Scenario>(fineGridScenario(problem.scenario(), instantsPerInterval))) {
  problem_ = std::make_unique<MotionProblem>(*scenario_, MotionProblemOptions{.hessian = scenario_->solve.hessian, .derivatives = false});
  point_ = problem_->pointWithWrenchesFrom(problem, x);
  physics_ = problem_->sampledPhysics(point_, MotionProblem::ClosureDrift::Skipped);

  const Scenario& scenario = *scenario_;
  if (scenario.contacts.empty() || contactForceFormulation(scenario.contactForces).innerProblem) return;
  redistribution_.applies = true;

  const double weight = scenario.robot.totalMass() * scenario.gravity.norm();
  const std::size_t contacts = physics_.contactNames.size();
  std::vector<ContactRows> rows;
  rows.reserve(contacts);
  for (std::size_t c = 0; c < contacts; ++c) {
    const ContactSurface& surface = c == 0 ? scenario.support : scenario.contacts[c - 1].surface;
    ContactRows r{ContactAdmissibilityRows(surface, RigidTransform{}, weight, scenario.inner.problem), {}, {}, {}, false};
    // A quadratic row (the report model's friction cone) is no QP's: its scenario keeps the
    // formulation's wrenches between the samples, as they are.
    if (r.rows.hasQuadraticRows()) {
      redistribution_.applies = false;
      return;
    }
    const int k = r.rows.rowCount();
    r.offset.resize(k);
    ContactRowsByWrench byWrench(k, 6);
    r.rows.evaluate(Vector6::Zero(), r.offset, byWrench);
    r.linear = byWrench;
    r.bound = Eigen::VectorXd::Zero(k);
    r.bound[0] = scenario.minimumNormalForce;
    r.forceOnly = contactModelOf(contactSpec(surface), scenario.inner.problem).wrenchSize() == 3;
    rows.push_back(std::move(r));
  }

  // The original samples' instants: the optimum holds the rows there, and they stay as they are.
  const double T = problem.duration(x);
  std::vector<double> sampleTimes;
  for (int s = 0; s < problem.sampleCount(); ++s) sampleTimes.push_back(problem.sampleTime(s, T));
  const double sameInstant = 1e-9 * std::max(1.0, T);

  const DynamicsModel& model = problem_->model();
  DynamicsData data(model);
  inner_detail::DualActiveSetQp qp;
  std::vector<Eigen::MatrixXd> wrenches(scenario.contacts.size());
  for (std::size_t c = 1; c < contacts; ++c) wrenches[c - 1] = physics_.wrenches[c];
  Eigen::VectorXd values;
  bool moved = false;
  for (Eigen::Index s = 0; s < physics_.time.size(); ++s) {
    const double t = physics_.time[s];
    if (std::any_of(sampleTimes.begin(), sampleTimes.end(), [&](double u) { return std::abs(u - t) <= sameInstant; })) continue;
    std::vector<std::size_t> active;
    double broken = 0.0;
    for (std::size_t c = 0; c < contacts; ++c) {
      if (!physics_.active[c][static_cast<std::size_t>(s)]) continue;
      active.push_back(c);
      values.resize(rows[c].rows.rowCount());
      rows[c].rows.evaluate(physics_.wrenches[c].col(s), values);
      broken = std::max(broken, (rows[c].bound - values).maxCoeff());
    }
    if (!(broken > rowTolerance) || active.size() < 2) {  // NaN, or nothing to share it with: as it is
      if (broken > rowTolerance) ++redistribution_.unreachable;
      continue;
    }

    // min ½ Σ ‖W_c − W̄_c‖²  s.t.  Σ X_c W_c = Σ X_c W̄_c,  rows_c(W_c) ≥ bound_c (m_c = 0 for a force alone).
    inverseDynamics(model, data, physics_.q.col(s), physics_.v.col(s), physics_.a.col(s));  // the frames' poses
    const int n = 6 * static_cast<int>(active.size());
    int equalities = 6, inequalities = 0;
    for (const std::size_t c : active) {
      equalities += rows[c].forceOnly ? 3 : 0;
      inequalities += rows[c].rows.rowCount();
    }
    qp.resize(n, equalities, inequalities);
    qp.hessian.setIdentity();
    qp.equality.setZero();
    qp.equalityTarget.setZero();
    qp.inequality.setZero();
    qp.inequalityCount = inequalities;
    int eq = 6, in = 0;
    for (std::size_t k = 0; k < active.size(); ++k) {
      const std::size_t c = active[k];
      const ContactSurface& surface = c == 0 ? scenario.support : scenario.contacts[c - 1].surface;
      const Matrix6 X = wrenchToWorld(framePose(model, data, surface.frame) * surface.placement);
      const Vector6 given = physics_.wrenches[c].col(s);
      const auto column = 6 * static_cast<Eigen::Index>(k);
      qp.gradient.segment<6>(column) = -given;
      qp.equality.block<6, 6>(0, column) = X;
      qp.equalityTarget.head<6>() += X * given;
      if (rows[c].forceOnly) {
        for (int i = 0; i < 3; ++i) qp.equality(eq + i, column + 3 + i) = 1.0;
        eq += 3;
      }
      const int count = rows[c].rows.rowCount();  // −A W ≤ offset − bound
      qp.inequality.block(in, column, count, 6) = -rows[c].linear;
      qp.inequalityBound.segment(in, count) = rows[c].offset - rows[c].bound;
      in += count;
    }
    if (qp.solve({}, 50 * (n + inequalities), 1e-12) != inner_detail::DualActiveSetQp::Status::Optimal) {
      ++redistribution_.unreachable;
      continue;
    }
    ++redistribution_.instants;
    moved = true;
    for (std::size_t k = 0; k < active.size(); ++k) {
      const std::size_t c = active[k];
      const Vector6 next = qp.x.segment<6>(6 * static_cast<Eigen::Index>(k));
      const double change = (next - physics_.wrenches[c].col(s)).cwiseAbs().maxCoeff();
      if (change > redistribution_.largestChange) {
        redistribution_.largestChange = change;
        redistribution_.time = t;
        redistribution_.contact = physics_.contactNames[c];
      }
      if (c > 0) wrenches[c - 1].col(s) = next;  // the reference's is what the dynamics leaves
    }
  }
  if (!moved) return;

  // The redistributed wrenches as a point of the per-sample formulation on the same grid: its
  // rows, torques and energy are then those of the wrenches the instants carry.
  const std::string& perSample = perSampleFormulation();
  if (scenario.contactForces != perSample) {
    auto carrier = std::make_unique<Scenario>(scenario);
    carrier->contactForces = perSample;
    auto next = std::make_unique<MotionProblem>(*carrier, MotionProblemOptions{.hessian = carrier->solve.hessian, .derivatives = false});
    problem_ = std::move(next);  // the old problem refers to scenario_, still alive until the swap below
    scenario_ = std::move(carrier);
  }
  point_ = problem_->pointWithWrenches(problem.motionParameters(x), T, wrenches);
  physics_ = problem_->sampledPhysics(point_, MotionProblem::ClosureDrift::Skipped);
}

}  // namespace mcopt
