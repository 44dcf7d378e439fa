// SPDX-License-Identifier: BSD-3-Clause
// Polishing on HRP-2's own infeasible samples (docs/theory/inner-problem.md, "Polishing"): at the
// boundary of dynamic balance the elastic phase 2's optimum moves by tens of newtons for 1e-5 N
// of least slack, so an NLP solver's least-slack point, right in its objective but not in its
// point, set another phase 2 than the active-set method's; the crossover finishes both phases
// on the QP's own KKT point. The states are the weight shift's (weight_shift_boundary_states.json).
#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>

#include "common/json_file.hpp"
#include "common/robots.hpp"
#include "core/inverse_dynamics.hpp"
#include "inner_qp/multi_contact_dynamics.hpp"

using namespace mcopt;

namespace {

/// HRP-2 on both soles, the left one the reference body at the world origin, the wrench-cone
/// model: the weight shift's sample problems (scenarios/hrp2_weight_shift.yaml).
struct TwoSoles {
  RobotModel robot = loadUrdfFile(test::hrp2().urdf);
  ActuatorSet actuators = loadActuators(test::sourceDir() / "robots/hrp2/actuators.yaml", robot);
  std::vector<ContactSurface> contacts = soles();
  DynamicsModel model{robot, "l_sole"};
  DynamicsData data{model};
  SampleProblem sample{model, contacts, wrenchCone()};

  std::vector<ContactSurface> soles() const {
    std::vector<ContactSurface> chosen;
    for (const ContactSurface& s : loadContactSurfaces(test::sourceDir() / "robots/hrp2/contacts.yaml", robot))
      if (s.name == "l_sole" || s.name == "r_sole") chosen.push_back(s);
    REQUIRE(chosen.size() == 2);
    return chosen;
  }
  static ContactProblemSettings wrenchCone() {
    ContactProblemSettings settings;
    settings.model = makeWrenchConeContactModel();
    return settings;
  }
  /// The sample's inner problem at (q, v, a).
  const ContactProblem& at(const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd& a) {
    inverseDynamics(model, data, q, v, a);
    sample.update(model, data, actuators, contacts, v, a);
    return sample.problem;
  }
};

/// One of a state's arrays (q, v or a) from weight_shift_boundary_states.json.
Eigen::VectorXd stateVector(const nlohmann::json& state, const char* key) {
  const std::vector<double> values = state.at(key).get<std::vector<double>>();
  return Eigen::Map<const Eigen::VectorXd>(values.data(), static_cast<Eigen::Index>(values.size()));
}

nlohmann::json boundaryStates() {
  return test::readJson(test::sourceDir() / "tests/inner_qp/weight_shift_boundary_states.json");
}

}  // namespace

TEST_CASE("polishing: on the weight shift's infeasible samples SLSQP and Ipopt end on the active-set method's elastic solution",
          "[inner][solvers][polish]") {
  TwoSoles hrp2;
  InnerSettings polishing;
  polishing.polish = true;
  auto activeSet = makeActiveSetSolver();
  const nlohmann::json states = boundaryStates();
  int compared = 0;
  for (const nlohmann::json& state : states.at("samples")) {
    ++compared;
    const ContactProblem& p = hrp2.at(stateVector(state, "q"), stateVector(state, "v"), stateVector(state, "a"));
    InnerResult reference;
    activeSet->solve(p, reference);
    INFO("iterate " << state.at("iteration") << ", sample " << state.at("sample") << "; active-set: slack "
                    << reference.balanceSlack.transpose() << ", objective " << reference.objective);
    REQUIRE(reference.status == InnerStatus::Infeasible);
    for (auto make : {makeSlsqpSolver, makeIpoptSolver}) {
      auto solver = make(polishing);
      InnerResult polished;
      solver->solve(p, polished);
      INFO(solver->name() << " polished: " << toString(polished.status) << " (" << polished.message << "), slack "
                          << polished.balanceSlack.transpose() << ", objective " << polished.objective);
      CHECK(polished.status == InnerStatus::Infeasible);
      // The least slack and phase 2 to rounding: measured equal slacks and wrenches at most
      // 7e-8 N apart, against 50 to 109 N without the crossover.
      CHECK((polished.balanceSlack - reference.balanceSlack).cwiseAbs().maxCoeff() <= 1e-9);
      CHECK((polished.wrenches - reference.wrenches).cwiseAbs().maxCoeff() <= 1e-6);
      CHECK(std::abs(polished.objective - reference.objective) <= 1e-9 * (1.0 + std::abs(reference.objective)));
    }
  }
  CHECK(compared == 3);
}

TEST_CASE("polishing: warm-started re-solves at a boundary sample's perturbed states keep its status and wrenches",
          "[inner][solvers][polish]") {
  // The sample-differences Hessian (outer_nlp/motion_hessian.cpp) re-solves each sample at
  // 90 states, one component moved by 1e-6 (1 + |value|), warm-started from its solution. An
  // NLP solver warm-started at an exact least-slack point may end there with a residual no
  // candidate betters; that answer is certified to its own residual (not to kktTolerance, which
  // called a 0.05 N m slack negligible, the sample solved again as feasible and `failed` at 9
  // of the 90 states, and made SLSQP's Hessian differ from the active-set method's by 61 in
  // 35070).
  TwoSoles hrp2;
  const nlohmann::json states = boundaryStates();
  const nlohmann::json& state = states.at("perturbed");
  const Eigen::VectorXd q = stateVector(state, "q"), v = stateVector(state, "v"), a = stateVector(state, "a");
  const int n = hrp2.robot.jointCount();
  InnerSettings polishing;
  polishing.polish = true;
  auto activeSet = makeActiveSetSolver();
  auto slsqp = makeSlsqpSolver(polishing);
  const ContactProblem& p = hrp2.at(q, v, a);
  InnerResult baseReference, base;
  activeSet->solve(p, baseReference);
  slsqp->solve(p, base);
  REQUIRE(baseReference.status == InnerStatus::Infeasible);
  REQUIRE(base.status == InnerStatus::Infeasible);
  int same = 0;
  for (int c = 0; c < 3 * n; ++c) {
    Eigen::VectorXd moved[3] = {q, v, a};
    double& component = moved[c / n][c % n];
    component += 1e-6 * std::max(1.0, std::abs(component));
    const ContactProblem& probe = hrp2.at(moved[0], moved[1], moved[2]);
    InnerResult reference = baseReference, polished = base;  // warm starts, as the Hessian's probes
    activeSet->solve(probe, reference);
    slsqp->solve(probe, polished);
    INFO("component " << c << ": active-set " << toString(reference.status) << "; slsqp " << toString(polished.status) << " ("
                      << polished.message << ")");
    CHECK(polished.status == reference.status);
    CHECK((polished.wrenches - reference.wrenches).cwiseAbs().maxCoeff() <= 1e-6);
    same += polished.status == reference.status;
  }
  CHECK(same == 3 * n);
}
