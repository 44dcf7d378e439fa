# SPDX-License-Identifier: BSD-3-Clause
"""The reference pages cannot drift from the code (issue 43):

- docs/reference/cli.md is the binary's own help (scripts/cli_reference.py): a command or flag
  the binary has and the page lacks, or the other way round, fails;
- every key the scenario reader accepts is a row of docs/reference/scenario-file.md with a
  default, and every row there names a key the reader accepts. The reader is asked itself: a
  scenario with an unknown key at some mapping is refused with "unknown key (expected one of
  …)", the list of what that mapping accepts;
- every key `mcopt run` writes into result.json, contact_wrenches.json and states.json, and
  every CSV column, is a row of docs/reference/results.md.

Each check is shown to fail once, on a fixture."""
import copy
import json
import os
import pathlib
import re
import subprocess
import sys

import pytest
import yaml

SOURCE = pathlib.Path(os.environ["MCOPT_SOURCE_DIR"])
EXE = os.environ["MCOPT_EXECUTABLE"]
REFERENCE = SOURCE / "docs" / "reference"
sys.path.insert(0, str(SOURCE / "scripts"))
import cli_reference  # noqa: E402


# ---- the command line ------------------------------------------------------------------

def test_the_cli_reference_is_the_binarys_help():
    done = subprocess.run([sys.executable, str(SOURCE / "scripts" / "cli_reference.py"), EXE, "--check",
                           str(REFERENCE / "cli.md")], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr + "\nregenerate: /usr/bin/python3 scripts/cli_reference.py " \
                                               "build/release/apps/mcopt > docs/reference/cli.md"


def test_a_flag_missing_from_the_cli_reference_fails():
    generated = cli_reference.page(EXE)
    fixture = generated.replace("--strict", "--lenient")
    problems = cli_reference.differences(generated, fixture)
    assert "`mcopt run` flag --strict is missing from the reference" in problems
    assert "the reference names `mcopt run` flag --lenient, which the binary lacks" in problems
    fixture = re.sub(r"## `mcopt replay`.*?```\n", "", generated, flags=re.S)
    assert "command `mcopt replay` is missing from the reference" in cli_reference.differences(generated, fixture)


def test_every_mcopt_flag_named_in_the_docs_exists():
    # `mcopt run --flag` written anywhere in the docs must be a flag of that command.
    flags = cli_reference.inventory(cli_reference.page(EXE))
    pages = [SOURCE / "README.md"] + sorted((SOURCE / "docs").rglob("*.md"))
    pattern = re.compile(r"mcopt ((?:robot info|robot check|robot init|study collect|study case|[a-z]+))\b([^`\n|]*)")
    problems = []
    for page in pages:
        if "lab-notes" in page.parts:
            continue
        for number, line in enumerate(page.read_text(encoding="utf-8").splitlines(), 1):
            for m in pattern.finditer(line):
                command = f"mcopt {m.group(1)}"
                if command not in flags:
                    continue
                for flag in cli_reference.FLAG.findall(m.group(2)):
                    if flag not in flags[command] | {"--help"}:
                        problems.append(f"{page.relative_to(SOURCE)}:{number}: `{command}` has no flag {flag}")
    assert not problems, "\n".join(problems)


# ---- scenario keys ---------------------------------------------------------------------

def documented_tables(page):
    """{prefix: {key: (meaning, default)}} of a reference page: each `### `path`` heading's
    table, under every path the heading names (the page's first table, under "Top level" or
    "`result.json`", is prefix ""). A cell `a`, `b` names two keys."""
    tables, prefixes = {}, None
    for line in page.read_text(encoding="utf-8").splitlines():
        heading = re.match(r"^#{2,3} (.*)$", line)
        if heading:
            title = heading.group(1)
            if title in ("Top level", "`result.json`"):
                prefixes = [""]
            elif re.match(r"^`[a-z_\[\]\.]+`(, `[a-z_\[\]\.]+`)*( \(periodic\)| of kind `throw`)?$", title):
                prefixes = re.findall(r"`([a-z_\[\]\.]+)`", title.split(" of kind")[0])
            else:
                prefixes = None
            continue
        if prefixes is None or not line.startswith("| `"):
            continue
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        for key in re.findall(r"`([A-Za-z_:]+)`", cells[0]):
            for prefix in prefixes:
                tables.setdefault(prefix, {})[key] = (cells[1], cells[2] if len(cells) > 2 else "")
    return tables


# Where each mapping of a scenario is, in a bundled file (path of keys; an int is a list index).
SCENARIO_PROBES = [
    ("", "hrp2_kick.yaml", []),
    ("reference_pose", "hrp2_kick.yaml", ["reference_pose"]),
    ("start", "hrp2_kick.yaml", ["start"]),
    ("end", "hrp2_kick_free_ends.yaml", ["end"]),
    ("end", "hrp2_kick.yaml", ["end"]),
    ("objective", "hrp2_kick.yaml", ["objective"]),
    ("limits", "hrp2_kick.yaml", ["limits"]),
    ("initialisation", "hrp2_kick.yaml", ["initialisation"]),
    ("continuation[]", "hrp2_kick.yaml", ["continuation", 0]),
    ("tasks[]", "hrp2_kick.yaml", ["tasks", 0]),
    ("tasks[]", "hrp2_throw.yaml", ["tasks", 0]),
    ("inner", "hrp2_weight_shift.yaml", ["inner"]),
    ("contacts[]", "hrp2_lean_reach.yaml", ["contacts", 2]),
    ("contacts[].pose", "hrp2_lean_reach.yaml", ["contacts", 2, "pose"]),
    ("duration", "hrp2_throw_free_release.yaml", ["duration"]),
    ("closure_tolerance", "hrp2_weight_shift.yaml", ["closure_tolerance"]),
]


def scenario_with(name, path, tmp_path):
    file = SOURCE / "scenarios" / name
    data = yaml.safe_load(file.read_text(encoding="utf-8"))
    for key in ("robot", "actuators", "contact_surfaces", "postures"):
        data[key] = str((file.parent / data[key]).resolve())
    node = data
    for step in path:
        if isinstance(step, str) and step not in node:
            node[step] = {"position": 1e-3} if step == "closure_tolerance" else {}
        node = node[step]
    node["zz_probe"] = 1
    out = tmp_path / f"probe_{len(list(tmp_path.iterdir()))}.yaml"
    out.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return out


def accepted_keys(name, path, tmp_path):
    probe = scenario_with(name, path, tmp_path)
    done = subprocess.run([EXE, "run", str(probe), "--out", str(tmp_path / "never")], capture_output=True, text=True)
    assert done.returncode == 2, done.stdout + done.stderr
    m = re.search(r"zz_probe: unknown key \(expected one of ([^)]*)\)", done.stderr)
    assert m, f"the reader did not refuse the probe key as unknown:\n{done.stderr}"
    return set(m.group(1).split(", "))


@pytest.fixture(scope="module")
def reader_keys(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("probes")
    keys = {}
    for prefix, name, path in SCENARIO_PROBES:
        keys.setdefault(prefix, set()).update(accepted_keys(name, path, tmp))
    return keys


def scenario_key_problems(reader, documented):
    problems = []
    for prefix in sorted(set(reader) | set(documented)):
        want, have = reader.get(prefix, set()), documented.get(prefix, {})
        where = f"`{prefix}`" if prefix else "the top level"
        problems += [f"{where}: key `{k}` is accepted by the reader but not in the reference" for k in sorted(want - set(have))]
        problems += [f"{where}: the reference names `{k}`, which the reader refuses" for k in sorted(set(have) - want)]
        problems += [f"{where}: key `{k}` has no default in the reference" for k in sorted(have) if not have[k][1]]
    return problems


def test_every_scenario_key_is_documented_with_its_default(reader_keys):
    documented = documented_tables(REFERENCE / "scenario-file.md")
    # A map reached only through a top-level key's table: each such key must have its table.
    nested = {k for k in reader_keys[""] if any(p == k or p.startswith(k + "[") for p in reader_keys if p)}
    assert nested >= {"inner", "duration", "objective", "limits", "start", "end", "contacts", "tasks", "continuation"}
    problems = scenario_key_problems(reader_keys, documented)
    assert not problems, "docs/reference/scenario-file.md and the scenario reader differ:\n" + "\n".join(problems)


def test_an_undocumented_scenario_key_fails(reader_keys):
    documented = copy.deepcopy(documented_tables(REFERENCE / "scenario-file.md"))
    del documented["inner"]["polish"]
    documented["limits"]["acceleration"] = ("a limit", "true")
    problems = scenario_key_problems(reader_keys, documented)
    assert "`inner`: key `polish` is accepted by the reader but not in the reference" in problems
    assert "`limits`: the reference names `acceleration`, which the reader refuses" in problems


# ---- result keys -------------------------------------------------------------------------

def key_paths(value, prefix=""):
    """Every key path of a JSON value: maps joined by dots, list elements as []. The
    per-joint map `parameters` is keyed by joint names, which are data."""
    if isinstance(value, dict):
        for k, v in value.items():
            path = f"{prefix}.{k}" if prefix else k
            yield path
            if path != "parameters":
                yield from key_paths(v, path)
    elif isinstance(value, list):
        for v in value:
            yield from key_paths(v, prefix + "[]")


def result_rows():
    """{full key path: meaning} of docs/reference/results.md's tables."""
    rows = {}
    for prefix, table in documented_tables(REFERENCE / "results.md").items():
        for key, (meaning, _) in table.items():
            rows[f"{prefix}.{key}" if prefix else key] = meaning
    return rows


def documented(path, rows):
    """A path is documented when it is a row, or when the row of one of its ancestors names
    its last key in backticks (a small map described in one cell: `reference_pose` →
    `position`, `quaternion_xyzw`)."""
    if path in rows:
        return True
    leaf = path.rpartition(".")[2]
    ancestor = path
    while "." in ancestor:
        ancestor = ancestor.rpartition(".")[0]
        if ancestor in rows and f"`{leaf}`" in rows[ancestor]:
            return True
    return False


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("runs")
    out = {}
    for name, args in [("kick", ["hrp2_kick.yaml"]), ("kick_free_ends", ["hrp2_kick_free_ends.yaml"]),
                       ("weight_shift", ["hrp2_weight_shift.yaml"]), ("throw", ["hrp2_throw.yaml"])]:
        done = subprocess.run([EXE, "run", str(SOURCE / "scenarios" / args[0]), "--out", str(tmp / name),
                               "--max-iterations", "2"], capture_output=True, text=True)
        assert done.returncode in (0, 4), done.stderr
        out[name] = tmp / name
    return out


def undocumented(paths, rows):
    return sorted(p for p in paths if not documented(p, rows))


def test_every_result_key_is_documented(runs):
    rows = result_rows()
    written = set()
    for folder in runs.values():
        written |= set(key_paths(json.loads((folder / "result.json").read_text())))
    assert {"energy_balance.joint_work_J", "release.miss_distance_m", "contacts[].closure_drift_m",
            "configuration_optimisation.end.same_as", "configuration_optimisation.end.status"} <= written
    missing = undocumented(written, rows)
    assert not missing, "result.json keys not in docs/reference/results.md:\n" + "\n".join(missing)


def test_every_side_file_key_and_column_is_documented(runs):
    text = (REFERENCE / "results.md").read_text(encoding="utf-8")
    sections = {name: text.split(f"## `{name}`", 1)[1].split("\n## ", 1)[0] for name in
                ("contact_wrenches.json", "states.json", "trajectory.csv", "power_fine.csv")}
    problems = []
    for folder in runs.values():
        for name in ("contact_wrenches.json", "states.json"):
            for path in key_paths(json.loads((folder / name).read_text())):
                leaf = path.rpartition(".")[2].replace("[]", "")
                if f"`{leaf}`" not in sections[name]:
                    problems.append(f"{name}: key {path}")
        joints = json.loads((folder / "states.json").read_text())["joint_names"]
        for name in ("trajectory.csv", "power_fine.csv"):
            header = (folder / name).read_text().splitlines()[0].split(",")
            for column in header:
                kind, _, what = column.partition(":")
                generic = column if not what else (f"{kind}:JOINT" if what in joints else f"SURFACE:{what}")
                if f"`{generic}`" not in sections[name]:
                    problems.append(f"{name}: column {column}")
    assert not problems, "not in docs/reference/results.md:\n" + "\n".join(sorted(set(problems)))


def test_an_undocumented_result_key_fails(runs):
    rows = result_rows()
    written = set(key_paths(json.loads((runs["kick"] / "result.json").read_text())))
    assert undocumented(written, rows) == []
    assert undocumented(written | {"energy_balance.flux_capacitor_J"}, rows) == ["energy_balance.flux_capacitor_J"]
    del rows["timings"]
    assert "timings.total_seconds" in undocumented(written, rows)
