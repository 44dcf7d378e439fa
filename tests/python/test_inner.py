# SPDX-License-Identifier: BSD-3-Clause
"""mcopt.InnerProblem / InnerSolver / InnerResult against `mcopt inner [--sensitivity]`: the
same problems (built from robot states along a motion), each solver and contact model, warm
starts along the list as the CLI does, results and sensitivities equal to 1e-12."""
import json

import numpy as np
import pytest

import mcopt
from conftest import HRP2, assert_same, cli_error, run_cli, write_json

SOLVERS = list(mcopt.inner_solvers())  # every registered solver
MODELS = ["report", "pyramid", "wrench-cone"]


def motion_problems(hrp2, model, count=6):
    """Samples of a sway in double support: both soles, then a hand on the table as well."""
    d = mcopt.Dynamics(hrp2, "r_sole")
    q0 = hrp2.postures(HRP2 / "postures.yaml")["half_sitting"]
    problems = []
    for k in range(count):
        t = k / (count - 1)
        q = q0 + 0.02 * np.sin(2 * np.pi * t) * np.ones(30)
        v = 0.1 * np.cos(2 * np.pi * t) * np.ones(30)
        a = -0.4 * np.sin(2 * np.pi * t) * np.ones(30)
        contacts = ["r_sole", "l_sole"] if k < count // 2 else ["r_sole", "l_sole", "r_hand"]
        problems.append(mcopt.InnerProblem.from_state(d, q, v, a, contacts=contacts, contact_model=model))
    return problems


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("solver", SOLVERS)
def test_solvers_equal_the_cli(mcopt_exe, hrp2, tmp_path, solver, model):
    problems = motion_problems(hrp2, model)
    write_json(tmp_path / "problems.json", {"problems": [p.to_dict() for p in problems]})
    if solver == "barrier" and model == "report":  # linear contact models only: refused alike, by name
        message = cli_error(mcopt_exe, "inner", "--problems", tmp_path / "problems.json", "--solver", solver,
                            "--contact-model", model, "--out", tmp_path / "out.json")
        assert "second-order friction cones" in message and "pyramid or wrench-cone" in message
        assert not (tmp_path / "out.json").exists()
        with pytest.raises(mcopt.InputError, match="second-order friction cones"):
            mcopt.InnerSolver(solver).solve(problems[0])
        return
    code, _, _ = run_cli(mcopt_exe, "inner", "--problems", tmp_path / "problems.json", "--solver", solver,
                         "--contact-model", model, "--sensitivity", "--out", tmp_path / "out.json", check=False)
    cli = json.loads((tmp_path / "out.json").read_text())
    # A failed problem is the command's failure (exit 1), its results written all the same.
    assert code == (1 if any(r["status"] == "failed" for r in cli["results"]) else 0)
    s = mcopt.InnerSolver(solver)
    assert s.name == cli["solver"]
    previous = None
    statuses = set()
    for k, p in enumerate(problems):
        # The problem as the CLI reads it from the file: the state's problem to rounding
        # (its contact poses went through quaternions).
        again = mcopt.InnerProblem(**p.to_dict(), contact_model=model)
        np.testing.assert_allclose(again.balance, p.balance, rtol=0, atol=1e-12)
        np.testing.assert_array_equal(again.hessian, p.hessian)
        result = s.solve(again, previous)
        previous = result
        expected = dict(cli["results"][k])
        python = result.to_dict()
        python.update(result.sensitivity())
        assert_same(python, expected, f"results[{k}]", skip=("solve_time_us",))
        assert result.status == expected["status"] and result.objective == expected["objective"]
        np.testing.assert_array_equal(result.wrenches.reshape(-1), np.concatenate(expected["wrenches"]))
        assert result.active_set == expected["active_set"]
        statuses.add(result.status)
    assert "optimal" in statuses


@pytest.mark.parametrize("solver", ["slsqp", "ipopt"])
def test_polish_equals_the_cli_and_reaches_the_active_set_optimum(mcopt_exe, hrp2, tmp_path, solver):
    """`polish=True` is `mcopt inner --polish`: each answer solved again on its own active set,
    the active-set method's optimum to rounding (docs/theory/inner-problem.md, "Polishing")."""
    problems = motion_problems(hrp2, "wrench-cone")
    write_json(tmp_path / "problems.json", {"problems": [p.to_dict() for p in problems]})
    run_cli(mcopt_exe, "inner", "--problems", tmp_path / "problems.json", "--solver", solver, "--contact-model",
            "wrench-cone", "--polish", "--out", tmp_path / "out.json")
    cli = json.loads((tmp_path / "out.json").read_text())["results"]
    polished, raw, reference = mcopt.InnerSolver(solver, polish=True), mcopt.InnerSolver(solver), mcopt.InnerSolver()
    previous = previous_raw = None
    for k, p in enumerate(problems):
        again = mcopt.InnerProblem(**p.to_dict(), contact_model="wrench-cone")
        result = polished.solve(again, previous)
        previous = result
        previous_raw = raw.solve(again, previous_raw)
        assert result.status == cli[k]["status"] == "optimal", k
        np.testing.assert_array_equal(result.wrenches.reshape(-1), np.concatenate(cli[k]["wrenches"]))
        best = reference.solve(again)
        assert abs(result.objective - best.objective) <= 1e-11 * (1 + abs(best.objective)), k
        assert result.kkt_residual <= 1e-11 and result.kkt_residual <= previous_raw.kkt_residual, k


@pytest.mark.parametrize("solver", ["active-set", "ipopt"])
def test_an_infeasible_sample_equals_the_cli(mcopt_exe, hrp2, tmp_path, solver):
    """The right hand alone cannot carry the robot (it would have to pull): status
    infeasible with the least-norm balance slack, as the CLI reports it."""
    d = mcopt.Dynamics(hrp2, "r_sole")
    q0 = hrp2.postures(HRP2 / "postures.yaml")["half_sitting"]
    p = mcopt.InnerProblem.from_state(d, q0, contacts=["r_hand"])
    write_json(tmp_path / "problems.json", {"problems": [p.to_dict()]})
    run_cli(mcopt_exe, "inner", "--problems", tmp_path / "problems.json", "--solver", solver, "--sensitivity",
            "--out", tmp_path / "out.json")
    cli = json.loads((tmp_path / "out.json").read_text())["results"][0]
    r = mcopt.InnerSolver(solver).solve(mcopt.InnerProblem(**p.to_dict()))
    assert r.status == "infeasible" == cli["status"]
    assert np.linalg.norm(r.balance_slack) > 1.0
    python = r.to_dict()
    python.update(r.sensitivity())
    assert python["dwrenches_dtau0"] is None
    assert_same(python, cli, skip=("solve_time_us",))


def test_solution_satisfies_its_problem(hrp2):
    for p in motion_problems(hrp2, "report"):
        r = mcopt.InnerSolver().solve(p)
        assert r.status == "optimal"
        w = r.wrenches.reshape(-1)
        assert p.constraint_violation(w) < 1e-8
        assert p.objective(w) == pytest.approx(r.objective, rel=1e-12)
        # Balance: B F = W at the solution.
        np.testing.assert_allclose(p.balance @ w, p.balance_target, atol=1e-6 * np.abs(p.balance_target).max())
        assert r.kkt_residual < 1e-6


def test_sensitivity_against_central_differences(hrp2):
    p = motion_problems(hrp2, "report")[0]
    data = p.to_dict()
    r = mcopt.InnerSolver().solve(p)
    sens = r.sensitivity("dense")
    assert sens["dwrenches_dtau0"].shape == (12, 30)
    h = 1e-4
    for j in (0, 6, 13):
        shifted = []
        for sign in (1, -1):
            tau0 = np.array(data["tau0"])
            tau0[j] += sign * h
            shifted.append(mcopt.InnerSolver().solve(mcopt.InnerProblem(**{**data, "tau0": tau0})).wrenches.reshape(-1))
        np.testing.assert_allclose((shifted[0] - shifted[1]) / (2 * h), sens["dwrenches_dtau0"][:, j], atol=1e-5)
    # Each backend gives the same sensitivity.
    for backend in ("klu", "umfpack"):
        np.testing.assert_allclose(r.sensitivity(backend)["dwrenches_dbalance"], sens["dwrenches_dbalance"], atol=1e-9)


def test_bad_problems_raise_the_cli_messages(mcopt_exe, hrp2, tmp_path):
    data = motion_problems(hrp2, "report", 2)[0].to_dict()
    bad = [{**data, "tau0": data["tau0"][:29]},
           {**data, "contacts": [{**data["contacts"][0], "mu": -1.0}, data["contacts"][1]]},
           {**data, "contacts": [{**data["contacts"][0], "colour": "red"}, data["contacts"][1]]}]
    for k, problem in enumerate(bad):
        write_json(tmp_path / "bad.json", {"problems": [problem]})
        message = cli_error(mcopt_exe, "inner", "--problems", tmp_path / "bad.json")
        with pytest.raises(mcopt.InputError) as raised:
            mcopt.InnerProblem(**problem)
        # The same words after the location (a file and problems[0] there, the constructor here).
        cli_words = message.split(": ", 2)[2]
        assert str(raised.value).split(": ", 2)[2] == cli_words, k


def test_the_registry_lists_the_solvers_in_document_order():
    solvers = mcopt.inner_solvers()
    assert list(solvers)[:3] == ["active-set", "slsqp", "ipopt"]
    assert all(isinstance(d, str) and d for d in solvers.values())
    for name in solvers:
        assert mcopt.InnerSolver(name).name == name


def test_the_registry_lists_the_contact_models():
    models = mcopt.contact_models()
    assert list(models) == ["report", "pyramid", "wrench-cone", "point"]
    assert all(isinstance(d, str) and d for d in models.values())
    assert set(MODELS) < set(models)


def test_a_point_hand_carries_a_force_alone(hrp2):
    """The point model (a force at the contact point, no moment) on every contact of a problem
    built from arrays: three variables a contact, the whole wrench maps accepted, moments zero."""
    data = motion_problems(hrp2, "report", 6)[-1].to_dict()  # both soles and the right hand
    p = mcopt.InnerProblem(**data, contact_model="point")
    assert p.variable_count == 9 and p.hessian.shape == (9, 9) and p.balance.shape == (6, 9)
    r = mcopt.InnerSolver().solve(p)
    assert r.status == "optimal"  # measured: three points hold this sample
    assert r.wrenches.shape == (3, 6)
    np.testing.assert_array_equal(r.wrenches[:, 3:], 0.0)
    assert p.constraint_violation(r.wrenches[:, :3].reshape(-1)) < 1e-6
    # Two points alone cannot hold a moment about the line through them: the first sample
    # (both soles as points) is infeasible, where the soles' own model holds it.
    two = motion_problems(hrp2, "report", 6)[0].to_dict()
    assert mcopt.InnerSolver().solve(mcopt.InnerProblem(**two, contact_model="point")).status == "infeasible"
    assert mcopt.InnerSolver().solve(mcopt.InnerProblem(**two, contact_model="wrench-cone")).status == "optimal"


def test_bad_types_and_names_raise(hrp2):
    data = motion_problems(hrp2, "report", 2)[0].to_dict()
    with pytest.raises(ValueError, match="tau0"):
        mcopt.InnerProblem(**{**data, "tau0": [object()] * 30})
    with pytest.raises(ValueError, match="not a finite|Out of range"):
        mcopt.InnerProblem(**{**data, "tau0": [float("nan")] * 30})
    with pytest.raises(mcopt.InputError, match="contact-model"):
        mcopt.InnerProblem(**data, contact_model="cone")
    with pytest.raises(mcopt.InputError, match="only the pyramid contact model has facets"):
        mcopt.InnerProblem(**data, pyramid_facets=6)
    with pytest.raises(mcopt.InputError, match="expected active-set, slsqp, ipopt, barrier, auglag-mma or auglag-lbfgs; got 'simplex'"):
        mcopt.InnerSolver("simplex")
    d = mcopt.Dynamics(hrp2, "r_sole")
    with pytest.raises(ValueError, match="unknown contact surface 'foot'"):
        mcopt.InnerProblem.from_state(d, np.zeros(30), contacts=["foot"])
    p = mcopt.InnerProblem(**data)
    with pytest.raises(ValueError, match=r"wrenches: expected an array of shape \(12,\)"):
        p.objective(np.zeros(5))
