// SPDX-License-Identifier: BSD-3-Clause
// The contact model is one type that every layer asks (inner_qp/contact_model.hpp): the
// problem records which rows and cone belong to which contact, and the sensitivity reads that
// record instead of assuming a layout. Checked with the registered models and with a model
// written here, outside the registry, whose rows come in another order and number.
#include <catch2/catch.hpp>

#include <algorithm>
#include <map>
#include <numbers>

#include "common/random_inner_problem.hpp"
#include "core/contact_maps.hpp"
#include "core/errors.hpp"
#include "inner_qp/contact_model.hpp"
#include "sensitivity/inner_sensitivity.hpp"

using namespace mcopt;

namespace {

/// A model none of the registered ones is: the friction pyramid |fx|, |fy| ≤ μ̃ fz right after
/// the normal force, then the centre of pressure, then a yaw band |m_z| ≤ 0.02 m · fz —
/// 11 rows, its yaw rows not where the wrench cone has them.
class ShuffledContactModel final : public ContactModel {
 public:
  std::string name() const override { return "shuffled"; }
  int rowCount() const override { return 11; }

 protected:
  void writeRows(const ContactSpec& c, ContactRowWriter& out) const override {
    using W = ContactRowWriter;
    using K = ContactRowKind;
    const double mu = c.friction / std::numbers::sqrt2;
    out.add("fz_min", K::NormalForce, {{W::Fz, -1.0}}, -c.minNormalForce);
    out.add("fx_max", K::Friction, {{W::Fx, 1.0}, {W::Fz, -mu}});
    out.add("fy_max", K::Friction, {{W::Fy, 1.0}, {W::Fz, -mu}});
    out.add("fx_min", K::Friction, {{W::Fx, -1.0}, {W::Fz, -mu}});
    out.add("fy_min", K::Friction, {{W::Fy, -1.0}, {W::Fz, -mu}});
    out.add("yaw_max", K::Yaw, {{W::Mz, 1.0}, {W::Fz, -0.02}});
    out.add("cop_x_max", K::CenterOfPressure, {{W::My, -1.0}, {W::Fz, -c.xMax}});
    out.add("cop_x_min", K::CenterOfPressure, {{W::My, 1.0}, {W::Fz, c.xMin}});
    out.add("yaw_min", K::Yaw, {{W::Mz, -1.0}, {W::Fz, -0.02}});
    out.add("cop_y_max", K::CenterOfPressure, {{W::Mx, 1.0}, {W::Fz, -c.yMax}});
    out.add("cop_y_min", K::CenterOfPressure, {{W::Mx, -1.0}, {W::Fz, c.yMin}});
  }
};

/// Two feet and a hand: every registered model with six wrench components on all three, the
/// shuffled one, and a point hand beside feet with moments (the use a point contact has).
struct Case {
  std::string label;
  std::shared_ptr<const ContactModel> feet, hand;  ///< hand: the third contact's own model, or null
  const ContactModel& modelOf(int contact) const { return contact == 2 && hand ? *hand : *feet; }
};

std::vector<Case> everyCase() {
  std::vector<Case> cases;
  for (const std::string& name : contactModelNames()) {
    auto model = makeContactModel(name);
    if (model->wrenchSize() == 6) cases.push_back({name, model, nullptr});
  }
  const auto shuffled = std::make_shared<ShuffledContactModel>();
  cases.push_back({"shuffled", shuffled, nullptr});
  cases.push_back({"wrench-cone feet, point hand", makeContactModel("wrench-cone"), makeContactModel("point")});
  cases.push_back({"shuffled feet, point hand", shuffled, makeContactModel("point")});
  return cases;
}

ContactProblem assemble(const test::RandomProblem& r, const Case& c) {
  ContactProblemSettings settings;
  settings.model = c.feet;
  if (c.hand && r.contacts.size() == 3) settings.byContact[r.contacts.back().name] = c.hand;
  return assembleContactProblem(r.contacts, r.wrenchToTorque, r.tau0, r.balance, r.weights, r.linear, settings);
}

/// Wrenches of the problem re-solved from a cold start with τ0 (or W) moved.
Eigen::VectorXd solveMoved(InnerSolver& solver, test::RandomProblem r, const Case& c, int which, double step) {
  if (which < r.tau0.size())
    r.tau0[which] += step;
  else
    r.balance[which - r.tau0.size()] += step;
  InnerResult result;
  solver.solve(assemble(r, c), result);
  REQUIRE(result.status == InnerStatus::Optimal);
  return result.wrenches;
}

}  // namespace

TEST_CASE("contact models by registration: names, rows, the normal force first, bad names and facets refused",
          "[inner][contact]") {
  CHECK(contactModelNames() == std::vector<std::string>{"report", "pyramid", "wrench-cone", "point"});
  CHECK(contactModelList() == "report, pyramid, wrench-cone or point");
  ContactSpec c;
  c.name = "sole", c.xMin = -0.1, c.xMax = 0.13, c.yMin = -0.06, c.yMax = 0.07, c.minNormalForce = 5.0;
  const std::map<std::string, int> expected = {{"report", 5}, {"pyramid", 5 + 8}, {"wrench-cone", 17}, {"point", 1}};
  for (const ContactModelEntry& e : contactModels()) {
    INFO(e.name);
    const auto model = e.make({});
    CHECK(model->name() == e.name);
    CHECK_FALSE(e.description.empty());
    const ContactModelRows rows = model->rows(c);
    CHECK(rows.rows.rows() == model->rowCount());
    CHECK(model->rowCount() == expected.at(e.name));
    CHECK(rows.kinds.front() == ContactRowKind::NormalForce);
    CHECK(rows.bound[0] == -5.0);  // fz ≥ f_min
    CHECK(model->hasSecondOrderCone() == (e.name == "report" || e.name == "point"));
    CHECK(model->wrenchSize() == (e.name == "point" ? 3 : 6));
    if (model->wrenchSize() < 6) CHECK(rows.rows.rightCols(6 - model->wrenchSize()).cwiseAbs().maxCoeff() == 0.0);
  }
  CHECK(makeContactModel("pyramid", {.pyramidFacets = 5})->rowCount() == 10);
  CHECK_THROWS_WITH(makeContactModel("cone"), Catch::Matchers::Contains("expected report, pyramid, wrench-cone or point") &&
                                                  Catch::Matchers::Contains("'cone'"));
  CHECK_THROWS_AS(makeContactModel("pyramid", {.pyramidFacets = 2}), InputError);
  ContactProblemSettings none;
  none.model = nullptr;
  std::mt19937 rng(5);
  const test::RandomProblem r = test::randomProblem(rng, 2);
  CHECK_THROWS_WITH(assembleContactProblem(r.contacts, r.wrenchToTorque, r.tau0, r.balance, r.weights, r.linear, none),
                    Catch::Matchers::Contains("no contact model"));
}

TEST_CASE("the assembled problem records which rows and which cone belong to which contact", "[inner][contact]") {
  std::mt19937 rng(41);
  const test::RandomProblem r = test::randomProblem(rng, 3);
  for (const Case& c : everyCase()) {
    INFO(c.label);
    const ContactProblem p = assemble(r, c);
    REQUIRE(p.contactRowStart.size() == 4);
    REQUIRE(p.contactCone.size() == 3);
    REQUIRE(p.contactColumn.size() == 4);
    CHECK(p.contactRowStart.front() == 0);
    CHECK(p.contactRowStart.back() == p.inequality.rows());
    CHECK(p.contactColumn.front() == 0);
    CHECK(p.contactColumn.back() == p.variableCount());
    CHECK(p.rowKinds.size() == static_cast<std::size_t>(p.inequality.rows()));
    CHECK(p.rowNames.size() == p.rowKinds.size());
    int cones = 0;
    for (int i = 0; i < 3; ++i) {
      const ContactModel& model = c.modelOf(i);
      const int begin = p.contactRowStart[static_cast<std::size_t>(i)], end = p.contactRowStart[static_cast<std::size_t>(i) + 1];
      const int column = p.contactColumn[static_cast<std::size_t>(i)];
      CHECK(end - begin == model.rowCount());
      CHECK(p.wrenchSize(i) == model.wrenchSize());
      CHECK(p.normalForceRow(i) == begin);
      CHECK(p.rowKinds[static_cast<std::size_t>(begin)] == ContactRowKind::NormalForce);
      CHECK(p.rowNames[static_cast<std::size_t>(begin)] == "contact" + std::to_string(i) + ".fz_min");
      // Its rows touch its own columns only, and its balance columns are its wrench map's first ones.
      Eigen::MatrixXd others = p.inequality.middleRows(begin, end - begin);
      others.middleCols(column, p.wrenchSize(i)).setZero();
      CHECK(others.cwiseAbs().maxCoeff() == 0.0);
      Eigen::Matrix<double, 6, 6> toWorld;
      wrenchToWorld(r.contacts[static_cast<std::size_t>(i)].pose, toWorld);
      CHECK((p.balance.middleCols(column, p.wrenchSize(i)) - toWorld.leftCols(p.wrenchSize(i))).cwiseAbs().maxCoeff() == 0.0);
      const int cone = p.contactCone[static_cast<std::size_t>(i)];
      if (model.hasSecondOrderCone()) {
        REQUIRE(cone >= 0);
        ++cones;
        CHECK(p.cones[static_cast<std::size_t>(cone)].contact == i);
        CHECK(p.cones[static_cast<std::size_t>(cone)].index == column);
      } else {
        CHECK(cone == -1);
      }
    }
    CHECK(p.cones.size() == static_cast<std::size_t>(cones));
    // The objective's columns are the wrench maps' own: F = (f, m) of each contact, m = 0 for
    // a force alone.
    Eigen::VectorXd variables = Eigen::VectorXd::LinSpaced(p.variableCount(), 1.0, 2.0);
    Eigen::VectorXd wrenches = Eigen::VectorXd::Zero(18);
    for (int i = 0; i < 3; ++i) wrenches.segment<6>(6 * i) = p.contactWrench(variables, i);
    const Eigen::VectorXd gamma = r.tau0 - r.wrenchToTorque * wrenches;
    CHECK(p.objective(variables) ==
          Approx((r.weights.array() * gamma.array().square() + r.linear.array() * gamma.array()).sum()).epsilon(1e-12));
  }
}

TEST_CASE("the sensitivity takes each model's own layout: dF/dτ0 and dF/dW against differences, loaded and unloaded",
          "[sensitivity][contact]") {
  // Two feet and a hand on a wall (which the optimum may leave unloaded: then its pins,
  // m_z among them where the model bounds the yaw, replace its rows). A layout guessed from
  // the bundled models would take the shuffled model's friction rows for centre-of-pressure
  // rows and miss its yaw rows.
  InnerSettings cold;
  cold.warmStart = false;
  auto activeSet = makeActiveSetSolver(cold);
  for (const Case& c : everyCase()) {
    std::mt19937 rng(419);
    int checked = 0, unloaded = 0, withYaw = 0, trials = 0, degenerate = 0, degenerateUnloaded = 0;
    for (; trials < 80 && (checked < 12 || unloaded < 3); ++trials) {
      const test::RandomProblem feet = test::randomProblem(rng, 2, 30);
      const test::RandomProblem three = test::randomProblem(rng, 3, 30);
      test::RandomProblem r = feet;  // the feet alone balance: the hand may go unloaded
      r.contacts.push_back(three.contacts[2]);
      r.wrenchToTorque.conservativeResize(Eigen::NoChange, 18);
      r.wrenchToTorque.rightCols(6) = three.wrenchToTorque.rightCols(6);
      const ContactProblem p = assemble(r, c);
      InnerResult solution;
      activeSet->solve(p, solution);
      REQUIRE(solution.status == InnerStatus::Optimal);
      InnerSensitivity sensitivity;
      const SensitivityDiagnostics& d = sensitivity.factorize(p, solution);
      if (d.degenerate()) {
        ++degenerate;
        degenerateUnloaded += d.unloadedContacts > 0;
        continue;
      }
      if (checked >= 12 && d.unloadedContacts == 0) continue;  // enough loaded ones: look for unloaded hands
      ++checked;
      unloaded += d.unloadedContacts > 0;
      for (int k = 0; k < p.inequality.rows(); ++k)
        withYaw += p.rowKinds[static_cast<std::size_t>(k)] == ContactRowKind::Yaw &&
                   std::find(solution.activeSet.begin(), solution.activeSet.end(), k) != solution.activeSet.end();
      Eigen::MatrixXd dTau0, dBalance;
      sensitivity.dataSensitivities(p, dTau0, dBalance);
      const double forceScale = 1.0 + solution.wrenches.cwiseAbs().maxCoeff();
      for (int which = 0; which < r.tau0.size() + 6; which += 3) {
        // W steps of 3 mN: with a point hand on its cone, 30 mN showed the O(h²) term (3e-6).
        const double step = 3e-3;
        const Eigen::VectorXd difference = (solveMoved(*activeSet, r, c, which, step) -
                                            solveMoved(*activeSet, r, c, which, -step)) /
                                           (2.0 * step);
        const Eigen::VectorXd analytic = which < r.tau0.size() ? Eigen::VectorXd(dTau0.col(which))
                                                                 : Eigen::VectorXd(dBalance.col(which - r.tau0.size()));
        INFO(c.label << ", trial " << trials << ", parameter " << which << ": " << d.describe());
        const double columnScale = std::max(1.0, difference.cwiseAbs().maxCoeff()) * std::max(1.0, forceScale / 300.0);
        CHECK((analytic - difference).cwiseAbs().maxCoeff() <= 1e-6 * columnScale);
      }
    }
    WARN(c.label << ": " << checked << " checked in " << trials << " trials, " << unloaded
                       << " with an unloaded hand, " << withYaw << " active yaw rows; " << degenerate
                       << " degenerate (" << degenerateUnloaded << " unloaded) skipped");
    CHECK(checked >= 12);
    // Measured with this seed: 3 unloaded hands within 15–25 trials for the report, wrench-cone
    // and shuffled models; the pyramid's optimum leaves the hand loaded in all 80.
    if (c.label != "pyramid") CHECK(unloaded >= 3);
  }
}
