#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""Summary plots of a study (docs/reference/studies.md, "Collecting"): the energy of each case against
each varied field, from the study's cases.csv. Called by `mcopt study collect`; needs
matplotlib (Debian's python3-matplotlib).

    plot_study.py CASES_CSV OUT_DIR    writes OUT_DIR/energy_vs_<field>.png and .svg
"""
import csv
import math
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

RESULT_COLUMNS = ["status", "energy", "max_violation", "iterations", "seconds", "host"]


def as_number(text):
    try:
        value = float(text)
    except ValueError:
        return None
    return value if math.isfinite(value) else None


def main(argv):
    if len(argv) != 3:
        sys.exit("usage: plot_study.py CASES_CSV OUT_DIR")
    with open(argv[1], newline="") as f:
        rows = list(csv.DictReader(f))
        header = list(rows[0].keys()) if rows else []
    if not rows:
        sys.exit(f"{argv[1]}: no cases")
    fields = header[1:header.index("status")]
    os.makedirs(argv[2], exist_ok=True)
    written = []
    for field in fields:
        numeric = all(as_number(r[field]) is not None for r in rows)
        categories = sorted({r[field] for r in rows}) if not numeric else []
        fig, ax = plt.subplots(figsize=(6.4, 4.2))
        for finished, style in ((True, {"marker": "o"}), (False, {"marker": "x"})):
            xs, ys = [], []
            for r in rows:
                energy = as_number(r["energy"])
                # An optimum is a filled marker; any other end (iteration limit, timeout,
                # cancelled) a cross at the energy of its last iterate.
                if energy is None or (r["status"] in ("optimal", "acceptable")) != finished:
                    continue
                xs.append(as_number(r[field]) if numeric else categories.index(r[field]))
                ys.append(energy)
            if xs:
                ax.scatter(xs, ys, label="optimal" if finished else "not optimal", **style)
        if not numeric:
            ax.set_xticks(range(len(categories)))
            ax.set_xticklabels(categories, rotation=20)
        missing = sum(as_number(r["energy"]) is None for r in rows)
        ax.set_xlabel(field)
        ax.set_ylabel("energy [J]")
        ax.set_title(f"energy against {field}" + (f" ({missing} cases without a result)" if missing else ""))
        ax.grid(True, alpha=0.3)
        ax.legend()
        fig.tight_layout()
        stem = "energy_vs_" + re.sub(r"[^A-Za-z0-9_.-]+", "_", field).strip("_")
        for extension in ("png", "svg"):
            path = os.path.join(argv[2], f"{stem}.{extension}")
            fig.savefig(path + ".tmp", format=extension)
            os.replace(path + ".tmp", path)  # atomically, as every result
            written.append(path)
        plt.close(fig)
    print("\n".join(written))


if __name__ == "__main__":
    main(sys.argv)
