#!/usr/bin/env python3
"""A frictional suspension in plane Couette flow (paper section 6.1, Table 8, Eqs. 49-57).

Walls y = 0 and y = L_y move at -U and +U along x (nominal shear rate gamma_dot_0 = 2U/L_y = 1),
x and z are periodic. The suspension: by default the paper's, spheres of radii a1 = 1 and a2 = 1.4 a1 in
equal volumes (phi_1 = phi_2 = phi_bulk/2); any other with --radii and --volume-fractions (or --distribution
lognormal MEDIAN SIGMA N), each species a LIGGGHTS atom type; placed at random without overlap and clear of the walls
(fdmsubgrid.packing.channel_packing), frictional contact with h_r = 5e-3 a1 and mu_s = 0.5 (pairs and
walls), sub-grid lubrication for pairs and walls, stresslets on. Units: a1 = 1 m, eta = 1 Pa s,
gamma_dot_0 = 1 1/s (time = strain).

The contact springs follow the rules of docs/contact.md ("A recipe", fdmsubgrid.suspension), computed
and printed, with the design load F_max = 6 pi a2^2 tau for the shear stress tau = eta gamma_dot_0
eta_MP(phi) (the relative viscosity from the paper's Maron-Pierce fit, Eq. 55: alpha = 0.803,
phi_m = 0.59), a2 the largest radius; the smallest sets the mesh (at least 2 cells, and a calibration for
each of its pairs) and the time step (the default dt 0.02 shortened when a_max/a_min exceeds 1.4:
fdmsubgrid.suspension.time_step_factor); the scene (Table 8, the time-step limits, the springs, the run folder) is
fdmsubgrid.couettescene's, on fdmsubgrid.suspension.write_case, shared with cases/poiseuille.

  couette.py                         the small scene (about 40 spheres, 10 x 12 x 8 a1, a1/Delta = 3,
                                     3 strain units at dt = 0.02): a few minutes
  couette.py --acceleration none     the same with the plain inner iteration (issue 13, benchmark c)
  couette.py --table8 0.27           writes the paper's Table 8 scene for phi_bulk = 0.27 (box, N_P, dt)
                                     and stops (run it with fdmRun, or --run)
  couette.py --phi 0.47 --write-only the scene written, not run (fdmRun, or timeStepWithoutFluid.py --run)
  couette.py --radii 1 1.2 1.4 --volume-fractions 0.5 0.3 0.2
                                     three species (any radii the mesh and the calibration cover)
  couette.py ... --from-snapshot DIR the scene of these options written afresh and the compact snapshot DIR
                                     continued in it (its file `scene` holds the options; docs/coupling.md):
                                     a long row continued on another machine
  couette.py --help                  every option
Writes <workdir>/<run>/ (fluid/, dem/), results.json and results_couette.png here (docs/cases.md).
"""

import argparse
import os
import sys
import time
from dataclasses import asdict

from fdmsubgrid import case, checkpoint, shear, suspension
from fdmsubgrid.results import Row, write_results
from fdmsubgrid.couettescene import (A1, A2, ETA, FRICTION, MEASURED_DT_LIMITS, MEASURED_FLUID_DT,  # noqa: F401
                                     ROUGHNESS, SHEAR_RATE, TABLE8, UncalibratedScene, choose_springs, fluid_dt,
                                     fluid_every, largest_good_dt, measured_reference, table8_row,
                                     time_step_warning, write_case, write_run)

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_DT = 0.02   # 1/gamma_dot_0, for the paper's radii (suspension.scaled_time_step carries it to others)


def validation_rows(results: dict) -> list[Row]:
    """The run's rows (fdmsubgrid.results): phi_core, gamma_core/gamma0 (beside Table 8 for its scenes),
    eta_s beside the paper's fit of Fig. 21 at phi_core, N1, N2 and the stress balance."""
    return shear.validation_rows(results, "φ_bulk %g, %d particles, %.1f strain units" % (
        results["phi_bulk"], results["n_particles"], results["strain_units"]))


def results_writer(argv: list[str] | None, args: argparse.Namespace, started: float):
    """shear.report's writer of this case: results.json in the one shape (fdmsubgrid.results)."""
    def write(out: str, results: dict) -> None:
        write_results(out, __file__, argv, args, validation_rows, results, started)
    return write


def main(argv: list[str] | None = None) -> dict:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--phi", type=float, default=0.3, help="phi_bulk, the volume fraction of the spheres in the box")
    p.add_argument("--size", type=float, nargs=3, default=[10.0, 12.0, 8.0], metavar=("LX", "LY", "LZ"),
                   help="box in units of a1 (walls normal to y); each a whole number of cells")
    p.add_argument("--a-over-delta", type=float, default=3.0, help="a1/Delta, mesh cells per small radius")
    p.add_argument("--dt", type=float, default=None, help="time step in units of 1/gamma_dot_0 (default 0.02, "
                   "shortened for size ratios above 1.4; with --table8, Table 8's)")
    p.add_argument("--fluid-every", type=int, default=1, metavar="K",
                   help="solve the fluid every K-th particle step (its step K dt); the steps between hold its "
                   "force on each particle as a drag toward the velocity it gave (docs/dem.md, 'Particle steps "
                   "between fluid steps')")
    p.add_argument("--held-drag", choices=suspension.HELD_DRAG, default=suspension.HELD_DRAG[0],
                   help="with --fluid-every: the held force's drag target extrapolated from the last two fluid "
                   "steps (default) or constant (fix fdm/couple held_drag, docs/dem.md)")
    p.add_argument("--coulomb-solve", choices=suspension.COULOMB_SOLVE, default=suspension.COULOMB_SOLVE[0],
                   help="how a contact slides within its step (fix fdm/couple coulomb_solve, docs/contact.md 2c): "
                   "frozen (default) or consistent")
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
    p.add_argument("--from-snapshot", metavar="SNAPSHOT", default=None,
                   help="continue the compact snapshot in this folder (python3 -m fdmsubgrid.checkpoint snapshot RUN "
                        "DEST) in the scene of these options, written afresh: the particles from its step, the fluid "
                        "from rest (fdmRun --from-snapshot; docs/coupling.md \"Compact snapshot\")")
    p.add_argument("--analyse", metavar="RUN_DIR", default=None,
                   help="analyse this run folder as it stands (a resumed, stopped or running run) and write --out")
    case.add_size_options(p)
    case.add_run_options(p, HERE, tol_lambda=1e-3, model=True)
    args = p.parse_args(argv)
    started = time.time()

    if args.analyse:
        # a run folder as it stands (finished, stopped or still going): its own files say the scene
        # (the same as fdmProfiles RUN_DIR --out OUT, with the case's keys)
        run = shear.read_run(args.analyse)
        name = os.path.basename(os.path.normpath(args.analyse))
        table8 = None
        if name.startswith("table8_"):
            table8 = table8_row(min(TABLE8, key=lambda k: abs(k - run.packing.phi)))
        return shear.report(run, args.out, dict(case="couette", run=name, run_dir=os.path.abspath(args.analyse),
                                                table8=table8), h_layer=args.h_layer,
                            write=results_writer(argv, args, started))

    sizes = case.size_distribution(p, args)
    try:
        suspension.check_resolution(sizes, args.a_over_delta)
    except ValueError as e:
        p.error(str(e))
    n_particles = None
    phi = args.phi
    if args.table8 is not None:
        key = min(TABLE8, key=lambda k: abs(k - args.table8))
        if abs(key - args.table8) > 1e-9:
            p.error("--table8 %g: Table 8 has phi_bulk = %s" % (args.table8, ", ".join("%g" % k for k in TABLE8)))
        _, _, size, n_particles, dt_paper = TABLE8[key]
        args.size, phi = list(size), key
        args.dt = dt_paper if args.dt is None else args.dt
    dt = suspension.scaled_time_step(DEFAULT_DT, sizes) if args.dt is None else args.dt
    delta = A1 / args.a_over_delta
    for L, name in zip(args.size, "xyz"):
        if abs(L / delta - round(L / delta)) > 1e-9 * L / delta:
            p.error("--size: L%s = %g a1 is not a whole number of cells of a1/%g" % (name, L, args.a_over_delta))
    if args.strain <= 0 or dt <= 0:
        p.error("--strain and --dt must be positive")
    if args.fluid_every < 1:
        p.error("--fluid-every must be at least 1")

    try:
        written = write_run(args.workdir, args.size, dt, args.strain, phi=phi, n_particles=n_particles, seed=args.seed,
                            a_over_delta=args.a_over_delta, dump_every=args.dump_every, write_every=args.write_every,
                            tol_lambda=args.tol_lambda, acceleration=args.acceleration, n_max=args.n_max,
                            text_dump=args.text_dump, model=args.model, fluid_every=args.fluid_every,
                            held_drag=args.held_drag, kn=args.kn, kt=args.kt, table8=args.table8 is not None,
                            overwrite=args.overwrite, sizes=sizes, coulomb_solve=args.coulomb_solve)
    except (UncalibratedScene, FileExistsError) as e:
        raise SystemExit(str(e))
    run_dir, name, springs, scene = written["run_dir"], written["name"], written["springs"], written["scene"]
    # the command that writes this scene again, for a compact snapshot of its run
    checkpoint.write_scene_command(run_dir, __file__, sys.argv[1:] if argv is None else list(argv))
    from_snapshot = ("--from-snapshot", args.from_snapshot) if args.from_snapshot else ()
    if (args.table8 is not None and not args.run) or args.write_only:
        print("%s scene written, not run: fdmRun -f N -d M %s" % ("Table 8" if args.table8 is not None else "the",
                                                                  " ".join(from_snapshot + (run_dir,))))
        return dict(run_dir=run_dir, **scene)

    wall = case.run(run_dir, np_fluid=args.np_fluid, np_dem=args.np_dem, extra=from_snapshot)
    results = shear.report(shear.read_run(run_dir), args.out,
                           dict(case="couette", run=name, run_dir=run_dir, acceleration=args.acceleration,
                                tol_lambda=args.tol_lambda, n_max=args.n_max, a_over_delta=args.a_over_delta,
                                seed=args.seed, springs=asdict(springs),
                                table8=None if args.table8 is None else table8_row(phi)),
                           wall_seconds=wall, ranks=args.np_fluid + args.np_dem, h_layer=args.h_layer,
                           write=results_writer(argv, args, started))
    if not args.keep:
        case.delete_fields(run_dir)
    return results


if __name__ == "__main__":
    main()
