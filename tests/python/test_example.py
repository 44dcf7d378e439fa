# SPDX-License-Identifier: BSD-3-Clause
"""The example of docs/reference/python.md runs as a user would run it, and says what it should."""
import pathlib
import re
import subprocess
import sys

from conftest import SOURCE


def test_compare_inner_solvers(tmp_path):
    done = subprocess.run([sys.executable, SOURCE / "examples" / "compare_inner_solvers.py", "--samples", "20",
                           "--out", tmp_path], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    rows = {m.group(1): m.groups()[1:] for m in re.finditer(r"^(active-set|slsqp|ipopt)\s+(\d+)\s+(\d+)\s+\S+\s+\S+\s+(\S+)$",
                                                           done.stdout, re.M)}
    assert set(rows) == {"active-set", "slsqp", "ipopt"}, done.stdout
    # The three solvers agree on every sample's status (after 5 iterations the weight shift's
    # motion has a few samples whose inner problem is infeasible: the robot would tip there).
    assert len({(optimal, other) for optimal, other, _ in rows.values()}) == 1, done.stdout
    for name, (optimal, other, gap) in rows.items():
        assert int(optimal) + int(other) == 20 and int(optimal) >= 10, (name, done.stdout)
        # Every solver reaches the active-set method's optimum.
        assert float(gap) < 1e-8, (name, gap)
    for suffix in ("png", "svg"):
        figure = pathlib.Path(tmp_path) / f"inner_solvers.{suffix}"
        assert figure.stat().st_size > 10_000, figure
