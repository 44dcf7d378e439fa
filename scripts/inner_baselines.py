#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""Fair baselines for the inner contact-force solvers (issue 19, docs/theory/inner-problem.md).

Random feasible inner problems of the report contact model (formulation.md §7) are each
solved twice over: by an independent conic solver — CVXOPT's coneqp, an interior-point
method for quadratic programs over second-order cones, fed from this file's own reading of
the problem (not mcopt's assembly) — and by `mcopt inner --cold` with each of its solvers.
A solver *reaches the conic optimum* on a problem when its wrenches are feasible to 1e-8
(rows, cones and balance, relative to 1 + the largest |fz|, as tests/inner_qp measure) and
its objective, with the Tikhonov term, is at most 1e-6 (1 + |f*|) above the conic one's.

    scripts/inner_baselines.py [--count N] [--seed S] [--mcopt PATH] [--out REPORT.json]
                               [--keep DIR] [--solvers active-set,slsqp,ipopt,auglag-mma,auglag-lbfgs]

Prints a Markdown table and every miss (problem, solver, status, objective gap, violation,
message); REPORT.json holds the same. Problems whose conic optimum CVXOPT cannot certify are
left out and counted. Exit code 0 (a miss is a finding, not an error); 2 when more than 1 % of
the problems have no certified reference (the comparison would not be fair).
"""
import argparse
import json
import math
import os
import pathlib
import subprocess
import sys
import tempfile

import numpy as np
from cvxopt import matrix, solvers

TIKHONOV = 1e-9  # mcopt's default (inner_qp/contact_problem.hpp), passed explicitly below
FEASIBLE = 1e-8
GAP = 1e-6


def rotation_rpy(roll, pitch, yaw):
    cr, sr, cp, sp, cy, sy = math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch), math.cos(yaw), math.sin(yaw)
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return rz @ ry @ rx


def quaternion_xyzw(r):
    # Shepperd's method, the branch on the largest diagonal term.
    t = np.trace(r)
    if t > 0:
        s = math.sqrt(t + 1.0) * 2
        return [(r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s, 0.25 * s]
    i = int(np.argmax(np.diag(r)))
    j, k = (i + 1) % 3, (i + 2) % 3
    s = math.sqrt(1.0 + r[i, i] - r[j, j] - r[k, k]) * 2
    q = [0.0, 0.0, 0.0, 0.0]
    q[i] = 0.25 * s
    q[j] = (r[j, i] + r[i, j]) / s
    q[k] = (r[k, i] + r[i, k]) / s
    q[3] = (r[k, j] - r[j, k]) / s
    return q


def skew(p):
    return np.array([[0, -p[2], p[1]], [p[2], 0, -p[0]], [-p[1], p[0], 0]])


def wrench_to_world(rotation, position):
    """6 × 6: a wrench in the contact frame (force, moment) → world axes, about the origin."""
    x = np.zeros((6, 6))
    x[:3, :3] = rotation
    x[3:, 3:] = rotation
    x[3:, :3] = skew(position) @ rotation
    return x


def generate(rng, contacts, joints, hands_free=False):
    """A feasible problem: feet near the floor, a hand on a wall (third contact), a hand on a
    table (fourth); random J1, τ0, weights; the balance wrench made by admissible wrenches
    strictly inside every cone and rectangle — or, `hands_free`, by the feet alone, so that
    the optimum often leaves a hand unloaded, at its cone's apex (where a smooth solver's
    constraint qualification is weakest, formulation.md §7)."""
    u = lambda: rng.uniform(-1.0, 1.0)
    specs, balance = [], np.zeros(6)
    for i in range(contacts):
        mu = 0.4 + 0.4 * abs(u())
        half_x, half_y = 0.03 + 0.1 * abs(u()), 0.02 + 0.05 * abs(u())
        cx, cy = 0.02 * u(), 0.01 * u()
        rect = [cx - half_x, cx + half_x, cy - half_y, cy + half_y]
        yaw = math.pi * u()
        if i == 2:
            rotation = rotation_rpy(0.0, -math.pi / 2, yaw)
        else:
            rotation = rotation_rpy(0.1 * u(), 0.1 * u(), yaw)
        position = np.array([0.5 * u(), 0.5 * u(), 1.0 + 0.2 * u() if i >= 2 else 0.05 * u()])
        fz = 50.0 + 200.0 * abs(u())
        angle, shear = math.pi * u(), 0.8 * mu * fz * abs(u())
        cop_x = rect[0] + (rect[1] - rect[0]) * (0.1 + 0.8 * abs(u()))
        cop_y = rect[2] + (rect[3] - rect[2]) * (0.1 + 0.8 * abs(u()))
        admissible = np.array([shear * math.cos(angle), shear * math.sin(angle), fz, cop_y * fz, -cop_x * fz, 5.0 * u()])
        if hands_free and i >= 2:
            admissible[:] = 0.0
        balance += wrench_to_world(rotation, position) @ admissible
        specs.append({"name": f"contact{i}", "position": position.tolist(), "quaternion_xyzw": quaternion_xyzw(rotation),
                      "mu": mu, "rectangle": rect, "min_normal_force": 0.0, "_rotation": rotation})
    j1 = rng.uniform(-1.0, 1.0, (joints, 6 * contacts))
    tau0 = 30.0 * rng.uniform(-1.0, 1.0, joints)
    weights = 0.01 + 0.1 * np.abs(rng.uniform(-1.0, 1.0, joints))
    linear = rng.uniform(-1.0, 1.0, joints)
    return {"contacts": specs, "wrench_to_torque": j1, "tau0": tau0, "balance_wrench": balance,
            "torque_weights": weights, "torque_linear": linear}


def as_json(problem):
    return {"contacts": [{k: v for k, v in c.items() if not k.startswith("_")} for c in problem["contacts"]],
            "wrench_to_torque": problem["wrench_to_torque"].tolist(), "tau0": problem["tau0"].tolist(),
            "balance_wrench": problem["balance_wrench"].tolist(), "torque_weights": problem["torque_weights"].tolist(),
            "torque_linear": problem["torque_linear"].tolist()}


def pieces(problem):
    """Objective ½FᵀPF + qᵀF + const, balance A F = b, linear rows G F ≤ h, cones."""
    j1, w, l, tau0 = problem["wrench_to_torque"], problem["torque_weights"], problem["torque_linear"], problem["tau0"]
    n = j1.shape[1]
    p = 2.0 * j1.T @ (w[:, None] * j1) + TIKHONOV * np.eye(n)
    q = -j1.T @ (2.0 * w * tau0 + l)
    const = float(np.sum((w * tau0 + l) * tau0))
    a = np.hstack([wrench_to_world(c["_rotation"], np.array(c["position"])) for c in problem["contacts"]])
    rows, bounds = [], []
    for i, c in enumerate(problem["contacts"]):
        x_min, x_max, y_min, y_max = c["rectangle"]
        def row(entries, bound=0.0):
            r = np.zeros(n)
            for k, v in entries:
                r[6 * i + k] += v
            rows.append(r)
            bounds.append(bound)
        fx, fy, fz, mx, my = 0, 1, 2, 3, 4
        row([(fz, -1.0)], -c["min_normal_force"])      # fz ≥ f_min
        row([(my, -1.0), (fz, -x_max)])                 # −m_y ≤ x_max fz
        row([(my, 1.0), (fz, x_min)])                   # x_min fz ≤ −m_y
        row([(mx, 1.0), (fz, -y_max)])                  # m_x ≤ y_max fz
        row([(mx, -1.0), (fz, y_min)])                  # y_min fz ≤ m_x
    return p, q, const, a, np.array(rows), np.array(bounds)


def objective(problem, f):
    p, q, const, *_ = pieces(problem)
    return float(0.5 * f @ p @ f + q @ f + const)


def violation(problem, f):
    _, _, _, a, g, h = pieces(problem)
    worst = float(np.max(np.abs(a @ f - problem["balance_wrench"])))
    worst = max(worst, float(np.max(g @ f - h)))
    for i, c in enumerate(problem["contacts"]):
        worst = max(worst, math.hypot(f[6 * i], f[6 * i + 1]) - c["mu"] * f[6 * i + 2])
    scale = max(1.0 + abs(f[6 * i + 2]) for i in range(len(problem["contacts"])))
    return max(worst, 0.0) / scale


def conic_optimum(problem):
    p, q, _, a, g, h = pieces(problem)
    n, nc = p.shape[0], len(problem["contacts"])
    cone_rows = np.zeros((3 * nc, n))
    for i, c in enumerate(problem["contacts"]):
        cone_rows[3 * i, 6 * i + 2] = -c["mu"]   # s0 = μ fz
        cone_rows[3 * i + 1, 6 * i] = -1.0       # s1 = fx
        cone_rows[3 * i + 2, 6 * i + 1] = -1.0   # s2 = fy
    big_g = np.vstack([g, cone_rows])
    big_h = np.concatenate([h, np.zeros(3 * nc)])
    solvers.options.update({"show_progress": False, "abstol": 1e-9, "reltol": 1e-10, "feastol": 1e-10, "maxiters": 200})
    # Forces in units of `unit` newtons and the objective in `scale` watts: a second and third
    # try when CVXOPT's scaling update breaks down (a square root of a negative number).
    for unit, scale in ((1.0, 1.0), (100.0, 1e3), (10.0, 1e2)):
        try:
            result = solvers.coneqp(matrix(p * unit * unit / scale), matrix(q * unit / scale), matrix(big_g * unit),
                                    matrix(big_h), {"l": g.shape[0], "q": [3] * nc, "s": []}, matrix(a * unit),
                                    matrix(problem["balance_wrench"]))
            break
        except (ValueError, ArithmeticError):
            continue
    else:
        return np.full(n, math.nan), "breakdown"
    f = np.array(result["x"]).ravel() * unit
    # With 12 joints H is singular but for the 1e-9 Tikhonov term, and CVXOPT often stops
    # with "unknown" when it can no longer make progress, its duality gap already ~1e-15
    # relative while its own residual measure (slacks included) stays near 1e-6. Its point is
    # taken as the reference when this file's own check finds it feasible to 1e-10 and the
    # relative duality gap is below 1e-8; a solver that finds a feasible point more than the
    # comparison's tolerance below it is reported ("reference beaten"), never hidden.
    certified = (result["relative gap"] is not None and result["relative gap"] <= 1e-8 and
                 bool(np.all(np.isfinite(f))) and violation(problem, f) <= 1e-10)
    return f, "optimal" if certified else result["status"]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--count", type=int, default=1000)
    parser.add_argument("--seed", type=int, default=19)
    parser.add_argument("--mcopt", default=os.environ.get("MCOPT_EXECUTABLE", "build/release/apps/mcopt"))
    parser.add_argument("--solvers", default="active-set,slsqp,ipopt,auglag-mma,auglag-lbfgs")
    parser.add_argument("--out", help="report JSON (written atomically)")
    parser.add_argument("--keep", help="folder for the problems and mcopt's outputs (default: a temporary one)")
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    # Problems the conic reference cannot certify are left out (and counted): the comparison
    # needs a trusted optimum. Generation continues until `count` are certified.
    problems, reference, uncertified = [], [], 0
    k = 0
    while len(problems) < args.count:
        # Families in turn: 2, 3, 4 contacts; 12 joints (H singular on the balance's null
        # space: the hard case) or 30 (HRP-2's count); with 3 and 4 contacts, every other time
        # the balance is made by the feet alone (hands often unloaded at the optimum).
        contacts = 2 + k % 3
        problem = generate(rng, contacts, 12 if (k // 3) % 2 == 0 else 30, hands_free=contacts > 2 and (k // 6) % 2 == 1)
        k += 1
        f, status = conic_optimum(problem)
        if status != "optimal":
            uncertified += 1
            continue
        problems.append(problem)
        reference.append((f, objective(problem, f)))
    if uncertified > args.count // 100:
        print(f"inner_baselines: the conic reference could not certify {uncertified} problems", file=sys.stderr)
        sys.exit(2)

    work = pathlib.Path(args.keep) if args.keep else pathlib.Path(tempfile.mkdtemp(prefix="mcopt-baselines-"))
    work.mkdir(parents=True, exist_ok=True)
    problem_file = work / "problems.json"
    problem_file.write_text(json.dumps({"problems": [as_json(p) for p in problems]}))
    table, misses, beaten = {}, [], []
    for solver in args.solvers.split(","):
        out = work / f"{solver}.json"
        run = subprocess.run([args.mcopt, "inner", "--problems", str(problem_file), "--solver", solver, "--cold",
                              "--tikhonov", repr(TIKHONOV), "--out", str(out)], capture_output=True, text=True)
        if run.returncode not in (0, 1):
            print(run.stderr, file=sys.stderr)
            sys.exit(run.returncode)
        results = json.loads(out.read_text())["results"]
        reached = optimal = 0
        for k, (problem, result) in enumerate(zip(problems, results)):
            f = np.array(result["wrenches"], dtype=float).ravel()
            f_star, objective_star = reference[k]
            value = objective(problem, f) if np.all(np.isfinite(f)) else math.inf
            gap = value - objective_star
            infeasibility = violation(problem, f) if np.all(np.isfinite(f)) else math.inf
            ok = infeasibility <= FEASIBLE and gap <= GAP * (1.0 + abs(objective_star))
            reached += int(ok)
            if infeasibility <= FEASIBLE and gap < -GAP * (1.0 + abs(objective_star)):
                beaten.append({"problem": k, "solver": solver, "relative_gap": gap / (1.0 + abs(objective_star))})
            optimal += int(result["status"] == "optimal")
            if not ok:
                misses.append({"problem": k, "contacts": len(problem["contacts"]),
                               "joints": int(problem["wrench_to_torque"].shape[0]), "solver": solver,
                               "status": result["status"], "relative_gap": gap / (1.0 + abs(objective_star)),
                               "violation": infeasibility, "message": result.get("message", ""),
                               "least_fz_at_optimum": float(min(f_star[6 * i + 2] for i in range(len(problem["contacts"]))))})
        table[solver] = {"reached": reached, "optimal_status": optimal, "count": len(problems)}
    unloaded = sum(1 for problem, (f, _) in zip(problems, reference)
                   if min(f[6 * i + 2] for i in range(len(problem["contacts"]))) < 1e-3)
    print(f"{len(problems)} problems, seed {args.seed}, {unloaded} with a contact unloaded at the optimum (fz < 1 mN); "
          f"{uncertified} more generated and left out (conic reference not certified)")
    print(f"| solver | reaches the conic optimum (of {len(problems)}) | status optimal |")
    print("|---|---|---|")
    for solver, row in table.items():
        print(f"| {solver} | {row['reached']} ({100.0 * row['reached'] / row['count']:.1f} %) | {row['optimal_status']} |")
    for m in misses:
        print(f"miss: problem {m['problem']} ({m['contacts']} contacts, {m['joints']} joints), {m['solver']}: {m['status']}, "
              f"relative gap {m['relative_gap']:.2e}, violation {m['violation']:.2e}, least fz at the optimum "
              f"{m['least_fz_at_optimum']:.3g} N; {m['message']}")
    for b in beaten:
        print(f"reference beaten: problem {b['problem']} by {b['solver']}, relative {b['relative_gap']:.2e}")
    if args.out:
        target = pathlib.Path(args.out)
        temporary = target.with_name(target.name + ".tmp")
        temporary.write_text(json.dumps({"seed": args.seed, "count": len(problems), "unloaded_at_optimum": unloaded,
                                                    "uncertified_left_out": uncertified,
                                                    "table": table, "misses": misses,
                                                    "reference_beaten": beaten},
                                        indent=1) + "\n")
        temporary.replace(target)


if __name__ == "__main__":
    main()
