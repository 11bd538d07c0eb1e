#!/usr/bin/env python3
"""Stokes flow through a simple cubic periodic array of spheres (paper section 5.1).

One free sphere of radius a in a fully periodic cube of side L, an imposed mean pressure gradient
grad P0 along x, and an external force on the sphere that balances it (Eqs. 42-43). The drag
coefficient K = F / (6 pi eta a U_s) (Eq. 40) with F = V0 |grad P0| (Eq. 43) and the slip velocity
U_s = <u> - U (Eq. 44) is averaged over sphere positions spread evenly inside one mesh cell, and
compared with Hasimoto's series (Eq. 41).

All positions of one configuration run in one coupled run, one position per time step (the
sphere is held: fix fdm/couple move no), each step warm-started from the previous flow.

  periodicArray.py                 L/a = 8, a/Delta = 5, 64 positions (8 computed), a few minutes
  periodicArray.py --full          L/a = 8, 10, 20 with 64 positions, and the c sweep of Table 2
  periodicArray.py --help          every option
"""
import argparse
import math
import os
import sys
import time
from typing import List

from fdmsubgrid import case
from fdmsubgrid.results import Row, relative, write_results
# the computation lives in the package (tests and scripts/benchmarkPeriodicArray.py use it too)
from fdmsubgrid.periodicarray import hasimoto_K, positions_in_cell, run_configuration  # noqa: F401

HERE = os.path.dirname(os.path.abspath(__file__))


# The paper's Table 4 (periodic array, (b, c) = (5, 0.3), 64 positions): L/a -> (K, error in %)
PAPER_TABLE4 = {8.0: (1.532059, 0.11), 10.0: (1.389611, 0.11), 20.0: (1.167027, 0.21), 30.0: (1.109563, 0.48),
                40.0: (1.085323, 0.84), 50.0: (1.073184, 1.23)}


def validation_rows(summary: dict) -> List[Row]:
    """The drag K of each run against Hasimoto's series, beside the paper's Table 4 where it has the run."""
    rows = []
    for run in summary["runs"]:
        paper = PAPER_TABLE4.get(float(run["L_over_a"])) if abs(run["c"] - 0.3) < 1e-12 else None
        rows.append(Row("K (Eq. 40)", "L/a %g, a/Δ %g, c %g, %d positions" % (run["L_over_a"], run["a_over_delta"],
                                                                            run["c"], run["n_positions"]),
                        run["K"], run["K_hasimoto"],
                        "%.6f (%+.2f %%)" % paper if paper else "—", relative(run["K"], run["K_hasimoto"]),
                        spread=run.get("sigma_K")))
    return rows


def plot(results, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(5, 3.6))
    Ls = sorted({r["L_over_a"] for r in results if abs(r["c"] - 0.3) < 1e-12})
    sim = [next(r for r in results if r["L_over_a"] == L and abs(r["c"] - 0.3) < 1e-12) for L in Ls]
    import numpy as np
    Lf = np.linspace(min(Ls) * 0.9, max(Ls) * 1.1, 100)
    ax.plot(Lf, [hasimoto_K(4 / 3 * math.pi / L ** 3) for L in Lf], "k-", label="Hasimoto (1958)")
    ax.errorbar(Ls, [r["K"] for r in sim], yerr=[r["sigma_K"] for r in sim], fmt="o", color="C3",
                label="fdmFoam + fdmDEM")
    ax.set_xlabel("L/a")
    ax.set_ylabel("K")
    ax.legend()
    ax.set_title("Periodic array of spheres (b, c) = (5, 0.3)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--full", action="store_true", help="L/a = 8, 10, 20 with 64 positions and the c sweep")
    p.add_argument("--L-over-a", type=float, nargs="+", default=[8.0])
    p.add_argument("--a-over-delta", type=float, default=5.0)
    p.add_argument("--positions", type=int, default=64,
                   help="lattice points in the cell, a cube: 1, 8, 27, 64 (even m: one octant computed)")
    p.add_argument("--c", type=float, nargs="+", default=[0.3], help="indicator parameter c (Eq. 36)")
    p.add_argument("--b", type=float, default=5.0, help="indicator parameter b (Eq. 37)")
    case.add_run_options(p, HERE, tol_lambda=0.0001)
    p.add_argument("--tol-u", type=float, default=1e-6)
    p.add_argument("--tol-p", type=float, default=5e-6)
    args = p.parse_args(argv)

    configs = []
    if args.full:
        for L in (8.0, 10.0, 20.0):
            configs.append(dict(L_over_a=L, c=0.3, n_positions=64))
        for c in (0.2, 0.4):
            configs.append(dict(L_over_a=8.0, c=c, n_positions=64))
    else:
        for L in args.L_over_a:
            for c in args.c:
                configs.append(dict(L_over_a=L, c=c, n_positions=args.positions))

    os.makedirs(args.workdir, exist_ok=True)
    t0 = time.time()
    results = []
    for cfg in configs:
        r = run_configuration(args.workdir, cfg["L_over_a"], args.a_over_delta, cfg["n_positions"],
                              b=args.b, c=cfg["c"], tol_lambda=args.tol_lambda, tol_u=args.tol_u,
                              tol_p=args.tol_p, np_fluid=args.np_fluid, keep=args.keep,
                              acceleration=args.acceleration)
        print("L/a %-5g a/Delta %-3g c %-4g positions %-3d  K = %.6f  K_Hasimoto = %.6f  error %+.3f %%"
              "  sigma_K %.4f  inner iterations %s  %.1f s"
              % (r["L_over_a"], r["a_over_delta"], r["c"], r["n_positions"], r["K"], r["K_hasimoto"],
                 100 * r["rel_error"], r["sigma_K"], r["inner_iterations"], r["wall_seconds"]), flush=True)
        results.append(r)

    main_result = results[0]
    summary = {k: main_result[k] for k in ("K", "K_hasimoto", "rel_error", "sigma_K", "n_positions", "cells",
                                           "L_over_a", "a_over_delta", "b", "c")}
    summary["runs"] = results
    summary["figures"] = []
    if any(abs(r["c"] - 0.3) < 1e-12 for r in results):
        fig = os.path.splitext(args.out)[0] + "_K_vs_L.png"
        plot(results, fig)
        summary["figures"].append(os.path.basename(fig))
    write_results(args.out, __file__, argv, args, validation_rows, summary, t0)
    print("wrote %s" % args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
