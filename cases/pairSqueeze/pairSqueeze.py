#!/usr/bin/env python3
"""Two spheres pushed together along their line of centres (squeeze flow), with and without the
sub-grid lubrication correction (paper section 3, Eq. 21 with Appendix C.2).

Spheres of radii a1 = 1 and a2 = lambda*a1 in a periodic cube, held at a reduced gap
xi = 2r/(a1 + a2) - 2 (fix fdm/couple move no), with equal and opposite forces F = 6 pi eta a1 along
the line of centres. The closing velocity V = (U1 - U2).d, in units of F/(6 pi eta a1), is compared
with the two-sphere theory (Jeffrey & Onishi 1984, full range: fdmResistance squeeze). Every gap is
one coupled time step of one run (warm-started from the previous gap), once with pair_style
fdm/subgrid and once with its lubrication switched off.

  pairSqueeze.py               lambda = 1 and 1.4, xi = 1e-4 ... 1, a1/Delta = 4, L = 8 a1 (minutes)
  pairSqueeze.py --full        a1/Delta = 5, L = 12 a1
  pairSqueeze.py --help        every option
Writes results.json and results_pairSqueeze.png here (docs/cases.md).
"""
import argparse
import os
import time
from typing import List

from fdmsubgrid import case, theory
from fdmsubgrid import squeeze
from fdmsubgrid.results import Row, write_results
from fdmsubgrid.squeeze import run_pair

HERE = os.path.dirname(os.path.abspath(__file__))

XI_DEFAULT = [1.0, 0.3, 0.1, 0.03, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4]


def plot(results, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for i, r in enumerate(results["cases"]):
        colour = "C%d" % i
        axes[0].loglog(r["xi"], r["theory"], "-", color=colour, label="theory, a2/a1 = %g" % r["lambda"])
        axes[0].loglog(r["xi"], r["subgrid"]["velocity"], "o", color=colour, label="FDM + sub-grid")
        axes[0].loglog(r["xi"], r["nosubgrid"]["velocity"], "x", color=colour, label="FDM alone")
        axes[1].semilogx(r["xi"], [100 * e for e in r["subgrid"]["rel_error"]], "o-", color=colour,
                         label="FDM + sub-grid, a2/a1 = %g" % r["lambda"])
        axes[1].semilogx(r["xi"], [100 * e for e in r["nosubgrid"]["rel_error"]], "x--", color=colour,
                         label="FDM alone, a2/a1 = %g" % r["lambda"])
    axes[0].set_xlabel(r"$\xi = 2r/(a_1+a_2) - 2$")
    axes[0].set_ylabel(r"closing velocity $/ (F/6\pi\eta a_1)$")
    axes[0].legend(fontsize=7)
    axes[1].set_xlabel(r"$\xi$")
    axes[1].set_ylabel("error against theory [%]")
    axes[1].set_yscale("symlog", linthresh=5)
    axes[1].axhline(5, color="grey", lw=0.5)
    axes[1].axhline(-5, color="grey", lw=0.5)
    axes[1].legend(fontsize=7)
    fig.suptitle("Squeeze flow of a sphere pair (a1/Delta = %g, L = %g a1)" % (results["a_over_delta"],
                                                                             results["L_over_a"]))
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def validation_rows(results: dict) -> List[Row]:
    """The closing velocity at every gap and size ratio against the two-sphere theory, with the sub-grid
    correction and (comparison rows) without."""
    return [row for c in results["cases"] for row in
            squeeze.validation_rows("a2/a1 %g, %s, " % (c["lambda"], squeeze.box_text(results)), c["xi"], "ξ",
                                    c["theory"], c)]


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--full", action="store_true", help="a1/Delta = 5, L = 12 a1")
    p.add_argument("--lambda", dest="ratios", type=float, nargs="+", default=[1.0, 1.4], help="a2/a1")
    p.add_argument("--xi", type=float, nargs="+", default=XI_DEFAULT, help="reduced gaps, largest first")
    p.add_argument("--a-over-delta", type=float, default=4.0)
    p.add_argument("--L-over-a", type=float, default=8.0)
    squeeze.add_options(p)
    case.add_run_options(p, HERE, tol_lambda=0.0001, cutoff=True)
    p.add_argument("--no-reference", action="store_true", help="run without the sub-grid-off comparison runs")
    args = p.parse_args(argv)
    if args.full:
        args.a_over_delta, args.L_over_a = 5.0, 12.0

    os.makedirs(args.workdir, exist_ok=True)
    t0 = time.time()
    results = dict(case="pairSqueeze", a_over_delta=args.a_over_delta, L_over_a=args.L_over_a,
                   box_extrapolated_with=args.box_extrapolate, model=args.model,
                   cutoff_cells=args.cutoff or "default", tol_lambda=args.tol_lambda, cases=[])
    for ratio in args.ratios:
        reference = [theory.pair_squeeze_velocity(1.0, ratio, xi) for xi in args.xi]
        entry = dict(**{"lambda": ratio}, xi=args.xi, theory=reference)
        entry.update(squeeze.against_theory(
            lambda L, subgrid, options: run_pair(args.workdir, ratio, args.xi, subgrid, args.a_over_delta, L,
                                                 args.tol_lambda, args.cutoff, args.np_fluid, args.keep,
                                                 pair_options=options, offset=args.offset),
            args.xi, "xi", reference, args, label="lambda %g, " % ratio))
        results["cases"].append(entry)
    write_results(args.out, __file__, argv, args, validation_rows, results, t0)
    if "nosubgrid" in results["cases"][0]:
        plot(results, os.path.join(os.path.dirname(args.out), "results_pairSqueeze.png"))
    print("wrote %s (%.0f s)" % (args.out, results["wall_seconds"]))
    return results


if __name__ == "__main__":
    main()
