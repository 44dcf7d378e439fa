// SPDX-License-Identifier: BSD-3-Clause
// Contacts held by construction (outer_nlp/closed_chains.hpp): the closure's map against
// central differences of the closure itself (all contacts closed, and one left open), the held
// frame on a fine grid between the samples (pose, velocity), a window's contact held inside it
// and met by the splines at its ends, the closing joints' limits as rows, and the refusals (a
// loop with too few joints, a singular one, the exact Hessian option). The motion problem's
// derivatives through the closure are in test_multi_contact_problem.cpp (the weight shift's
// right sole, the lean reach's hand).
#include <catch2/catch.hpp>

#include <random>

#include "common/perturbed_motion.hpp"
#include "common/test_support.hpp"
#include "core/inverse_dynamics.hpp"
#include "core/kinematics.hpp"
#include "outer_nlp/closed_chains.hpp"
#include "outer_nlp/motion_problem.hpp"

namespace mcopt {

namespace {

Scenario weightShift() {
  Scenario s = loadScenario(test::sourceDir() / "scenarios/hrp2_weight_shift.yaml");
  s.samples = 16;
  s.outputSamples = 20;
  return s;
}

/// The weight shift's right sole, held where half-sitting puts it, with the left sole the reference.
HeldContact rightSole(const Scenario& s) {
  for (const EnvironmentContact& c : s.contacts)
    if (c.surface.name == "r_sole") return {c.surface.name, c.surface.frame, c.surface.placement, c.worldPose};
  FAIL("no r_sole contact");
  return {};
}

/// The closing joints' (q, q̇, q̈) after closing the contacts of `set` at the state x = (q, q̇, q̈).
Eigen::VectorXd closedJointsState(const ClosedChains& chains, const DynamicsModel& model, ClosedChainData& d,
                                  const Eigen::VectorXd& x, ClosureSet set) {
  const int n = model.jointCount(), c = chains.closingCount();
  Eigen::VectorXd q = x.head(n), v = x.segment(n, n), a = x.tail(n);
  REQUIRE(chains.close(model, d, q, v, a, nullptr, set));
  Eigen::VectorXd out(3 * c);
  for (int k = 0; k < c; ++k) {
    const int j = chains.closingJoints()[static_cast<std::size_t>(k)];
    out[k] = q[j], out[c + k] = v[j], out[2 * c + k] = a[j];
  }
  return out;
}

Scenario leanReach() {
  Scenario s = loadScenario(test::sourceDir() / "scenarios/hrp2_lean_reach.yaml");
  s.samples = 16;
  s.outputSamples = 20;
  return s;
}

/// The lean reach's environment contacts (the right sole, the hand), held over the whole motion.
std::vector<HeldContact> leanReachContacts(const Scenario& s) {
  std::vector<HeldContact> held;
  for (const EnvironmentContact& c : s.contacts)
    held.push_back({c.surface.name, c.surface.frame, c.surface.placement, c.worldPose, {0.0, 1.0}});
  REQUIRE(held.size() == 2);
  return held;
}

/// A state near the start posture: q within 0.05 rad of it, velocities and accelerations of
/// about 0.5 rad/s and 2 rad/s².
void stateNearStart(std::mt19937& random, const Scenario& s, Eigen::VectorXd& q, Eigen::VectorXd& v, Eigen::VectorXd& a) {
  const auto n = static_cast<int>(s.start.size());
  q = s.start + test::randomVector(random, n, 0.05), v = test::randomVector(random, n, 0.5), a = test::randomVector(random, n, 2.0);
}

}  // namespace

TEST_CASE("closed chains: the closure's map is its derivative (central differences)", "[outer][closure]") {
  const Scenario s = weightShift();
  const DynamicsModel model(s.robot, s.referenceBody, s.referencePose, s.gravity);
  const ClosedChains chains(model, {rightSole(s)}, s.start);
  REQUIRE(chains.closingCount() == 6);
  for (const int j : chains.closingJoints()) CHECK(s.robot.joints[static_cast<std::size_t>(j)].name.rfind("RLEG", 0) == 0);
  const int n = model.jointCount(), c = chains.closingCount();
  ClosedChainData d(model, 1);
  std::mt19937 random(3);
  Eigen::VectorXd q, v, a;
  stateNearStart(random, s, q, v, a);
  Eigen::MatrixXd map(3 * c, 3 * n);
  REQUIRE(chains.close(model, d, q, v, a, &map, chains.all()));
  // The contact holds: pose, twist and acceleration of the frame.
  CHECK(chains.poseError(model, d, q, chains.all()).first < 1e-11);
  CHECK(chains.poseError(model, d, q, chains.all()).second < 1e-11);
  inverseDynamics(model, d.data, q, v, a);
  const int body = model.framePosition(rightSole(s).frame);
  CHECK(d.data.linearVelocity[static_cast<std::size_t>(body)].norm() < 1e-12);
  CHECK(d.data.angularVelocity[static_cast<std::size_t>(body)].norm() < 1e-12);
  CHECK((d.data.linearAcceleration[static_cast<std::size_t>(body)] - d.data.linearAcceleration[0]).norm() < 1e-10);
  CHECK((d.data.angularAcceleration[static_cast<std::size_t>(body)] - d.data.angularAcceleration[0]).norm() < 1e-10);

  auto closedState = [&](const Eigen::VectorXd& x) { return closedJointsState(chains, model, d, x, chains.all()); };
  Eigen::VectorXd x(3 * n);
  x << q, v, a;
  double worst = 0.0;
  for (int col = 0; col < 3 * n; ++col) {
    if (chains.closes(col % n)) {
      CHECK(map.col(col).norm() == 0.0);  // the closing joints' own columns
      continue;
    }
    const double h = 1e-6;
    Eigen::VectorXd plus = x, minus = x;
    plus[col] += h, minus[col] -= h;
    const Eigen::VectorXd fd = (closedState(plus) - closedState(minus)) / (2 * h);
    worst = std::max(worst, ((map.col(col) - fd).array().abs() / (1.0 + fd.array().abs())).maxCoeff());
  }
  INFO("worst relative error of the map " << worst);
  CHECK(worst < 1e-6);
}

TEST_CASE("closed chains: the held sole stays put between the samples, whichever motion", "[outer][closure]") {
  Scenario s = weightShift();
  s.fixStart = s.fixEnd = false;
  MotionProblem problem(s);
  REQUIRE(problem.closedChains() != nullptr);
  CHECK(problem.closedChains()->contacts().front().name == "r_sole");
  const Eigen::VectorXd x = test::perturbedMotion(problem, 0.05, 11);
  const SampledPhysics p = problem.sampledPhysics(x);
  // Fine grid: 10 instants a sample interval; the band this replaces left 1.7 mm.
  INFO("drift " << p.closureDrift[0] << " m, " << p.closureRotationDrift[0] << " rad; sliding " << p.closureSpeed[0]
                << " m/s, turning " << p.closureAngularSpeed[0] << " rad/s");
  CHECK(p.closureDrift[0] < 1e-10);
  CHECK(p.closureRotationDrift[0] < 1e-10);
  CHECK(p.closureSpeed[0] < 1e-9);
  CHECK(p.closureAngularSpeed[0] < 1e-9);
  // The closing joints move (they are the closure's, not their fixed splines).
  double motion = 0.0;
  for (const int j : problem.closedChains()->closingJoints()) motion = std::max(motion, p.q.row(j).maxCoeff() - p.q.row(j).minCoeff());
  CHECK(motion > 1e-3);
  // Their limits are rows at every sample.
  int rows = 0;
  for (int r = 0; r < problem.constraintCount(); ++r) rows += problem.rowKind(r) == "closing_joint_limit";
  CHECK(rows >= 6 * problem.sampleCount());
}

TEST_CASE("closed chains: a contact left open keeps its joints, and the map of the others is still their derivative",
          "[outer][closure]") {
  // The lean reach's sole and hand; the hand open (outside its window): its arm joints stay as
  // given and are free columns of the sole's map; closed, the hand's joints follow it too.
  const Scenario s = leanReach();
  const DynamicsModel model(s.robot, s.referenceBody, s.referencePose, s.gravity);
  std::vector<HeldContact> held = leanReachContacts(s);
  held[1].window = {0.3, 0.6};
  const ClosedChains chains(model, held, s.start);
  CHECK(chains.closedAt(0.1, 0) == 1U);
  CHECK(chains.closedAt(0.3, 0) == 3U);
  CHECK(chains.closedAround(0.3) == 1U);
  CHECK(chains.closedAround(0.45) == 3U);
  const int n = model.jointCount(), c = chains.closingCount();
  REQUIRE(c == 12);
  ClosedChainData d(model, 2);
  std::mt19937 random(7);
  Eigen::VectorXd q0, v0, a0;
  stateNearStart(random, s, q0, v0, a0);
  for (const ClosureSet set : {ClosureSet{1}, ClosureSet{3}}) {
    Eigen::VectorXd q = q0, v = v0, a = a0;
    Eigen::MatrixXd map(3 * c, 3 * n);
    // The hand's pose: where this posture puts it, so that its closure is near.
    REQUIRE(chains.close(model, d, q, v, a, &map, set));
    for (int k = 0; k < c; ++k) {
      const int j = chains.closingJoints()[static_cast<std::size_t>(k)];
      if (chains.closesIn(j, set)) continue;
      CHECK(q[j] == q0[j]);
      CHECK(v[j] == v0[j]);
      CHECK(a[j] == a0[j]);
      CHECK(map.row(k).norm() == 0.0);
      CHECK(map.row(c + k).norm() == 0.0);
      CHECK(map.row(2 * c + k).norm() == 0.0);
    }
    CHECK(chains.poseError(model, d, q, set).first < 1e-11);
    auto closedState = [&](const Eigen::VectorXd& x) { return closedJointsState(chains, model, d, x, set); };
    Eigen::VectorXd x(3 * n);
    x << q, v, a;
    double worst = 0.0;
    int freeColumns = 0;
    for (int col = 0; col < 3 * n; ++col) {
      if (chains.closesIn(col % n, set)) {
        CHECK(map.col(col).norm() == 0.0);
        continue;
      }
      freeColumns += chains.closes(col % n);  // an open contact's joint: a free column
      const double h = 1e-6;
      Eigen::VectorXd plus = x, minus = x;
      plus[col] += h, minus[col] -= h;
      const Eigen::VectorXd fd = (closedState(plus) - closedState(minus)) / (2 * h);
      for (int k = 0; k < 3 * c; ++k)
        if (chains.closesIn(chains.closingJoints()[static_cast<std::size_t>(k % c)], set))
          worst = std::max(worst, std::abs(map(k, col) - fd[k]) / (1.0 + std::abs(fd[k])));
    }
    INFO("set " << set << ": worst relative error of the map (its closed joints' rows) " << worst);
    CHECK(worst < 1e-6);
    CHECK(freeColumns == (set == 1U ? 18 : 0));
  }
}

TEST_CASE("closed chains: closing to positions or velocities gives the whole closure's values to the bit, the rest left",
          "[outer][closure]") {
  // The lean reach's sole and hand, both closed and the hand open: what a task's closure reads
  // (q, and q̇ for a velocity task) and its map's rows are the whole closure's, bit for bit; the
  // entries past the order keep their values and the map's rows past it are zero.
  const Scenario s = leanReach();
  const DynamicsModel model(s.robot, s.referenceBody, s.referencePose, s.gravity);
  const ClosedChains chains(model, leanReachContacts(s), s.start);
  const int n = model.jointCount(), c = chains.closingCount();
  ClosedChainData d(model, 2);
  std::mt19937 random(11);
  Eigen::VectorXd q0, v0, a0;
  stateNearStart(random, s, q0, v0, a0);
  for (const ClosureSet set : {ClosureSet{1}, ClosureSet{3}}) {
    Eigen::VectorXd q = q0, v = v0, a = a0;
    Eigen::MatrixXd whole(3 * c, 3 * n);
    REQUIRE(chains.close(model, d, q, v, a, &whole, set));
    CHECK(whole.topRows(c).rightCols(2 * n).norm() == 0.0);  // M_q reads q alone, M_v q and q̇
    CHECK(whole.middleRows(c, c).rightCols(n).norm() == 0.0);
    for (const ClosureOrder order : {ClosureOrder::Positions, ClosureOrder::Velocities}) {
      const int rows = order == ClosureOrder::Positions ? 1 : 2;
      INFO("set " << set << ", closing " << (rows == 1 ? "positions" : "velocities"));
      Eigen::VectorXd qo = q0, vo = v0, ao = a0;
      Eigen::MatrixXd map = Eigen::MatrixXd::Constant(3 * c, 3 * n, 7.0);
      REQUIRE(chains.close(model, d, qo, vo, ao, &map, set, order));
      CHECK(qo == q);
      CHECK(ao == a0);
      if (rows == 2) CHECK(vo == v);
      else CHECK(vo == v0);
      CHECK(map.topRows(rows * c) == whole.topRows(rows * c));
      CHECK(map.bottomRows((3 - rows) * c).norm() == 0.0);
      Eigen::VectorXd qn = q0, vn = v0, an = a0;  // and without a map
      REQUIRE(chains.close(model, d, qn, vn, an, nullptr, set, order));
      CHECK(qn == q);
      CHECK(vn == vo);
      CHECK(an == a0);
    }
  }
}

TEST_CASE("closed chains: a window's contact holds inside it, and the splines meet it at rest at its ends",
          "[outer][closure]") {
  // The lean reach's hand on the table over [1.0, 2.2] s: its arm's six joints follow the
  // closure at the samples inside, their splines outside; the window's ends are twelve rows of
  // equality (pose, twist) on the splines' state there.
  Scenario s = leanReach();
  MotionProblem problem(s);
  const ClosedChains* chains = problem.closedChains();
  REQUIRE(chains != nullptr);
  REQUIRE(chains->contactCount() == 2);
  CHECK(chains->contacts()[1].name == "r_hand");
  CHECK_FALSE(chains->wholeMotion(1));
  for (int k = 6; k < 12; ++k)
    CHECK(s.robot.joints[static_cast<std::size_t>(chains->closingJoints()[static_cast<std::size_t>(k)])].name.rfind("RARM", 0) == 0);
  int endRows = 0, closingRows = 0;
  for (int r = 0; r < problem.constraintCount(); ++r) {
    if (problem.rowKind(r) == "closing_joint_limit") ++closingRows;
    if (problem.rowKind(r) != "closure") continue;
    ++endRows;
    CHECK(problem.rowName(r).find("at its window's") != std::string::npos);
  }
  CHECK(endRows == 24);
  // Each end of the window is sampled twice, out of contact and in (neither is a regular
  // sample here: 16 over 3.2 s); the hand's joints' limits are rows at the samples in contact.
  CHECK(problem.sampleCount() == s.samples + 4);
  int inside = 0;
  for (int k = 0; k < problem.sampleCount(); ++k) inside += problem.contactActive(1, k);
  for (const int j : chains->closingJoints()) REQUIRE(std::isfinite(s.actuators.joints[static_cast<std::size_t>(j)].velocityLimit));
  CHECK(inside == 6 + 2);  // the six regular samples inside (1.07 … 2.13 s) and a twin at each end
  CHECK(closingRows == 2 * 6 * (problem.sampleCount() + inside));  // position and velocity limits
  // Any motion: at every sample inside the window the hand is at the table's pose (forward
  // kinematics of the sampled state), the sole everywhere; the closing arm joints move there.
  const Eigen::VectorXd x = test::perturbedMotion(problem, 0.03, 9);
  const SampledPhysics p = problem.sampledPhysics(x);
  CHECK(p.closureDrift[0] < 1e-10);
  const DynamicsModel model(s.robot, s.referenceBody, s.referencePose, s.gravity);
  DynamicsData data(model);
  const EnvironmentContact& table = s.contacts[1];
  double worst = 0.0, motion = 0.0;
  int checked = 0;
  for (Eigen::Index k = 0; k < p.time.size(); ++k) {
    if (!p.active[2][static_cast<std::size_t>(k)]) continue;  // the reference sole, the right sole, the hand
    CHECK(p.time[k] >= 1.0 - 1e-9);
    CHECK(p.time[k] <= 2.2 + 1e-9);
    ++checked;
    forwardKinematics(model, data, p.q.col(k));
    const RigidTransform pose = framePose(model, data, table.surface.frame) * table.surface.placement;
    worst = std::max(worst, (pose.translation - table.worldPose.translation).norm());
    for (int c = 6; c < 12; ++c) {
      const int j = chains->closingJoints()[static_cast<std::size_t>(c)];
      motion = std::max(motion, std::abs(p.q(j, k) - p.q(j, (k + 1) % p.time.size())));
    }
  }
  INFO("hand at the samples inside its window: " << worst << " m from the table's pose; its splines at the ends: "
                                                  << p.closureDrift[1] << " m");
  CHECK(checked == inside);
  CHECK(worst < 1e-11);
  CHECK(motion > 1e-4);
  // Outside it the arm is its splines': the ends' mismatch is what the drift reports.
  CHECK(p.closureDrift[1] > 1e-6);
  // Without the drift's grid (the fine grids' call): the same samples, to the bit, and no drift.
  const SampledPhysics skipped = problem.sampledPhysics(x, MotionProblem::ClosureDrift::Skipped);
  CHECK(skipped.q == p.q);
  CHECK(skipped.tau == p.tau);
  CHECK(skipped.wrenches == p.wrenches);
  CHECK(skipped.closureDrift == std::vector<double>(2, 0.0));
  CHECK(skipped.closureSpeed == std::vector<double>(2, 0.0));
}

TEST_CASE("closed chains: a loop that cannot be closed is refused, naming the contact", "[outer][closure]") {
  const Scenario s = weightShift();
  const DynamicsModel model(s.robot, s.referenceBody, s.referencePose, s.gravity);
  // A frame on the reference leg's knee: two joints from the reference body.
  HeldContact knee{"knee", s.robot.frameIndex("LLEG_LINK3"), RigidTransform{}, RigidTransform{}};
  CHECK_THROWS_WITH(ClosedChains(model, {knee}, s.start), Catch::Contains("contact 'knee'") && Catch::Contains("takes six"));
  // Straight legs (posture zero): the right leg's six joints cannot move the sole along the leg.
  CHECK_THROWS_WITH(ClosedChains(model, {rightSole(s)}, Eigen::VectorXd::Zero(model.jointCount())),
                    Catch::Contains("contact 'r_sole'") && Catch::Contains("singular"));
  // The exact Hessian option has no stencil for the closure's map.
  Scenario exact = weightShift();
  exact.contactForces = "splines";
  exact.solve.hessian = HessianOption::Exact;
  CHECK_THROWS_WITH(MotionProblem(exact), Catch::Contains("contact 'r_sole' is held by construction"));
}

}  // namespace mcopt


namespace mcopt {

TEST_CASE("closed chains: the same motion's torques and wrenches do not depend on which sole is the reference",
          "[outer][closure]") {
  // The multi-contact scenarios' motions (their closure exact), rooted at the left sole as
  // bundled; the same states rooted at the right sole, where the bundled left-rooted motion puts
  // it, with each sample's inner problem solved again there: the same torques and wrenches.
  // With the right sole held by a band instead (a window over the whole motion), it slides,
  // and the same comparison shows it.
  for (const char* name : {"hrp2_weight_shift.yaml", "hrp2_lean_reach.yaml"}) {
    {
      Scenario s = loadScenario(test::sourceDir() / "scenarios" / name);
      s.samples = 16;
      s.outputSamples = 20;
      // The random motion below was sized for 9 and 11 control points (the bundled files have 13 and 15).
      s.controlPoints = std::string(name) == "hrp2_weight_shift.yaml" ? 9 : 11;
      MotionProblem problem(s);
      REQUIRE(problem.closedChains() != nullptr);
      const Eigen::VectorXd x = test::perturbedMotion(problem, 0.03, 5);
      const SampledPhysics left = problem.sampledPhysics(x);
      REQUIRE(left.q.allFinite());
      // A random motion may tip at an instant (its inner problem infeasible): those are left out.
      REQUIRE(left.infeasibleSamples <= left.time.size() / 10);

      // The right-rooted model, its sole at the world pose the left-rooted start puts it.
      const EnvironmentContact& rightSole = s.contacts.front();
      REQUIRE(rightSole.surface.name == "r_sole");
      const RigidTransform rootPose = rightSole.worldPose * rightSole.surface.placement.inverse();
      const DynamicsModel right(s.robot, s.robot.frames[static_cast<std::size_t>(rightSole.surface.frame)].name, rootPose, s.gravity);
      DynamicsData data(right);
      const auto solver = makeInnerSolver(s.inner.solverName, s.inner.solver);
      double torqueError = 0.0, wrenchError = 0.0, torqueScale = 0.0;
      for (Eigen::Index k = 0; k < left.time.size(); ++k) {
        if (left.innerStatus[static_cast<std::size_t>(k)] != "optimal") continue;
        // The right sole first (the reference), then the left one, then the others active here.
        std::vector<ContactSurface> surfaces{rightSole.surface, s.support};
        std::vector<int> fromLeft{1, 0};  // each surface's index in left.wrenches
        for (std::size_t c = 1; c < s.contacts.size(); ++c)
          if (left.active[c + 1][static_cast<std::size_t>(k)]) surfaces.push_back(s.contacts[c].surface), fromLeft.push_back(static_cast<int>(c) + 1);
        SampleProblem sample(right, surfaces, s.inner.problem);
        inverseDynamics(right, data, left.q.col(k), left.v.col(k), left.a.col(k));
        sample.update(right, data, s.actuators, surfaces, left.v.col(k), left.a.col(k));
        InnerResult result;
        solver->solve(sample.problem, result);
        REQUIRE(result.status == InnerStatus::Optimal);
        const Eigen::VectorXd torque = data.tau - sample.wrenchToTorque * result.wrenches;
        torqueError = std::max(torqueError, (torque - left.tau.col(k)).cwiseAbs().maxCoeff());
        torqueScale = std::max(torqueScale, left.tau.col(k).cwiseAbs().maxCoeff());
        for (std::size_t c = 0; c < surfaces.size(); ++c)
          wrenchError = std::max(wrenchError, (result.wrenches.segment<6>(6 * static_cast<Eigen::Index>(c)) -
                                               left.wrenches[static_cast<std::size_t>(fromLeft[c])].col(k))
                                                  .cwiseAbs()
                                                  .maxCoeff());
      }
      INFO(name << ": torques differ by " << torqueError << " N m (largest " << torqueScale << "), wrenches by "
                << wrenchError << " N or N m");
      CHECK(torqueError < 1e-6 * torqueScale);
      CHECK(wrenchError < 1e-5);
    }
  }
}

}  // namespace mcopt
