# SPDX-License-Identifier: BSD-3-Clause
"""The README's and docs' commands name paths that exist (issue 19: "the README's commands and
paths are the ones that work"): every build/release/... path is checked in this build tree,
every scripts/, scenarios/, robots/, docs/ path and every relative Markdown link in the
source tree. A renamed binary or moved file fails here, not for a newcomer."""
import os
import pathlib
import re

SOURCE = pathlib.Path(os.environ["MCOPT_SOURCE_DIR"])
BUILD = pathlib.Path(os.environ["MCOPT_BUILD_DIR"])
DOCUMENTS = [SOURCE / "README.md", SOURCE / "DEVELOPERS.md"] + sorted((SOURCE / "docs").rglob("*.md"))

BUILD_PATH = re.compile(r"build/release/([A-Za-z0-9_./-]+)")
SOURCE_PATH = re.compile(r"(?<![\w./-])((?:scripts|scenarios|robots|docs|apps|bench|tests)/[A-Za-z0-9_./-]+)")
LINK = re.compile(r"\]\(([^)#\s]+)(?:#[^)]*)?\)")


def mentions(pattern):
    for document in DOCUMENTS:
        for number, line in enumerate(document.read_text(encoding="utf-8").splitlines(), 1):
            for match in pattern.finditer(line):
                yield document, number, match.group(1)


def test_documents_exist():
    assert (SOURCE / "README.md").is_file() and len(DOCUMENTS) > 5


def test_build_paths_exist_in_this_build():
    missing = []
    checked = 0
    for document, number, path in mentions(BUILD_PATH):
        path = path.rstrip(".")
        checked += 1
        if not (BUILD / path).exists():
            missing.append(f"{document.relative_to(SOURCE)}:{number}: build/release/{path}")
    assert checked >= 10
    assert not missing, "paths named in the docs but not built:\n" + "\n".join(missing)


def test_source_paths_exist():
    missing = []
    checked = 0
    for document, number, path in mentions(SOURCE_PATH):
        path = path.rstrip(".,:;")
        # Patterns and placeholders (tests/fuzz/corpus/<target>/, results/*.json) name no file.
        if any(c in path for c in "<>*") or path.endswith("_"):
            continue
        checked += 1
        if not (SOURCE / path).exists():
            missing.append(f"{document.relative_to(SOURCE)}:{number}: {path}")
    assert checked >= 50
    assert not missing, "paths named in the docs but not in the source tree:\n" + "\n".join(missing)


def test_relative_links_resolve():
    missing = []
    for document in DOCUMENTS:
        for number, line in enumerate(document.read_text(encoding="utf-8").splitlines(), 1):
            for match in LINK.finditer(line):
                target = match.group(1)
                if re.match(r"^[a-z]+:", target):
                    continue
                if not (document.parent / target).exists():
                    missing.append(f"{document.relative_to(SOURCE)}:{number}: {target}")
    assert not missing, "links that resolve to nothing:\n" + "\n".join(missing)
