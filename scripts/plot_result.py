#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""Figures of one optimised motion (docs/guides/plots.md), from the result folder `mcopt run` wrote:
joint positions and torques within their limits, contact wrenches and friction-cone margins,
centres of pressure inside their rectangles, power per joint and cumulative energy,
Ipopt's convergence, and a throw's ball flight to its target; with `mcopt verify`'s verify.json
beside result.json, the instants it found broken as red lines on the figures they concern, and a
figure of its own (docs/reference/verify.md). Called by `mcopt plot`; needs matplotlib (Debian's python3-matplotlib).

    plot_result.py RESULT_DIR OUT_DIR    writes OUT_DIR/<figure>.png and .svg, one path a line
"""
import json
import math
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

# Fixed colours and line styles: 30 joints need more than the default cycle's ten colours.
STYLES = [(c, s) for s in ("-", "--", ":") for c in plt.rcParams["axes.prop_cycle"].by_key()["color"]]


class BadResult(Exception):
    pass


def field(result, key):
    if key not in result:
        raise BadResult(f"no '{key}' field (written by mcopt run of an older version, or not a result.json)")
    return result[key]


def joint_groups(names):
    """Joints grouped by limb: the name without its trailing number and _JOINT (HRP-2's
    RLEG_JOINT3 -> RLEG). One group when that gives more than eight."""
    groups = {}
    for j, name in enumerate(names):
        limb = re.sub(r"(_?JOINT)?_?\d+$", "", name) or name
        groups.setdefault(limb, []).append(j)
    return groups if len(groups) <= 8 else {"joints": list(range(len(names)))}


def grid(count):
    cols = min(3, count)
    return (count + cols - 1) // cols, cols


def save(fig, out, stem, written):
    fig.tight_layout()
    for extension in ("png", "svg"):
        path = os.path.join(out, f"{stem}.{extension}")
        fig.savefig(path + ".tmp", format=extension)
        os.replace(path + ".tmp", path)  # atomically, as every result
        written.append(path)
    plt.close(fig)


# Which of verify.json's checks each figure shows (docs/reference/verify.md).
POSITION_CHECKS = {"joint_position_limit", "closing_joint_limit"}
TORQUE_CHECKS = {"torque_limit"}
CONTACT_CHECKS = {"contact_unilateral", "contact_friction", "contact_cop", "contact_yaw", "contact_wrench_admissible",
                  "inner_feasibility", "inner_problem_solved", "closure", "closure_drift"}


def read_verify(folder):
    """verify.json beside the result as {kind: (passed, [failing times])}, or None without one."""
    path = os.path.join(folder, "verify.json")
    if not os.path.exists(path):
        return None
    try:
        with open(path) as f:
            verify = json.load(f)
    except (OSError, ValueError) as e:
        raise BadResult(f"{path}: cannot read it ({e})")
    if not isinstance(verify, dict) or not isinstance(verify.get("checks"), list):
        raise BadResult(f"{path}: checks: expected a list (not a verify.json of mcopt verify?)")
    checks = {}
    for i, check in enumerate(verify["checks"]):
        times = check.get("failing_times") if isinstance(check, dict) else None
        if not isinstance(times, list) or not all(isinstance(t, (int, float)) for t in times) or "kind" not in check:
            raise BadResult(f"{path}: checks[{i}]: expected a kind and failing_times, a list of numbers")
        checks[check["kind"]] = (bool(check.get("passed")), times)
    return checks


def mark(ax, verify, kinds):
    """Red lines at the instants verify found any of `kinds` broken; True when there were some."""
    times = sorted({t for kind, (_, failing) in (verify or {}).items() if kind in kinds for t in failing})
    for t in times:
        ax.axvline(t, color="tab:red", lw=0.8, alpha=0.5, zorder=0)
    return bool(times)


def verify_figure(result, verify, out, written):
    """Each check of verify.json: the instants at which it is broken, over the motion."""
    if verify is None:
        return
    kinds = list(verify)
    fig, ax = plt.subplots(figsize=(10, 0.45 * len(kinds) + 1.5))
    for row, kind in enumerate(kinds):
        _, times = verify[kind]
        ax.plot(times, [row] * len(times), "|", color="tab:red", markersize=12)
    ax.set_yticks(range(len(kinds)))
    ax.set_yticklabels([f"{kind} ({'pass' if verify[kind][0] else 'FAIL'})" for kind in kinds], fontsize=8)
    ax.set_ylim(-0.5, len(kinds) - 0.5)
    ax.invert_yaxis()
    ax.set_xlim(0.0, field(result, "duration"))
    ax.set_xlabel("time [s]")
    failed = [k for k in kinds if not verify[k][0]]
    ax.set_title("mcopt verify: every check holds between the samples" if not failed else
                 f"mcopt verify: {len(failed)} checks broken (red: the instants)")
    save(fig, out, "verify", written)


def within_limits(result, out, written, values_key, lower, upper, stem, what, verify=None, kinds=()):
    """Per limb, each joint's value scaled into its limits: 0 at the lower, 1 at the upper."""
    time, names, values = field(result, "time"), field(result, "joint_names"), field(result, values_key)
    groups = joint_groups(names)
    rows, cols = grid(len(groups))
    fig, axes = plt.subplots(rows, cols, figsize=(5 * cols, 3.2 * rows), squeeze=False)
    unlimited = 0
    for ax, (limb, joints) in zip(axes.flat, groups.items()):
        for k, j in enumerate(joints):
            lo, hi = lower[j], upper[j]
            if lo is None or hi is None or not hi > lo:
                unlimited += 1
                continue
            colour, style = STYLES[k % len(STYLES)]
            ax.plot(time, [(row[j] - lo) / (hi - lo) for row in values], style, color=colour, lw=1.2, label=names[j])
        ax.axhline(0.0, color="k", lw=0.8, ls="--")
        ax.axhline(1.0, color="k", lw=0.8, ls="--")
        mark(ax, verify, kinds)
        ax.set_title(limb)
        ax.set_xlabel("time [s]")
        ax.set_ylabel("0 = lower, 1 = upper limit")
        ax.legend(fontsize=6, ncol=2)
    for ax in axes.flat[len(groups):]:
        ax.axis("off")
    broken = any(not verify[k][0] and verify[k][1] for k in kinds if k in verify) if verify else False
    fig.suptitle(what + (f" ({unlimited} joints without limits not drawn)" if unlimited else "") +
                 (" · red lines: instants mcopt verify found broken" if broken else ""))
    save(fig, out, stem, written)


def contact_figures(result, out, written, verify=None):
    time, contacts = field(result, "time"), field(result, "contacts")
    fig, axes = plt.subplots(len(contacts), 3, figsize=(15, 3.4 * len(contacts)), squeeze=False)
    for row, contact in zip(axes, contacts):
        wrench = contact["wrench"]
        for ax in row:
            mark(ax, verify, CONTACT_CHECKS)
        for ax, (first, unit, labels) in zip(row[:2], ((0, "N", "fx fy fz"), (3, "N m", "mx my mz"))):
            for i, label in enumerate(labels.split()):
                ax.plot(time, [w[first + i] if w is not None else math.nan for w in wrench], label=label)
            ax.set_title(f"{contact['name']}: {'force' if first == 0 else 'moment'} in the contact frame")
            ax.set_xlabel("time [s]")
            ax.set_ylabel(unit)
            ax.legend(fontsize=7)
        margin = [m if m is not None else math.nan for m in contact["friction_margin_N"]]
        row[2].plot(time, margin, color="tab:green")
        row[2].axhline(0.0, color="k", lw=0.8, ls="--")
        row[2].set_title(f"{contact['name']}: friction-cone margin μ f_z − ‖f_t‖ (μ = {contact.get('friction', '?')})")
        row[2].set_xlabel("time [s]")
        row[2].set_ylabel("N")
    save(fig, out, "contact_wrenches", written)

    fig, axes = plt.subplots(1, len(contacts), figsize=(5 * len(contacts), 4.6), squeeze=False)
    for ax, contact in zip(axes.flat, contacts):
        rect = contact.get("rectangle_m")
        if rect:
            (x0, x1), (y0, y1) = rect["x"], rect["y"]
            ax.plot([x0, x1, x1, x0, x0], [y0, y0, y1, y1, y0], "k-", lw=1.2, label="contact rectangle")
        points = [(t, p) for t, p in zip(time, contact["center_of_pressure"]) if p is not None and None not in p]
        if points:
            sc = ax.scatter([p[0] for _, p in points], [p[1] for _, p in points], c=[t for t, _ in points], s=12, cmap="viridis")
            fig.colorbar(sc, ax=ax, label="time [s]")
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_title(f"{contact['name']}: centre of pressure")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.legend(fontsize=7, loc="upper right")
    save(fig, out, "center_of_pressure", written)


def power_figure(result, out, written):
    names = field(result, "joint_names")
    fine = result.get("power_fine")
    time, power = (fine["time"], fine["power"]) if fine else (field(result, "time"), field(result, "power"))
    groups = joint_groups(names)
    fig, (ax, ax_energy) = plt.subplots(2, 1, figsize=(10, 7.5), sharex=True)
    for g, (limb, joints) in enumerate(groups.items()):
        colour = STYLES[g % len(STYLES)][0]
        for k, j in enumerate(joints):
            ax.plot(time, [row[j] for row in power], color=colour, lw=0.9, alpha=0.8, label=limb if k == 0 else None)
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_ylabel("electrical power per joint [W]")
    ax.legend(fontsize=7, ncol=3)
    ax.set_title("power (a limb's joints share its colour)")
    # ∫ Σ max(P, 0) dt by trapezoids: the energy result.json reports (over its samples).
    positive = [sum(max(p, 0.0) for p in row) for row in power]
    energy, cumulative = 0.0, [0.0]
    for s in range(1, len(time)):
        energy += 0.5 * (positive[s - 1] + positive[s]) * (time[s] - time[s - 1])
        cumulative.append(energy)
    ax_energy.plot(time, cumulative, color="tab:red")
    ax_energy.set_xlabel("time [s]")
    ax_energy.set_ylabel("cumulative energy ∫ Σ max(P, 0) dt [J]")
    reference = result.get("energy_fine") if fine else result.get("energy")
    which = "energy_fine" if fine else "energy"
    ax_energy.set_title(f"∫ Σ max(P, 0) dt = {energy:.6g} J over the {'output ' if fine else ''}samples")
    save(fig, out, "power_energy", written)
    # The curve's end against the figure result.json gives for the same instants (a test reads it).
    return f"cumulative energy {energy!r} J, result.json {which} {reference!r} J"


def convergence_figure(result, out, written):
    history = field(result, "history")
    if not history:
        return
    its = list(range(len(history)))
    fig, (ax_obj, ax_inf) = plt.subplots(2, 1, figsize=(9, 6.5), sharex=True)
    ax_obj.plot(its, [h["objective"] for h in history], color="tab:blue")
    ax_obj.set_ylabel("objective")
    ax_obj.set_yscale("symlog", linthresh=1e-3)
    ax_obj.set_title(f"Ipopt's convergence: {len(history)} iterations, {result.get('status', '?')}")
    for key, label in (("violation", "constraint violation"), ("dual_infeasibility", "dual infeasibility")):
        ax_inf.plot(its, [max(h[key], 1e-20) for h in history], label=label)
    if any(h.get("miss_m") is not None for h in history):
        # A throw: each iterate's miss [m] on the same log axis (gaps: Ipopt's restoration phase).
        ax_inf.plot(its, [None if h.get("miss_m") is None else max(h["miss_m"], 1e-20) for h in history],
                    label="throw's miss distance [m]", color="tab:red", linewidth=0.8)
    ax_inf.set_yscale("log")
    ax_inf.set_xlabel("iteration (all stages in turn)")
    ax_inf.legend()
    save(fig, out, "convergence", written)


def throw_figure(result, out, written):
    """A throw's ball from its release to the target's height: side (x–z) and top (x–y)
    views of p + v τ + ½ g τ², with the target (and its box) and the landing point."""
    release = result.get("release")
    if not release:
        return
    p, v, g = release["position"], release["velocity"], result.get("gravity", [0.0, 0.0, -9.81])
    tau = release["flight_time"]
    steps = 100
    flight = [[p[i] + v[i] * t + 0.5 * g[i] * t * t for i in range(3)] for t in (tau * k / steps for k in range(steps + 1))]
    target, half = release["target"], release["target_half_widths_m"]
    landing = release["landing_point"]
    fig, (side, top) = plt.subplots(1, 2, figsize=(12, 4.5))
    for ax, (a, b), labels in ((side, (0, 2), ("x [m]", "z [m]")), (top, (0, 1), ("x [m]", "y [m]"))):
        ax.plot([f[a] for f in flight], [f[b] for f in flight], color="tab:blue", label="ball's flight")
        ax.plot([p[a]], [p[b]], "o", color="tab:blue", label=f"release at t = {release['time']:.3f} s")
        ax.plot([target[a]], [target[b]], "x", color="tab:red", markersize=10, label="target")
        ax.plot([landing[a]], [landing[b]], "+", color="black", markersize=12, label="landing point")
        ax.set_xlabel(labels[0])
        ax.set_ylabel(labels[1])
        ax.set_aspect("equal", adjustable="datalim")
    if half[0] > 0 or half[1] > 0:
        top.add_patch(plt.Rectangle((target[0] - half[0], target[1] - half[1]), 2 * half[0], 2 * half[1], fill=False,
                                    edgecolor="tab:red", linestyle="--", label="target box"))
    side.axhline(target[2], color="gray", linewidth=0.8)
    side.set_title(f"side view: {release['speed_m_s']:.2f} m/s at {release['elevation_deg']:.1f}°, "
                   f"flight {tau:.3f} s")
    top.set_title(f"top view: miss {release['miss_distance_m']:.2e} m")
    top.legend(fontsize="small")
    save(fig, out, "throw", written)


def main(argv):
    if len(argv) != 3:
        print("usage: plot_result.py RESULT_DIR OUT_DIR", file=sys.stderr)
        return 2
    source = os.path.join(argv[1], "result.json")
    try:
        with open(source) as f:
            result = json.load(f)
    except (OSError, ValueError) as e:
        print(f"{source}: cannot read a result ({e})", file=sys.stderr)
        return 2
    written = []
    try:
        verify = read_verify(argv[1])
        os.makedirs(argv[2], exist_ok=True)
        limits = field(result, "joint_limits")
        within_limits(result, argv[2], written, "q", limits["position_lower"], limits["position_upper"], "joint_positions",
                      "joint positions within their limits", verify, POSITION_CHECKS)
        torque = [None if t is None else -t for t in limits["torque"]]
        within_limits(result, argv[2], written, "torques", torque, limits["torque"], "joint_torques",
                      "joint torques within their limits (0 = −limit, 1 = +limit)", verify, TORQUE_CHECKS)
        contact_figures(result, argv[2], written, verify)
        verify_figure(result, verify, argv[2], written)
        energy_line = power_figure(result, argv[2], written)
        convergence_figure(result, argv[2], written)
        throw_figure(result, argv[2], written)
    except BadResult as e:
        message = str(e)
        print(message if message.startswith(os.path.join(argv[1], "verify.json")) else f"{source}: {message}", file=sys.stderr)
        return 2
    print("\n".join(written))
    print(energy_line)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
