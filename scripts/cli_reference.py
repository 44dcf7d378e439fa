#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""Writes docs/reference/cli.md from the `mcopt` binary's own help: every command and
subcommand, found by walking the "Subcommands:" sections, with its help text verbatim.

    scripts/cli_reference.py build/release/apps/mcopt [--check docs/reference/cli.md]

Without --check it prints the page (redirect it into docs/reference/cli.md). With --check it
compares the page with the file and exits 1 on any difference, naming the commands and flags
one has and the other lacks (tests/python/test_reference.py runs it)."""
import re
import subprocess
import sys

INTRO = """# Command line: `mcopt`

Generated from the binary's own help by `scripts/cli_reference.py` — do not edit; run
`/usr/bin/python3 scripts/cli_reference.py build/release/apps/mcopt > docs/reference/cli.md`
after changing a command. A test fails when this page and the binary differ in a command or a
flag.

Every command refuses bad input with a message naming the file, line or field, and exit
status 2. `mcopt run` exits 0 only when Ipopt reports an optimal solution (4 when it stopped
otherwise, 130 when interrupted: [results](results.md)). The input and output files are in
[input files](input-files.md), [results](results.md), [studies](studies.md) and [the inner
problem](../theory/inner-problem.md). URDFs whose inertias are not physical (Romeo's published
model) are refused unless allowed: `--allow-nonphysical-inertia` in `mcopt robot info`,
`mcopt robot check`, `mcopt dynamics` and `mcopt run`, or `allow_nonphysical_inertia: true` in a
scenario (which studies and the Python module then run too); each such body is then a warning.
The torques of such a model are those of its numbers — inverse dynamics needs no positive
definite mass matrix — but no real robot has that body: fix the inertias when you can.
`mcopt evaluate` refuses them.
"""

SUBCOMMAND = re.compile(r"^  ([a-z][a-z0-9-]*)\s{2,}")
FLAG = re.compile(r"(?<![\w-])(--[a-z][a-z0-9-]*)")


def help_text(binary, path):
    out = subprocess.run([binary, *path, "--help"], capture_output=True, text=True, check=True).stdout
    # The usage line names the binary as it was called; the page names it `mcopt`.
    return re.sub(r"^Usage: \S+", "Usage: mcopt", out.rstrip(), count=1, flags=re.M)


def subcommands(text):
    names, inside = [], False
    for line in text.splitlines():
        if line.startswith("Subcommands:"):
            inside = True
            continue
        if inside:
            m = SUBCOMMAND.match(line)
            if m:
                names.append(m.group(1))
            elif line and not line.startswith(" "):
                inside = False
    return names


def commands(binary, path=()):
    text = help_text(binary, list(path))
    yield path, text
    for name in subcommands(text):
        yield from commands(binary, (*path, name))


def page(binary):
    parts = [INTRO]
    for path, text in commands(binary):
        title = "mcopt" + "".join(" " + p for p in path)
        parts.append(f"## `{title}`\n\n```text\n{text}\n```\n")
    return "\n".join(parts)


def inventory(text):
    """{command: set of flags} of a page."""
    found, current = {}, None
    for line in text.splitlines():
        m = re.match(r"^## `(mcopt[^`]*)`", line)
        if m:
            current = m.group(1)
            found[current] = set()
        elif current:
            found[current].update(FLAG.findall(line))
    return found


def differences(expected, actual):
    """What one page has and the other lacks, as sentences."""
    want, have = inventory(expected), inventory(actual)
    out = []
    for command in sorted(set(want) | set(have)):
        if command not in have:
            out.append(f"command `{command}` is missing from the reference")
        elif command not in want:
            out.append(f"the reference names command `{command}`, which the binary lacks")
        else:
            out += [f"`{command}` flag {f} is missing from the reference" for f in sorted(want[command] - have[command])]
            out += [f"the reference names `{command}` flag {f}, which the binary lacks" for f in sorted(have[command] - want[command])]
    if not out and expected != actual:
        out.append("the reference's text differs from the binary's help (regenerate it)")
    return out


def main():
    binary = sys.argv[1]
    generated = page(binary)
    if len(sys.argv) == 4 and sys.argv[2] == "--check":
        with open(sys.argv[3], encoding="utf-8") as f:
            committed = f.read()
        problems = differences(generated, committed)
        for p in problems:
            print(f"{sys.argv[3]}: {p}", file=sys.stderr)
        sys.exit(1 if problems else 0)
    sys.stdout.write(generated)


if __name__ == "__main__":
    main()
