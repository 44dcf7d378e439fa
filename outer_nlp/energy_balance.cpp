// SPDX-License-Identifier: BSD-3-Clause
#include "outer_nlp/energy_balance.hpp"

#include <algorithm>
#include <cmath>

#include "core/dynamics_data.hpp"
#include "core/inverse_dynamics.hpp"
#include "core/kinematics.hpp"
#include "outer_nlp/formulation_registry.hpp"

namespace mcopt {

double EnergyBalance::mechanicalScale() const {
  return std::max({std::abs(jointWork), std::abs(contactWork), std::abs(potentialChange), std::abs(kineticChange),
                   std::abs(ballEnergy), jointPowerFlow});
}

namespace {

/// The mechanical energy of the robot (without the ball) and of the ball where it is carried.
struct InstantEnergy {
  double potential = 0.0, kinetic = 0.0, ball = 0.0;
};

}  // namespace

int energyGridInstants(const Scenario& scenario, int atLeast) {
  const BSplineBasis basis(scenario.controlPoints);
  const int intervals = scenario.samples - 1;
  std::vector<double> marks;  // normalised instants that must fall on an even grid index
  for (const double u : basis.knots())
    if (u > 0.0 && u < 1.0) marks.push_back(u);
  if (scenario.ball)  // the release sample, as MotionProblem places it
    marks.push_back(static_cast<double>(std::lround(scenario.ball->releaseTime / scenario.duration.initial * intervals)) /
                    intervals);
  for (const EnvironmentContact& c : scenario.contacts)  // a window's ends (sampled twice)
    if (c.window)
      for (const double end : {c.start / scenario.duration.initial, c.end / scenario.duration.initial})
        if (end > 0.0 && end < 1.0) marks.push_back(end);
  for (int k = atLeast; k <= 20 * atLeast; ++k) {
    const double instants = static_cast<double>(k) * intervals;
    const bool aligned = std::all_of(marks.begin(), marks.end(), [&](double u) {
      const double index = u * instants;
      return std::abs(index - std::round(index)) <= 1e-9 * instants && std::lround(index) % 2 == 0;
    });
    if (aligned && k % 2 == 0) return k;
  }
  return atLeast;
}

EnergyBalance energyBalance(MotionProblem& problem, const Eigen::VectorXd& x, int instantsPerInterval) {
  if (instantsPerInterval == 0) instantsPerInterval = energyGridInstants(problem.scenario(), 10);
  FineGridMotion fine(problem, x, instantsPerInterval, scenarioConstraintTolerance(problem.scenario()));
  EnergyBalance b = energyBalanceOf(fine.problem(), fine.physics());
  b.instantsPerInterval = instantsPerInterval;
  b.wrenchesBetweenSamples = wrenchesBetweenSamples(problem.scenario());  // a redistributed grid's carrier is `variables`
  b.redistribution = fine.redistribution();
  return b;
}

std::string wrenchesBetweenSamples(const Scenario& scenario) {
  return scenario.contacts.empty() ? "balance" : contactForceFormulation(scenario.contactForces).betweenSamples;
}

EnergyBalance energyBalanceOf(const MotionProblem& fine, const SampledPhysics& p) {
  const Scenario& scenario = fine.scenario();
  EnergyBalance b;
  b.instants = static_cast<int>(p.time.size());
  b.wrenchesBetweenSamples = wrenchesBetweenSamples(scenario);

  const DynamicsModel& model = fine.model();  // the robot without the ball
  DynamicsData data(model);
  const int n = model.jointCount(), M = b.instants;
  const double sharpness = scenario.actuators.frictionSharpness;
  Eigen::VectorXd jointPower(M), contactPower = Eigen::VectorXd::Zero(M), joule(M), friction(M), net(M), positive(M), negative(M);
  std::vector<InstantEnergy> energy(static_cast<std::size_t>(M));
  for (int s = 0; s < M; ++s) {
    inverseDynamics(model, data, p.q.col(s), p.v.col(s), p.a.col(s));
    InstantEnergy& e = energy[static_cast<std::size_t>(s)];
    e.potential = potentialEnergy(model, data);
    e.kinetic = kineticEnergy(model, data);
    if (scenario.ball && fine.sampleCarriesBall(s)) {
      const ThrownBall& ball = *scenario.ball;
      const Vector3 position = framePose(model, data, ball.frame).apply(ball.point);
      const Vector3 velocity = pointTwist(data, model.framePosition(ball.frame), position).head<3>();
      e.ball = 0.5 * ball.mass * velocity.squaredNorm() - ball.mass * model.gravity().dot(position);
    }
    jointPower[s] = 0.0, joule[s] = 0.0, friction[s] = 0.0, net[s] = 0.0, positive[s] = 0.0, negative[s] = 0.0;
    for (int j = 0; j < n; ++j) {
      const ActuatorParameters& actuator = scenario.actuators.joints[static_cast<std::size_t>(j)];
      const double torque = p.tau(j, s), velocity = p.v(j, s), acceleration = p.a(j, s);
      const double omega = actuator.gearRatio * velocity;
      const double frictionTorqueValue = frictionTorque(actuator, omega, sharpness);
      const double motorTorque = torque / actuator.gearRatio + actuator.rotorInertia * actuator.gearRatio * acceleration + frictionTorqueValue;
      const double power = p.power(j, s);
      jointPower[s] += torque * velocity;
      joule[s] += actuator.resistance / (actuator.torqueConstant * actuator.torqueConstant) * motorTorque * motorTorque;
      friction[s] += frictionTorqueValue * omega;
      net[s] += power;
      positive[s] += std::max(power, 0.0);
      negative[s] += std::min(power, 0.0);
    }
    // The environment contacts' power on the robot: their wrench (contact frame, about its
    // origin) against the twist of that frame. The reference contact's frame does not move.
    for (std::size_t c = 1; c < p.contactNames.size(); ++c) {
      if (!p.active[c][static_cast<std::size_t>(s)]) continue;
      const ContactSurface& surface = scenario.contacts[c - 1].surface;
      const RigidTransform pose = framePose(model, data, surface.frame) * surface.placement;
      const Vector6 twist = pointTwist(data, model.framePosition(surface.frame), pose.translation);
      const Vector6 F = p.wrenches[c].col(s);
      contactPower[s] += (pose.rotation * F.head<3>()).dot(twist.head<3>()) + (pose.rotation * F.tail<3>()).dot(twist.tail<3>());
    }
  }
  // Composite Simpson between breakpoints: the instants sampled twice (a throw's release, a
  // window's end: the power jumps there, each twin ends its side) and the regular instants of
  // even index, where energyGridInstants puts the splines' knots (q̈ has a kink there). Between
  // two breakpoints lie two intervals — Simpson's rule, for unequal intervals where a window's
  // end falls between regular instants — or one, next to such an end (a trapezoid). The error
  // then falls as h⁴ where the motion is smooth.
  const int regular = scenario.samples;  // the fine grid's regular instants
  std::vector<int> breakpoints;
  for (int s = 0; s < M; ++s) {
    const bool twin = (s > 0 && p.time[s] == p.time[s - 1]) || (s + 1 < M && p.time[s + 1] == p.time[s]);
    const double index = p.time[s] / p.time[M - 1] * (regular - 1);
    const bool even = std::abs(index - std::round(index)) <= 1e-6 && std::lround(index) % 2 == 0;
    if (s == 0 || s == M - 1 || twin || even) breakpoints.push_back(s);
  }
  auto integral = [&](const Eigen::VectorXd& f) {
    double sum = 0.0;
    for (std::size_t k = 0; k + 1 < breakpoints.size(); ++k) {
      int s = breakpoints[k];
      const int end = breakpoints[k + 1];
      for (; s + 2 <= end; s += 2) {
        // Exact for quadratics on intervals h0, h1.
        const double h0 = p.time[s + 1] - p.time[s], h1 = p.time[s + 2] - p.time[s + 1];
        sum += (h0 + h1) / 6.0 *
               ((2.0 - h1 / h0) * f[s] + (h0 + h1) * (h0 + h1) / (h0 * h1) * f[s + 1] + (2.0 - h0 / h1) * f[s + 2]);
      }
      if (s < end) sum += 0.5 * (p.time[end] - p.time[s]) * (f[s] + f[end]);
    }
    return sum;
  };
  b.jointWork = integral(jointPower);
  b.jointPowerFlow = integral(jointPower.cwiseAbs());
  b.contactWork = integral(contactPower);
  b.jouleLosses = integral(joule);
  b.frictionDissipation = integral(friction);
  b.electricalEnergy = integral(net);
  b.positiveEnergy = integral(positive);
  b.braking = integral(negative);
  const InstantEnergy& first = energy.front();
  const InstantEnergy& last = energy.back();
  b.potentialChange = last.potential - first.potential;
  b.kineticChange = last.kinetic - first.kinetic;
  if (scenario.ball) {
    // The ball's energy where it leaves the hand (the last instant that carries it) less at the start.
    int release = 0;
    while (release + 1 < M && fine.sampleCarriesBall(release + 1)) ++release;
    b.ballEnergy = energy[static_cast<std::size_t>(release)].ball - first.ball;
  }
  for (int j = 0; j < n; ++j) {
    const ActuatorParameters& actuator = scenario.actuators.joints[static_cast<std::size_t>(j)];
    const double reflected = actuator.rotorInertia * actuator.gearRatio * actuator.gearRatio;
    b.rotorKineticChange += 0.5 * reflected * (p.v(j, M - 1) * p.v(j, M - 1) - p.v(j, 0) * p.v(j, 0));
  }
  return b;
}

}  // namespace mcopt
