#!/usr/bin/env python3
"""A sphere pushed toward a plane wall (squeeze flow), with and without the sub-grid wall
lubrication correction (paper Appendix D, Eq. D.6).

A sphere of radius a between two walls at rest (y = 0 and y = H), periodic in x and z, held at
eps = h/a - 1 from the wall y = 0 (fix fdm/couple move no), with a force F = 6 pi eta a toward it.
Its velocity V, in units of F/(6 pi eta a), is compared with 1/X^A of a sphere and one wall
(Brenner 1961, the reference table's column Fzt; fdmResistance squeeze --wall). The second wall is
at H = 10 a by default. Every gap is one coupled time step of one run, once with pair_style
fdm/subgrid and once with its lubrication switched off.

  wallSqueeze.py               eps = 1e-4 ... 1, a/Delta = 4, 8a x 10a x 8a (minutes)
  wallSqueeze.py --full        a/Delta = 5, 12a x 24a x 12a
  wallSqueeze.py --help        every option
Writes results.json and results_wallSqueeze.png here (docs/cases.md).
"""
import argparse
import os
import time
from typing import List

from fdmsubgrid import case, theory
from fdmsubgrid import squeeze
from fdmsubgrid.results import Row, write_results
from fdmsubgrid.squeeze import run_wall

HERE = os.path.dirname(os.path.abspath(__file__))

EPS_DEFAULT = [1.0, 0.3, 0.1, 0.03, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4]


def plot(results, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    r = results
    axes[0].loglog(r["eps"], r["theory"], "k-", label="Brenner (1961)")
    axes[0].loglog(r["eps"], r["subgrid"]["velocity"], "o", color="C0", label="FDM + sub-grid")
    axes[0].loglog(r["eps"], r["nosubgrid"]["velocity"], "x", color="C1", label="FDM alone")
    axes[1].semilogx(r["eps"], [100 * e for e in r["subgrid"]["rel_error"]], "o-", color="C0", label="FDM + sub-grid")
    axes[1].semilogx(r["eps"], [100 * e for e in r["nosubgrid"]["rel_error"]], "x--", color="C1", label="FDM alone")
    axes[0].set_xlabel(r"$\varepsilon = h/a - 1$")
    axes[0].set_ylabel(r"velocity toward the wall $/ (F/6\pi\eta a)$")
    axes[0].legend(fontsize=8)
    axes[1].set_xlabel(r"$\varepsilon$")
    axes[1].set_ylabel("error against theory [%]")
    axes[1].set_yscale("symlog", linthresh=5)
    axes[1].axhline(5, color="grey", lw=0.5)
    axes[1].axhline(-5, color="grey", lw=0.5)
    axes[1].legend(fontsize=8)
    fig.suptitle("Sphere pushed toward a wall (a/Delta = %g, %g a x %g a x %g a)" % (
        r["a_over_delta"], r["L_over_a"], r["H_over_a"], r["L_over_a"]))
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def validation_rows(results: dict) -> List[Row]:
    """The velocity toward the wall at every gap against Brenner (1961), with the sub-grid correction and
    (comparison rows) without."""
    return squeeze.validation_rows(squeeze.box_text(results) + ", ", results["eps"], "ε", results["theory"], results)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--full", action="store_true", help="a/Delta = 5, 12a x 24a x 12a")
    p.add_argument("--eps", type=float, nargs="+", default=EPS_DEFAULT, help="reduced gaps, largest first")
    p.add_argument("--a-over-delta", type=float, default=4.0)
    p.add_argument("--L-over-a", type=float, default=8.0)
    p.add_argument("--H-over-a", type=float, default=10.0)
    squeeze.add_options(p)
    case.add_run_options(p, HERE, tol_lambda=0.0001, cutoff=True)
    p.add_argument("--no-reference", action="store_true", help="run without the sub-grid-off comparison run")
    args = p.parse_args(argv)
    if args.full:
        args.a_over_delta, args.L_over_a, args.H_over_a = 5.0, 12.0, 24.0

    os.makedirs(args.workdir, exist_ok=True)
    t0 = time.time()
    reference = [theory.wall_squeeze_velocity(1.0, eps) for eps in args.eps]
    results = dict(case="wallSqueeze", a_over_delta=args.a_over_delta, L_over_a=args.L_over_a, H_over_a=args.H_over_a,
                   box_extrapolated_with=args.box_extrapolate, model=args.model,
                   cutoff_cells=args.cutoff or "default", tol_lambda=args.tol_lambda, eps=args.eps, theory=reference)
    results.update(squeeze.against_theory(
        lambda L, subgrid, options: run_wall(args.workdir, args.eps, subgrid, args.a_over_delta, L,
                                             args.H_over_a * (L / args.L_over_a), args.tol_lambda, args.cutoff,
                                             args.np_fluid, args.keep, pair_options=options, offset=args.offset),
        args.eps, "eps", reference, args))
    write_results(args.out, __file__, argv, args, validation_rows, results, t0)
    if "nosubgrid" in results:
        plot(results, os.path.join(os.path.dirname(args.out), "results_wallSqueeze.png"))
    print("wrote %s (%.0f s)" % (args.out, results["wall_seconds"]))
    return results


if __name__ == "__main__":
    main()
