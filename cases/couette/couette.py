#!/usr/bin/env python3
"""A frictional bidisperse suspension in plane Couette flow (paper section 6.1, Table 8, Eqs. 49-57).

Walls y = 0 and y = L_y move at -U and +U along x (nominal shear rate gamma_dot_0 = 2U/L_y = 1),
x and z are periodic. The suspension: spheres of radii a1 = 1 and a2 = 1.4 a1 in equal volumes
(phi_1 = phi_2 = phi_bulk/2), placed at random without overlap and clear of the walls
(fdmsubgrid.packing.channel_packing), frictional contact with h_r = 5e-3 a1 and mu_s = 0.5 (pairs and
walls), sub-grid lubrication for pairs and walls, stresslets on. Units: a1 = 1 m, eta = 1 Pa s,
gamma_dot_0 = 1 1/s (time = strain).

The contact springs follow the rules of docs/contact.md ("A recipe", fdmsubgrid.suspension), computed
and printed, with the design load F_max = 6 pi a2^2 tau for the shear stress tau = eta gamma_dot_0
eta_MP(phi) (the relative viscosity from the paper's Maron-Pierce fit, Eq. 55: alpha = 0.803,
phi_m = 0.59); the scene is written by fdmsubgrid.suspension.write_case, shared with cases/poiseuille.

  couette.py                         the small scene (about 40 spheres, 10 x 12 x 8 a1, a1/Delta = 3,
                                     3 strain units at dt = 0.02): a few minutes
  couette.py --acceleration none     the same with the plain inner iteration (issue 13, benchmark c)
  couette.py --table8 0.27           writes the paper's Table 8 scene for phi_bulk = 0.27 (box, N_P, dt)
                                     and stops (run it with fdmRun, or --run)
  couette.py --phi 0.47 --write-only the scene written, not run (fdmRun, or timeStepWithoutFluid.py --run)
  couette.py --help                  every option
Writes <workdir>/<run>/ (fluid/, dem/), results.json and results_couette.png here (docs/cases.md).
"""

import argparse
import math
import os
import shutil
import sys
from dataclasses import asdict

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "scripts"))
from fdmsubgrid import case, packing, shear, suspension  # noqa: E402

A1 = suspension.A1
A2 = suspension.A2
ETA = suspension.ETA
SHEAR_RATE = 1.0
ROUGHNESS = suspension.ROUGHNESS   # h_r (section 6)
FRICTION = suspension.FRICTION     # mu_s (section 6)

# Table 8: phi_bulk -> (phi_core, gamma_core/gamma_0, (Lx, Ly, Lz)/a1, N_P, dt)
TABLE8 = {
    0.27: (0.303, 0.923, (20, 20, 20), 350, 1e-4),
    0.32: (0.359, 0.885, (20, 20, 20), 416, 1e-4),
    0.37: (0.405, 0.873, (20, 20, 20), 481, 1e-4),
    0.42: (0.458, 0.773, (20, 20, 20), 547, 1e-4),
    0.47: (0.493, 0.745, (25, 25, 20), 956, 1e-4),
    0.52: (0.543, 0.563, (25, 25, 20), 1057, 1e-4),
    0.54: (0.570, 0.391, (25, 25, 20), 1098, 2e-5),
}


# The largest time step measured good with the case's springs (phi_bulk -> dt gamma_dot_0, a1/Delta = 3,
# seed 1): the run holds (no overlap beyond h_r) and its viscosity is that of smaller steps within the error
# bars. History (docs/benchmarks.md, "Stability map", "The time step at phi 0.37 / 0.42"): the coupled
# runs' error bars (3-7 % over 8-16 strain units) could not resolve it; the particle side alone in a
# background shear (fix fdm/couple background_shear; cases/couette/timeStepWithoutFluid.py, "Without the
# fluid: the time step") does, in minutes: with k_t = k_n, dt 0.04 gives eta_r 0.7 % below dt 0.02 at
# phi_bulk 0.27, 7 % at 0.32, 12-15 % at 0.37 and 21 % at 0.42 (as the coupled runs), dt 0.02 within
# 3 % of 0.01 and 0.005 up to 0.42; at 0.47 dt 0.02 is 30 % below 0.01, which agrees with 0.005
# (14.8 +- 0.7, 21.1 +- 0.9, 20.9 +- 0.7, 2026-11-27: "What limits the time step"). What sets the limit
# is the position update: where it limits more than 0.005 gap targets per particle and step (gaps asked to
# change by more than a factor e in a step; 0.010-0.027 in the runs 12-30 % low, 0.0002-0.0027 in the good
# ones) its targets contradict each other in most steps and the particle stress is low; a run reports it
# (demonly.position_update_counts, docs/errors.md 27f). Beyond the densest measured row the
# limit is carried with the stress scale, dt proportional to 1/eta_MP(phi) (Eq. 55): the loads in the
# contacts, and the closing rates of loaded gaps, grow with it (0.0034 at 0.52, 0.0024 at 0.54).
MEASURED_DT_LIMITS = {0.27: 0.04, 0.32: 0.02, 0.37: 0.02, 0.42: 0.02, 0.47: 0.01}


# The largest fluid step measured good with particle steps between fluid steps (fix fdm/couple ... fluid_every K,
# docs/dem.md "Particle steps between fluid steps"; phi_bulk -> fluid dt gamma_dot_0, the denser row's applies,
# the densest's beyond it). Measured on the first strain unit of the small scenes, where runs from one packing
# stay together and their wall-stress curves differ by the time-step error (cases/couette/fluidEvery.py,
# docs/benchmarks.md "Particle steps between fluid steps"): the particle step sets the error, the fluid's the
# cost. At 0.42 the fluid every 0.04 with the particles at 0.02 or 0.01 is within 2.3 % of the run at 0.005
# throughout (0.04 throughout: 6.6 % low); at 0.47 the fluid every 0.02 with the particles at 0.01-0.0025 is
# within 3 % (0.02 throughout: 10 % low), every 0.04 as close on average but 8 % rms; on a second packing
# (seed 2) every 0.02 -3.8 %, every 0.04 -5.6 %, 0.02 throughout -9.7 %.
MEASURED_FLUID_DT = {0.42: 0.04, 0.47: 0.02}


def _nearest_denser(measured: dict, phi: float) -> float | None:
    """The nearest volume fraction of `measured` at or above phi (within 0.01: a measured row counts for the
    packings of its nominal phi_bulk), None beyond the densest."""
    denser = [p for p in sorted(measured) if p >= phi - 0.01]
    return denser[0] if denser else None


def fluid_dt(phi: float) -> float:
    """The fluid step [1/gamma_dot_0] at phi_bulk: MEASURED_FLUID_DT of the nearest measured row at or above
    phi (within 0.01), the densest's beyond."""
    reference = _nearest_denser(MEASURED_FLUID_DT, phi)
    return MEASURED_FLUID_DT[max(MEASURED_FLUID_DT) if reference is None else reference]


def fluid_every(phi: float, dt: float | None = None) -> int:
    """Particle steps per fluid step at phi_bulk with the particle step dt (default largest_good_dt(phi)):
    fluid_dt(phi) / dt rounded, at least 1."""
    step = largest_good_dt(phi) if dt is None else dt
    return max(1, int(round(fluid_dt(phi) / step)))


def measured_reference(phi: float) -> float | None:
    """The nearest volume fraction of MEASURED_DT_LIMITS at or above phi (within 0.01), None beyond the
    densest."""
    return _nearest_denser(MEASURED_DT_LIMITS, phi)


def largest_good_dt(phi: float) -> float:
    """The largest time step [1/gamma_dot_0] measured good at measured_reference(phi); beyond the densest,
    that row's limit scaled by eta_MP(densest)/eta_MP(phi)."""
    reference = measured_reference(phi)
    if reference is not None:
        return MEASURED_DT_LIMITS[reference]
    densest = max(MEASURED_DT_LIMITS)
    scaled = MEASURED_DT_LIMITS[densest] * (suspension.maron_pierce_viscosity(densest)
                                            / suspension.maron_pierce_viscosity(phi))
    unit = 10.0 ** (math.floor(math.log10(scaled)) - 1)
    return round(math.floor(scaled / unit * (1 + 1e-12)) * unit, 12)   # rounded down to two digits


def time_step_warning(phi: float, dt: float) -> str | None:
    """A warning if dt exceeds largest_good_dt(phi), else None."""
    limit = largest_good_dt(phi)
    if dt <= limit * (1 + 1e-9):
        return None
    reference = measured_reference(phi)
    if reference is not None:
        where = "the largest time step measured good at phi_bulk %g with these springs, %g" % (reference, limit)
    else:
        where = ("%g, the limit at phi_bulk %g scaled by the stress, 1/eta_MP(phi) (phi_bulk %.3g is denser "
                 "than any measured)" % (limit, max(MEASURED_DT_LIMITS), phi))
    return ("WARNING: dt = %g/gamma_dot_0 is beyond %s (docs/benchmarks.md, 'What limits the time step'): "
            "expect a viscosity below that of smaller steps, or overlapping spheres; a smaller --dt is safe, "
            "and with --fluid-every K (the fluid every K steps) it costs little more: --dt %g --fluid-every %d"
            % (dt, where, limit, max(1, int(round(dt / limit)))))


def choose_springs(phi: float, dt: float, delta: float, kn: float | None = None, kt: float | None = None
                   ) -> suspension.Springs:
    """The springs by the rule of the module docstring (docs/contact.md) for the shear stress
    eta gamma_dot_0 eta_MP(phi), unless given."""
    return suspension.choose_springs(ETA * SHEAR_RATE * suspension.maron_pierce_viscosity(phi), dt, delta, kn, kt)


def write_case(run_dir: str, pack: packing.Packing, springs: suspension.Springs, a_over_delta: float, dt: float,
               strain: float, dump_every: int, tol_lambda: float, acceleration: str, n_max: int = 50,
               write_every: int = 100000, text_dump: bool = False, model: str = "calibrated",
               fluid_options: dict | None = None, fluid_every: int = 1, held_drag: str = "extrapolated") -> dict:
    """fluid/ and dem/ of the run (suspension.write_case with the walls at -U and +U); returns the
    scene's description. fluid_options: more arguments of case.write_fluid_case; fluid_every: particle
    steps per fluid step; held_drag: how the steps between hold the fluid's force (fix fdm/couple)."""
    U = SHEAR_RATE * float(pack.box[1]) / 2
    steps = int(round(strain / (SHEAR_RATE * dt)))
    scene = suspension.write_case(run_dir, pack, springs, a_over_delta, dt, steps, dump_every, tol_lambda,
                                  acceleration, n_max, write_every, text_dump, model, wall_velocities=(-U, U),
                                  name="in.couette", fluid_options=fluid_options, fluid_every=fluid_every,
                                  held_drag=held_drag)
    scene.update(wall_velocity=U)
    return scene


def table8_row(phi: float) -> dict:
    """The paper's Table 8 row of phi_bulk."""
    return dict(zip(("phi_core", "gamma_core_over_gamma0", "size", "n_particles", "dt"), TABLE8[phi]))


def main(argv: list[str] | None = None) -> dict:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--phi", type=float, default=0.3, help="phi_bulk, the volume fraction of the spheres in the box")
    p.add_argument("--size", type=float, nargs=3, default=[10.0, 12.0, 8.0], metavar=("LX", "LY", "LZ"),
                   help="box in units of a1 (walls normal to y); each a whole number of cells")
    p.add_argument("--a-over-delta", type=float, default=3.0, help="a1/Delta, mesh cells per small radius")
    p.add_argument("--dt", type=float, default=None, help="time step in units of 1/gamma_dot_0 (default 0.02; "
                   "with --table8, Table 8's)")
    p.add_argument("--fluid-every", type=int, default=1, metavar="K",
                   help="solve the fluid every K-th particle step (its step K dt); the steps between hold its "
                   "force on each particle as a drag toward the velocity it gave (docs/dem.md, 'Particle steps "
                   "between fluid steps')")
    p.add_argument("--held-drag", choices=suspension.HELD_DRAG, default=suspension.HELD_DRAG[0],
                   help="with --fluid-every: the held force's drag target extrapolated from the last two fluid "
                   "steps (default) or constant (fix fdm/couple held_drag, docs/dem.md)")
    p.add_argument("--strain", type=float, default=3.0, help="strain units to run")
    p.add_argument("--seed", type=int, default=1, help="seed of the random packing")
    p.add_argument("--dump-every", type=float, default=0.1, help="strain between two particle snapshots")
    p.add_argument("--write-every", type=float, default=1.0, help="strain between two writes of the fluid fields "
                   "and of the particles' ParaView files (dem/vtk/particles.pvd; the fluid fields are deleted after the run unless --keep)")
    p.add_argument("--text-dump", action="store_true", help="also write the LIGGGHTS text dump dem/particles.dump "
                   "(the binary records dem/particles.records are what the analysis reads)")
    p.add_argument("--h-layer", type=float, default=5.0, help="H_layer/a1: the core is |y| < L_y/2 - H_layer")
    p.add_argument("--kn", type=float, default=None, help="normal spring [N/m] (default: the rule above)")
    p.add_argument("--kt", type=float, default=None, help="tangential spring [N/m] (default: the rule above)")
    p.add_argument("--n-max", type=int, default=50, help="fdmFoam's innerIterations nMax: a step that reaches it "
                   "unconverged is counted in unconverged_steps")
    p.add_argument("--np-dem", type=int, default=1, help="MPI ranks of fdmDEM")
    p.add_argument("--table8", type=float, default=None, metavar="PHI",
                   help="the paper's Table 8 scene for phi_bulk = PHI (box, N_P, dt): written, not run")
    p.add_argument("--run", action="store_true", help="with --table8: run it too")
    p.add_argument("--write-only", action="store_true", help="write the scene's folder and stop (as --table8 does): "
                   "run it later with fdmRun, or its particle side alone with timeStepWithoutFluid.py --run")
    p.add_argument("--overwrite", action="store_true", help="replace a run folder that already exists")
    p.add_argument("--analyse", metavar="RUN_DIR", default=None,
                   help="analyse this run folder as it stands (a resumed, stopped or running run) and write --out")
    case.add_run_options(p, HERE, tol_lambda=1e-3, model=True)
    args = p.parse_args(argv)

    if args.analyse:
        # a run folder as it stands (finished, stopped or still going): its own files say the scene
        # (the same as fdmProfiles RUN_DIR --out OUT, with the case's keys)
        run = shear.read_run(args.analyse)
        name = os.path.basename(os.path.normpath(args.analyse))
        table8 = None
        if name.startswith("table8_"):
            table8 = table8_row(min(TABLE8, key=lambda k: abs(k - run.packing.phi)))
        return shear.report(run, args.out, dict(case="couette", run=name, run_dir=os.path.abspath(args.analyse),
                                                table8=table8), h_layer=args.h_layer)

    n_particles = None
    phi = args.phi
    if args.table8 is not None:
        key = min(TABLE8, key=lambda k: abs(k - args.table8))
        if abs(key - args.table8) > 1e-9:
            p.error("--table8 %g: Table 8 has phi_bulk = %s" % (args.table8, ", ".join("%g" % k for k in TABLE8)))
        _, _, size, n_particles, dt_paper = TABLE8[key]
        args.size, phi = list(size), key
        args.dt = dt_paper if args.dt is None else args.dt
    dt = 0.02 if args.dt is None else args.dt
    delta = A1 / args.a_over_delta
    for L, name in zip(args.size, "xyz"):
        if abs(L / delta - round(L / delta)) > 1e-9 * L / delta:
            p.error("--size: L%s = %g a1 is not a whole number of cells of a1/%g" % (name, L, args.a_over_delta))
    if args.strain <= 0 or dt <= 0:
        p.error("--strain and --dt must be positive")
    if args.fluid_every < 1:
        p.error("--fluid-every must be at least 1")

    pack = packing.channel_packing(args.size, phi=None if n_particles else phi, n=n_particles, seed=args.seed,
                                   min_gap=2 * ROUGHNESS, wall_gap=2 * ROUGHNESS)
    print("packing:", pack.summary())
    missing = case.uncalibrated(pack.radii, delta, walls=True, model=args.model)
    if missing:
        raise SystemExit("couette: " + "; ".join(missing))
    springs = choose_springs(pack.phi, dt, delta, args.kn, args.kt)
    print(springs.describe(dt))
    warning = time_step_warning(pack.phi, dt)
    if warning:
        print(warning, flush=True)

    name = "phi%g_%gx%gx%g_ad%g_dt%g_seed%d%s" % (pack.phi if n_particles is None else phi, *args.size,
                                                  args.a_over_delta, dt, args.seed,
                                                  ("" if args.acceleration == "anderson" else "_" + args.acceleration)
                                                  + "_" + args.model)
    if args.fluid_every > 1:
        name += "_fluidEvery%d" % args.fluid_every
    if args.table8 is not None:
        name = "table8_" + name
    run_dir = os.path.join(args.workdir, name)
    if os.path.exists(run_dir):
        if not args.overwrite:
            raise SystemExit("couette: %s already holds a run; --overwrite replaces it" % run_dir)
        shutil.rmtree(run_dir)
    # snapshots on steps the fluid solved: multiples of K
    K = args.fluid_every
    every = K * max(1, int(round(args.dump_every / (SHEAR_RATE * dt * K))))
    write_every = K * max(1, int(round(args.write_every / (SHEAR_RATE * dt * K))))
    scene = write_case(run_dir, pack, springs, args.a_over_delta, dt, args.strain, every, args.tol_lambda,
                       args.acceleration, args.n_max, write_every, args.text_dump, args.model,
                       fluid_every=args.fluid_every, held_drag=args.held_drag)
    print("wrote %s: %d spheres (%d a1, %d a2), phi %.4f, box %s a1, %d cells, %d steps of dt %g, a snapshot "
          "every %d steps" % (run_dir, pack.n, np.sum(pack.types == 1), np.sum(pack.types == 2), pack.phi,
                              " x ".join("%g" % v for v in args.size), scene["cells"], scene["steps"], dt, every))
    if (args.table8 is not None and not args.run) or args.write_only:
        print("%s scene written, not run: fdmRun -f N -d M %s" % ("Table 8" if args.table8 is not None else "the",
                                                                  run_dir))
        return dict(run_dir=run_dir, **scene)

    wall = case.run(run_dir, np_fluid=args.np_fluid, np_dem=args.np_dem)
    results = shear.report(shear.read_run(run_dir), args.out,
                           dict(case="couette", run=name, run_dir=run_dir, acceleration=args.acceleration,
                                tol_lambda=args.tol_lambda, n_max=args.n_max, a_over_delta=args.a_over_delta,
                                seed=args.seed, springs=asdict(springs),
                                table8=None if args.table8 is None else table8_row(phi)),
                           wall_seconds=wall, ranks=args.np_fluid + args.np_dem, h_layer=args.h_layer)
    if not args.keep:
        case.delete_fields(run_dir)
    return results


if __name__ == "__main__":
    main()
