#!/usr/bin/env python3
"""Strong scaling of the fluid solver over MPI ranks (fdmRun -f N): one coupled scene of
--cells^3 cells (default 100^3 = 1 M) with a few spheres in a wall-driven shear cell, the paper's
suspension settings (section 6: tol_p = 1e-3, tol_u = 1e-5) and tolLambda 1e-3 with at most
--n-max inner iterations per step (the far field starts from rest, so every step uses them all and
the runs of different rank counts do the same work). The rank counts run back to back, --repeats
times, so that they share the machine's load alike (--busy-poll adds runs with Open MPI's
busy-polling, which fdmRun switches off when the ranks outnumber the cores); the table gives the medians over the repeats
of each run's median over its steps of

  fluid seconds per inner iteration   (steps.dat fluidSeconds / innerIterations)
  seconds per step                    (fluid + particle forcing + exchange with fdmDEM)

  scripts/benchmarkParallel.py                     # 100^3, ranks 1 2, 3 repeats (15 min here with --busy-poll)
  scripts/benchmarkParallel.py --cells 40 --repeats 1

Writes --out (default docs/data/benchmarks_parallel.json) and prints the table of docs/benchmarks.md
("Parallel runs"); run folders go to --workdir (default .cache/runs/benchmarkParallel).
"""
import argparse
import json
import os
import shutil
import statistics
import subprocess
import time

from fdmsubgrid import case, decomposition, output

HERE = os.path.dirname(os.path.abspath(__file__))
PROJECT = os.path.dirname(HERE)

DELTA = 0.2
RADIUS = 1.0   # a/Delta = 5, the paper's resolution


def spheres(length):
    """Four spheres around the mid-plane y = L/2 (where a 2-rank split of the walled direction cuts),
    one across the periodic face x = 0."""
    c = length / 2
    return [(0.5, c + 0.4, c, RADIUS), (c - 1.5, c - 0.6, c - 2.0, RADIUS),
            (c + 1.5, c + 0.3, c + 2.5, RADIUS), (c + 4.0, c - 2.5, c - 4.0, RADIUS)]


def write(root, cells, steps, n_max, mesh_from=None):
    length = cells * DELTA
    box = case.Box((0, 0, 0), (length,) * 3, DELTA, faces=("cyclic", ((-1, 0, 0), (1, 0, 0)), "cyclic"))
    fluid = os.path.join(root, "fluid")
    case.write_fluid_case(fluid, box, tol_lambda=1e-3, n_max=n_max, first_step=(1e-3, n_max), tol_u=1e-5,
                          tol_p=1e-3, n_particles=4)
    if mesh_from:  # blockMesh of 1 M cells takes a while: mesh once, copy
        shutil.copytree(os.path.join(mesh_from, "fluid", "constant", "polyMesh"),
                        os.path.join(fluid, "constant", "polyMesh"))
    case.write_dem_input(os.path.join(root, "dem"), box, spheres(length), dt=0.05,
                         pair_style="fdm/subgrid wall ylo -1 0 0 wall yhi 1 0 0", runs=("run %d" % steps,))


def measure(root, ranks):
    wall = case.run(root, np_fluid=ranks)
    s = output.steps(os.path.join(root, "fluid"))
    per_iteration = [f / n for f, n in zip(s["fluidSeconds"], s["innerIterations"])]
    per_step = [f + p + e for f, p, e in zip(s["fluidSeconds"], s["particleSeconds"], s["exchangeSeconds"])]
    return dict(ranks=ranks, wall=wall, inner_iterations=[int(n) for n in s["innerIterations"]],
                fluid_seconds_per_iteration=statistics.median(per_iteration),
                seconds_per_step=statistics.median(per_step))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--cells", type=int, default=100, help="cells per side of the cubic mesh")
    parser.add_argument("--ranks", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--steps", type=int, default=3)
    parser.add_argument("--n-max", type=int, default=10, help="inner iterations per step at most")
    parser.add_argument("--busy-poll", action="store_true",
                        help="also run every rank count > 1 with Open MPI busy-polling (mpi_yield_when_idle 0), "
                             "which fdmRun switches off when the ranks outnumber the cores")
    parser.add_argument("--workdir", default=os.path.join(PROJECT, ".cache", "runs", "benchmarkParallel"))
    parser.add_argument("--out", default=os.path.join(PROJECT, "docs", "data", "benchmarks_parallel.json"))
    args = parser.parse_args()

    shutil.rmtree(args.workdir, ignore_errors=True)
    template = os.path.join(args.workdir, "mesh")
    write(template, args.cells, args.steps, args.n_max)
    subprocess.run(["bash", "-c", ". '%s/etc/bashrc' && blockMesh -case '%s/fluid'" % (PROJECT, template)],
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
    cells, periodic = decomposition.mesh_layout(os.path.join(template, "fluid"))

    variants = [(n, False) for n in args.ranks] + [(n, True) for n in args.ranks if n > 1 and args.busy_poll]
    os.environ.pop("OMPI_MCA_mpi_yield_when_idle", None)   # fdmRun's default, unless --busy-poll
    runs = []
    started = time.time()
    for repeat in range(args.repeats):
        for ranks, busy in variants:
            root = os.path.join(args.workdir, "r%d_np%d%s" % (repeat, ranks, "_busy" if busy else ""))
            write(root, args.cells, args.steps, args.n_max, mesh_from=template)
            if busy:
                os.environ["OMPI_MCA_mpi_yield_when_idle"] = "0"
            try:
                result = measure(root, ranks)
            finally:
                os.environ.pop("OMPI_MCA_mpi_yield_when_idle", None)
            result.update(repeat=repeat, busy_poll=busy)
            if ranks > 1:
                result["split"] = decomposition.choose_split(cells, periodic, ranks)
            runs.append(result)
            print("repeat %d, %d rank(s)%s: %.3f s per inner iteration, %.2f s per step, %.0f s wall, load %.1f"
                  % (repeat, ranks, " busy-polling" if busy else "", result["fluid_seconds_per_iteration"],
                     result["seconds_per_step"], result["wall"], os.getloadavg()[0]), flush=True)
            shutil.rmtree(root)

    table = []
    for ranks, busy in variants:
        mine = [r for r in runs if r["ranks"] == ranks and r["busy_poll"] == busy]
        table.append(dict(ranks=ranks, busy_poll=busy, split=mine[0].get("split"),
                          fluid_seconds_per_iteration=statistics.median(r["fluid_seconds_per_iteration"] for r in mine),
                          seconds_per_step=statistics.median(r["seconds_per_step"] for r in mine),
                          per_iteration_runs=[r["fluid_seconds_per_iteration"] for r in mine],
                          inner_iterations_per_step=mine[0]["inner_iterations"]))
    base = table[0]
    print("\n| fluid ranks | split | fluid s / inner iteration (runs) | s / step | speed-up per iteration | per step |")
    print("|---|---|---|---|---|---|")
    for row in table:
        print("| %d%s | %s | %.2f (%s) | %.1f | %.2f | %.2f |" % (
            row["ranks"], " busy-polling" if row["busy_poll"] else "",
            "(%d %d %d)" % tuple(row["split"]) if row["split"] else "serial",
            row["fluid_seconds_per_iteration"], ", ".join("%.2f" % t for t in row["per_iteration_runs"]),
            row["seconds_per_step"], base["fluid_seconds_per_iteration"] / row["fluid_seconds_per_iteration"],
            base["seconds_per_step"] / row["seconds_per_step"]))
    with open(args.out, "w") as f:
        json.dump(dict(cells=cells, periodic=periodic, steps=args.steps, n_max=args.n_max, repeats=args.repeats,
                       minutes=(time.time() - started) / 60, table=table, runs=runs),
                  f, indent=1)


if __name__ == "__main__":
    main()
