# SPDX-License-Identifier: BSD-3-Clause
"""mcopt.Scenario: fields by path, validation with the loader's messages, a run equal to
`mcopt run` (result.json to 1e-12), progress, stop, Ctrl-C and the GIL released."""
import json
import os
import signal
import threading
import time

import numpy as np
import pytest

import mcopt
from conftest import SOURCE, assert_same, cli_error, run_cli

KICK = SOURCE / "scenarios" / "hrp2_kick.yaml"
THROW = SOURCE / "scenarios" / "hrp2_throw.yaml"  # bilevel on two soles
# Wall-clock times and the scenario's own path differ between two runs of the same problem.
UNTIMED = ("timings", "seconds", "elapsed_seconds", "scenario", "contact_surfaces")


def small_kick(samples=12):
    """The kick at fewer samples, one stage: its Gauss–Newton Hessian alone, so that an
    iteration limit bounds the whole run."""
    s = mcopt.Scenario(KICK)
    s["samples"] = samples
    s["hessian"] = "gauss-newton"
    s["continuation"] = []
    return s


def test_fields_by_path():
    s = mcopt.Scenario(KICK)
    assert s["samples"] == 100
    target = s["tasks[kick].target"]
    assert isinstance(target, list) and len(target) == 3
    s["tasks[kick].target[0]"] = target[0] + 0.01
    assert s["tasks[kick].target"][0] == pytest.approx(target[0] + 0.01)
    s["duration"] = np.float64(1.7)  # numpy scalars are numbers too
    assert s["duration"] == 1.7
    assert s.to_dict()["samples"] == 100
    assert s.joint_names == s.robot.joint_names and len(s.joint_names) == 30
    with pytest.raises(KeyError, match="no_such_field"):
        s["no_such_field"]
    with pytest.raises(KeyError, match="has no element named 'jump'"):
        s["tasks[jump].target"]


def test_the_registry_lists_the_task_kinds():
    kinds = mcopt.task_kinds()
    assert list(kinds) == ["position", "orientation", "orientation_angle", "linear_velocity", "angular_velocity",
                           "center_of_mass", "throw"]
    assert all(isinstance(d, str) and d for d in kinds.values())


def test_the_registry_lists_the_contact_force_formulations():
    formulations = mcopt.contact_force_formulations()
    assert list(formulations) == ["bilevel", "splines", "variables"]
    assert all(isinstance(d, str) and d for d in formulations.values())
    for name in formulations:
        assert mcopt.Scenario(SOURCE / "scenarios" / "hrp2_weight_shift.yaml", contact_forces=name).contact_forces == name
    with pytest.raises(mcopt.InputError, match="unknown contact-force formulation 'lagrangian'"):
        mcopt.Scenario(SOURCE / "scenarios" / "hrp2_weight_shift.yaml", contact_forces="lagrangian")


def test_a_refused_value_raises_the_loader_message_and_changes_nothing(mcopt_exe, tmp_path):
    s = mcopt.Scenario(KICK)
    with pytest.raises(mcopt.InputError) as raised:
        s["samples"] = "ten"
    assert str(raised.value) == f"{KICK}: samples = ten: the scenario refuses it: samples: expected a number"
    assert s["samples"] == 100
    # The same value in a file: the CLI's words after its file:line.
    s.save(tmp_path / "ok.yaml")
    text = (tmp_path / "ok.yaml").read_text().replace("samples: 100", "samples: ten")
    (tmp_path / "bad.yaml").write_text(text)
    message = cli_error(mcopt_exe, "run", tmp_path / "bad.yaml", "--out", tmp_path / "o")
    assert message.split(": ", 1)[1].split(": ", 0)[0].endswith("samples: expected a number")
    with pytest.raises(mcopt.InputError) as loaded:
        mcopt.Scenario(tmp_path / "bad.yaml")
    assert str(loaded.value) == message
    with pytest.raises(mcopt.InputError, match="unknown key"):
        s["colour"] = "red"
    with pytest.raises(ValueError, match="cannot be written"):
        s["samples"] = object()


def test_a_missing_file_raises_the_cli_message(mcopt_exe, tmp_path):
    with pytest.raises(mcopt.InputError, match="file not found"):
        mcopt.Scenario(tmp_path / "none.yaml")


def test_run_equals_the_cli(mcopt_exe, tmp_path):
    s = small_kick()
    s.save(tmp_path / "kick.yaml")
    code, _, _ = run_cli(mcopt_exe, "run", tmp_path / "kick.yaml", "--max-iterations", 8, "--out", tmp_path / "cli", check=False)
    assert code == 4  # not optimal after 8 iterations
    cli = json.loads((tmp_path / "cli" / "result.json").read_text())
    lines = []
    result = s.run(progress=lines.append, max_iterations=8, out=tmp_path / "py")
    assert result["status"] == "maximum_iterations" == cli["status"]
    assert_same({k: v for k, v in result.items() if k != "x"}, cli, skip=UNTIMED)
    assert result["q"].shape == (12, 30) and result["time"].shape == (12,)
    assert result["x"].shape == (result["solver"]["variables"],)
    assert [l["iteration"] for l in lines] == list(range(9))
    assert lines[-1]["objective"] == pytest.approx(result["history"][-1]["objective"], rel=1e-15)
    # The files written from Python are the CLI's files.
    written = json.loads((tmp_path / "py" / "result.json").read_text())
    assert_same(written, cli, skip=UNTIMED)
    for name in ("trajectory.csv", "power_fine.csv", "states.json"):
        assert (tmp_path / "py" / name).read_text() == (tmp_path / "cli" / name).read_text(), name


def test_the_hessian_override_equals_the_cli(mcopt_exe, tmp_path):
    # The bundled kick's two hand-over stages on the smooth maximum (gauss-newton, then
    # sample-differences) become one by the override, on both sides, before the epigraph's.
    s = mcopt.Scenario(KICK)
    s["samples"] = 12
    s.save(tmp_path / "kick.yaml")
    run_cli(mcopt_exe, "run", tmp_path / "kick.yaml", "--hessian", "exact", "--max-iterations", 3,
            "--configuration-optimisation", "off", "--out", tmp_path / "cli", check=False)
    cli = json.loads((tmp_path / "cli" / "result.json").read_text())
    result = s.run(max_iterations=3, configuration_optimisation=False, hessian="exact")
    assert result["solver"]["hessian"] == "exact" == cli["solver"]["hessian"]
    assert [stage["hessian"] for stage in result["continuation"]] == ["exact", "exact"]
    assert [stage["energy_form"] for stage in result["continuation"]] == ["smooth_max", "epigraph"]
    assert_same({k: v for k, v in result.items() if k != "x"}, cli, skip=UNTIMED)
    with pytest.raises(mcopt.InputError, match="hessian: expected limited-memory, .* or exact, got 'newton'"):
        s.run(hessian="newton")


def test_the_chosen_formulation_is_the_one_the_files_checks_see(mcopt_exe, tmp_path):
    """As `mcopt run --contact-forces`: `hessian: exact` is refused for the bilevel formulation
    with environment contacts for one reason, and for splines for another (the contacts, held by
    construction, have no stencil): each with the CLI's message for the formulation chosen."""
    s = mcopt.Scenario(THROW, contact_forces="splines")
    assert s.contact_forces == "splines" and s["contact_forces"] == "bilevel"  # a choice, not a field
    with pytest.raises(mcopt.InputError, match="contact 'r_sole' is held by construction"):
        s["hessian"] = "exact"  # checked for the formulation chosen, as it is set
    # A file that asks for it (written around the checks: the saved throw, its line edited).
    s.save(tmp_path / "throw.yaml")
    text = (tmp_path / "throw.yaml").read_text()
    # The scenario's own line (a continuation stage of the throw names sample differences too).
    assert text.count("\nhessian: sample-differences") == 1
    (tmp_path / "exact.yaml").write_text(text.replace("\nhessian: sample-differences", "\nhessian: exact"))
    message = cli_error(mcopt_exe, "run", tmp_path / "exact.yaml", "--out", tmp_path / "o")
    assert "hessian: exact: the bilevel formulation" in message
    with pytest.raises(mcopt.InputError) as refused:
        mcopt.Scenario(tmp_path / "exact.yaml")
    assert str(refused.value) == message
    splines = cli_error(mcopt_exe, "run", tmp_path / "exact.yaml", "--contact-forces", "splines", "--out", tmp_path / "o")
    assert "contact 'r_sole' is held by construction" in splines
    with pytest.raises(mcopt.InputError) as refused_splines:
        mcopt.Scenario(tmp_path / "exact.yaml", contact_forces="splines")
    assert str(refused_splines.value) == splines
    # Past the checks, it is the CLI's run with the same choice (iterate 0 alone).
    opened = mcopt.Scenario(tmp_path / "throw.yaml", contact_forces="splines")
    run_cli(mcopt_exe, "run", tmp_path / "throw.yaml", "--contact-forces", "splines", "--max-iterations", 0,
            "--out", tmp_path / "cli", check=False)
    cli = json.loads((tmp_path / "cli" / "result.json").read_text())
    result = opened.run(max_iterations=0)
    assert result["contact_forces"] == "splines" == cli["contact_forces"]
    assert_same({k: v for k, v in result.items() if k != "x"}, cli, skip=UNTIMED)
    with pytest.raises(mcopt.InputError, match="unknown contact-force formulation 'springs'"):
        mcopt.Scenario(THROW, contact_forces="springs")


def test_progress_returning_false_stops_with_the_last_iterate():
    s = small_kick()
    result = s.run(progress=lambda line: line["iteration"] < 3, configuration_optimisation=False)
    assert result["status"] == "interrupted"
    assert result["solver"]["iterations"] == 3
    assert np.all(np.isfinite(result["x"]))


def test_an_exception_in_progress_is_raised_again():
    def progress(line):
        if line["iteration"] == 2:
            raise RuntimeError("seen enough")
    with pytest.raises(RuntimeError, match="seen enough"):
        small_kick().run(progress=progress, configuration_optimisation=False)


def test_ctrl_c_interrupts_and_returns_the_last_iterate():
    """SIGINT while the run is in C++ (no callback): Python's handler raises
    KeyboardInterrupt at the next check, the run ends 'interrupted' with its iterate."""
    s = small_kick(40)
    timer = threading.Timer(1.0, lambda: os.kill(os.getpid(), signal.SIGINT))
    started = time.monotonic()
    timer.start()
    try:
        result = s.run(configuration_optimisation=False)
    finally:
        timer.cancel()
    assert result["status"] == "interrupted"
    assert time.monotonic() - started < 30
    assert 0 < result["solver"]["iterations"]
    assert result["reason"].startswith("interrupted")
    assert np.all(np.isfinite(result["x"])) and result["q"].shape == (40, 30)


def test_runs_from_two_threads_take_turns_and_equal_runs_one_after_the_other():
    """Ipopt's MUMPS is not thread-safe: runs (and Ipopt inner solves) from several threads
    are serialised by the module, so results are those of the same runs in sequence."""
    alone = [small_kick(12).run(max_iterations=6, configuration_optimisation=False)["x"] for _ in range(2)]
    results = [None, None]
    problem_data = {}

    def run(k):
        results[k] = small_kick(12).run(max_iterations=6, configuration_optimisation=False)["x"]

    def inner_solves():
        robot = small_kick().robot
        d = mcopt.Dynamics(robot, "r_sole")
        p = mcopt.InnerProblem.from_state(d, np.zeros(30), contacts=["r_sole", "l_sole"])
        problem_data["objectives"] = [mcopt.InnerSolver("ipopt").solve(p).objective for _ in range(20)]

    threads = [threading.Thread(target=run, args=(k,)) for k in range(2)] + [threading.Thread(target=inner_solves)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for k in range(2):
        np.testing.assert_array_equal(results[k], alone[k])
    assert len(set(problem_data["objectives"])) == 1


def test_the_gil_is_released_while_it_runs():
    ticks = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(time.monotonic())
            time.sleep(0.01)

    worker_result = {}
    worker = threading.Thread(target=lambda: worker_result.update(small_kick(40).run(max_iterations=15, configuration_optimisation=False)))
    counter = threading.Thread(target=count)
    counter.start()
    started = time.monotonic()
    worker.start()
    worker.join()
    elapsed = time.monotonic() - started
    stop.set()
    counter.join()
    during = [t for t in ticks if started <= t <= started + elapsed]
    assert worker_result["status"] == "maximum_iterations"
    # A Python thread kept running: about one tick per 10 ms of the run.
    assert len(during) >= 0.3 * elapsed / 0.01, (len(during), elapsed)
