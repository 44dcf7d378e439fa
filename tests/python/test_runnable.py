# SPDX-License-Identifier: BSD-3-Clause
"""Every command the getting-started pages and the tutorials show as runnable runs (issue 43).

A shell block marked by the line `<!-- runnable -->` just before its fence is run as written;
`<!-- runnable: cap -->` runs it with `--max-iterations 5` added to each `mcopt run`, which may
then end with exit 4 (not optimal), because a full run is too long for CI; an `mcopt verify` of
such a capped run may then end with exit 1 (its motion need not hold: it is no optimum). The blocks of one page
run in order in one working folder that looks like a checkout after its build (build/release is
this build tree; scenarios/, robots/, scripts/, examples/ the source's), so a later block reads
what an earlier one wrote, as a reader following the page would."""
import os
import pathlib
import re
import subprocess

import pytest

SOURCE = pathlib.Path(os.environ["MCOPT_SOURCE_DIR"])
BUILD = pathlib.Path(os.environ["MCOPT_BUILD_DIR"])
PAGES = sorted((SOURCE / "docs" / "getting-started").glob("*.md")) + sorted((SOURCE / "docs" / "tutorials").glob("*.md"))
CAP = 5


def runnable_blocks(text):
    """[(line, capped, code)] of the blocks marked runnable."""
    blocks, lines = [], text.splitlines()
    for i, line in enumerate(lines):
        m = re.match(r"^<!-- runnable(: cap)? -->$", line.strip())
        if not m:
            continue
        assert i + 1 < len(lines) and re.match(r"^```(sh|bash)$", lines[i + 1]), \
            f"line {i + 1}: a runnable marker must be followed by a ```sh fence"
        end = next(j for j in range(i + 2, len(lines)) if lines[j] == "```")
        blocks.append((i + 2, bool(m.group(1)), "\n".join(lines[i + 2:end])))
    return blocks


def capped(code):
    """The block with `--max-iterations` added to every `mcopt run` and exit 4 accepted, and exit 1
    of every `mcopt verify` (of such a run)."""
    joined = re.sub(r"\s*\\\n\s*", " ", code)
    out = []
    for line in joined.splitlines():
        if re.search(r"apps/mcopt run\b", line):
            command, _, comment = line.partition("  #")
            line = f"{command.rstrip()} --max-iterations {CAP} || [ $? -eq 4 ]"
        elif re.search(r"apps/mcopt verify\b", line):
            command, _, comment = line.partition("  #")
            line = f"{command.rstrip()} || [ $? -eq 1 ]"
        out.append(line)
    return "\n".join(out)


def test_the_pages_have_runnable_blocks():
    counts = {p.name: len(runnable_blocks(p.read_text(encoding="utf-8"))) for p in PAGES}
    assert counts["first-run.md"] >= 4 and counts["install.md"] >= 1, counts
    assert sum(counts.values()) >= 10, counts


def test_capping_keeps_the_command_and_bounds_it():
    code = "build/release/apps/mcopt run scenarios/x.yaml \\\n  --out out/x   # a comment\nls out/x"
    assert capped(code) == f"build/release/apps/mcopt run scenarios/x.yaml --out out/x --max-iterations {CAP} || [ $? -eq 4 ]\nls out/x"
    assert capped("build/release/apps/mcopt verify out/x   # exit 0") == "build/release/apps/mcopt verify out/x || [ $? -eq 1 ]"


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_runnable_blocks_run(page, tmp_path):
    (tmp_path / "build").mkdir()
    (tmp_path / "build" / "release").symlink_to(BUILD)
    for folder in ("scenarios", "robots", "scripts", "examples"):
        (tmp_path / folder).symlink_to(SOURCE / folder)
    environment = dict(os.environ, OMP_NUM_THREADS="1")
    for line, cap, code in runnable_blocks(page.read_text(encoding="utf-8")):
        script = capped(code) if cap else code
        done = subprocess.run(["bash", "-euo", "pipefail", "-c", script], cwd=tmp_path, env=environment,
                              capture_output=True, text=True, timeout=600)
        assert done.returncode == 0, f"{page.relative_to(SOURCE)}:{line}: the block failed (exit {done.returncode})\n" \
                                     f"{script}\n--- stdout\n{done.stdout[-3000:]}\n--- stderr\n{done.stderr[-3000:]}"
