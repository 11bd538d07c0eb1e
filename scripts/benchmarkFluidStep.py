#!/usr/bin/env python3
"""The cost of an inner iteration with the direct box solver against the iterative solvers (issue 47;
docs/benchmarks.md "Direct solver for box meshes (FFTBox)").

Two scenes, each written twice by the cases' own writers, once per linear-solver choice
(FDM_LINEAR_SOLVER, fdmsubgrid.foamcase: "FFTBox" = FFTBox for p, smoothSolver symGaussSeidel for U,
the momentum predictor on, the cases' default; "GAMG" = GAMG for p, symGaussSeidel for U, the momentum
predictor on, the cases' fvSolution before FFTBox):

  table8    the Table 8 scene at phi_bulk 0.37 (481 spheres, 60^3 = 216 000 cells:
            couette.py --table8 0.37 --dt 0.04 --tol-lambda 0.01), --steps steps;
  channel   the paper's section 6.2 channel (2345 spheres, 120 x 120 x 60 = 864 000 cells:
            poiseuille.py --paper), --channel-steps steps with the first (cold) step capped at
            --first-step-cap inner iterations in both variants (uncapped it takes about a thousand).

--variants compares other fvSolutions of the same scene (the first is the baseline of the ratios):
  GAMG              the iterative solvers (above)
  FFTBox            the cases' default (FFTBox for p, the momentum predictor one symGaussSeidel sweep)
  FFTBox-relTol     FFTBox, the momentum predictor solved to its relTol (0.3) instead of one sweep
  FFTBox-sweeps2    FFTBox, two sweeps of the momentum predictor
  FFTBox-1corrector FFTBox, one PISO pressure corrector instead of two

The variants run one after the other and the set is repeated (--repeats), so that the load of a
shared machine falls on all alike. Per run: fdmFoam's fluid seconds (its "fluid solve"), inner
iterations, seconds per inner iteration and per step, and fdmFoam's breakdown by part (momentum and
pressure assembly and solves, Anderson mixing, ...); the summary gives medians over the repeats and the
ratio of each variant to the first, pair by pair.

  python3 scripts/benchmarkFluidStep.py [--scenes table8 channel] [--variants GAMG FFTBox] [--steps 8]
                                        [--channel-steps 3] [--repeats 2] [--workdir DIR] [--out FILE]
Writes docs/data/benchmarks_fluidStep.json unless --out says otherwise (e.g. docs/benchmarks.md "The
momentum predictor as one sweep": --variants FFTBox-relTol FFTBox FFTBox-sweeps2 FFTBox-1corrector).
"""
import argparse
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from typing import Dict, List

from fdmsubgrid import output, runner

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
# each variant: the FDM_LINEAR_SOLVER its scene is written with, and the edits of its fvSolution
# (pattern, replacement, how many times it must match)
VARIANTS = {
    "GAMG": ("GAMG", []),
    "FFTBox": ("FFTBox", []),
    "FFTBox-relTol": ("FFTBox", [(r"\n +nSweeps +-1;[^\n]*", "", 1)]),
    "FFTBox-sweeps2": ("FFTBox", [(r"nSweeps +-1;", "nSweeps         -2;", 1)]),
    "FFTBox-1corrector": ("FFTBox", [(r"nCorrectors +2;", "nCorrectors     1;", 1)]),
}


def write_scene(scene: str, variant: str, workdir: str, args: argparse.Namespace) -> str:
    """Write the scene with the variant's fvSolution into workdir/<scene>_<variant>; returns the run
    folder."""
    target = os.path.join(workdir, "%s_%s" % (scene, variant))
    shutil.rmtree(target, ignore_errors=True)
    os.makedirs(target)
    linear_solver, edits = VARIANTS[variant]
    env = dict(os.environ, FDM_LINEAR_SOLVER=linear_solver)
    if scene == "table8":
        cmd = [sys.executable, os.path.join(ROOT, "cases", "couette", "couette.py"), "--table8", "0.37",
               "--dt", "0.04", "--tol-lambda", "0.01", "--strain", "%g" % (0.04 * args.steps),
               "--write-only", "--workdir", target]
    else:
        cmd = [sys.executable, os.path.join(ROOT, "cases", "poiseuille", "poiseuille.py"), "--paper",
               "--duration", "%g" % (0.05 * args.channel_steps), "--fluid-every", "1", "--workdir", target]
    subprocess.run(cmd, check=True, env=env, stdout=subprocess.DEVNULL)
    (run_dir,) = [os.path.join(target, d) for d in os.listdir(target) if os.path.isdir(os.path.join(target, d))]
    path = os.path.join(run_dir, "fluid", "system", "fvSolution")
    with open(path) as f:
        text = f.read()
    for pattern, replacement, count in edits:
        text, n = re.subn(pattern, replacement, text)
        if n != count:
            raise RuntimeError("%s: variant %s expects %d match(es) of %r, found %d" % (path, variant, count, pattern, n))
    with open(path, "w") as f:
        f.write(text)
    if scene == "channel":
        path = os.path.join(run_dir, "fluid", "constant", "fdmProperties")
        with open(path) as f:
            text = f.read()
        text, n = re.subn(r"(firstStep \{[^}]*nMax )\d+;", r"\g<1>%d;" % args.first_step_cap, text)
        if n != 1:
            raise RuntimeError("%s: no firstStep nMax to cap" % path)
        with open(path, "w") as f:
            f.write(text)
    return run_dir


def measure(run_dir: str) -> Dict:
    """Run a written scene (a fresh copy each time) and read fdmFoam's breakdowns."""
    fresh = run_dir + "_run"
    shutil.rmtree(fresh, ignore_errors=True)
    shutil.copytree(run_dir, fresh)
    t0 = time.time()
    runner.run(fresh)
    wall = time.time() - t0
    with open(os.path.join(fresh, "log.fluid")) as f:
        text = f.read()
    breakdown = output.fluid_time_breakdown(text)
    profile = output.fluid_inner_profile(text)
    steps = output.steps(os.path.join(fresh, "fluid"))
    shutil.rmtree(fresh, ignore_errors=True)
    n_inner = breakdown["inner_iterations"]
    return dict(wall=wall, steps=breakdown["steps"], inner_iterations=n_inner,
                inner_per_step=[int(v) for v in steps["innerIterations"]],
                fluid_seconds=breakdown["fluid_solve"],
                fluid_seconds_per_inner=breakdown["fluid_solve"] / n_inner,
                fluid_seconds_per_step=breakdown["fluid_solve"] / breakdown["steps"],
                parts_ms_per_inner={k: 1e3 * v / n_inner for k, v in (profile or {}).get("parts", {}).items()})


def load_average() -> List[float]:
    return [round(v, 2) for v in os.getloadavg()]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--scenes", nargs="+", choices=("table8", "channel"), default=["table8", "channel"])
    parser.add_argument("--variants", nargs="+", choices=tuple(VARIANTS), default=["GAMG", "FFTBox"],
                        help="the fvSolutions compared, the first the baseline of the ratios")
    parser.add_argument("--steps", type=int, default=8, help="time steps of the Table 8 scene")
    parser.add_argument("--channel-steps", type=int, default=3, help="time steps of the paper's channel")
    parser.add_argument("--first-step-cap", type=int, default=20,
                        help="inner iterations of the channel's first (cold) step, both variants")
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--workdir", default=None, help="where the scenes run (default: a temporary folder)")
    parser.add_argument("--out", default=os.path.join(ROOT, "docs", "data", "benchmarks_fluidStep.json"))
    args = parser.parse_args(argv)
    workdir = args.workdir or tempfile.mkdtemp(prefix="fdm-fluidstep-")

    # the command as given, its work folder left out (a folder of this machine)
    given = list(argv or sys.argv[1:])
    if "--workdir" in given:
        i = given.index("--workdir")
        del given[i:i + 2]
    summary = dict(command="python3 scripts/benchmarkFluidStep.py " + " ".join(given),
                   commit=subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], text=True,
                                         stdout=subprocess.PIPE).stdout.strip(),
                   machine=dict(cores=os.cpu_count(), load_average_start=load_average()), scenes={})
    variants = list(dict.fromkeys(args.variants))
    base = variants[0]
    summary["variants"] = variants
    for scene in args.scenes:
        written = {v: write_scene(scene, v, workdir, args) for v in variants}
        runs: Dict[str, List[Dict]] = {v: [] for v in variants}
        for repeat in range(args.repeats):
            for v in variants:
                r = measure(written[v])
                r["load_average"] = load_average()
                runs[v].append(r)
                print("%s %-6s repeat %d: %d steps, %d inner iterations, %.3f s fluid per inner iteration, "
                      "%.2f s per step (load %s)" % (scene, v, repeat + 1, r["steps"], r["inner_iterations"],
                                                    r["fluid_seconds_per_inner"], r["fluid_seconds_per_step"],
                                                    r["load_average"]), flush=True)
        medians = {v: dict(fluid_seconds_per_inner=statistics.median(r["fluid_seconds_per_inner"] for r in runs[v]),
                           fluid_seconds_per_step=statistics.median(r["fluid_seconds_per_step"] for r in runs[v]),
                           inner_iterations=statistics.median(r["inner_iterations"] for r in runs[v]),
                           parts_ms_per_inner={k: statistics.median(r["parts_ms_per_inner"].get(k, 0.0) for r in runs[v])
                                               for k in runs[v][0]["parts_ms_per_inner"]})
                   for v in variants}
        # each variant against the first: the ratio of each repeat's pair (run side by side), then their median
        ratios = {}
        for v in variants[1:]:
            ratios[v] = dict(
                per_inner_iteration=statistics.median(f["fluid_seconds_per_inner"] / g["fluid_seconds_per_inner"]
                                                      for g, f in zip(runs[base], runs[v])),
                per_step=statistics.median(f["fluid_seconds_per_step"] / g["fluid_seconds_per_step"]
                                           for g, f in zip(runs[base], runs[v])))
            print("%s: %s/%s fluid seconds per inner iteration %.3f, per step %.3f"
                  % (scene, v, base, ratios[v]["per_inner_iteration"], ratios[v]["per_step"]), flush=True)
        summary["scenes"][scene] = dict(runs=runs, medians=medians, ratios_to_first=ratios)
    summary["machine"]["load_average_end"] = load_average()
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    with open(args.out, "w") as f:
        json.dump(summary, f, indent=1)
    print("wrote", os.path.relpath(args.out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
