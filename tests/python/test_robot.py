# SPDX-License-Identifier: BSD-3-Clause
"""mcopt.Robot against `mcopt robot info --json`, and its refusals against the CLI's."""
import numpy as np
import pytest

import mcopt
from conftest import HRP2, assert_same, cli_error, run_cli
import json


def test_info_is_what_the_cli_prints(mcopt_exe, hrp2):
    _, out, _ = run_cli(mcopt_exe, "robot", "info", "--robot", HRP2 / "hrp2.urdf", "--actuators", HRP2 / "actuators.yaml", "--json")
    cli = json.loads(out)
    assert_same(hrp2.info(), cli)
    assert hrp2.joint_names == [j["name"] for j in cli["joints"]]
    assert hrp2.joint_count == 30 and abs(hrp2.total_mass - cli["total_mass"]) < 1e-12
    limits = hrp2.joint_limits()
    assert limits["effort"].shape == (30,)
    np.testing.assert_array_equal(limits["effort"], [j["effort"] for j in cli["joints"]])
    np.testing.assert_array_equal(limits["lower"], [j["lower"] for j in cli["joints"]])
    assert set(hrp2.contact_surfaces) >= {"r_sole", "l_sole"}
    assert "r_sole" in hrp2.frame_names


def test_postures_in_joint_order(hrp2):
    postures = hrp2.postures(HRP2 / "postures.yaml")
    assert postures and all(q.shape == (30,) for q in postures.values())


def test_bad_urdf_raises_the_cli_message(mcopt_exe, tmp_path):
    bad = tmp_path / "bad.urdf"
    bad.write_text('<robot name="r"><link name="a"/><joint name="j" type="revolute"><parent link="a"/>'
                   '<child link="missing"/><axis xyz="0 0 1"/></joint></robot>')
    message = cli_error(mcopt_exe, "robot", "info", "--robot", bad)
    with pytest.raises(mcopt.InputError) as raised:
        mcopt.Robot(bad)
    assert str(raised.value) == message
    assert isinstance(raised.value, ValueError)


def test_missing_side_file_raises(tmp_path):
    with pytest.raises(mcopt.InputError, match="file not found|cannot open"):
        mcopt.Robot(HRP2 / "hrp2.urdf", actuators=tmp_path / "none.yaml")
