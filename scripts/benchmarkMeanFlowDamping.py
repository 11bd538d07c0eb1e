#!/usr/bin/env python3
"""Damping of the mean-flow correction where the particles force the flow (issue 13;
fdmFoam innerIterations meanFlowDamping, docs/fluid.md "Mean-flow correction of a channel").

A dense sheared suspension (cases/couette's small scene: 10 x 12 x 8 a1, a1/Delta = 3,
dt = 0.04/gamma_dot_0, phi_bulk 0.37 by default) runs two steps per configuration. The first step
is converged tightly in every run (tolLambda 1e-7), so that the second starts from the same
positions and flow; the second step's fluid solves and particle velocities are compared with
a reference converged to tolLambda 1e-7 with its linear solves converged to 1e-10. Error: per particle the larger of max|dU| and
max|dOmega| a1 over the wall speed U; the median and the largest over the particles of all seeds.
Friction is off by default (mu_s = 0): with Coulomb friction the stick or slip of a contact
depends on the path of the iteration, and two converged runs may differ at a contact by 1e-2 U
(--friction keeps the case's mu_s = 0.5).

  python3 scripts/benchmarkMeanFlowDamping.py [--phi 0.37] [--seeds 1 2 3] [--friction]
                                              [--workdir DIR] [--out FILE]
Writes docs/data/benchmarks_meanFlowDamping.json unless --out says otherwise.
"""
import argparse
import dataclasses
import json
import os
import shutil
import sys
import tempfile

import numpy as np

from fdmsubgrid import case, couettescene, output, packing

HERE = os.path.dirname(os.path.abspath(__file__))

TIGHT = 1e-7
# (label, acceleration, meanFlowDamping, tolLambda, nMax); the reference's linear solves to 1e-10 as
# well (the case's tol_u 1e-5 and tol_p 1e-3 leave about 2e-4 between two runs converged in lambda)
RUNS = [
    ("reference", "anderson", 10.0, TIGHT, 3000),
    ("Anderson, undamped, tolLambda 1e-2", "anderson", 0.0, 1e-2, 50),
    ("Anderson, undamped, tolLambda 3e-3", "anderson", 0.0, 3e-3, 100),
    ("Anderson, undamped, tolLambda 1e-3", "anderson", 0.0, 1e-3, 200),
    ("Anderson, damping 10, tolLambda 1e-2", "anderson", 10.0, 1e-2, 50),
    ("Anderson, damping 10, tolLambda 3e-3", "anderson", 10.0, 3e-3, 100),
    ("Anderson, damping 10, tolLambda 1e-3", "anderson", 10.0, 1e-3, 200),
    ("Anderson, damping 3, tolLambda 1e-2", "anderson", 3.0, 1e-2, 50),
    ("Anderson, damping 30, tolLambda 1e-2", "anderson", 30.0, 1e-2, 50),
    ("plain, undamped, tolLambda 1e-2", "none", 0.0, 1e-2, 200),
    ("plain, damping 10, tolLambda 1e-2", "none", 10.0, 1e-2, 200),
]


def run_scene(workdir: str, label: str, acceleration: str, damping: float, tol_lambda: float, n_max: int,
              phi: float, seed: int, friction: bool, tol_solve: float | None = None,
              rel_tol: tuple[float, float, float] | None = None) -> dict:
    """Two steps of the scene; the second step's solves, convergence and particle velocities.
    tol_solve: the linear solvers' tolerance (tol_u = tol_p, every solve to it: relTol 0; None: the
    case's, 1e-5 and 1e-3); rel_tol: the linear solves' relTol, (U, p, pFinal) (None: the case's)."""
    run_dir = os.path.join(workdir, "seed%d" % seed, label.replace(", ", "_").replace(" ", ""))
    shutil.rmtree(run_dir, ignore_errors=True)
    size, a_over_delta, dt = (10.0, 12.0, 8.0), 3.0, 0.04
    pack = packing.channel_packing(size, phi=phi, seed=seed, min_gap=2 * couettescene.ROUGHNESS,
                                   wall_gap=2 * couettescene.ROUGHNESS)
    springs = couettescene.choose_springs(pack.phi, dt, couettescene.A1 / a_over_delta)
    if not friction:
        springs = dataclasses.replace(springs, mu_s=0.0)
    # the first step (from rest) converged tightly in every run, the second with the run's criterion
    fluid = dict(first_step=(TIGHT, 3000), mean_flow_damping=damping)
    if tol_solve is not None:
        fluid.update(tol_u=tol_solve, tol_p=tol_solve)
        rel_tol = (0.0, 0.0, 0.0)
    if rel_tol is not None:
        # the momentum predictor solved to its relTol, not the case's fixed sweep
        fluid.update(zip(("u_rel_tol", "p_rel_tol", "p_final_rel_tol"), rel_tol), u_sweeps=None)
    scene = couettescene.write_case(run_dir, pack, springs, a_over_delta, dt, 2 * dt, 1, tol_lambda, acceleration,
                               n_max, fluid_options=fluid)
    try:
        wall = case.run(run_dir)
    except RuntimeError as failure:
        if "diverging" not in str(failure):
            raise
        # fdmFoam stopped a diverging iteration (its first step, from rest): say where
        lines = [line for line in open(os.path.join(run_dir, "log.fluid")) if "diverging" in line]
        return dict(label=label, acceleration=acceleration, damping=damping, tol_lambda=tol_lambda, seed=seed,
                    diverged=True, message=lines[-1].strip() if lines else str(failure)[-300:])
    records = output.read_particle_records(os.path.join(run_dir, "dem", "particles.records"))
    steps = output.steps(os.path.join(run_dir, "fluid"))
    k = list(records.steps).index(2)
    return dict(label=label, acceleration=acceleration, damping=damping, tol_lambda=tol_lambda, seed=seed,
                diverged=False, phi=float(pack.phi), n_particles=int(pack.n), wall_velocity=float(scene["wall_velocity"]),
                solves=int(steps["innerIterations"][1]), converged=bool(steps["converged"][1]),
                first_step_solves=int(steps["innerIterations"][0]), wall_seconds=wall,
                U=records["U"][k].tolist(), Omega=records["omega"][k].tolist(),
                radius=records["radius"][k].tolist())


def errors(run: dict, reference: dict) -> np.ndarray:
    """Per particle: max(|dU|, |dOmega| a) / U_wall against the reference."""
    dU = np.abs(np.array(run["U"]) - np.array(reference["U"])).max(axis=1)
    dW = np.abs(np.array(run["Omega"]) - np.array(reference["Omega"])).max(axis=1) * np.array(reference["radius"])
    return np.maximum(dU, dW) / run["wall_velocity"]


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--phi", type=float, default=0.37)
    p.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    p.add_argument("--friction", action="store_true", help="keep Coulomb friction (mu_s 0.5)")
    p.add_argument("--workdir", default=os.path.join(tempfile.gettempdir(), "fdmMeanFlowDamping"))
    p.add_argument("--out", default=os.path.join(HERE, "..", "docs", "data", "benchmarks_meanFlowDamping.json"))
    args = p.parse_args(argv)
    runs = [run_scene(args.workdir, *r, phi=args.phi, seed=s, friction=args.friction,
                      tol_solve=1e-10 if r[0] == "reference" else None)
            for s in args.seeds for r in RUNS]
    summary = []
    for label, *_ in RUNS:
        mine = [r for r in runs if r["label"] == label]
        refs = {r["seed"]: r for r in runs if r["label"] == "reference"}
        if any(r["diverged"] for r in mine):
            summary.append(dict(label=label, diverged=True, messages=[r.get("message") for r in mine]))
            print("%-40s diverged: %s" % (label, mine[0].get("message", "")), flush=True)
            continue
        e = np.concatenate([errors(r, refs[r["seed"]]) for r in mine])
        row = dict(label=label, diverged=False, solves=[r["solves"] for r in mine], solves_mean=float(np.mean([r["solves"] for r in mine])),
                   converged=all(r["converged"] for r in mine), error_median=float(np.median(e)),
                   error_max=float(e.max()))
        summary.append(row)
        print("%-40s solves %-14s mean %5.1f  converged %d  error median %.1e  max %.1e"
              % (label, " ".join(map(str, row["solves"])), row["solves_mean"], row["converged"],
                 row["error_median"], row["error_max"]), flush=True)
    # the per-particle velocities stay in the run folders; the file keeps each run's counts
    kept = [{k: v for k, v in r.items() if k not in ("U", "Omega", "radius")} for r in runs]
    with open(args.out, "w") as f:
        json.dump(dict(phi=args.phi, seeds=args.seeds, friction=args.friction, summary=summary, runs=kept), f,
                  indent=1)
    print("wrote", args.out)


if __name__ == "__main__":
    sys.exit(main())
