// SPDX-License-Identifier: BSD-3-Clause
#include "outer_nlp/motion_verification.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string_view>

#include "core/dynamics_data.hpp"
#include "core/inverse_dynamics.hpp"
#include "core/kinematics.hpp"

namespace mcopt {

namespace {

/// A check being gathered: its worst value and where, and the instants it fails at.
class CheckBuilder {
 public:
  CheckBuilder(std::string kind, std::string unit, double tolerance) {
    check_.kind = std::move(kind);
    check_.unit = std::move(unit);
    check_.tolerance = tolerance;
  }
  /// One compared value: `violation` ≥ 0 where it is broken (or an error), at `time` (NaN: none).
  void add(double violation, const std::string& where, double time) {
    ++check_.rowsChecked;
    if (!(violation <= check_.worst)) {  // NaN counts as broken, the worst there is
      if (std::isnan(violation) || !std::isnan(check_.worst)) {
        check_.worst = violation;
        check_.where = where;
        check_.time = time;
      }
    }
    if (!(violation <= check_.tolerance) && !std::isnan(time)) failing_.push_back(time);
  }
  VerificationCheck finish(const std::vector<double>& sampleTimes) {
    std::sort(failing_.begin(), failing_.end());
    failing_.erase(std::unique(failing_.begin(), failing_.end()), failing_.end());
    check_.failingTimes = failing_;
    if (!std::isnan(check_.time)) {
      const double scale = 1e-9 * std::max(1.0, sampleTimes.empty() ? 1.0 : sampleTimes.back());
      check_.betweenSamples = std::none_of(sampleTimes.begin(), sampleTimes.end(),
                                           [&](double t) { return std::abs(t - check_.time) <= scale; });
    }
    return check_;
  }

 private:
  VerificationCheck check_;
  std::vector<double> failing_;
};


}  // namespace

bool MotionVerification::passed() const {
  return std::all_of(checks.begin(), checks.end(), [](const VerificationCheck& c) { return c.passed(); });
}

std::vector<std::string> MotionVerification::failures() const {
  std::vector<std::string> names;
  for (const VerificationCheck& c : checks)
    if (!c.passed()) names.push_back(c.kind);
  return names;
}

MotionVerification verifyMotion(MotionProblem& problem, const Eigen::VectorXd& x, const VerificationSettings& settings) {
  if (settings.instantsPerInterval < 1) throw std::invalid_argument("verifyMotion: instantsPerInterval must be at least 1");
  const Scenario& scenario = problem.scenario();
  MotionVerification v;
  v.instantsPerInterval = settings.instantsPerInterval;
  v.scenarioSamples = scenario.samples;
  v.duration = problem.duration(x);
  v.constraintTolerance = settings.constraintTolerance >= 0.0 ? settings.constraintTolerance : scenarioConstraintTolerance(scenario);
  const double tol = v.constraintTolerance, T = v.duration;

  const SampledPhysics sampled = problem.sampledPhysics(x);
  v.sampledEnergy = sampled.energy;
  std::vector<double> sampleTimes(sampled.time.data(), sampled.time.data() + sampled.time.size());

  FineGridMotion fineGrid(problem, x, settings.instantsPerInterval, tol);
  MotionProblem& fine = fineGrid.problem();
  const Eigen::VectorXd& xf = fineGrid.point();
  const SampledPhysics& physics = fineGrid.physics();
  v.instants = static_cast<int>(physics.time.size());

  // Every row of the problem on the fine grid, by kind (the epigraph's slacks are set at
  // max(P, 0) on that grid: their rows say nothing about the motion).
  Eigen::VectorXd g, lower, upper;
  fine.constraints(xf, g);
  fine.constraintBounds(lower, upper);
  std::vector<CheckBuilder> rowChecks;
  std::map<std::string_view, std::size_t> builderOf;
  for (int r = 0; r < fine.constraintCount(); ++r) {
    const ConstraintKindInfo& kind = fine.rowKindInfo(r);
    if (!kind.verified) continue;
    const auto [found, added] = builderOf.try_emplace(kind.name, rowChecks.size());
    if (added) rowChecks.emplace_back(std::string(kind.name), std::string(kind.unit), tol);
    const std::size_t b = found->second;
    const double violation = std::isnan(g[r]) ? g[r] : std::max({0.0, lower[r] - g[r], g[r] - upper[r]});
    rowChecks[b].add(violation, fine.rowSubject(r), fine.rowTime(r, T));
  }
  for (CheckBuilder& b : rowChecks) v.checks.push_back(b.finish(sampleTimes));

  // Every joint's angle and velocity against its limits, at every instant (closing joints too).
  const RobotModel& robot = scenario.robot;
  const int n = robot.jointCount();
  CheckBuilder position("joint_position_limit", "rad", tol), velocity("joint_velocity_limit", "rad/s", tol);
  for (Eigen::Index s = 0; s < physics.time.size(); ++s)
    for (int j = 0; j < n; ++j) {
      const auto u = static_cast<std::size_t>(j);
      const JointLimits& limit = robot.joints[u].limits;
      const double q = physics.q(j, s), qd = physics.v(j, s);
      if (scenario.positionLimits)
        position.add(std::isnan(q) ? q : std::max({0.0, limit.lower - q, q - limit.upper}), robot.joints[u].name, physics.time[s]);
      const double vmax = scenario.actuators.joints[u].velocityLimit;
      if (scenario.velocityLimits && std::isfinite(vmax))
        velocity.add(std::isnan(qd) ? qd : std::max(0.0, std::abs(qd) - vmax), robot.joints[u].name, physics.time[s]);
    }
  v.checks.push_back(position.finish(sampleTimes));
  v.checks.push_back(velocity.finish(sampleTimes));

  // Each environment contact's frame against its world pose wherever it is in contact.
  if (!scenario.contacts.empty()) {
    CheckBuilder drift("closure_drift", "m, rad", settings.closureTolerance);
    const DynamicsModel& model = fine.model();
    DynamicsData data(model);
    for (Eigen::Index s = 0; s < physics.time.size(); ++s) {
      inverseDynamics(model, data, physics.q.col(s), physics.v.col(s), physics.a.col(s));  // the poses
      for (std::size_t c = 0; c < scenario.contacts.size(); ++c) {
        if (!physics.active[c + 1][static_cast<std::size_t>(s)]) continue;
        const EnvironmentContact& contact = scenario.contacts[c];
        const RigidTransform pose = framePose(model, data, contact.surface.frame) * contact.surface.placement;
        const double distance = (pose.translation - contact.worldPose.translation).norm();
        const double angle = std::abs(Eigen::AngleAxisd(Matrix3(contact.worldPose.rotation.transpose() * pose.rotation)).angle());
        drift.add(std::isnan(distance) ? distance : std::max(distance, angle), contact.surface.name, physics.time[s]);
      }
    }
    v.checks.push_back(drift.finish(sampleTimes));
  }

  // Every contact's wrench at every instant it is active against its contact model's rows, on
  // the wrench itself (in its own frame): whatever formulation gave it — the inner problem's
  // answer included, whose own rows the outer problem does not hold.
  {
    CheckBuilder admissible("contact_wrench_admissible", "contact row units (contact model)", tol);
    const double weight = scenario.robot.totalMass() * scenario.gravity.norm();
    for (std::size_t c = 0; c < physics.contactNames.size(); ++c) {
      const ContactSurface& surface = c == 0 ? scenario.support : scenario.contacts[c - 1].surface;
      const ContactAdmissibilityRows rows(surface, RigidTransform{}, weight, scenario.inner.problem);
      Eigen::VectorXd values(rows.rowCount());
      for (Eigen::Index s = 0; s < physics.time.size(); ++s) {
        if (!physics.active[c][static_cast<std::size_t>(s)]) continue;
        rows.evaluate(physics.wrenches[c].col(s), values);
        for (int k = 0; k < rows.rowCount(); ++k) {
          const double bound = k == 0 ? scenario.minimumNormalForce : 0.0;
          const double violation = std::isnan(values[k]) ? values[k] : std::max(0.0, bound - values[k]);
          admissible.add(violation, surface.name + " " + rows.rowName(k), physics.time[s]);
        }
      }
    }
    v.checks.push_back(admissible.finish(sampleTimes));
  }

  // Bilevel: an instant whose inner problem has no answer cannot be held at all.
  if (fine.bilevel()) {
    CheckBuilder inner("inner_problem_solved", "instants without an answer", 0.0);
    int unsolved = 0;
    for (std::size_t s = 0; s < physics.innerStatus.size(); ++s) {
      const std::string& status = physics.innerStatus[s];
      const bool bad = status == toString(InnerStatus::Infeasible) || status == toString(InnerStatus::Failed);
      unsolved += bad;
      ++v.innerProblems;
      inner.add(bad ? 1.0 : 0.0, bad ? status : "", physics.time[static_cast<Eigen::Index>(s)]);
    }
    v.innerInfeasible = physics.infeasibleSamples;
    v.innerFailed = physics.failedSamples;
    VerificationCheck c = inner.finish(sampleTimes);
    c.worst = unsolved;  // the count, not the worst single one
    v.checks.push_back(c);
  }

  // The criterion: the energy the optimiser saw at the samples against the fine grid's; the
  // mechanical energy identity on the fine grid.
  v.balance = energyBalanceOf(fine, physics);
  v.balance.instantsPerInterval = settings.instantsPerInterval;
  v.balance.wrenchesBetweenSamples = wrenchesBetweenSamples(scenario);  // a redistributed grid's carrier is `variables`
  v.balance.redistribution = fineGrid.redistribution();
  v.wrenchesBetweenSamples = v.balance.wrenchesBetweenSamples;
  v.fineEnergy = v.balance.positiveEnergy;
  CheckBuilder energy("energy_sampled_vs_fine", "relative", settings.energyTolerance);
  energy.add(std::abs(v.fineEnergy - v.sampledEnergy) / std::max(std::abs(v.fineEnergy), 1e-12), "", std::nan(""));
  v.checks.push_back(energy.finish(sampleTimes));
  CheckBuilder balance("energy_balance", "relative", settings.balanceTolerance);
  balance.add(std::abs(v.balance.mechanicalResidual()) / std::max(v.balance.mechanicalScale(), 1e-12), "", std::nan(""));
  v.checks.push_back(balance.finish(sampleTimes));
  return v;
}

}  // namespace mcopt
