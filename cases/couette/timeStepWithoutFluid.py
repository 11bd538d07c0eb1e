#!/usr/bin/env python3
"""The time step of a sheared suspension's particle side, without the fluid solver (issue 11).

A Couette scene's packing and pair style (sub-grid lubrication, frictional springs, moving walls),
run by fdmDEM alone with `fix fdm/couple transport none background_shear 1` (docs/dem.md): each
sphere's isolated drag is taken relative to the simple shear, the sub-grid lubrication and the
springs act as in the coupled run, and the position update is the same. The viscosity measure is
the bulk particle stress, eta_r = 1 + sum_p (S^h_xy + S^c_xy) / (V eta gamma_dot) (the isolated
spheres' stresslets, the sub-grid part and the contacts), time-averaged after --from-strain with
block-averaging errors. Not a suspension model (no hydrodynamic interaction beyond the sub-grid
range): a testbed in seconds of what the time step does to the particles' dynamics.

  timeStepWithoutFluid.py --run RUN_DIR                  dt 0.04, 0.02, 0.01, 120 strain units each
  timeStepWithoutFluid.py --run RUN_DIR --dts 0.04 --fix "integrator euler"
  timeStepWithoutFluid.py --phi 0.52 --dts 0.0068 0.0034 0.0017 --strain 40
                                                          the scene written first: couette.py --phi 0.52
                                                          --size 10 16 8 --seed 1 --write-only (--size, --seed)

RUN_DIR is a folder couette.py wrote (its dem/spheres.data and dem/in.couette are read; the scene's
units: a1 = 1, eta = 1, gamma_dot_0 = 1). Writes <workdir>/dt<DT>/ per run and --out (JSON). Each row
also gives the position update's counts (demonly.position_update_counts): above 0.005 limited gap targets
per particle and step the step is too large (docs/benchmarks.md, "What limits the time step").
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import time

import numpy as np

from fdmsubgrid import case, demonly, output, profiles, timeseries
from fdmsubgrid.environment import program, run_environment
import couette  # --phi: the scene is couette.py's, written and not run

HERE = os.path.dirname(os.path.abspath(__file__))

ETA, SHEAR_RATE = 1.0, 1.0   # the Couette scenes' units (couette.py)


def dem_input(couette_input: str, dt: float, steps: int, a_over_delta: float, extra_fix: str) -> str:
    """The coupled run's LIGGGHTS input with the fluid replaced by the background shear."""
    lines = []
    for line in couette_input.splitlines():
        word = line.split()[0] if line.split() else ""
        if word in ("timestep", "run", "thermo", "thermo_style") or line.startswith("#") or not word:
            continue
        if word == "fix" and "fdm/couple" in line:
            line = ("fix             couple all fdm/couple transport none viscosity %r mesh %r background_shear %r "
                    "stresslets yes walls walls.dat %s" % (ETA, 1.0 / a_over_delta, SHEAR_RATE, extra_fix)).rstrip()
        elif word == "fix" and "fdm/output" in line:
            line = case.records_line(max(1, round(0.04 / dt)))
        elif word == "read_data":
            line = "read_data       spheres.data"
        lines.append(line)
        if word == "neigh_modify":
            lines.append("timestep        %r" % dt)
    return "\n".join(lines + ["thermo          1000", "run             %d" % steps]) + "\n"


def viscosity(records_path: str, from_strain: float) -> dict:
    """eta_r from the records' bulk particle shear stress, and the core's shear rate (profiles.core_shear_rate:
    the core |y - y_mid| < L_y/2 - 5 a1, as for the coupled runs)."""
    r = output.read_particle_records(records_path)
    channel = profiles.Channel(r.header["box_lo"], r.header["box_hi"])
    volume = float(np.prod(np.subtract(channel.hi, channel.lo)))
    hydro = (r["S_fluid"][..., 1] + r["S_subgrid"][..., 1]).sum(axis=1) / volume
    contact = r["S_contact"][..., 1].sum(axis=1) / volume
    keep = r.times * SHEAR_RATE >= from_strain
    eta = timeseries.block_average(1 + (hydro[keep] + contact[keep]) / (ETA * SHEAR_RATE))
    snapshots, _ = output.record_snapshots(r, SHEAR_RATE)
    rates = [profiles.core_shear_rate(s, channel) for s, k in zip(snapshots, keep) if k]
    return dict(eta_r=float(eta.mean), eta_r_err=float(eta.error), contact=float(contact[keep].mean()),
                hydrodynamic=float(hydro[keep].mean()), gamma_core=float(np.mean(rates)), samples=int(keep.sum()))


def report_progress(process: subprocess.Popen, log_path: str, dt: float, steps: int, t0: float,
                    every: float = 60.0) -> None:
    """Wait for fdmDEM, printing the step it reached (its thermo lines, every 1000 steps) and an ETA every
    `every` seconds of a long run."""
    last, shown = t0, 0
    while process.poll() is None:
        time.sleep(1.0)
        if time.time() - last < every:
            continue
        last = time.time()
        with open(log_path) as f:
            reached = [int(line.split()[0]) for line in f if line.split() and line.split()[0].isdigit()]
        if reached and reached[-1] > shown:
            shown = reached[-1]
            rate = (time.time() - t0) / reached[-1]
            print("dt %g: step %d of %d (%.0f %%), about %.0f s to go" % (dt, reached[-1], steps,
                                                                         100.0 * reached[-1] / steps,
                                                                         rate * (steps - reached[-1])), flush=True)


def main(argv=None) -> dict:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    source = p.add_mutually_exclusive_group(required=True)
    source.add_argument("--run", help="a Couette run folder (couette.py's RUN_DIR)")
    source.add_argument("--phi", type=float, help="write the Couette scene of this phi_bulk first (couette.py "
                        "--write-only, in --workdir) and use it")
    p.add_argument("--size", type=float, nargs=3, default=(10, 16, 8), help="with --phi: box in a1")
    p.add_argument("--seed", type=int, default=1, help="with --phi: seed of the packing")
    p.add_argument("--dts", type=float, nargs="+", default=[0.04, 0.02, 0.01], help="time steps [1/gamma_dot_0]")
    p.add_argument("--strain", type=float, default=120.0, help="strain units per run")
    p.add_argument("--from-strain", type=float, default=6.0, help="average from this strain on")
    p.add_argument("--a-over-delta", type=float, default=3.0, help="the sub-grid model's a1/Delta")
    p.add_argument("--fix", default="", help="more fix fdm/couple keywords, e.g. 'integrator euler'")
    p.add_argument("--workdir", default=os.path.join(HERE, "runs", "timeStepWithoutFluid"))
    p.add_argument("--out", default="timeStepWithoutFluid.json")
    args = p.parse_args(argv)
    if args.phi is not None:
        scenes = os.path.join(args.workdir, "scene")
        shutil.rmtree(scenes, ignore_errors=True)
        args.run = couette.main(["--phi", repr(args.phi), "--size", *map(repr, args.size), "--seed", str(args.seed),
                                 "--a-over-delta", repr(args.a_over_delta), "--write-only", "--workdir", scenes])["run_dir"]
    dem = os.path.join(args.run, "dem")
    for name in ("spheres.data", "in.couette"):
        if not os.path.isfile(os.path.join(dem, name)):
            raise SystemExit("timeStepWithoutFluid: %s has no dem/%s: is it a folder couette.py wrote?" % (args.run, name))
    with open(os.path.join(dem, "in.couette")) as f:
        couette_input = f.read()
    rows = []
    for dt in args.dts:
        folder = os.path.join(args.workdir, "dt%g" % dt)
        shutil.rmtree(folder, ignore_errors=True)
        os.makedirs(folder)
        shutil.copy(os.path.join(dem, "spheres.data"), folder)
        steps = int(round(args.strain / dt))
        with open(os.path.join(folder, "in.dem"), "w") as f:
            f.write(dem_input(couette_input, dt, steps, args.a_over_delta, args.fix))
        t0 = time.time()
        with open(os.path.join(folder, "log"), "w") as log:
            done = subprocess.Popen([program("fdmDEM"), "-in", "in.dem", "-log", "none"], cwd=folder, stdout=log,
                                    stderr=subprocess.STDOUT, env=run_environment())
            report_progress(done, os.path.join(folder, "log"), dt, steps, t0)
        if done.returncode != 0:
            raise SystemExit("timeStepWithoutFluid: fdmDEM stopped at dt %g (exit code %d): see %s"
                             % (dt, done.returncode, os.path.join(folder, "log")))
        row = dict(dt=dt, steps=steps, wall_seconds=time.time() - t0, fix=args.fix)
        row.update(viscosity(os.path.join(folder, "particles.records"), args.from_strain))
        with open(os.path.join(folder, "log")) as log:
            counts = demonly.position_update_counts(log.read())
        # the position update's counts: beyond demonly.LIMITED_RATE_LIMIT limited targets per particle and
        # step the time step is too large
        row["position_update"] = counts
        rows.append(row)
        print("dt %-6g eta_r %.2f +- %.2f (contact %.2f, hydrodynamic %.2f), gamma_core %.3f, %d steps in %.0f s%s"
              % (dt, row["eta_r"], row["eta_r_err"], row["contact"], row["hydrodynamic"], row["gamma_core"], steps,
                 row["wall_seconds"], "" if counts is None else
                 "; position update: %.2g limited targets per particle and step, fallback in %.0f %% of the steps"
                 % (counts["limited_per_particle_step"] or 0.0, 100 * counts["fallback_fraction"])),
              flush=True)
    summary = dict(run=os.path.abspath(args.run), strain=args.strain, from_strain=args.from_strain, rows=rows,
                   command="cases/couette/timeStepWithoutFluid.py " + " ".join(argv if argv is not None else sys.argv[1:]))
    with open(args.out, "w") as f:
        json.dump(summary, f, indent=1)
    print("wrote %s" % args.out)
    return summary


if __name__ == "__main__":
    main()
