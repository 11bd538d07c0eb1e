#!/usr/bin/env python3
"""Stability map of a sheared suspension (issue 16): volume fraction x time step x contact stiffness
on the Couette scene, each run long enough to show a blow-up, and how each run ends.

Every run is couette.py (same box, seed, a1/Delta 3, implicit springs, the docs/contact.md recipe's
k_n = k_t = 2 F_max/h_r, or that times --stiffness). A run that stops reports its error (the last
ERROR / FATAL line of its logs); a finished one its gaps, inner iterations and the stress balance.
Every run's particle records are checked for non-finite values (there must be none, finished or not).

  stabilityMap.py                      phi 0.27 and 0.47 x dt 0.02, 0.05, 0.1 x stiffness 1, 10
  stabilityMap.py --quick              phi 0.47, dt 0.05 and 0.1, stiffness 1

Writes --out (default docs/data/benchmarks_stabilityMap.json) and a figure beside it.
"""
import argparse
import glob
import itertools
import json
import os
import subprocess
import sys
from typing import Dict, List, Optional

import numpy as np

from fdmsubgrid import case, couettescene, files, output, results

HERE = os.path.dirname(os.path.abspath(__file__))
PROJECT = os.path.dirname(os.path.dirname(HERE))


def run_one(phi: float, dt: float, stiffness: float, args: argparse.Namespace) -> Dict:
    name = "phi%g_dt%g_k%g" % (phi, dt, stiffness)
    workdir = os.path.join(args.workdir, name)
    out = os.path.join(args.workdir, name + ".json")
    row: Dict = dict(phi=phi, dt=dt, stiffness_factor=stiffness, run=name)
    if os.path.exists(out):
        with open(out) as f:
            return json.load(f)
    cmd = [sys.executable, os.path.join(HERE, "couette.py"), "--phi", str(phi), "--size", *map(str, args.size),
           "--dt", str(dt), "--strain", str(args.strain), "--seed", str(args.seed), "--dump-every", str(max(dt, 0.1)),
           "--workdir", workdir, "--out", os.path.join(args.workdir, name + ".results.json"), "--overwrite"]
    if stiffness != 1:
        # the recipe's springs (at the nominal phi) times the factor
        rule = couettescene.choose_springs(phi, dt, couettescene.A1 / 3.0)
        cmd += ["--kn", repr(rule.kn * stiffness), "--kt", repr(rule.kt * stiffness)]
    print("running:", " ".join(cmd), flush=True)
    proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, errors="replace")
    run_dirs = sorted(glob.glob(os.path.join(workdir, "phi*")))
    run_dir = run_dirs[0] if run_dirs else None
    row["finished"] = proc.returncode == 0
    row["error"] = None if proc.returncode == 0 else (case.last_error(run_dir) if run_dir else proc.stdout[-400:])
    row["records_finite"] = case.records_finite(run_dir) if run_dir else None
    if run_dir and os.path.exists(os.path.join(run_dir, "fluid", "postProcessing", "fdm", "steps.dat")):
        steps = output.steps(os.path.join(run_dir, "fluid"))
        row["steps_done"] = int(len(steps["step"]))
        row["strain_reached"] = float(len(steps["step"]) * dt)
        row["inner_iterations_mean"] = float(np.mean(steps["innerIterations"])) if len(steps["step"]) else None
        row["unconverged_steps"] = int(np.sum(steps["converged"] == 0))
    if proc.returncode == 0:
        r = results.read_data(os.path.join(args.workdir, name + ".results.json"))
        for k in ("min_pair_gap", "min_wall_gap", "eta_s", "eta_s_err", "stress_balance_rel_error", "springs",
                  "core_seconds_per_strain_unit", "n_particles"):
            row[k] = r.get(k)
    files.write_json(out, row)   # whole or absent: a rerun takes it instead of running
    return row


def plot(rows: List[Dict], path: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4))
    for r in rows:
        x, y = r["dt"] * (1.06 if r["stiffness_factor"] != 1 else 0.94), r["phi"]
        ok = r["finished"] and r.get("records_finite") is not False
        ax.scatter([x], [y], marker="o" if ok else "x", s=80, c="tab:green" if ok else "tab:red",
                   edgecolors="k" if r["stiffness_factor"] != 1 else None)
        label = "%.1f" % (r["inner_iterations_mean"] or 0)
        ax.annotate(label, (x, y), textcoords="offset points", xytext=(6, 6), fontsize=7)
    ax.set_xscale("log")
    ax.set_xlabel("Δt γ̇0 (left: recipe springs, right: 10 × stiffer)")
    ax.set_ylabel("φ_bulk")
    ax.set_title("Couette scene: o finished, x stopped (numbers: solves per step)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main(argv: Optional[List[str]] = None) -> Dict:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--phis", type=float, nargs="+", default=[0.27, 0.47])
    p.add_argument("--dts", type=float, nargs="+", default=[0.02, 0.05, 0.1])
    p.add_argument("--stiffness", type=float, nargs="+", default=[1.0, 10.0])
    p.add_argument("--size", type=float, nargs=3, default=(10, 12, 8))
    p.add_argument("--strain", type=float, default=2.0)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--quick", action="store_true")
    p.add_argument("--workdir", default=os.path.join(HERE, "runs", "stabilityMap"))
    p.add_argument("--out", default=os.path.join(PROJECT, "docs", "data", "benchmarks_stabilityMap.json"))
    args = p.parse_args(argv)
    if args.quick:
        args.phis, args.dts, args.stiffness = [0.47], [0.05, 0.1], [1.0]
    os.makedirs(args.workdir, exist_ok=True)
    rows = [run_one(phi, dt, k, args) for phi, dt, k in itertools.product(args.phis, args.dts, args.stiffness)]
    summary = dict(rows=rows, size=list(args.size), strain=args.strain, seed=args.seed,
                   command="cases/couette/stabilityMap.py " + " ".join(argv if argv is not None else sys.argv[1:]))
    with open(args.out, "w") as f:
        json.dump(summary, f, indent=1)
    plot(rows, os.path.splitext(args.out)[0] + ".png")
    print("%-22s %-9s %-7s %-10s %-10s %-8s %s" % ("run", "finished", "finite", "solves/st", "min gap", "eta_s",
                                                   "error"))
    for r in rows:
        print("%-22s %-9s %-7s %-10s %-10s %-8s %s" % (
            r["run"], r["finished"], r.get("records_finite"), "%.1f" % (r.get("inner_iterations_mean") or 0),
            "%.2e" % r["min_pair_gap"] if r.get("min_pair_gap") is not None else "-",
            "%.2f" % r["eta_s"] if r.get("eta_s") is not None else "-", (r.get("error") or "")[:120]))
    return summary


if __name__ == "__main__":
    main()
