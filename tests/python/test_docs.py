# SPDX-License-Identifier: BSD-3-Clause
"""The README's and docs' commands name paths that exist (issue 19: "the README's commands and
paths are the ones that work"): every build/release/... path is checked in this build tree,
every scripts/, scenarios/, robots/, docs/ path and every relative Markdown link in the
source tree. A renamed binary or moved file fails here, not for a newcomer."""
import os
import pathlib
import re
import shutil
import subprocess

SOURCE = pathlib.Path(os.environ["MCOPT_SOURCE_DIR"])
BUILD = pathlib.Path(os.environ["MCOPT_BUILD_DIR"])
DOCUMENTS = [SOURCE / "README.md"] + sorted((SOURCE / "docs").rglob("*.md"))

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



# The site (issue 43): mkdocs builds it strictly, fences close, anchors resolve, and the
# reference pages carry no history.

SITE_PAGES = sorted((SOURCE / "docs").rglob("*.md"))
LAB_NOTES = SOURCE / "docs" / "developers" / "lab-notes"
GENERATED_BEGIN, GENERATED_END = "<!-- mcopt report: begin", "<!-- mcopt report: end"


def mkdocs_build(project, site):
    mkdocs = shutil.which("mkdocs")
    assert mkdocs, "mkdocs is missing (scripts/install-deps.sh installs Debian's mkdocs)"
    return subprocess.run([mkdocs, "build", "--strict", "-f", str(project / "mkdocs.yml"), "-d", str(site)],
                          capture_output=True, text=True)


def test_the_site_builds_strictly(tmp_path):
    done = mkdocs_build(SOURCE, tmp_path / "site")
    assert done.returncode == 0, done.stdout + done.stderr
    assert (tmp_path / "site" / "index.html").is_file()
    assert (tmp_path / "site" / "reference" / "results.html").is_file()


def test_every_page_is_in_the_site_navigation():
    nav = (SOURCE / "mkdocs.yml").read_text(encoding="utf-8")
    missing = [str(p.relative_to(SOURCE / "docs")) for p in SITE_PAGES if str(p.relative_to(SOURCE / "docs")) not in nav]
    assert not missing, "pages not in mkdocs.yml's nav:\n" + "\n".join(missing)


def test_a_broken_link_fails_the_strict_build(tmp_path):
    (tmp_path / "docs").mkdir()
    (tmp_path / "mkdocs.yml").write_text("site_name: fixture\nstrict: true\n")
    (tmp_path / "docs" / "index.md").write_text("# Fixture\n\nSee [a page that does not exist](missing.md).\n")
    done = mkdocs_build(tmp_path, tmp_path / "site")
    assert done.returncode != 0
    assert "missing.md" in done.stdout + done.stderr


def unclosed_fences(text):
    """Line numbers of fences that do not close where they seem to: a fence opens with ```
    (and an info string) and closes with a bare ``` of at least its length. A fence left open
    at the end, and a fence *with an info string* met inside an open block — meant to open a
    new block, it is text of the open one — are both reported at the block's opening line."""
    open_at, width, problems = None, 0, []
    for number, line in enumerate(text.splitlines(), 1):
        m = re.match(r"^\s*(`{3,})(.*)$", line)
        if not m:
            continue
        ticks, rest = m.group(1), m.group(2).strip()
        if open_at is None:
            open_at, width = number, len(ticks)
        elif len(ticks) >= width and not rest:
            open_at = None
        elif rest and open_at not in problems:
            problems.append(open_at)
    if open_at is not None and open_at not in problems:
        problems.append(open_at)
    return problems


def test_every_fence_is_closed():
    problems = []
    for page in [SOURCE / "README.md"] + SITE_PAGES:
        for line in unclosed_fences(page.read_text(encoding="utf-8")):
            problems.append(f"{page.relative_to(SOURCE)}:{line}: a code fence opened here is never closed")
    assert not problems, "\n".join(problems)


def test_an_unclosed_fence_is_found():
    # The shape of the bug that hid most of the old scenarios page: a second opening fence
    # (with an info string) where a closing one was meant.
    page = "# Page\n\n```\nmcopt run x.yaml\n```yaml\nkey: 1\n```\n\ntext\n"
    assert unclosed_fences(page) == [3]
    assert unclosed_fences("```sh\nls\n```\n") == []
    assert unclosed_fences("text\n\n```sh\nls\n") == [3]


def slug(heading):
    from markdown.extensions.toc import slugify  # the slugs mkdocs' toc extension gives
    text = re.sub(r"`([^`]*)`", r"\1", heading)
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", text)
    return slugify(text, "-")


def anchors(page):
    return {slug(m.group(1)) for m in re.finditer(r"^#{1,6}\s+(.*?)\s*$", page.read_text(encoding="utf-8"), re.M)}


def test_every_anchor_resolves():
    # mkdocs 1.4 (Debian's) does not check anchors; this does, with mkdocs' own slugs.
    missing = []
    for page in SITE_PAGES + [SOURCE / "README.md"]:
        for number, line in enumerate(page.read_text(encoding="utf-8").splitlines(), 1):
            for m in re.finditer(r"\]\(([^)\s#]*)#([^)\s]+)\)", line):
                target = (page.parent / m.group(1)) if m.group(1) else page
                if re.match(r"^[a-z]+:", m.group(1)) or not target.suffix == ".md":
                    continue
                if m.group(2) not in anchors(target):
                    missing.append(f"{page.relative_to(SOURCE)}:{number}: #{m.group(2)} is not a heading of {m.group(1) or 'this page'}")
    assert not missing, "\n".join(missing)


HASH = re.compile(r"(?<![\w/.-])(?=[0-9a-f]*[0-9])(?=[0-9a-f]*[a-f])[0-9a-f]{7,40}(?![\w/-])")
DATE = re.compile(r"\b20\d\d-\d\d-\d\d\b")


def history_in(text):
    """(line, what) of commit hashes and dates outside a generated block."""
    found, generated = [], False
    for number, line in enumerate(text.splitlines(), 1):
        if GENERATED_BEGIN in line:
            generated = True
        if not generated:
            for m in HASH.finditer(line):
                found.append((number, f"commit hash {m.group(0)}"))
            for m in DATE.finditer(line):
                found.append((number, f"date {m.group(0)}"))
        if GENERATED_END in line:
            generated = False
    return found


def test_no_history_outside_the_lab_notes():
    # Measurement history, bug stories and old figures live in docs/developers/lab-notes/; a
    # reference or guide page states the current figure once, with its command.
    problems = []
    for page in [SOURCE / "README.md"] + SITE_PAGES:
        if LAB_NOTES in page.parents:
            continue
        for number, what in history_in(page.read_text(encoding="utf-8")):
            problems.append(f"{page.relative_to(SOURCE)}:{number}: {what}")
    assert not problems, "history outside docs/developers/lab-notes/:\n" + "\n".join(problems)


def test_history_is_found():
    page = "# Results\n\nMeasured at 4ba4e0b on 2026-11-26: 3.57 J.\n"
    assert [what for _, what in history_in(page)] == ["commit hash 4ba4e0b", "date 2026-11-26"]
    generated = f"{GENERATED_BEGIN} -->\nat eac93cc on 2026-11-26\n{GENERATED_END} -->\n"
    assert history_in(generated) == []
    assert history_in("the 3000 rows, 150 variables, 1e-9, 0x1f, the default\n") == []


def test_licence_and_citation():
    assert "BSD 3-Clause" in (SOURCE / "LICENSE").read_text(encoding="utf-8")
    import yaml
    cff = yaml.safe_load((SOURCE / "CITATION.cff").read_text(encoding="utf-8"))
    assert cff["cff-version"] and cff["license"] == "BSD-3-Clause"
    assert any("HRP-2" in r["title"] for r in cff["references"])


def test_every_source_file_carries_the_licence():
    files = subprocess.run(["git", "ls-files"], cwd=SOURCE, capture_output=True, text=True).stdout.split()
    if not files:  # an exported tree without git: walk it
        files = [str(p.relative_to(SOURCE)) for p in SOURCE.rglob("*") if p.is_file() and "build" not in p.parts]
    missing = []
    for f in files:
        p = pathlib.Path(f)
        if f.startswith(("tests/fuzz/corpus/", "tests/fuzz/regressions/")):
            continue
        if p.suffix in (".cpp", ".hpp", ".py", ".sh", ".cmake", ".js", ".html") or p.name in ("CMakeLists.txt",) or f == ".ci/run":
            head = "\n".join((SOURCE / f).read_text(encoding="utf-8").splitlines()[:3])
            if "SPDX-License-Identifier: BSD-3-Clause" not in head:
                missing.append(f)
    assert not missing, "source files without an SPDX line in their first three lines:\n" + "\n".join(missing)
