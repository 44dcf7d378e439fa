# SPDX-License-Identifier: BSD-3-Clause
"""`mcopt report --quick` (docs/benchmarks/index.md): the structure of report.json and report.md,
the report's own figures beside ours, the generated block of a docs file replaced and nothing
else, and a whole optimisation stopped at the time limit with its last iterate."""
import importlib.util
import json
import os
import pathlib
import subprocess

import pytest

from conftest import SOURCE, run_cli

FIGURE_5_1 = ["InverseDynamics/Trajectory100/hrp2", "Gradient/OneContact100/hrp2"]
FIGURE_5_2 = ["BilevelDynamics/WeightShift100/hrp2", "BilevelDynamics/WeightShift100/hrp2/slsqp",
              "BilevelDynamics/WeightShift100/hrp2/ipopt", "BilevelGradient/WeightShift100/hrp2/dense",
              "OuterGradient/weight_shift/bilevel/active-set", "OuterGradient/weight_shift/bilevel/slsqp",
              "OuterGradient/weight_shift/bilevel/ipopt", "OuterGradient/weight_shift/splines",
              "OuterGradient/weight_shift/variables"]


def load_script():
    spec = importlib.util.spec_from_file_location("report_script", SOURCE / "scripts" / "report.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def quick(mcopt_exe, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("report")
    docs = tmp / "benchmarks.md"
    script = load_script()
    docs.write_text(f"# Before\n\nkept\n\n{script.BEGIN}\nold tables\n{script.END}\n\nafter, kept\n")
    _, out, _ = run_cli(mcopt_exe, "report", "--quick", "--out", tmp / "report", "--docs", docs)
    return tmp, out, docs, script


def test_report_json_has_the_machine_every_figure_and_every_run(quick):
    tmp, _, _, _ = quick
    report = json.loads((tmp / "report" / "report.json").read_text())
    machine = report["machine"]
    assert machine["cpu"] and machine["cores"] >= 1 and machine["commit"] and machine["build_type"] in ("Release", "RelWithDebInfo", "Debug")
    assert report["settings"]["quick"] and report["settings"]["bench"]["threads"] == 1
    for name in FIGURE_5_1 + FIGURE_5_2:
        assert report["benchmarks_ms"][name] > 0, name
    runs = report["optimisations"]
    expected = {"kick/configuration-on", "kick/configuration-off", "lean_reach/bilevel/active-set"}
    expected |= {"kick-free-ends/configuration-on", "kick-free-ends/configuration-off"}
    expected |= {f"weight_shift/bilevel/{s}" for s in ("active-set", "slsqp", "ipopt", "as-bundled")}
    expected |= {"weight_shift/splines", "weight_shift/variables", "throw"}
    assert set(runs) == expected
    for label, run in runs.items():
        # --max-iterations 1 bounds each continuation stage (the bundled scenarios have two: a
        # Gauss–Newton stage, then sample-differences; the weight shift's first is solved bilevel
        # whatever the formulation; the kick's are the smooth maximum's Gauss–Newton stage, then
        # its epigraph form with sample differences; the throw has a margin-row stage between).
        assert run["status"] == "maximum_iterations" and run["iterations"] == run["stages"], label
        # The free-ends kick keeps the three stages the bundled kick had: the smooth maximum's
        # Gauss–Newton and sample-differences stages, then the epigraph form.
        stages = 3 if label.startswith("kick-free-ends/") or label == "throw" else 2
        assert run["stages"] == stages, label
        assert run["seconds"] > 0 and run["energy_J"] > 0 and run["max_violation"] >= 0, label
    # The runs are what their arguments say.
    assert "--inner-solver" in runs["weight_shift/bilevel/ipopt"]["arguments"]
    assert runs["weight_shift/bilevel/as-bundled"]["arguments"][:2] == ["--contact-forces", "bilevel"]
    assert "--inner-solver" not in runs["weight_shift/bilevel/as-bundled"]["arguments"]
    assert runs["kick/configuration-off"]["arguments"][:2] == ["--configuration-optimisation", "off"]


def test_report_md_puts_the_report_figures_beside_ours(quick):
    tmp, printed, _, _ = quick
    text = (tmp / "report" / "report.md").read_text()
    for heading in ("**Figure 5.1**", "**Figure 5.2**", "**Table 3.1**", "**Bundled scenarios**"):
        assert heading in text
    for quoted in ("3.2 ms", "73 ms", "1380 ms (IPOPT)", "303 ms (FSQP)", "1830 ms (IPOPT)", "750 ms (FSQP)", "280 ms",
                   "1–2 days (estimated, never run)", "14.8 J, 2000, 169 s", "16.35 J, 2000, 126 s"):
        assert quoted in text, quoted
    assert "Intel" in text or "AMD" in text or "cores" in text
    assert "**Figure 5.1**" in printed  # also printed


def test_the_docs_block_is_replaced_and_nothing_else(quick):
    tmp, _, docs, script = quick
    body = docs.read_text()
    assert body.startswith("# Before\n\nkept\n\n" + script.BEGIN + "\n")
    assert body.endswith(script.END + "\n\nafter, kept\n")
    assert "old tables" not in body and "**Figure 5.2**" in body
    # The docs block states the figures and the machine; the run's date and commit stay in
    # report.json (and the lab notes), out of the reference page.
    machine = json.loads((tmp / "report" / "report.json").read_text())["machine"]
    block = body.split(script.BEGIN, 1)[1]
    assert machine["commit"] not in block and machine["date"] not in block and machine["cpu"] in block


def test_a_docs_file_without_the_block_is_refused(mcopt_exe, tmp_path):
    (tmp_path / "plain.md").write_text("no block\n")
    done = subprocess.run([mcopt_exe, "report", "--quick", "--out", str(tmp_path / "r"), "--docs", str(tmp_path / "plain.md")],
                          capture_output=True, text=True)
    assert done.returncode == 1
    assert f"{tmp_path / 'plain.md'}: no generated block" in done.stderr
    assert (tmp_path / "plain.md").read_text() == "no block\n"
    assert not (tmp_path / "r").exists()  # refused before anything was measured


def test_a_run_beyond_the_time_limit_is_stopped_with_its_last_iterate(mcopt_exe, tmp_path):
    script = load_script()
    r = script.run(mcopt_exe, SOURCE / "scenarios" / "hrp2_kick.yaml", tmp_path / "kick",
                   ["--configuration-optimisation", "off"], time_limit=4.0)
    assert r["stopped_at_time_limit"]
    assert r["status"] == "interrupted" and r["iterations"] > 0
    assert 4.0 <= r["seconds"] < 30.0
