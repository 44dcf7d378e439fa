# SPDX-License-Identifier: BSD-3-Clause
"""`mcopt.verify` (docs/reference/verify.md): the same table as `mcopt verify --json`, and bad
input raised as mcopt.InputError naming the file."""
import json

import pytest

from conftest import SOURCE, run_cli


@pytest.fixture(scope="module")
def result(mcopt_exe, tmp_path_factory):
    out = tmp_path_factory.mktemp("verify") / "kick"
    code, _, _ = run_cli(mcopt_exe, "run", SOURCE / "scenarios" / "hrp2_kick.yaml", "--out", out, "--max-iterations", "1",
                         "--configuration-optimisation", "off", check=False)
    assert (out / "result.json").exists(), code
    return out


def test_verify_gives_the_command_lines_table(mcopt_exe, result, tmp_path):
    import mcopt
    code, printed, _ = run_cli(mcopt_exe, "verify", result, "--json", "--out", tmp_path / "cli.json", check=False)
    assert code in (0, 1)
    cli = json.loads(printed)
    mine = mcopt.verify(result, out=tmp_path / "python.json")
    assert mine["passed"] == cli["passed"] and (code == 0) == mine["passed"]
    assert [c["kind"] for c in mine["checks"]] == [c["kind"] for c in cli["checks"]]
    for a, b in zip(mine["checks"], cli["checks"]):
        assert a["worst"] == pytest.approx(b["worst"], rel=1e-12, abs=1e-15), a["kind"]
        assert a["where"] == b["where"] and a["passed"] == b["passed"]
    assert json.loads((tmp_path / "python.json").read_text())["checks"] == cli["checks"]
    assert mine["instants"] == 10 * (100 - 1) + 1


def test_verify_refuses_a_folder_without_a_result(tmp_path):
    import mcopt
    with pytest.raises(mcopt.InputError, match="result.json: no such file"):
        mcopt.verify(tmp_path)
    with pytest.raises(mcopt.InputError, match="fine: 0"):
        mcopt.verify(tmp_path, fine=0)


def test_run_with_refinement_reports_its_rounds():
    import mcopt
    kick = mcopt.Scenario(SOURCE / "scenarios" / "hrp2_kick.yaml")
    with pytest.raises(mcopt.InputError, match="refine: expected a number of rounds"):
        kick.run(refine=-1)
    with pytest.raises(mcopt.InputError, match="max-iterations: expected a number ≥ 0"):
        kick.run(max_iterations=-1)
    # One iteration: not optimal, so nothing to refine from — round 0 says so, no round follows.
    result = kick.run(max_iterations=1, configuration_optimisation=False, refine=2)
    assert result["status"] != "optimal"
    assert "refinement" not in result  # refinement starts from an optimum only
    assert result["samples"] == 100
