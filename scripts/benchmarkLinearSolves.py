#!/usr/bin/env python3
"""How tightly each inner iteration solves its linear systems (issue 13: "tolerances relative to the
lambda residual"; docs/benchmarks.md "Linear solves inside the inner iteration").

Every inner iteration of fdmFoam is one PISO solve: the momentum predictor (smoothSolver,
symGaussSeidel) and two pressure correctors (GAMG, the last with pFinal). The cases solve the
momentum to an absolute tol_u and the last pressure corrector to an absolute tol_p (relTol 0), in
every inner iteration (before 2026-11-27), although the inner iteration itself only converges to
tolLambda. The suspension scenes now use U relTol 0.1 (fdmsubgrid.suspension.MOMENTUM_REL_TOL). A relative
tolerance (relTol: stop once the residual fell by that factor, never below the absolute floor) lets
the early inner iterations, far from the answer, cost less; near convergence each linear solve
starts close to its answer and the relative criterion tightens by itself.

Two measurements, one per part:

  accuracy   the second step of cases/couette's small dense scene (as benchmarkMeanFlowDamping.py:
             10 x 12 x 8 a1, a1/Delta = 3, dt = 0.04, phi_bulk 0.37, seeds 1-3, friction off), the
             first step converged to tolLambda 1e-7 in every run so that the second starts alike;
             fluid solves and the particle velocities' error against a reference (tolLambda 1e-7,
             the linear solves to 1e-10), per linear-solve setting, at the Table 8 criterion
             tolLambda 1e-2 (and 3e-3);
  cost       the Table 8 scene at phi_bulk 0.37 (481 spheres, 216 000 cells: couette.py --table8 0.37
             --dt 0.04 --tol-lambda 0.01), its first --steps steps per setting, the settings run one
             after the other and repeated (--repeats) in turn: fluid seconds per solve and per step
             (medians over steps 2..), solves per step.

  python3 scripts/benchmarkLinearSolves.py [--part accuracy cost] [--seeds 1 2 3] [--steps 8]
                                           [--repeats 2] [--workdir DIR] [--out FILE]
Writes docs/data/benchmarks_linearSolves.json unless --out says otherwise.
"""
import argparse
import dataclasses
import json
import os
import re
import shutil
import sys
import tempfile
import time
from typing import Dict, List, Optional

import numpy as np

from fdmsubgrid import case, couettescene, output, packing

HERE = os.path.dirname(os.path.abspath(__file__))

TIGHT = 1e-7


@dataclasses.dataclass(frozen=True)
class Setting:
    """The linear solves of one inner iteration: relTol of the momentum predictor (U), of the
    pressure correctors before the last (p) and of the last (pFinal); the absolute tolerances stay
    the case's (tol_u 1e-5, tol_p 1e-3) as the floor."""
    label: str
    u_rel: float = 0.0
    p_rel: float = 0.01
    p_final_rel: float = 0.0


SETTINGS = [
    Setting("U relTol 0 (before), p 0.01, pFinal 0"),
    Setting("U relTol 0.1", u_rel=0.1),
    Setting("U relTol 0.1, pFinal 0.01", u_rel=0.1, p_final_rel=0.01),
    Setting("U relTol 0.3, pFinal 0.05, p 0.05", u_rel=0.3, p_rel=0.05, p_final_rel=0.05),
]


def set_linear_solves(fluid_dir: str, s: Setting, tight: Optional[float] = None) -> None:
    """Rewrite system/fvSolution's relTol entries (tight: every tolerance this, relTol 0)."""
    path = os.path.join(fluid_dir, "system", "fvSolution")
    text = open(path).read()

    def block(name: str, body: str) -> str:
        m = re.search(r"(\n    %s\n    \{)(.*?)(\n    \})" % name, body, re.S)
        assert m, "no %s block in %s" % (name, path)
        return m.group(2)

    def replace(name: str, key: str, value: float, body: str) -> str:
        inner = block(name, body)
        if re.search(r"\b%s\s+[^;]+;" % key, inner):
            new = re.sub(r"\b(%s\s+)[^;]+;" % key, r"\g<1>%g;" % value, inner)
        else:
            new = inner + "\n        %s %g;" % (key, value)
        return body.replace(inner, new, 1)

    if tight is not None:       # the reference: every linear solve converged to `tight`
        for name in ("p", "U"):
            text = replace(name, "tolerance", tight, text)
        s = Setting("tight", u_rel=0.0, p_rel=0.0, p_final_rel=0.0)
    text = replace("U", "relTol", s.u_rel, text)
    text = replace("p", "relTol", s.p_rel, text)
    text = replace("pFinal", "relTol", s.p_final_rel, text)
    open(path, "w").write(text)


# ---- accuracy: the second step of the small dense scene -----------------------------------------

def accuracy_run(workdir: str, label: str, setting: Setting, tol_lambda: float, n_max: int, phi: float,
                 seed: int, tight: bool = False) -> Dict:
    run_dir = os.path.join(workdir, "accuracy", "seed%d" % seed, re.sub(r"[^A-Za-z0-9.]+", "_", label))
    shutil.rmtree(run_dir, ignore_errors=True)
    size, a_over_delta, dt = (10.0, 12.0, 8.0), 3.0, 0.04
    pack = packing.channel_packing(size, phi=phi, seed=seed, min_gap=2 * couettescene.ROUGHNESS,
                                   wall_gap=2 * couettescene.ROUGHNESS)
    springs = dataclasses.replace(couettescene.choose_springs(pack.phi, dt, couettescene.A1 / a_over_delta), mu_s=0.0)
    scene = couettescene.write_case(run_dir, pack, springs, a_over_delta, dt, 2 * dt, 1, tol_lambda, "anderson", n_max,
                               fluid_options=dict(first_step=(TIGHT, 3000)))
    set_linear_solves(os.path.join(run_dir, "fluid"), setting, tight=1e-10 if tight else None)
    wall = case.run(run_dir)
    records = output.read_particle_records(os.path.join(run_dir, "dem", "particles.records"))
    steps = output.steps(os.path.join(run_dir, "fluid"))
    k = list(records.steps).index(2)
    return dict(label=label, setting=dataclasses.asdict(setting), tol_lambda=tol_lambda, seed=seed,
                wall_velocity=float(scene["wall_velocity"]), solves=int(steps["innerIterations"][1]),
                converged=bool(steps["converged"][1]), fluid_seconds=float(steps["fluidSeconds"][1]),
                wall_seconds=wall, U=records["U"][k].tolist(), Omega=records["omega"][k].tolist(),
                radius=records["radius"][k].tolist())


def errors(run: Dict, reference: Dict) -> np.ndarray:
    """Per particle: max(|dU|, |dOmega| a) / U_wall against the reference."""
    dU = np.abs(np.array(run["U"]) - np.array(reference["U"])).max(axis=1)
    dW = np.abs(np.array(run["Omega"]) - np.array(reference["Omega"])).max(axis=1) * np.array(reference["radius"])
    return np.maximum(dU, dW) / run["wall_velocity"]


def accuracy(args) -> List[Dict]:
    refs = {s: accuracy_run(args.workdir, "reference", SETTINGS[0], TIGHT, 3000, args.phi, s, tight=True)
            for s in args.seeds}
    rows = []
    for tol_lambda in args.tol_lambdas:
        for setting in SETTINGS:
            runs = [accuracy_run(args.workdir, "%s tolLambda %g" % (setting.label, tol_lambda), setting, tol_lambda,
                                 100, args.phi, s) for s in args.seeds]
            e = np.concatenate([errors(r, refs[r["seed"]]) for r in runs])
            row = dict(label=setting.label, setting=dataclasses.asdict(setting), tol_lambda=tol_lambda,
                       solves=[r["solves"] for r in runs], solves_mean=float(np.mean([r["solves"] for r in runs])),
                       converged=all(r["converged"] for r in runs), error_median=float(np.median(e)),
                       error_max=float(e.max()))
            rows.append(row)
            print("accuracy  tolLambda %-6g %-40s solves %-12s mean %5.1f  converged %d  error median %.1e max %.1e"
                  % (tol_lambda, setting.label, " ".join(map(str, row["solves"])), row["solves_mean"],
                     row["converged"], row["error_median"], row["error_max"]), flush=True)
    return rows


# ---- cost: the Table 8 scene at phi_bulk 0.37 ---------------------------------------------------

def cost_run(workdir: str, setting: Setting, repeat: int, steps: int) -> Dict:
    dt = 0.04
    # couette.py --table8 0.37 --dt 0.04 --tol-lambda 0.01 --strain STEPS*dt --overwrite: the row's box and count
    _, _, size, n_particles, _ = couettescene.TABLE8[0.37]
    written = couettescene.write_run(os.path.join(workdir, "cost", "r%d_%s" % (
        repeat, re.sub(r"[^A-Za-z0-9.]+", "_", setting.label))), list(size), dt, steps * dt, phi=0.37,
        n_particles=n_particles, tol_lambda=0.01, table8=True, overwrite=True)
    run_dir = written["run_dir"]
    set_linear_solves(os.path.join(run_dir, "fluid"), setting)
    t0 = time.time()
    case.run(run_dir)
    wall = time.time() - t0
    st = output.steps(os.path.join(run_dir, "fluid"))
    later = slice(1, None)
    solves = st["innerIterations"][later]
    fluid = st["fluidSeconds"][later]
    return dict(label=setting.label, repeat=repeat, wall_seconds=wall, solves=solves.astype(int).tolist(),
                fluid_seconds=fluid.tolist(), first_step_solves=int(st["innerIterations"][0]),
                seconds_per_solve_median=float(np.median(fluid / solves)), seconds_per_step_median=float(np.median(fluid)),
                solves_per_step_mean=float(np.mean(solves)), mean_velocity=[float(st[c][-1]) for c in ("meanUx", "meanUy", "meanUz")])


def cost(args) -> List[Dict]:
    runs = [cost_run(args.workdir, s, r, args.steps) for r in range(args.repeats) for s in SETTINGS]
    rows = []
    for s in SETTINGS:
        mine = [r for r in runs if r["label"] == s.label]
        row = dict(label=s.label, setting=dataclasses.asdict(s),
                   seconds_per_solve=[r["seconds_per_solve_median"] for r in mine],
                   seconds_per_step=[r["seconds_per_step_median"] for r in mine],
                   solves_per_step=[r["solves_per_step_mean"] for r in mine],
                   first_step_solves=[r["first_step_solves"] for r in mine])
        rows.append(row)
        print("cost      %-40s s/solve %-22s s/step %-22s solves/step %-14s first step %s"
              % (s.label, " ".join("%.3f" % x for x in row["seconds_per_solve"]),
                 " ".join("%.2f" % x for x in row["seconds_per_step"]),
                 " ".join("%.1f" % x for x in row["solves_per_step"]), row["first_step_solves"]), flush=True)
    return rows, runs


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--part", nargs="+", choices=("accuracy", "cost"), default=["accuracy", "cost"])
    p.add_argument("--phi", type=float, default=0.37, help="phi_bulk of the accuracy scene")
    p.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    p.add_argument("--tol-lambdas", type=float, nargs="+", default=[1e-2, 3e-3])
    p.add_argument("--steps", type=int, default=8, help="steps of the Table 8 scene per cost run")
    p.add_argument("--repeats", type=int, default=2)
    p.add_argument("--workdir", default=os.path.join(tempfile.gettempdir(), "fdmLinearSolves"))
    p.add_argument("--out", default=os.path.join(HERE, "..", "docs", "data", "benchmarks_linearSolves.json"))
    args = p.parse_args(argv)
    result = dict(settings=[dataclasses.asdict(s) for s in SETTINGS])
    if "accuracy" in args.part:
        result["accuracy"] = dict(phi=args.phi, seeds=args.seeds, rows=accuracy(args))
    if "cost" in args.part:
        rows, runs = cost(args)
        result["cost"] = dict(scene="couette.py --table8 0.37 --dt 0.04 --tol-lambda 0.01", steps=args.steps,
                              rows=rows, runs=runs)
    with open(args.out, "w") as f:
        json.dump(result, f, indent=1)
    print("wrote", args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
