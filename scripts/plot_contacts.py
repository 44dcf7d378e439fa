#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""The contact surfaces of a robot drawn against its links' geometry (`mcopt robot check --plot`,
docs/tutorials/own-robot.md): for each surface, in its own frame (z its normal into the robot),
the view from below the surface (x, y: the rectangle over the footprint of the link's geometry)
and from the side (x, z: the surface's plane against the geometry's lowest points). The geometry
is the link's URDF collision primitives, or the uniform box with its inertia where the URDF has
only meshes: an estimate, as its label says. Needs matplotlib (Debian's python3-matplotlib).

    plot_contacts.py CONTACTS_JSON OUT_DIR    writes OUT_DIR/contacts.png and .svg, one path a line
"""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
matplotlib.rcParams["svg.fonttype"] = "none"  # the SVG's text stays text (searchable)
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import Polygon, Rectangle  # noqa: E402

# The six faces of a box given by its 8 corners (bit k of the index: the sign along axis k).
FACES = [(0, 1, 3, 2), (4, 5, 7, 6), (0, 1, 5, 4), (2, 3, 7, 6), (0, 2, 6, 4), (1, 3, 7, 5)]


def draw_box(ax, corners, a, b):
    """The box's faces projected on axes a, b (the outline of its projection)."""
    for face in FACES:
        ax.add_patch(Polygon([(corners[k][a], corners[k][b]) for k in face], closed=True,
                             facecolor="0.85", edgecolor="0.45", linewidth=0.6, alpha=0.5))


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    with open(sys.argv[1], encoding="utf-8") as f:
        data = json.load(f)
    out = sys.argv[2]
    surfaces = data["surfaces"]
    fig, axes = plt.subplots(len(surfaces), 2, figsize=(10, 3.2 * len(surfaces)), squeeze=False)
    for row, s in enumerate(surfaces):
        x0, x1, y0, y1 = s["rectangle"]
        points = [c for box in s["boxes"] for c in box]
        for col, (a, b, label) in enumerate(((0, 1, "from below: x, y"), (0, 2, "from the side: x, z"))):
            ax = axes[row][col]
            for box in s["boxes"]:
                draw_box(ax, box, a, b)
            if col == 0:
                ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False, edgecolor="tab:red", linewidth=1.8,
                                       label="contact rectangle"))
            else:
                ax.plot([x0, x1], [0, 0], color="tab:red", linewidth=2.5, label="contact rectangle (its plane)")
            ax.plot([0], [0], marker="+", color="tab:red", markersize=10)
            xs = [p[a] for p in points] + [x0, x1, 0.0]
            ys = [p[b] for p in points] + ([y0, y1] if col == 0 else [0.0])
            pad = 0.1 * max(max(xs) - min(xs), max(ys) - min(ys), 0.02)
            ax.set_xlim(min(xs) - pad, max(xs) + pad)
            ax.set_ylim(min(ys) - pad, max(ys) + pad)
            ax.set_aspect("equal")
            ax.set_xlabel("x [m]")
            ax.set_ylabel("y [m]" if col == 0 else "z [m] (normal)")
            ax.grid(True, linewidth=0.3)
            ax.set_title(f"{s['name']} on {s['link']}: {label}", fontsize=9)
            if row == 0:
                ax.legend(loc="upper right", fontsize=7)
        axes[row][0].text(0.01, 0.02, f"grey: {s['body']}'s {s['geometry']}", transform=axes[row][0].transAxes,
                          fontsize=7, color="0.3")
    fig.suptitle(f"{data['robot']}: contact surfaces against their links' geometry")
    fig.tight_layout()
    os.makedirs(out, exist_ok=True)
    for extension in ("png", "svg"):
        path = os.path.join(out, f"contacts.{extension}")
        fig.savefig(path + ".tmp", format=extension, dpi=110)
        os.replace(path + ".tmp", path)
        print(path)


if __name__ == "__main__":
    main()
