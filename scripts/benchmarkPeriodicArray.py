#!/usr/bin/env python3
"""Run time against error for the periodic array of spheres (paper 5.1): K error against
Hasimoto versus wall time, for a/Delta in {3, 4, 5, 6} and several lambda tolerances.
Writes docs/data/benchmarks_periodicArray.json, docs/data/benchmarks_periodicArray.png and prints a
Markdown table for docs/benchmarks.md. Runs `--jobs` configurations side by side.

  scripts/benchmarkPeriodicArray.py [--a-over-delta 3 4 5 6] [--tol-lambda 1e-3 1e-4]
                                    [--positions 64] [--L-over-a 8] [--jobs 2]
"""
import argparse
import concurrent.futures
import json
import os

from fdmsubgrid import periodicarray as periodic_array

HERE = os.path.dirname(os.path.abspath(__file__))
PROJECT = os.path.dirname(HERE)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--a-over-delta", type=float, nargs="+", default=[3.0, 4.0, 5.0, 6.0])
    p.add_argument("--tol-lambda", type=float, nargs="+", default=[1e-3, 1e-4])
    p.add_argument("--positions", type=int, default=64, help="lattice points (even m: one octant computed)")
    p.add_argument("--L-over-a", type=float, default=8.0)
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--workdir", default=os.path.join(PROJECT, "cases", "periodicArray", "runs", "benchmark"))
    p.add_argument("--out", default=os.path.join(PROJECT, "docs", "data", "benchmarks_periodicArray"))
    args = p.parse_args()
    os.makedirs(args.workdir, exist_ok=True)
    configs = [(ad, tol) for ad in args.a_over_delta for tol in args.tol_lambda]
    with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
        futures = {pool.submit(periodic_array.run_configuration, args.workdir, args.L_over_a, ad, args.positions,
                               tol_lambda=tol): (ad, tol) for ad, tol in configs}
        results = []
        for f in concurrent.futures.as_completed(futures):
            r = f.result()
            print("a/Delta %g tolLambda %g: K %.5f error %+.3f %% wall %.1f s" % (
                r["a_over_delta"], r["tol_lambda"], r["K"], 100 * r["rel_error"], r["wall_seconds"]), flush=True)
            results.append(r)
    results.sort(key=lambda r: (r["a_over_delta"], -r["tol_lambda"]))
    with open(args.out + ".json", "w") as f:
        json.dump(results, f, indent=2)

    print("\n| a/Delta | cells | tolLambda | K | error vs Hasimoto | sigma_K | inner iterations (first, then mean) "
          "| wall s | fluid s/iteration |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in results:
        its = r["inner_iterations"]
        rest = its[1:] or its
        print("| %g | %d | %g | %.5f | %+.3f %% | %.4f | %d, %.0f | %.1f | %.3f |" % (
            r["a_over_delta"], r["cells"], r["tol_lambda"], r["K"], 100 * r["rel_error"], r["sigma_K"], its[0],
            sum(rest) / len(rest), r["wall_seconds"], r["fluid_seconds"] / sum(its)))

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(5.5, 4))
    for tol in sorted({r["tol_lambda"] for r in results}):
        rs = [r for r in results if r["tol_lambda"] == tol]
        ax.plot([r["wall_seconds"] for r in rs], [100 * abs(r["rel_error"]) for r in rs], "o-",
                label="tolLambda %g" % tol)
        for r in rs:
            ax.annotate("a/Δ=%g" % r["a_over_delta"], (r["wall_seconds"], 100 * abs(r["rel_error"])), fontsize=8)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time for %d lattice positions (one octant computed) [s]" % args.positions)
    ax.set_ylabel("|K - K_Hasimoto| / K_Hasimoto [%]")
    ax.set_title("Periodic array, L/a = %g, (b, c) = (5, 0.3)" % args.L_over_a)
    ax.legend()
    fig.tight_layout()
    fig.savefig(args.out + ".png", dpi=120)
    print("wrote %s.json and %s.png" % (args.out, args.out))


if __name__ == "__main__":
    main()
