# SPDX-License-Identifier: BSD-3-Clause
"""mcopt.Dynamics against `mcopt dynamics [--derivatives]` (to 1e-12), batches against single
states, and refusals of wrong shapes and types."""
import json

import numpy as np
import pytest

import mcopt
from conftest import HRP2, assert_same, run_cli, write_json

RNG = np.random.default_rng(7)


def states(n, count):
    return [{"q": RNG.uniform(-0.5, 0.5, n), "v": RNG.uniform(-1, 1, n), "a": RNG.uniform(-2, 2, n)} for _ in range(count)]


@pytest.mark.parametrize("derivatives", [False, True])
def test_equals_the_cli(mcopt_exe, hrp2, tmp_path, derivatives):
    position, quaternion = [0.1, -0.05, 0.0], [0.0, 0.0, 0.2588190451, 0.9659258263]
    given = states(30, 4)
    write_json(tmp_path / "states.json", {"gravity": [0.0, 0.0, -9.81],
                                          "reference_pose": {"position": position, "quaternion_xyzw": quaternion},
                                          "states": given})
    args = ["dynamics", "--robot", HRP2 / "hrp2.urdf", "--reference-body", "r_sole", "--states", tmp_path / "states.json",
            "--out", tmp_path / "out.json"] + (["--derivatives"] if derivatives else [])
    run_cli(mcopt_exe, *args)
    cli = json.loads((tmp_path / "out.json").read_text())["results"]
    d = mcopt.Dynamics(hrp2, "r_sole", reference_position=position, reference_quaternion_xyzw=quaternion)
    call = d.derivatives if derivatives else d.inverse_dynamics
    for k, s in enumerate(given):
        assert_same(call(s["q"], s["v"], s["a"]), cli[k], f"states[{k}]")
    # A batch gives each state's result, stacked.
    batch = call(np.array([s["q"] for s in given]), np.array([s["v"] for s in given]), np.array([s["a"] for s in given]))
    for key, value in batch.items():
        assert value.shape[0] == len(given)
        for k in range(len(given)):
            np.testing.assert_allclose(value[k], np.array(cli[k][key]), rtol=1e-12, atol=1e-12, err_msg=key)


def test_gravity_is_carried_by_the_reference_wrench(hrp2):
    # Physics: at rest the reference body carries the whole weight (formulation.md §4).
    d = mcopt.Dynamics(hrp2, "r_sole")
    wrench = d.inverse_dynamics(np.zeros(30))["reference_wrench"]
    assert wrench[2] == pytest.approx(hrp2.total_mass * 9.81, rel=1e-12)
    assert d.reference_body == "r_sole"
    com = d.center_of_mass(np.zeros(30))
    position, rotation = d.frame_pose("r_sole", np.zeros(30))
    np.testing.assert_allclose(position, 0.0, atol=1e-12)
    np.testing.assert_allclose(rotation, np.eye(3), atol=1e-12)
    # The moment about the reference frame's origin is that of the weight at the centre of mass.
    np.testing.assert_allclose(wrench[3:5], [com[1] * wrench[2], -com[0] * wrench[2]], atol=1e-9)


@pytest.mark.parametrize("bad, message", [
    (np.zeros(29), r"q: expected an array of shape \(30,\) or \(N, 30\), got \(29,\)"),
    (np.zeros((2, 3, 30)), r"q: expected an array of shape"),
    (["x"] * 30, r"q: expected numbers"),
    ([[0.0] * 30, [0.0] * 29], r"q: expected numbers"),
    (np.full(30, np.nan), r"q: not a finite number"),
    ({"q": 1}, r"q: expected numbers"),
])
def test_bad_states_raise_value_errors(hrp2, bad, message):
    d = mcopt.Dynamics(hrp2)
    with pytest.raises(ValueError, match=message):
        d.inverse_dynamics(bad)


def test_velocity_must_have_the_shape_of_q(hrp2):
    d = mcopt.Dynamics(hrp2)
    with pytest.raises(ValueError, match="v: expected the shape of q"):
        d.inverse_dynamics(np.zeros((3, 30)), np.zeros((2, 30)))
    with pytest.raises(ValueError, match="v: expected the shape of q"):
        d.derivatives(np.zeros(30), np.zeros((1, 30)))


def test_unknown_reference_body_raises_the_cli_message(mcopt_exe, hrp2, tmp_path):
    write_json(tmp_path / "s.json", {"states": [{}]})
    from conftest import cli_error
    message = cli_error(mcopt_exe, "dynamics", "--robot", HRP2 / "hrp2.urdf", "--reference-body", "nowhere",
                        "--states", tmp_path / "s.json")
    with pytest.raises(mcopt.InputError) as raised:
        mcopt.Dynamics(hrp2, "nowhere")
    assert str(raised.value) == message
