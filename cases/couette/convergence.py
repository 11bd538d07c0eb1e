#!/usr/bin/env python3
"""Run time against error for a sheared suspension (issue 11): the Couette scene at several time
steps and two mesh sizes, the rheology of each with its error bar and its cost.

Every run is couette.py with the same packing (same box, phi_bulk and seed: the packing does not
depend on dt or a1/Delta) and the springs of the docs/contact.md recipe (k_t = k_n, whatever dt).
A run whose results file exists is not run again, so the study can be stopped and continued.

  convergence.py                      dt in {0.04, 0.02, 0.01} at a1/Delta = 3, dt 0.02 at 4, and
                                      tolLambda 1e-2 and 3e-3 (the case's 1e-3) at dt 0.02, a1/Delta 3
  convergence.py --strain 4 --quick   two runs only (dt 0.04 and 0.02 at a1/Delta = 3)

Writes <workdir>/<run>.json per run and --out (default docs/data/benchmarks_couetteConvergence.json) with
a figure beside it (eta_s, N2_hat and the stress balance against dt, core-seconds per strain unit).
"""
import argparse
import json
import os
import subprocess
import sys
from typing import Dict, List, Tuple

from fdmsubgrid import results

TOL_LAMBDA = 1e-3   # the case's default
HERE = os.path.dirname(os.path.abspath(__file__))
PROJECT = os.path.dirname(os.path.dirname(HERE))

KEYS = ("phi_bulk", "phi_core", "gamma_core_over_gamma0", "eta_s", "eta_s_err", "N1_hat", "N2_hat",
        "Sigma_c_hat", "stress_balance_rel_error", "stress_balance_rel_error_err", "strain_units",
        "steady_from_strain", "n_particles", "cells", "dt", "wall_seconds", "core_seconds_per_strain_unit",
        "inner_iterations_mean", "inner_iterations_max", "unconverged_steps", "min_pair_gap", "min_wall_gap",
        "springs")


def run_name(a_over_delta: int, dt: float, tol_lambda: float) -> str:
    return "ad%d_dt%g" % (a_over_delta, dt) + ("" if tol_lambda == TOL_LAMBDA else "_tol%g" % tol_lambda)


def run_one(a_over_delta: int, dt: float, tol_lambda: float, args: argparse.Namespace, run: bool = True) -> Dict | None:
    """One Couette run (or its results file if it exists): the keys of KEYS; None if it has no
    results file and run is False."""
    name = run_name(a_over_delta, dt, tol_lambda)
    out = os.path.join(args.workdir, name + ".json")
    if not os.path.exists(out):
        if not run:
            return None
        cmd = [sys.executable, os.path.join(HERE, "couette.py"), "--phi", str(args.phi), "--size", *map(str, args.size),
               "--a-over-delta", str(a_over_delta), "--dt", str(dt), "--strain", str(args.strain),
               "--seed", str(args.seed), "--tol-lambda", str(tol_lambda), "--workdir", os.path.join(args.workdir, name), "--out", out, "--overwrite"]
        print("running:", " ".join(cmd), flush=True)
        subprocess.run(cmd, check=True)
    r = results.read_data(out)
    return {k: r.get(k) for k in KEYS} | {"a_over_delta": a_over_delta, "tol_lambda": tol_lambda, "run": name}


def plot(runs: List[Dict], path: str) -> None:
    """eta_s and N2_hat against dt (one series per a1/Delta), and the cost per strain unit."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 3, figsize=(12, 3.6))
    for ad, tol in sorted({(r["a_over_delta"], r["tol_lambda"]) for r in runs}):
        rs = sorted((r for r in runs if r["a_over_delta"] == ad and r["tol_lambda"] == tol), key=lambda r: r["dt"])
        label = "a1/Δ = %d, tolLambda %g" % (ad, tol)
        dts = [r["dt"] for r in rs]
        ax[0].errorbar(dts, [r["eta_s"] for r in rs], [r["eta_s_err"] for r in rs], marker="o", capsize=3, label=label)
        ax[1].plot(dts, [r["stress_balance_rel_error"] * 100 for r in rs], marker="o", label=label)
        ax[2].plot(dts, [r["core_seconds_per_strain_unit"] for r in rs], marker="o", label=label)
    for a, ylabel in zip(ax, ("η_s (core)", "stress balance error [%]", "core-seconds per strain unit")):
        a.set_xscale("log")
        a.set_xlabel("Δt γ̇0")
        a.set_ylabel(ylabel)
        a.legend()
    ax[2].set_yscale("log")
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main(argv=None) -> Dict:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--phi", type=float, default=0.30)
    p.add_argument("--size", type=float, nargs=3, default=(10, 16, 8), help="box in a1 (L_y 16: a core 6 a1 wide)")
    p.add_argument("--strain", type=float, default=12.0)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--quick", action="store_true", help="dt 0.04 and 0.02 at a1/Delta = 3 only")
    p.add_argument("--runs", nargs="+", metavar="AD:DT[:TOL]", default=None,
                   help="run only these of the grid (e.g. 3:0.02 4:0.02 3:0.02:0.01), so that two processes can "
                   "share the grid; the summary holds every run of the grid whose results exist")
    p.add_argument("--workdir", default=os.path.join(HERE, "runs", "convergence"))
    p.add_argument("--out", default=os.path.join(PROJECT, "docs", "data", "benchmarks_couetteConvergence.json"))
    args = p.parse_args(argv)
    os.makedirs(args.workdir, exist_ok=True)
    grid: List[Tuple[int, float, float]] = [(3, 0.04, TOL_LAMBDA), (3, 0.02, TOL_LAMBDA)]
    if not args.quick:
        grid += [(3, 0.01, TOL_LAMBDA), (4, 0.02, TOL_LAMBDA), (3, 0.02, 1e-2), (3, 0.02, 3e-3)]
    if args.runs:
        chosen = []
        for spec in args.runs:
            fields = [float(v) for v in spec.split(":")]
            chosen.append((int(fields[0]), fields[1], fields[2] if len(fields) > 2 else TOL_LAMBDA))
        for ad, dt, tol in chosen:
            run_one(ad, dt, tol, args)
        grid += [c for c in chosen if c not in grid]
    runs = [r for r in (run_one(ad, dt, tol, args, run=not args.runs) for ad, dt, tol in grid) if r is not None]
    summary = dict(phi=args.phi, size=list(args.size), strain=args.strain, seed=args.seed,
                   command="cases/couette/convergence.py " + " ".join(argv if argv is not None else sys.argv[1:]),
                   runs=runs)
    with open(args.out, "w") as f:
        json.dump(summary, f, indent=1)
    figure = os.path.splitext(args.out)[0] + ".png"
    plot(runs, figure)
    print("%-16s %8s %14s %8s %8s %10s %10s %8s" % ("run", "phi_core", "eta_s", "N2_hat", "balance", "solves/st",
                                                 "core-s/str", "min gap"))
    for r in runs:
        print("%-16s %8.4f %7.3f ± %4.2f %8.3f %7.1f%% %10.1f %10.0f %8.1e" % (
            r["run"], r["phi_core"], r["eta_s"], r["eta_s_err"], r["N2_hat"], 100 * r["stress_balance_rel_error"],
            r["inner_iterations_mean"], r["core_seconds_per_strain_unit"], r["min_pair_gap"]))
    print("wrote %s and %s" % (args.out, figure))
    return summary


if __name__ == "__main__":
    main()
