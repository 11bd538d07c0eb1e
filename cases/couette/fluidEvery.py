#!/usr/bin/env python3
"""Particle steps between fluid steps (fix fdm/couple ... fluid_every K): the time-step error and the
cost of a sheared suspension, side by side (issue 11; docs/benchmarks.md, "Particle steps between
fluid steps").

Every variant DT:K[:TOL] is the same Couette scene (couette.py: the same packing for the same phi_bulk, box
and seed) run for a short strain with the particle step DT (in 1/gamma_dot_0) and the fluid solved
every K-th step (its step K DT), each fluid step converged to tolLambda TOL (default --tol-lambda).
Over the first strain unit or so the runs start from the same
packing and stay close: the wall shear stress against strain is then a deterministic curve, and its
difference from the reference run (the first variant, the finest step) is the time-step error, free
of the sampling noise of a long average (a run of 8 strain units at phi 0.47 in the small scene
averages to +-2-5 %, more than the error sought). Past that the trajectories separate as many-body
trajectories do; --window sets the strain range compared.

  fluidEvery.py --jobs 2                      phi 0.47, the small scene 10 x 16 x 8 a1, variants 0.005:1
                                              (reference) 0.02:1 0.01:1 0.01:2 0.005:4 0.01:4 0.02:2 0.0025:8
  fluidEvery.py --phi 0.42 --variants 0.005:1 0.04:1 0.02:1 0.02:2 0.01:4 0.01:2 --jobs 2
  fluidEvery.py --variants 0.01:2:0.001 0.01:2:0.01 0.01:2:0.03 --jobs 2     the inner iteration's tolerance
  fluidEvery.py --strain 0.4 --window 0.05 0.4 --dump-every 0.02 --variants 0.005:1 0.005:4 --held-drag constant
                                              the held drag constant instead of extrapolated (fix fdm/couple
                                              held_drag), the particles compared every 0.02 strain

Besides the stress curves, each variant's particles are compared with the reference's at the window's end
(the last common record): mean position and velocity differences (trajectory_difference).

Writes <workdir>/<variant>.json per variant (a variant whose file exists is not run again) and --out
(default docs/benchmarks_fluidEvery_phi<PHI>.json) with a figure beside it (the stress curves, and the
error against the wall time).
"""
import argparse
import json
import os
import sys
from concurrent.futures import ThreadPoolExecutor
from typing import Dict, List, Optional, Tuple

import numpy as np

from fdmsubgrid import case, contacts, demonly, files, output, profiles, rheology, suspension
import couette

HERE = os.path.dirname(os.path.abspath(__file__))
PROJECT = os.path.dirname(os.path.dirname(HERE))

DEFAULT_VARIANTS = ["0.005:1", "0.02:1", "0.01:1", "0.01:2", "0.005:4", "0.01:4", "0.02:2", "0.0025:8"]


Variant = Tuple[float, int, Optional[float]]


def parse_variant(text: str) -> Variant:
    """'DT:K' or 'DT:K:TOL' -> (DT, K, TOL or None: the run's --tol-lambda)."""
    try:
        fields = text.split(":")
        if len(fields) not in (2, 3):
            raise ValueError
        dt_value, k_value = float(fields[0]), int(fields[1])
        tol = float(fields[2]) if len(fields) == 3 else None
    except ValueError:
        raise argparse.ArgumentTypeError("a variant is DT:K or DT:K:TOL (particle step, steps per fluid step, "
                                         "tolLambda), got %r" % text)
    if dt_value <= 0 or k_value < 1 or (tol is not None and tol <= 0):
        raise argparse.ArgumentTypeError("%r: DT and TOL must be positive and K at least 1" % text)
    return dt_value, k_value, tol


def variant_name(dt: float, k: int, tol: Optional[float] = None, held_drag: str = "extrapolated") -> str:
    """dt<DT>_every<K>[_tol<TOL>], and _constant for a variant whose held drag is constant (K > 1)."""
    return ("dt%g_every%d" % (dt, k) + ("" if tol is None else "_tol%g" % tol)
            + ("_constant" if k > 1 and held_drag == "constant" else ""))


def result_held_drag(r: Dict) -> Optional[str]:
    """How a variant's steps between fluid steps held the fluid's force (None: K = 1, no such steps); results
    written before 2026-11-28 (no held_drag) held it constant, the only way there was."""
    return None if r["fluid_every"] <= 1 else r.get("held_drag", "constant")


def result_name(r: Dict) -> str:
    """The name of a variant's result: its results file's name (results written before 2026-11-28 hold none:
    then from its step, K and, where it says one, tolLambda)."""
    return r.get("name") or variant_name(r["dt"], r["fluid_every"], r.get("tol_lambda"))


def wall_stress_curve(run_dir: str, box: List[float]) -> Tuple[np.ndarray, np.ndarray]:
    """Strain (gamma_dot_0 t) and the shear stress of the suspension on the walls (fluid + sub-grid +
    contact, rheology.wall_shear_stresses, the mean of both walls) at the steps the fluid solved."""
    loads = output.read_wall_loads(run_dir)
    tau = rheology.wall_shear_stresses(loads, profiles.Channel.centred(box))["total"]
    return loads.times * couette.SHEAR_RATE, tau.mean(axis=1)


def run_variant(dt: float, k: int, tol: Optional[float], args: argparse.Namespace) -> Dict:
    """One variant (or its results file): wall time, fluid steps, inner iterations per fluid step, the
    position update's counts and the stress curve."""
    name = variant_name(dt, k, tol, args.held_drag)
    tol_lambda = args.tol_lambda if tol is None else tol
    out = os.path.join(args.workdir, name + ".json")
    if os.path.exists(out):
        with open(out) as f:
            kept = json.load(f)
        if result_held_drag(kept) == (args.held_drag if k > 1 else None):
            return kept
        print("%s: %s held its drag %s, not %s: run again" % (name, out, result_held_drag(kept), args.held_drag))
    scene = couette.main(["--phi", str(args.phi), "--size", *map(str, args.size), "--seed", str(args.seed),
                          "--a-over-delta", str(args.a_over_delta), "--dt", str(dt), "--fluid-every", str(k),
                          "--held-drag", args.held_drag,
                          "--strain", str(args.strain), "--tol-lambda", str(tol_lambda),
                          "--dump-every", str(args.dump_every), "--write-every", str(args.strain),
                          "--workdir", os.path.join(args.workdir, name), "--write-only", "--overwrite"])
    run_dir = scene["run_dir"]
    wall = case.run(run_dir)
    strain, stress = wall_stress_curve(run_dir, scene["box"])
    with open(os.path.join(run_dir, "log.dem"), errors="replace") as f:
        counts = demonly.position_update_counts(f.read())
    inner = output.steps(os.path.join(run_dir, "fluid"))["innerIterations"]
    result = dict(name=name, dt=dt, fluid_every=k, fluid_dt=dt * k, tol_lambda=tol_lambda, run_dir=run_dir,
                  held_drag=args.held_drag if k > 1 else None,
                  wall_seconds=wall,
                  steps=scene["steps"], fluid_steps=int(len(inner)), inner_iterations_mean=float(np.mean(inner)),
                  fluid_solves=int(np.sum(inner)), position_update=counts, strain=strain.tolist(),
                  wall_stress=stress.tolist())
    files.write_json(out, result, indent=None)   # whole or absent: a rerun takes it instead of running
    print("%s: %.0f s, %d fluid steps, %.1f inner iterations per fluid step" % (name, wall, len(inner),
                                                                               result["inner_iterations_mean"]),
          flush=True)
    return result


def variant_records(result: Dict) -> Optional[output.ParticleRecords]:
    """A variant's particle records, None where its run folder no longer holds them."""
    path = os.path.join(result["run_dir"], "dem", "particles.records")
    return output.read_particle_records(path, mmap=False) if os.path.isfile(path) else None


def trajectory_difference(ref: Optional[output.ParticleRecords], other: Optional[output.ParticleRecords],
                          strain: float) -> Optional[Dict]:
    """A variant's particle records `other` compared with the reference's `ref` at their last common record at or
    before `strain`: the mean over the particles of |x - x_ref| (a1; the minimum image in the periodic directions)
    and of |U - U_ref| over the wall speed. None where a run has no records left or none in common."""
    if ref is None or other is None:
        return None
    times, i, j = np.intersect1d(np.round(ref.times, 9), np.round(other.times, 9), return_indices=True)
    keep = (times > 0) & (times * couette.SHEAR_RATE <= strain + 1e-9)
    if not keep.any():
        return None
    k = int(np.nonzero(keep)[0][-1])
    dx = contacts.minimum_image(other["x"][j[k]] - ref["x"][i[k]], ref.period)
    wall_speed = couette.SHEAR_RATE * (ref.header["box_hi"][1] - ref.header["box_lo"][1]) / 2
    return dict(strain=float(times[k] * couette.SHEAR_RATE),
                position=float(np.linalg.norm(dx, axis=1).mean()),
                velocity=float(np.linalg.norm(other["U"][j[k]] - ref["U"][i[k]], axis=1).mean() / wall_speed))


def compare(results: List[Dict], window: Tuple[float, float]) -> None:
    """Adds to each result its error against the first over the strain window: the mean and the rms
    of the relative difference of the stress curves (interpolated on a common strain grid), and the
    particles' mean position and velocity differences at the window's end (trajectory_difference; finer
    with a smaller --dump-every)."""
    lo, hi = window
    grid = np.linspace(lo, hi, 200)
    ref = np.interp(grid, results[0]["strain"], results[0]["wall_stress"])
    ref_records = variant_records(results[0])   # read once for every variant's comparison
    for r in results:
        curve = np.interp(grid, r["strain"], r["wall_stress"])
        diff = (curve - ref) / ref.mean()
        r["window"] = [lo, hi]
        r["stress_mean"] = float(curve.mean())
        r["error_mean"] = float(diff.mean())
        r["error_rms"] = float(np.sqrt(np.mean(diff ** 2)))
        r["particles_difference"] = trajectory_difference(
            ref_records, ref_records if r is results[0] else variant_records(r), hi)
        r["fluid_solves_per_step"] = r["fluid_solves"] / r["steps"]


def plot(results: List[Dict], path: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 4.5))
    for r in results:
        label = "dt %g, fluid every %d (fluid dt %g), tolLambda %g" % (r["dt"], r["fluid_every"], r["fluid_dt"],
                                                                      r.get("tol_lambda", 0.01))
        a.plot(r["strain"], r["wall_stress"], lw=0.9, label=label)
        if r is not results[0]:
            b.plot(r["wall_seconds"], 100 * r["error_rms"], "o")
            b.annotate(result_name(r), (r["wall_seconds"], 100 * r["error_rms"]),
                       textcoords="offset points", xytext=(4, 4), fontsize=8)
    lo, hi = results[0]["window"]
    a.axvspan(lo, hi, color="0.92", zorder=0)
    a.set_xlabel("strain")
    a.set_ylabel("wall shear stress [Pa]")
    a.legend(fontsize=7)
    b.set_xlabel("wall time [s]")
    b.set_ylabel("rms difference from %s over strain %g-%g [%%]"
                 % (result_name(results[0]), lo, hi))
    b.set_ylim(bottom=0)
    fig.tight_layout()
    fig.savefig(path, dpi=100)


def main(argv=None) -> Dict:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--phi", type=float, default=0.47)
    p.add_argument("--size", type=float, nargs=3, default=(10, 16, 8))
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--a-over-delta", type=float, default=3.0)
    p.add_argument("--tol-lambda", type=float, default=0.01)
    p.add_argument("--strain", type=float, default=1.5, help="strain units each variant runs")
    p.add_argument("--window", type=float, nargs=2, default=(0.1, 1.2), metavar=("LO", "HI"),
                   help="strain range over which the curves are compared")
    p.add_argument("--dump-every", type=float, default=0.5, help="strain between particle snapshots")
    p.add_argument("--variants", nargs="+", type=parse_variant, default=[parse_variant(v) for v in DEFAULT_VARIANTS],
                   metavar="DT:K[:TOL]",
                   help="particle step, steps per fluid step and (optional) tolLambda; the first is the reference")
    p.add_argument("--held-drag", choices=suspension.HELD_DRAG, default=suspension.HELD_DRAG[0],
                   help="how the steps between fluid steps hold the fluid's force (fix fdm/couple held_drag)")
    p.add_argument("--jobs", type=int, default=1, help="variants run at once (each takes two processes)")
    p.add_argument("--workdir", default=os.path.join(HERE, "runs", "fluidEvery"))
    p.add_argument("--out", default=None, help="default docs/benchmarks_fluidEvery_phi<PHI>.json")
    args = p.parse_args(argv)
    if args.out is None:
        args.out = os.path.join(PROJECT, "docs", "data", "benchmarks_fluidEvery_phi%g.json" % args.phi)
    os.makedirs(args.workdir, exist_ok=True)
    with ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        results = list(pool.map(lambda v: run_variant(v[0], v[1], v[2], args), args.variants))
    compare(results, tuple(args.window))
    summary = dict(command="cases/couette/fluidEvery.py " + " ".join(sys.argv[1:] if argv is None else argv),
                   phi=args.phi, size=list(args.size), seed=args.seed, a_over_delta=args.a_over_delta,
                   tol_lambda=args.tol_lambda, strain=args.strain, window=list(args.window), held_drag=args.held_drag,
                   runs=[{k: v for k, v in r.items() if k not in ("strain", "wall_stress")} for r in results])
    print("%-26s %9s %8s %8s %11s %11s %10s %9s %9s %9s %9s" % (
        "variant", "fluid dt", "wall s", "fluid st", "inner/fluid", "solves/step", "limited/ps", "err mean", "err rms",
        "|dx| a1", "|dU|/U"))
    for r in results:
        pu = r.get("position_update") or {}
        moved = r.get("particles_difference") or {}
        print("%-26s %9g %8.0f %8d %11.1f %11.2f %10.4f %8.1f%% %8.1f%% %9.1e %9.1e"
              % (result_name(r), r["fluid_dt"], r["wall_seconds"], r["fluid_steps"],
                 r["inner_iterations_mean"], r["fluid_solves_per_step"], pu.get("limited_per_particle_step") or 0.0,
                 100 * r["error_mean"], 100 * r["error_rms"], moved.get("position", np.nan),
                 moved.get("velocity", np.nan)))
    summary = files.relative_paths(summary)   # run folders relative to here: a summary may be shipped (docs/data)
    files.write_json(args.out, summary, indent=1)
    plot(results, os.path.splitext(args.out)[0] + ".png")
    print("wrote", args.out)
    return summary


if __name__ == "__main__":
    main()
