#!/usr/bin/env python3
"""Cold start of the inner iteration (issue 13): one free sphere in a channel sheared by one moving
wall, the flow starting from rest, one time step. Counts the fluid solves of the first step for the
plain and the Anderson-accelerated iteration, with the lambda criterion and the velocity criterion,
with and without the mean-flow correction (the exact plane-averaged channel profile at every inner
iteration), against a tightly converged reference. Writes docs/benchmarks_coldStart.json.

  python3 scripts/benchmarkColdStart.py [--cells 48] [--a-over-delta 4] [--workdir DIR]
"""
import argparse
import json
import os
import shutil
import sys
import tempfile

from fdmsubgrid import case, output

HERE = os.path.dirname(os.path.abspath(__file__))

# (label, acceleration, mean-flow correction, tolLambda, tolVelocity, tol_u = tol_p)
RUNS = [
    ("plain, no mean-flow correction, tolLambda 1e-5", "none", False, 1e-5, 0.0, 1e-6),
    ("Anderson, no mean-flow correction, tolLambda 1e-5", "anderson", False, 1e-5, 0.0, 1e-6),
    ("Anderson, no mean-flow correction, tolVelocity 1e-4", "anderson", False, 0.0, 1e-4, 1e-6),
    ("plain, tolLambda 1e-5", "none", True, 1e-5, 0.0, 1e-6),
    ("Anderson, tolLambda 1e-5", "anderson", True, 1e-5, 0.0, 1e-6),
    ("Anderson, tolVelocity 1e-4", "anderson", True, 0.0, 1e-4, 1e-6),
    ("Anderson, tolVelocity 1e-5", "anderson", True, 0.0, 1e-5, 1e-6),
    ("reference: Anderson, tolLambda 1e-8, solves 1e-10", "anderson", True, 1e-8, 0.0, 1e-10),
]


def run_one(workdir, label, acceleration, mean_flow, tol_lambda, tol_velocity, tol_solve, cells, a_over_delta,
            n_max):
    a = 1.0
    delta = a / a_over_delta
    L = cells * delta
    U = 1.0
    name = label.split(":")[0].replace(", ", "_").replace(" ", "")
    run_dir = os.path.join(workdir, name)
    shutil.rmtree(run_dir, ignore_errors=True)
    # bottom wall at rest, top wall moving at U along x; periodic in x and z
    box = case.Box((0, 0, 0), (L, L, L), delta, faces=("cyclic", ((0, 0, 0), (U, 0, 0)), "cyclic"))
    case.write_fluid_case(os.path.join(run_dir, "fluid"), box, tol_lambda=tol_lambda, n_max=n_max,
                          first_step=(tol_lambda, n_max), tol_u=tol_solve, tol_p=tol_solve, n_particles=1,
                          acceleration=acceleration, tol_velocity=tol_velocity, mean_flow_correction=mean_flow)
    centre = (L / 2 + 0.3 * delta, L / 2 + 0.1 * delta, L / 2 + 0.2 * delta)
    case.write_dem_input(os.path.join(run_dir, "dem"), box, [centre + (a,)], dt=0.01,
                         pair_style="fdm/subgrid wall ylo 0 0 0 wall yhi %r 0 0" % U,
                         runs=("run 1",), name="in.coldStart")
    wall, parts, steps = case.run_and_read(run_dir)
    return dict(label=label, acceleration=acceleration, mean_flow_correction=mean_flow, tol_lambda=tol_lambda, tol_velocity=tol_velocity,
                tol_solve=tol_solve, inner_iterations=int(steps["innerIterations"][0]),
                converged=bool(steps["converged"][0]), wall_seconds=wall,
                U=[float(parts[c][0]) for c in ("Ux", "Uy", "Uz")],
                Omega=[float(parts[c][0]) for c in ("Wx", "Wy", "Wz")], cells=cells ** 3)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--cells", type=int, default=48, help="cells per side of the cubic box")
    p.add_argument("--a-over-delta", type=float, default=4.0)
    p.add_argument("--n-max", type=int, default=3000)
    p.add_argument("--workdir", default=os.path.join(tempfile.gettempdir(), "fdmColdStart"))
    p.add_argument("--out", default=os.path.join(HERE, "..", "docs", "data", "benchmarks_coldStart.json"))
    args = p.parse_args(argv)
    results = [run_one(args.workdir, *r, cells=args.cells, a_over_delta=args.a_over_delta, n_max=args.n_max)
               for r in RUNS]
    ref = results[-1]
    scale = 0.5 * 1.0  # the undisturbed flow at the sphere: about U/2
    for r in results:
        r["velocity_error"] = max(abs(u - v) for u, v in zip(r["U"] + r["Omega"], ref["U"] + ref["Omega"])) / scale
        print("%-55s inner %5d  converged %d  Ux %.8f  Omega_z %.8f  error %.2e  %.0f s"
              % (r["label"], r["inner_iterations"], r["converged"], r["U"][0], r["Omega"][2], r["velocity_error"],
                 r["wall_seconds"]), flush=True)
    with open(args.out, "w") as f:
        json.dump(dict(cells=args.cells ** 3, a_over_delta=args.a_over_delta, runs=results), f, indent=1)
    print("wrote", args.out)


if __name__ == "__main__":
    sys.exit(main())
