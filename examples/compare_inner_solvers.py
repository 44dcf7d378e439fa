#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""Compare three inner contact-force solvers over a motion — ours and the report's two (docs/reference/python.md).

The motion is a bundled two-contact scenario (by default the weight shift: both soles on the
floor) after a few Ipopt iterations (`mcopt run --max-iterations K`), its centre of mass on
the way to one side. At every sample the
inner problem of formulation.md §7 is built from the robot's state and solved by our
active-set method, NLopt's SLSQP and Ipopt, each warm-started from its previous sample as in
the bilevel formulation. Prints a table (status counts, mean time and iterations, the largest
objective difference from the active-set method) and draws objective, solve time and
iterations per sample into inner_solvers.png / .svg.

    PYTHONPATH=build/release/python python3 examples/compare_inner_solvers.py --out inner-solvers

(python3: the interpreter with Debian's numpy and matplotlib, the one the module was built for.)
"""
import argparse
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import mcopt  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[1]
SOLVERS = ("active-set", "slsqp", "ipopt")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", default=ROOT / "scenarios" / "hrp2_weight_shift.yaml", type=pathlib.Path)
    parser.add_argument("--contact-model", default="report", choices=["report", "pyramid", "wrench-cone"])
    parser.add_argument("--samples", type=int, default=40, help="samples of the motion (the scenario's field)")
    parser.add_argument("--iterations", type=int, default=5, help="Ipopt iterations of the scenario for the motion")
    parser.add_argument("--out", type=pathlib.Path, default=pathlib.Path("inner-solvers"))
    args = parser.parse_args()

    scenario = mcopt.Scenario(args.scenario)
    scenario["samples"] = args.samples
    motion = scenario.run(max_iterations=args.iterations, configuration_optimisation=False)
    robot = scenario.robot
    contacts = [c["name"] for c in motion["contacts"]]
    dynamics = mcopt.Dynamics(robot, motion["reference_body"])
    time = motion["time"]

    table = {}
    for name in SOLVERS:
        solver = mcopt.InnerSolver(name)
        previous = None
        rows = []
        for k in range(len(time)):
            active = [c for c, info in zip(contacts, motion["contacts"]) if info["active"][k]]
            problem = mcopt.InnerProblem.from_state(dynamics, motion["q"][k], motion["v"][k], motion["a"][k],
                                                    contacts=active, contact_model=args.contact_model)
            if previous is not None and previous.wrenches.shape[0] != len(active):
                previous = None
            result = solver.solve(problem, previous)
            previous = result
            rows.append((result.status, result.objective, result.to_dict()["solve_time_us"], result.iterations))
        table[name] = rows

    reference = np.array([r[1] for r in table["active-set"]])
    print(f"{args.scenario.name} after {args.iterations} iterations: {len(time)} samples, contacts {', '.join(contacts)}, model {args.contact_model}")
    print(f"{'solver':<11} {'optimal':>8} {'other':>6} {'mean µs':>10} {'mean it.':>9} {'max |Δ objective|':>18}")
    for name, rows in table.items():
        statuses = [r[0] for r in rows]
        objective = np.array([r[1] for r in rows])
        optimal = sum(s == "optimal" for s in statuses)
        both = np.array([s == "optimal" and t[0] == "optimal" for s, t in zip(statuses, table["active-set"])])
        gap = np.max(np.abs(objective - reference)[both]) if both.any() else float("nan")
        print(f"{name:<11} {optimal:>8} {len(rows) - optimal:>6} {np.mean([r[2] for r in rows]):>10.1f} "
              f"{np.mean([r[3] for r in rows]):>9.1f} {gap:>18.3e}")

    figure, axes = plt.subplots(3, 1, figsize=(8, 9), sharex=True)
    for name, rows in table.items():
        axes[0].plot(time, [r[1] for r in rows], label=name, marker=".")
        axes[1].semilogy(time, [max(r[2], 1e-1) for r in rows], label=name, marker=".")
        axes[2].plot(time, [r[3] for r in rows], label=name, marker=".")
    axes[0].set_ylabel("inner objective Σ wΓ² + lΓ [W]")
    axes[1].set_ylabel("solve time [µs]")
    axes[2].set_ylabel("iterations")
    axes[2].set_xlabel("time [s]")
    axes[0].legend()
    axes[0].set_title(f"Inner solvers over {args.scenario.stem} ({args.contact_model} contact model)")
    figure.tight_layout()
    args.out.mkdir(parents=True, exist_ok=True)
    for suffix in ("png", "svg"):
        figure.savefig(args.out / f"inner_solvers.{suffix}", dpi=110)
    print(f"figure: {args.out / 'inner_solvers.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
