// SPDX-License-Identifier: BSD-3-Clause
// What a motion says, for results: the ball at its release (formulation.md §10) and the motion's
// physics at its samples, with the closure's drift between them (motion_problem.hpp,
// SampledPhysics). Members of MotionProblem, apart from the NLP it evaluates (motion_problem.cpp).
#include "outer_nlp/motion_problem.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/contact_maps.hpp"
#include "core/inverse_dynamics.hpp"
#include "core/kinematics.hpp"
#include "core/spatial.hpp"
#include "core/trajectory_evaluation.hpp"
#include "outer_nlp/ball_flight_task.hpp"
#include "outer_nlp/ballistic_flight.hpp"
#include "outer_nlp/contact_force_formulation.hpp"
#include "outer_nlp/motion_workspace.hpp"

namespace mcopt {

std::optional<ReleaseState> MotionProblem::release(const Eigen::VectorXd& x) const {
  if (!scenario_.ball) return std::nullopt;
  const ThrownBall& ball = *scenario_.ball;
  const auto landing = std::find_if(scenario_.tasks.begin(), scenario_.tasks.end(), [](const TaskSpec& t) {
    return t.task->ballFlight() && t.task->ballFlight()->part() == BallFlightTask::Part::Landing;
  });
  const double T = duration(x);
  const SampledTrajectory atRelease(parametrization_, std::vector<double>{sampleTimes_[static_cast<std::size_t>(releaseSample_)]});
  Eigen::MatrixXd controlPoints;
  parametrization_.controlPoints(x.head(parameterCount_), controlPoints);
  Eigen::VectorXd q(jointCount_), v(jointCount_), a(jointCount_);
  atRelease.evaluate(0, controlPoints, T, q, v, a);
  if (closure_) {  // Newton from the release sample's angles where it has some: the motion's branch
    const SampleBlock& b = blocks_[static_cast<std::size_t>(releaseSample_)];
    closure_->placeAngles(b.closedAngles, b.closed, q);
    ClosedChainData closing(model_, closure_->contactCount());
    closure_->close(model_, closing, q, v, a, nullptr, b.closed);
  }
  DynamicsData data(model_);
  inverseDynamics(model_, data, q, v, a);  // the bodies' poses and twists
  const RigidTransform pose = framePose(model_, data, ball.frame);
  const auto body = static_cast<std::size_t>(model_.framePosition(ball.frame));
  ReleaseState r;
  r.time = atRelease.time(0, T);
  r.position = pose.rotation * ball.point + pose.translation;
  r.velocity = data.linearVelocity[body] + data.angularVelocity[body].cross(r.position);
  const BallisticFlight f = ballisticFlight(r.position, r.velocity, ball.target.z(), ball.gravity);
  r.flightTime = f.flightTime;
  r.landing = Vector3(f.landing.x(), f.landing.y(), ball.target.z());
  r.apexAboveTarget = f.apexAboveTarget;
  r.speed = f.speed, r.elevation = f.elevation;
  r.target = ball.target;
  r.targetHalfWidths = landing->upper.head<2>();
  const Eigen::Vector2d offset = f.landing - ball.target.head<2>();
  r.missDistance = offset.norm();
  r.missOutsideBox = (offset.cwiseAbs() - landing->upper.head<2>()).cwiseMax(0.0).norm();
  return r;
}

SampledPhysics MotionProblem::sampledPhysics(const Eigen::VectorXd& x, ClosureDrift drift) {
  evaluate(x, false);
  const int N = samples_.sampleCount(), n = jointCount_, contacts = outputs_.contacts;
  const double T = duration(x);
  SampledPhysics p;
  p.time.resize(N);
  for (Eigen::MatrixXd* m : {&p.q, &p.v, &p.a, &p.tau, &p.tau0, &p.power}) m->resize(n, N);
  p.referenceWrench.resize(6, N);
  p.contactNames.push_back(scenario_.support.name);
  for (const EnvironmentContact& c : scenario_.contacts) p.contactNames.push_back(c.surface.name);
  std::vector<const ContactSurface*> surfaces{&scenario_.support};
  for (const EnvironmentContact& c : scenario_.contacts) surfaces.push_back(&c.surface);
  p.wrenches.assign(surfaces.size(), Eigen::MatrixXd::Zero(6, N));
  p.active.assign(surfaces.size(), std::vector<bool>(static_cast<std::size_t>(N), true));
  p.centerOfPressure.assign(surfaces.size(), Eigen::MatrixXd::Constant(2, N, std::numeric_limits<double>::quiet_NaN()));
  p.frictionMargin.assign(surfaces.size(), Eigen::VectorXd::Zero(N));
  ThreadWorkspace& w = workspaces_.front();
  for (int s = 0; s < N; ++s) {
    const SampleBlock& b = blocks_[static_cast<std::size_t>(s)];
    p.time[s] = samples_.time(s, T);
    samples_.evaluate(s, controlPoints_, T, w.q, w.v, w.a);
    closeState(b, w, nullptr);
    p.q.col(s) = w.q, p.v.col(s) = w.v, p.a.col(s) = w.a;
    inverseDynamics(modelOf(s), w.data, p.q.col(s), p.v.col(s), p.a.col(s));
    p.tau0.col(s) = w.data.tau;
    p.referenceWrench.col(s) = referenceWrenchAtReferenceFrame(modelOf(s), w.data);
    for (int j = 0; j < n; ++j) p.tau(j, s) = b.y[outputs_.torque(j)], p.power(j, s) = b.y[outputs_.power(j)];
    for (std::size_t c = 0; c < surfaces.size(); ++c) {
      const bool active = c == 0 || contactActive(static_cast<int>(c) - 1, s);
      p.active[c][static_cast<std::size_t>(s)] = active;
      if (!active) continue;
      const Vector6 F = b.wrenches.segment<6>(6 * static_cast<Eigen::Index>(c));
      p.wrenches[c].col(s) = F;
      if (F[2] > 0.0) p.centerOfPressure[c].col(s) = Eigen::Vector2d(-F[4] / F[2], F[3] / F[2]);
      p.frictionMargin[c][s] = surfaces[c]->friction * F[2] - F.head<2>().norm();
    }
    if (const InnerResult* inner = formulation_->innerResult(s)) {
      const InnerStatus status = inner->status;
      p.innerStatus.push_back(toString(status));
      p.infeasibleSamples += status == InnerStatus::Infeasible;
      p.failedSamples += status == InnerStatus::Failed;
    }
  }
  p.energy = positiveEnergy(p.power, p.time);
  p.release = release(x);
  // The fine resampling knows one model: without a ball only (a thrown ball's samples carry it).
  if (contacts == 0 && !scenario_.ball) {
    TrajectoryEvaluator evaluator(model_, scenario_.actuators, SampledTrajectory(parametrization_, scenario_.outputSamples));
    TrajectoryResult fineResult;
    evaluator.evaluate(x.head(parameterCount_), T, fineResult);
    p.fineTime = fineResult.time, p.finePower = fineResult.power, p.fineEnergy = fineResult.energy;
  }
  // Closure drift between the samples: the contact frames on a fine grid, the scenario's output
  // samples or 10 instants per sample interval, whichever is finer, and each window's ends, read
  // from the splines there (where they meet the closure): how far each frame strays from its
  // world pose and how fast it slides. Nothing to do without environment contacts.
  for (std::vector<double>* figure : {&p.closureDrift, &p.closureRotationDrift, &p.closureSpeed, &p.closureAngularSpeed})
    figure->assign(static_cast<std::size_t>(contacts), 0.0);
  if (contacts == 0 || drift == ClosureDrift::Skipped) return p;
  const int fineCount = std::max(scenario_.outputSamples, 10 * (scenario_.samples - 1) + 1);
  std::vector<std::pair<double, bool>> instants;  // u, at a window's end
  for (int s = 0; s < fineCount; ++s) instants.emplace_back(static_cast<double>(s) / (fineCount - 1), false);
  for (const std::array<double, 2>& window : windows_)
    for (const double end : window)
      if (end > 0.0 && end < 1.0) instants.emplace_back(end, true);
  std::sort(instants.begin(), instants.end());
  std::vector<double> fineTimes;
  for (const auto& instant : instants) fineTimes.push_back(instant.first);
  const SampledTrajectory fine(parametrization_, fineTimes);
  Eigen::VectorXd previousAngles = closure_ ? Eigen::VectorXd(blocks_.front().closedAngles) : Eigen::VectorXd();
  for (int s = 0; s < fine.sampleCount(); ++s) {
    const double u = instants[static_cast<std::size_t>(s)].first;
    fine.evaluate(s, controlPoints_, T, w.q, w.v, w.a);
    if (closure_) {  // Newton from the previous closed instant's angles (the first: the first sample's)
      const bool end = instants[static_cast<std::size_t>(s)].second;
      const ClosureSet closed = end ? closure_->closedAround(u) : closure_->closedAt(u, 0);
      closure_->placeAngles(previousAngles, closed, w.q);
      closure_->close(model_, w.closure, w.q, w.v, w.a, nullptr, closed);
      closure_->readAngles(w.q, closed, previousAngles);
    }
    inverseDynamics(model_, w.data, w.q, w.v, w.a);  // the poses and the twists
    for (int i = 0; i < contacts; ++i) {
      if (!insideWindow(u, windows_[static_cast<std::size_t>(i)])) continue;
      const auto k = static_cast<std::size_t>(i);
      const EnvironmentContact& c = scenario_.contacts[k];
      const RigidTransform pose = framePose(model_, w.data, c.surface.frame) * c.surface.placement;
      const double distance = (pose.translation - c.worldPose.translation).norm();
      const Eigen::AngleAxisd error(Matrix3(c.worldPose.rotation.transpose() * pose.rotation));
      const Vector6 twist = pointTwist(w.data, model_.framePosition(c.surface.frame), pose.translation);
      p.closureDrift[k] = std::max(p.closureDrift[k], distance);
      p.closureRotationDrift[k] = std::max(p.closureRotationDrift[k], std::abs(error.angle()));
      p.closureSpeed[k] = std::max(p.closureSpeed[k], twist.head<3>().norm());
      p.closureAngularSpeed[k] = std::max(p.closureAngularSpeed[k], twist.tail<3>().norm());
    }
  }
  return p;
}

}  // namespace mcopt
