#!/usr/bin/env python3
"""The channel's time step: the particle step DT and the fluid every K-th step, measured where the core
is densest (issue 48; docs/benchmarks.md, "The channel's time step").

Every variant DT:K is the channel of poiseuille.py started from one dense state (the last record of a
run of the same channel, --start; without it the README's channel is run first, 40 time units, to a
migrated core at phi about 0.52) and run for --duration time units with the particle step DT (in
L_y/(2 U_c)) and the fluid solved every K-th step. At an imposed pressure gradient the suspension's
viscosity sets the bulk velocity (fdmsubgrid.poiseuille.flow_rate), as it sets the wall stress at an
imposed shear rate: its curve against time over --window is compared with the reference's (the first
variant, the finest step), mean and rms of the difference over the reference's mean, while the runs
stay on one path; and the smallest pair gap of each run says how deep its contacts went (the roughness
layer is h_r = 0.005 a1 deep; fdmDEM stops a run at an overlap of 0.05 a1).

  timeStep.py                              variants 0.025:1 (reference) 0.05:1 0.1:1 0.05:2 0.05:4 0.025:4
                                           0.2:1, 4 time units each
  timeStep.py --start RUN/dem/particles.records --variants 0.025:1 0.05:4
  timeStep.py --start RUN/dem/particles.records --variants 0.05:8 0.1:4 0.2:2 0.05:8:10 0.1:4:10
                                           the stability map (docs/benchmarks.md, "The channel's stability
                                           map"): DT:K:S, the recipe's springs k_n = k_t times S
  timeStep.py --start RUN/dem/particles.records --variants 0.025:1 0.05:4 0.025:1:consistent 0.05:4:consistent
                                           a variant ending in :consistent slides its contacts with fix
                                           fdm/couple coulomb_solve consistent (docs/contact.md 2c)

A variant that stops (fdmDEM's overlap of 0.05 a1, or any other fault) is reported with its error and the
smallest gap it reached; the runs it finished are compared.

Writes <workdir>/<variant>.json per variant (a variant whose file exists is not run again) and --out
(default docs/data/benchmarks_channelTimeStep.json) with a figure beside it.
"""
import argparse
import json
import os
import sys
import time
from typing import Dict, List, Tuple

import numpy as np

from fdmsubgrid import case, contacts, output, poiseuille as channel, suspension
import poiseuille

HERE = os.path.dirname(os.path.abspath(__file__))
PROJECT = os.path.dirname(os.path.dirname(HERE))
DEFAULT_VARIANTS = ["0.025:1", "0.05:1", "0.1:1", "0.05:2", "0.05:4", "0.025:4", "0.2:1"]


def parse_variant(text: str) -> Tuple[float, int, float, str]:
    """'DT:K', 'DT:K:S', each optionally ending in ':consistent' (or ':frozen') -> (DT, K, S, C): the particle
    step, the fluid every K-th step, the recipe's springs times S (default 1), fix fdm/couple's coulomb_solve C
    (default frozen; docs/contact.md 2c)."""
    try:
        parts = text.split(":")
        coulomb = suspension.COULOMB_SOLVE[0]
        if len(parts) > 2 and parts[-1] in suspension.COULOMB_SOLVE:
            coulomb = parts.pop()
        if len(parts) not in (2, 3):
            raise ValueError
        dt, k = float(parts[0]), int(parts[1])
        stiffness = float(parts[2]) if len(parts) == 3 else 1.0
    except ValueError:
        raise argparse.ArgumentTypeError("a variant is DT:K or DT:K:S (particle step, fluid every K-th step, "
                                         "springs times S), optionally ending in :consistent, got %r" % text)
    if dt <= 0 or k < 1 or not stiffness > 0:
        raise argparse.ArgumentTypeError("variant %r: DT and S must be positive and K at least 1" % text)
    return dt, k, stiffness, coulomb


def variant_name(dt: float, k: int, stiffness: float = 1.0, coulomb: str = suspension.COULOMB_SOLVE[0]) -> str:
    return "dt%g_K%d%s%s" % (dt, k, "" if stiffness == 1 else "_k%g" % stiffness,
                             "" if coulomb == suspension.COULOMB_SOLVE[0] else "_" + coulomb)


def spring_options(stiffness: float, size: List[float]) -> List[str]:
    """poiseuille.py's --kn and --kt: the recipe's springs of the channel (docs/contact.md, for its wall shear
    stress tau_w and the paper's radii, which the records' spheres are) times `stiffness`; none at 1."""
    if stiffness == 1:
        return []
    grad, _ = poiseuille.pressure_gradient(size[1])
    rule = suspension.choose_springs(abs(grad) * size[1] / 2, 1.0, suspension.A1 / 3.0)
    return ["--kn", repr(rule.kn * stiffness), "--kt", repr(rule.kt * stiffness)]


def run_variant(dt: float, k: int, start: str, args, workdir: str, stiffness: float = 1.0,
                coulomb: str = suspension.COULOMB_SOLVE[0]) -> Dict:
    """One variant from the start records: its flow-rate curve, smallest gaps and cost; how it ended."""
    name = variant_name(dt, k, stiffness, coulomb)
    path = os.path.join(workdir, name + ".json")
    if os.path.isfile(path):
        with open(path) as f:
            return json.load(f)
    folder = os.path.join(workdir, name)
    begin = time.time()
    error = None
    analysis_note = None
    try:
        results = poiseuille.main(["--from-records", start, "--dt", str(dt), "--fluid-every", str(k),
                                   "--duration", str(args.duration), "--dump-every", str(dt * k),
                                   "--workdir", folder, "--out", os.path.join(folder, "results.json"),
                                   "--overwrite", "--keep", "--coulomb-solve", coulomb] + (["--size", *map(str, args.size)])
                                  + spring_options(stiffness, args.size))
        run_dir = results["run_dir"]
    except (SystemExit, channel.PoiseuilleRunError) as e:
        # SystemExit: the run stopped; PoiseuilleRunError: it ran, but the channel's analysis cannot take
        # it (too few records for time averages: a coarse step over a short --duration); its flow-rate
        # curve still compares
        if isinstance(e, channel.PoiseuilleRunError):
            analysis_note = str(e)
        else:
            error = str(e)
        runs = [os.path.join(folder, d) for d in os.listdir(folder)] if os.path.isdir(folder) else []
        run_dir = next((r for r in runs if os.path.isdir(r)), None)
    wall = time.time() - begin
    if error is not None and run_dir:
        # the code's own message (the overlap that stopped fdmDEM names its particles)
        error = case.last_error(run_dir) or error
    out = dict(dt=dt, fluid_every=k, fluid_dt=dt * k, stiffness_factor=stiffness, coulomb_solve=coulomb,
               wall_seconds=wall, error=error)
    if analysis_note:
        out["analysis"] = analysis_note
    if run_dir and os.path.isdir(os.path.join(run_dir, "fluid", "postProcessing")):
        t, q = channel.flow_rate(run_dir)
        steps = output.steps(os.path.join(run_dir, "fluid"))
        gaps = contacts.smallest_gaps(os.path.join(run_dir, "dem", "particles.records"))
        out.update(time=t.tolist(), flow_rate=q.tolist(), fluid_steps=len(t),
                   solves_per_fluid_step=float(np.mean(steps["innerIterations"])),
                   fluid_seconds=float(np.sum(steps["fluidSeconds"])),
                   smallest_gap=float(gaps.min()) if len(gaps) else None, run=os.path.basename(run_dir),
                   time_reached=float(t[-1]) if len(t) else 0.0)
    with open(path, "w") as f:
        json.dump(out, f, indent=1)
    return out


def _springs_label(r: Dict) -> str:
    """What sets a variant apart besides DT and K: its springs' factor, its coulomb_solve if not frozen."""
    return (("" if r.get("stiffness_factor", 1.0) == 1 else ", springs x%g" % r["stiffness_factor"])
            + ("" if r.get("coulomb_solve", "frozen") == "frozen" else ", " + r["coulomb_solve"]))


def compare(reference: Dict, variant: Dict, window: Tuple[float, float]) -> Dict:
    """Mean and rms difference of the variant's flow-rate curve from the reference's over the window,
    over the reference's mean (the variant's fluid steps, the reference interpolated to them)."""
    t = np.asarray(variant.get("time", []))
    if len(t) == 0:
        return dict(mean_difference=None, rms_difference=None)
    inside = (t >= window[0]) & (t <= window[1])
    ref = np.interp(t[inside], reference["time"], reference["flow_rate"])
    d = np.asarray(variant["flow_rate"])[inside] - ref
    scale = float(np.mean(ref))
    return dict(mean_difference=float(np.mean(d) / scale), rms_difference=float(np.sqrt(np.mean(d ** 2)) / scale),
                reference_mean=scale)


def plot(path: str, runs: List[Dict], window) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 4.5))
    colours = {id(r): "C%d" % (i % 10) for i, r in enumerate(runs)}
    for r in runs:
        if r.get("time"):
            a.plot(r["time"], r["flow_rate"], color=colours[id(r)], lw=1.6 if r is runs[0] else 1.0,
                   label="dt %g, K %d%s%s%s" % (r["dt"], r["fluid_every"], _springs_label(r),
                                                " (reference)" if r is runs[0] else "",
                                              " (failed)" if r.get("error") else ""))
    a.axvspan(*window, color="0.9", zorder=0)
    a.set_xlabel("t 2U_c/L_y from the dense state")
    a.set_ylabel("bulk velocity <U_x>/(2 U_c)")
    a.legend(fontsize=8)
    for r in runs[1:]:
        if r.get("rms_difference") is not None:
            b.errorbar(r["wall_seconds"], 100 * r["mean_difference"], yerr=100 * r["rms_difference"], fmt="o",
                       capsize=3, color=colours[id(r)])
            b.annotate("%g:%d%s" % (r["dt"], r["fluid_every"], _springs_label(r)), (r["wall_seconds"], 100 * r["mean_difference"]),
                       fontsize=8, xytext=(4, 4), textcoords="offset points")
    b.axhline(0, color="0.5", lw=0.8)
    b.set_xlabel("wall seconds")
    b.set_ylabel("bulk velocity vs reference, % (bar: rms)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main(argv=None) -> Dict:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--variants", nargs="+", type=parse_variant, default=[parse_variant(v) for v in DEFAULT_VARIANTS],
                   help="DT:K ... (the first is the reference)")
    p.add_argument("--start", default=None, metavar="RECORDS",
                   help="particle records of a run of the channel whose last block is the start (default: the "
                        "README's channel, run first into <workdir>/start)")
    p.add_argument("--size", type=float, nargs=3, default=[8.0, 12.0, 8.0], metavar=("LX", "LY", "LZ"))
    p.add_argument("--duration", type=float, default=4.0, help="time units each variant runs")
    p.add_argument("--window", type=float, nargs=2, default=None, metavar=("FROM", "TO"),
                   help="the times compared (default: the whole run but its first coarse fluid step)")
    p.add_argument("--workdir", default=os.path.join(PROJECT, "runs", "channelTimeStep"))
    p.add_argument("--out", default=os.path.join(PROJECT, "docs", "data", "benchmarks_channelTimeStep.json"))
    args = p.parse_args(argv)
    os.makedirs(args.workdir, exist_ok=True)
    start = args.start
    if start is None:
        start_dir = os.path.join(args.workdir, "start")
        done = os.path.join(start_dir, "results.json")
        if not os.path.isfile(done):
            poiseuille.main(["--workdir", start_dir, "--out", done, "--overwrite", "--size", *map(str, args.size)])
        run = [d for d in os.listdir(start_dir) if os.path.isdir(os.path.join(start_dir, d))][0]
        start = os.path.join(start_dir, run, "dem", "particles.records")
    coarsest = max(dt * k for dt, k, _, _ in args.variants)
    window = tuple(args.window) if args.window else (coarsest, args.duration)
    runs = []
    for dt, k, stiffness, coulomb in args.variants:
        r = run_variant(dt, k, start, args, args.workdir, stiffness, coulomb)
        print("dt %g K %d springs x%g coulomb_solve %s: %s, %.0f s, smallest gap %s" % (
            dt, k, stiffness, coulomb, "failed: " + r["error"] if r.get("error") else "ran", r["wall_seconds"],
            r.get("smallest_gap")), flush=True)
        runs.append(r)
    for r in runs[1:]:
        r.update(compare(runs[0], r, window))
    print("%-6s %-3s %-7s %-10s %-8s %-8s %-12s %-10s %-10s %s" % ("dt", "K", "springs", "coulomb", "wall s", "fluid s",
                                                                   "solves/step", "mean diff", "rms diff", "smallest gap"))
    for r in runs:
        md, rd = r.get("mean_difference"), r.get("rms_difference")
        print("%-6g %-3d %-7s %-10s %-8.0f %-8.0f %-12.1f %-10s %-10s %s" % (
            r["dt"], r["fluid_every"], "x%g" % r.get("stiffness_factor", 1.0), r.get("coulomb_solve", "frozen"),
            r["wall_seconds"], r.get("fluid_seconds", float("nan")),
            r.get("solves_per_fluid_step", float("nan")), "ref" if r is runs[0] else ("%+.2f %%" % (100 * md) if md is not None else "-"),
            "%.2f %%" % (100 * rd) if rd is not None else "-", r.get("smallest_gap")))
    given = list(argv if argv is not None else sys.argv[1:])
    kept = []
    for i, a in enumerate(given):   # where the files go is not part of the measurement
        if a in ("--workdir", "--out") or (i and given[i - 1] in ("--workdir", "--out")):
            continue
        kept.append(a if not a.startswith(os.sep) else os.path.basename(a))
    command = " ".join(["cases/poiseuille/timeStep.py"] + kept)
    header = output.read_records_header(start)
    summary = dict(command=command, start="%s, last record (time %.4g s)" % (
                       "the README's channel run first (poiseuille.py defaults)" if args.start is None
                       else os.path.basename(start), output.read_particle_records(start).times[-1]),
                   start_particles=header["particles"], duration=args.duration, window=list(window),
                   variants=[{k: v for k, v in r.items() if k not in ("time", "flow_rate")} for r in runs])
    with open(args.out, "w") as f:
        json.dump(summary, f, indent=1)
    plot(os.path.splitext(args.out)[0] + ".png", runs, window)
    print("wrote %s and its figure" % args.out)
    return summary


if __name__ == "__main__":
    main()
