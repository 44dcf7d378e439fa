# SPDX-License-Identifier: BSD-3-Clause
"""Shared helpers of the Python module's tests (docs/reference/python.md).

CTest runs these with the build tree's module on PYTHONPATH and MCOPT_EXECUTABLE naming the
command line, so that every binding can be compared with what the CLI writes for the same
input."""
import json
import math
import os
import pathlib
import subprocess

import numpy as np
import pytest

SOURCE = pathlib.Path(os.environ.get("MCOPT_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
HRP2 = SOURCE / "robots" / "hrp2"


@pytest.fixture(scope="session")
def mcopt_exe():
    exe = os.environ.get("MCOPT_EXECUTABLE")
    if not exe or not pathlib.Path(exe).exists():
        pytest.fail("MCOPT_EXECUTABLE must name the mcopt command line (CTest sets it)")
    return exe


@pytest.fixture(scope="session")
def hrp2():
    import mcopt
    return mcopt.Robot(HRP2 / "hrp2.urdf", actuators=HRP2 / "actuators.yaml", contact_surfaces=HRP2 / "contacts.yaml")


def run_cli(exe, *args, check=True):
    """Runs the CLI; returns (exit code, stdout, stderr)."""
    done = subprocess.run([exe, *map(str, args)], capture_output=True, text=True)
    if check and done.returncode != 0:
        raise AssertionError(f"mcopt {' '.join(map(str, args))} exited {done.returncode}:\n{done.stderr}")
    return done.returncode, done.stdout, done.stderr


def cli_error(exe, *args):
    """The message of a refused CLI call: its last stderr line without the 'mcopt: error: ' head."""
    code, _, err = run_cli(exe, *args, check=False)
    assert code != 0, f"mcopt {args} was expected to fail"
    line = [l for l in err.splitlines() if l.strip()][-1]
    for head in ("mcopt: error: ", "mcopt: "):
        if line.startswith(head):
            return line[len(head):]
    return line


def as_plain(value):
    """numpy arrays → lists, recursively (to compare with JSON)."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, dict):
        return {k: as_plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [as_plain(v) for v in value]
    return value


def assert_same(python, cli, where="", tolerance=1e-12, skip=()):
    """Equal structure; numbers equal to `tolerance` relative to max(1, |value|); keys in
    `skip` (wall-clock times, paths) are not compared."""
    python = as_plain(python)
    if isinstance(cli, dict):
        assert isinstance(python, dict), f"{where}: expected an object, got {type(python).__name__}"
        keys = set(cli) | set(python)
        for key in sorted(keys):
            if key in skip:
                continue
            assert key in python, f"{where}.{key}: missing from the Python result"
            assert key in cli, f"{where}.{key}: not in the CLI's result"
            assert_same(python[key], cli[key], f"{where}.{key}", tolerance, skip)
    elif isinstance(cli, list):
        assert isinstance(python, list) and len(python) == len(cli), f"{where}: lengths differ"
        for i, (p, c) in enumerate(zip(python, cli)):
            assert_same(p, c, f"{where}[{i}]", tolerance, skip)
    elif isinstance(cli, bool) or cli is None or isinstance(cli, str):
        assert python == cli, f"{where}: {python!r} != {cli!r}"
    else:
        assert isinstance(python, (int, float)), f"{where}: expected a number, got {python!r}"
        assert math.isclose(python, cli, rel_tol=tolerance, abs_tol=tolerance), f"{where}: {python!r} != {cli!r}"


def write_json(path, value):
    path.write_text(json.dumps(as_plain(value)))
    return path
