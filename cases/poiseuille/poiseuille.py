#!/usr/bin/env python3
"""A frictional suspension driven through a plane channel by a pressure gradient (paper
section 6.2, Eqs. 58-63, Fig. 23): shear-induced migration toward the centre, its profiles, the momentum
balance and the Suspension Balance Model.

Walls y = 0 and y = L_y at rest, x and z periodic, the uniform pressure gradient dP0/dx = -8 eta U_c/L_y^2
(Eq. 58) with U_c = L_y/4 (units a1 = 1 m, eta = 1 Pa s: the Newtonian wall shear rate 4 U_c/L_y and the
wall shear stress tau_w = |dP0/dx| L_y/2 are 1). Times in units of L_y/(2 U_c) (= 2 s). The suspension
and its contact (h_r = 5e-3 a1, mu_s = 0.5, sub-grid lubrication, stresslets) as in cases/couette, the
scene written by the same code (fdmsubgrid.suspension); the springs by docs/contact.md's rule for the
wall shear stress tau_w. The paper's radii 1 and 1.4 in equal volumes by default; any other size
distribution with --radii and --volume-fractions (or --distribution lognormal MEDIAN SIGMA N), each species
a LIGGGHTS atom type, the smallest setting the mesh and the time step (fdmsubgrid.suspension).

  poiseuille.py                 the small channel (8 x 12 x 8 a1, phi_bulk 0.45, a1/Delta = 3, 40 time
                                units, the particles at dt 0.05, the fluid every 4th step): migration
                                begins; about a minute
  poiseuille.py --duration 2    a few steps (the CI test)
  poiseuille.py --paper         writes the paper's (40, 40, 20) a1 channel (not run; --run runs it)
  poiseuille.py --write-only    writes the scene and stops (fdmRun runs it)
  poiseuille.py --analyse RUN   the analysis of a run folder as it stands (--segments FOLDER: with the run's
                                kept history before the folder, for a run continued from a compact snapshot)
  poiseuille.py ... --from-snapshot DIR   writes the scene of these options and continues the compact
                                snapshot DIR in it (its file `scene` holds the options; docs/coupling.md)
  poiseuille.py --help          every option
Writes <workdir>/<run>/ (fluid/, dem/), results.json and results_poiseuille.png here (docs/cases.md).
The migration time grows as L_y^2: the paper reached the steady state after about 1500 time units at
L_y = 40 a1 (docs/validation.md, "Pressure-driven flow").
"""

import argparse
import math
import os
import shutil
import sys
import time
from typing import Any, List, Optional, Sequence

import numpy as np

from fdmsubgrid import case, checkpoint, couettescene, packing, poiseuille, sbm, suspension
from fdmsubgrid.results import Row, read_data, write_results

HERE = os.path.dirname(os.path.abspath(__file__))
PROJECT = os.path.dirname(os.path.dirname(HERE))
# this project's Table 8 rows (docs/validation.md, "Suspensions in Couette flow"): the SBM's second material functions
TABLE8 = os.path.join(PROJECT, "docs", "data", "validation_table8_fluidEvery.json")

PAPER_SIZE = (40.0, 40.0, 20.0)       # (L_x, L_y, L_z)/a1, section 6.2
PAPER_DT = 1e-3                       # L_y/(2 U_c)
NEWTONIAN_WALL_SHEAR_RATE = 1.0       # 4 U_c/L_y: sets U_c = L_y/4


def pressure_gradient(width: float) -> tuple[float, float]:
    """(dP0/dx, U_c) of Eq. (58) for the channel width L_y, with U_c = L_y/4."""
    u_c = NEWTONIAN_WALL_SHEAR_RATE * width / 4
    return -8 * suspension.ETA * u_c / width ** 2, u_c


def main(argv: list[str] | None = None) -> dict:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--phi", type=float, default=0.45, help="phi_bulk (section 6.2: 0.45)")
    p.add_argument("--size", type=float, nargs=3, default=[8.0, 12.0, 8.0], metavar=("LX", "LY", "LZ"),
                   help="channel in units of a1 (walls normal to y); each a whole number of cells")
    p.add_argument("--paper", action="store_true", help="the paper's (40, 40, 20) a1 channel: written, not run "
                   "(with --run, run)")
    p.add_argument("--run", action="store_true", help="with --paper: run it too")
    p.add_argument("--write-only", action="store_true", help="write the scene's folder and stop (run it with fdmRun)")
    p.add_argument("--a-over-delta", type=float, default=3.0, help="a1/Delta, mesh cells per small radius")
    p.add_argument("--dt", type=float, default=None,
                   help="particle time step in units of L_y/(2 U_c) (default %g, measured: docs/benchmarks.md, \"The "
                        "channel's time step\"; shortened for size ratios above 1.4)" % poiseuille.DEFAULT_DT)
    p.add_argument("--duration", type=float, default=40.0, help="time to run, in units of L_y/(2 U_c)")
    p.add_argument("--seed", type=int, default=1, help="seed of the random packing")
    p.add_argument("--dump-every", type=float, default=0.5, help="time between two particle snapshots")
    p.add_argument("--write-every", type=float, default=20.0, help="time between two writes of the fluid fields "
                   "and the particles' ParaView files")
    p.add_argument("--kn", type=float, default=None, help="normal spring [N/m] (default: the rule)")
    p.add_argument("--kt", type=float, default=None, help="tangential spring [N/m] (default: the rule)")
    p.add_argument("--n-max", type=int, default=50, help="fdmFoam's innerIterations nMax")
    p.add_argument("--np-dem", type=int, default=1, help="MPI ranks of fdmDEM")
    p.add_argument("--couette", nargs="+", default=None, metavar="RESULTS_JSON",
                   help="fit the SBM's material functions from these Couette results (default: the paper's "
                        "Maron-Pierce viscosity and Sigma_hat_22 = -0.8 (phi/phi_m)^2, fdmsubgrid.sbm)")
    p.add_argument("--table8", nargs="+", default=[TABLE8], metavar="RESULTS_JSON",
                   help="the SBM drawn beside the first with the material functions fitted to these Couette rows "
                        "(default: this project's Table 8, docs/data/validation_table8_fluidEvery.json: the "
                        "Maron-Pierce eta_s with its phi_m, Sigma_hat^c_22 a power law; 'none': not drawn)")
    p.add_argument("--plateau-threshold", type=float, default=poiseuille.PLATEAU_THRESHOLD, metavar="PHI",
                   help="the central plateau is where phi (bins of a1) is at least this (the paper's is about 0.63)")
    p.add_argument("--from-time", type=float, default=None, help="average from this time on (default: the steady "
                   "window found from the data, 3 migration times on, fdmsubgrid.poiseuille.steady_window)")
    p.add_argument("--segments", metavar="FOLDER", default=None,
                   help="the run's kept history before its folder's first record (segment_<t0>_<t1>.json files, as "
                        "ladderRun --save keeps them): a run continued from a compact snapshot is analysed over its "
                        "whole migration, not from the snapshot on")
    p.add_argument("--overwrite", action="store_true", help="replace a run folder that already exists")
    p.add_argument("--analyse", metavar="RUN_DIR", default=None, help="analyse this run folder as it stands")
    p.add_argument("--compare", metavar="RUN_DIR", default=None, help="with --analyse: the rms and largest "
                   "differences of the coarse phi and u_p* profiles from this other run of the same channel (e.g. "
                   "another dt), both averaged over the same window (from the later steady start, or --from-time)")
    p.add_argument("--fluid-every", type=int, default=poiseuille.DEFAULT_FLUID_EVERY, metavar="K",
                   help="solve the fluid every K-th particle step, the steps between holding its drag "
                        "(fix fdm/couple fluid_every; docs/benchmarks.md, 'The channel's time step')")
    p.add_argument("--held-drag", choices=suspension.HELD_DRAG, default=suspension.HELD_DRAG[0],
                   help="with --fluid-every: the held drag extrapolated from the last two fluid steps, or constant")
    p.add_argument("--coulomb-solve", choices=suspension.COULOMB_SOLVE, default=suspension.COULOMB_SOLVE[0],
                   help="how a contact slides within its step (fix fdm/couple coulomb_solve, docs/contact.md 2c): "
                   "frozen (default) or consistent")
    p.add_argument("--budget", metavar="RUN_DIR", default=None,
                   help="predict the wall time of --duration from a short run of the same scene (RUN_DIR: at least "
                        "two fluid steps, e.g. --paper --run --duration 1) and exit")
    p.add_argument("--required-duration", metavar="RESULTS", nargs="+", default=None,
                   help="the duration this channel (--size or --paper) needs from a uniform start to its steady state "
                        "and a window as long again, from the migration times of analysed ladder runs (their "
                        "results.json; tau grows as L_y^2: poiseuille.required_duration), and exit; with --budget "
                        "RUN_DIR also its wall time")
    p.add_argument("--ladder", metavar="RESULTS", nargs="+", default=None,
                   help="the ladder of channel sizes side by side from analysed runs (their results.json): a table "
                        "of phi_center, the central plateau and the migration time against L_y with their error "
                        "bars, and its figure (ladder_poiseuille.png beside --out), and exit")
    p.add_argument("--start", choices=START_PROFILES, default=START_PROFILES[0],
                   help="how the spheres are spread across the channel at the start: uniform (the paper's), or "
                        "near a steady state to shorten the migration: sbm, the Suspension Balance Model's steady "
                        "phi(y) at phi_bulk (the paper's material functions, or --couette's), sbm-table8, the same "
                        "with this project's Table 8 rows (--table8); docs/cases/poiseuille.md, \"Starting near "
                        "the steady state\"")
    p.add_argument("--from-records", metavar="RECORDS", default=None,
                   help="start from the particles of the last block of this particle records file (dem/"
                        "particles.records of a run of the same channel, e.g. its dense core) instead of a "
                        "random packing; the contacts' tangential history and the fluid start afresh")
    case.add_size_options(p)
    p.add_argument("--from-snapshot", metavar="SNAPSHOT", default=None,
                   help="continue the compact snapshot in this folder (python3 -m fdmsubgrid.checkpoint snapshot RUN "
                        "DIR) in the scene these options write: the particles from its step on, the fluid from rest "
                        "(fdmRun --from-snapshot; docs/coupling.md \"Compact snapshot\")")
    p.add_argument("--until", metavar="STEP", type=int, default=None,
                   help="with --from-snapshot: run on to this particle step instead of the scene's end (a run "
                        "continued past its --duration, as the ladder's rungs are)")
    case.add_run_options(p, HERE, tol_lambda=1e-2, model=True)
    args = p.parse_args(argv)
    if args.paper:
        args.size = list(PAPER_SIZE)
    if args.until is not None and not args.from_snapshot:
        p.error("--until %d goes with --from-snapshot (a new run ends at its --duration)" % args.until)
    started = time.time()
    material = sbm.from_couette_results(args.couette) if args.couette else None
    table8 = table8_material(args.table8)

    if args.ladder:
        try:
            rows = poiseuille.ladder_table([read_data(path) for path in args.ladder])
        except (OSError, KeyError, ValueError) as e:
            p.error("--ladder: %s" % e)
        print("%-10s %-8s %7s %-17s %-15s %-17s %-15s %s" % ("L / a1", "start", "T", "phi_center", "plateau / a1",
                                                            "plateau phi", "tau", "steady"))
        for r in rows:
            print("%-10s %-8s %7.0f %-17s %-15s %-17s %-15s %s" % (
                "x".join("%g" % v for v in r["L"]), r["start"], r["time"],
                "%.3f +- %.3f" % (r["phi_center"], r["phi_center_err"]),
                "%.1f +- %.1f" % (r["plateau_width"], r["plateau_width_err"]),
                "%.3f +- %.3f" % (r["plateau_phi"], r["plateau_phi_err"]),
                "%.0f +- %.0f" % (r["migration_time"], r["migration_time_err"]),
                "from %.0f" % r["steady_from"] if r["steady"] else "no"))
        folder = os.path.dirname(os.path.abspath(args.out))
        os.makedirs(folder, exist_ok=True)
        figure = poiseuille.plot_ladder(os.path.join(folder, "ladder_poiseuille.png"), rows)
        print("wrote %s" % figure)
        return dict(rows=rows, figure=figure)
    if args.required_duration:
        try:
            rungs = [read_data(path) for path in args.required_duration]
            need = poiseuille.required_duration(rungs, float(args.size[1]))
        except (OSError, KeyError, ValueError) as e:
            p.error("--required-duration: %s" % e)
        print("a channel of L_y = %g a1 needs about %.0f +- %.0f time units (L_y/(2 U_c)) from a uniform start: "
              "migration time %.0f +- %.0f (tau = %.3g L_y^2 through %s), the steady window from %.0f, then %g tau "
              "of it"
              % (need["width"], need["duration"], need["duration_err"], need["migration_time"],
                 need["migration_time_err"], need["c"], ", ".join("L_y %g: %.0f +- %.0f" % (
                     r["width"], r["migration_time"], r["migration_time_err"]) for r in need["rungs"]),
                 need["steady_from"], need["window_taus"]))
        args.duration = need["duration"]
        if not args.budget:
            return need
    if args.budget:
        try:
            b = poiseuille.budget(args.budget, args.duration)
        except (OSError, ValueError) as e:
            p.error("--budget: %s" % e)
        print("budget of %s for %g time units: %d fluid steps of %g (the particles at the run's own dt), %.1f s each "
              "(fluid %.1f, particles %.1f, exchange %.1f; %.0f inner iterations) after a first step of %.0f s: "
              "%.1f h at the load the short run had" % (
                  args.budget, b["duration"], b["fluid_steps"], b["fluid_dt"], b["seconds_per_fluid_step"],
                  b["parts_per_fluid_step"]["fluid"], b["parts_per_fluid_step"]["particle"],
                  b["parts_per_fluid_step"]["exchange"], b["inner_iterations_per_fluid_step"],
                  b["first_step_seconds"], b["predicted_hours"]))
        return b
    if args.analyse and args.compare:
        return compare(args.analyse, args.compare, material, args.from_time, table8)
    try:
        segments = poiseuille.read_segments(args.segments) if args.segments else []
    except (OSError, ValueError, poiseuille.PoiseuilleRunError) as e:
        p.error("--segments: %s" % e)
    if args.analyse:
        return report(args.analyse, args.out, material, args.from_time, argv, args, started, table8,
                      args.plateau_threshold, segments)

    pack = None
    if args.from_records:
        if args.start != START_PROFILES[0]:
            p.error("--from-records starts from the records' own positions: --start goes with a random packing")
        if args.radii is not None or args.volume_fractions is not None or args.distribution is not None:
            p.error("--from-records takes its spheres' sizes from the records: --radii, --volume-fractions and "
                    "--distribution go with a random packing")
        try:
            pack = poiseuille.packing_from_records(args.from_records, args.size)
        except (OSError, ValueError) as e:
            p.error("--from-records: %s" % e)
        species = pack.species()
        if sorted(a for _, a, _, _ in species) != list(packing.PAPER_SUSPENSION.radii):
            # the records' own sizes set the springs and the time step (their shares as recorded)
            args.radii = [a for _, a, _, _ in species]
            args.volume_fractions = [share / sum(v for _, _, _, v in species) for _, _, _, share in species]
    sizes = case.size_distribution(p, args)
    try:
        suspension.check_resolution(sizes, args.a_over_delta)
    except ValueError as e:
        p.error(str(e))
    if args.dt is None:
        args.dt = suspension.scaled_time_step(poiseuille.DEFAULT_DT, sizes)
    delta = suspension.A1 / args.a_over_delta
    for L, name in zip(args.size, "xyz"):
        if abs(L / delta - round(L / delta)) > 1e-9 * L / delta:
            p.error("--size: L%s = %g a1 is not a whole number of cells of a1/%g" % (name, L, args.a_over_delta))
    if args.duration <= 0 or args.dt <= 0:
        p.error("--duration and --dt must be positive")
    if not 0 < args.phi < 0.6:
        p.error("--phi %g: a random packing needs 0 < phi_bulk < 0.6" % args.phi)
    if args.fluid_every < 1:
        p.error("--fluid-every must be at least 1")

    width = float(args.size[1])
    grad, u_c = pressure_gradient(width)
    time_unit = width / (2 * u_c)
    dt = args.dt * time_unit
    if pack is None:
        try:
            profile = start_profile(args.start, args.phi, width, material, table8)
        except sbm.SBMError as e:
            p.error("--start %s: %s" % (args.start, e))
        options = dict(seed=args.seed, min_gap=2 * suspension.ROUGHNESS, wall_gap=2 * suspension.ROUGHNESS,
                       sizes=sizes)
        pack = (packing.channel_packing(args.size, phi=args.phi, **options) if profile is None
                else packing.profiled_channel_packing(args.size, profile, args.phi, **options))
    print("packing:", pack.summary())
    try:
        calibration = case.scene_calibration("poiseuille", pack.radii, delta, walls=True, model=args.model)
    except case.UncalibratedScene as e:
        raise SystemExit(str(e))
    if calibration.line():
        print(calibration.line(), flush=True)
    tau_w = abs(grad) * width / 2
    pair = suspension.holds_smallest_pair(pack.radii)
    springs = suspension.choose_springs(tau_w, dt, delta, args.kn, args.kt, sizes, model=args.model, pair=pair)
    print(springs.describe(dt))
    recipe = suspension.choose_springs(tau_w, dt, delta, None, None, sizes, model=args.model, pair=pair)
    warning = poiseuille.time_step_warning(args.dt, args.fluid_every, sizes,
                                           (springs.kn / recipe.kn, springs.kt / recipe.kt))
    if warning:
        print(warning, file=sys.stderr)

    name = "phi%g_%gx%gx%g_ad%g_dt%g_%s%s%s" % (args.phi, *args.size, args.a_over_delta, args.dt,
                                                 "records" if args.from_records else "seed%d" % args.seed
                                                 + START_TAGS[args.start],
                                                 "_" + args.model,
                                                 "_fluidEvery%d" % args.fluid_every if args.fluid_every > 1 else "")
    name += suspension.coulomb_tag(args.coulomb_solve) + couettescene.sizes_tag(sizes)
    run_dir = os.path.join(args.workdir, name)
    if os.path.exists(run_dir):
        if not args.overwrite:
            raise SystemExit("poiseuille: %s already holds a run; --overwrite replaces it" % run_dir)
        shutil.rmtree(run_dir)
    steps = int(round(args.duration / args.dt))
    K = args.fluid_every
    # snapshots on steps the fluid solves: multiples of K
    every = K * max(1, int(round(args.dump_every / args.dt / K)))
    write_every = K * max(1, int(round(args.write_every / args.dt / K)))
    scene = suspension.write_case(run_dir, pack, springs, args.a_over_delta, dt, steps, every, args.tol_lambda,
                                  args.acceleration, args.n_max, write_every, model=args.model,
                                  grad_p0=(grad, 0.0, 0.0), name="in.poiseuille", fluid_every=K,
                                  held_drag=args.held_drag, calibration=calibration, coulomb_solve=args.coulomb_solve)
    # the command that writes this scene again, for a compact snapshot of its run
    checkpoint.write_scene_command(run_dir, __file__, sys.argv[1:] if argv is None else list(argv))
    print("wrote %s: %d spheres (%s), phi %.4f, channel %s a1, %d cells, dP0/dx = %.4g Pa/m (U_c = %g), "
          "%d steps of dt %g L_y/(2U_c), a snapshot every %d steps"
          % (run_dir, pack.n, couettescene.species_text(pack), pack.phi,
             " x ".join("%g" % v for v in args.size), scene["cells"], grad, u_c, steps, args.dt, every))
    if (args.paper and not args.run) or args.write_only:
        print("%s written, not run: fdmRun -f N -d M %s%s" % ("the paper's channel" if args.paper else "the scene",
                                                              "--from-snapshot %s " % args.from_snapshot
                                                              if args.from_snapshot else "", run_dir))
        return dict(run_dir=run_dir, **scene)

    case.run(run_dir, np_fluid=args.np_fluid, np_dem=args.np_dem,
             extra=(("--from-snapshot", args.from_snapshot) if args.from_snapshot else ())
             + (("--until", str(args.until)) if args.until is not None else ()))
    results = report(run_dir, args.out, material, args.from_time, argv, args, started, table8,
                     args.plateau_threshold, segments)
    if not args.keep:
        case.delete_fields(run_dir)
    return results


# --start: how the spheres are spread at the start (the first the default), and what a run folder's name adds
START_PROFILES = ("uniform", "sbm", "sbm-table8")
START_TAGS = {"uniform": "", "sbm": "_startSbm", "sbm-table8": "_startSbmTable8"}


def start_profile(start: str, phi_bulk: float, width: float, material=None, table8=None):
    """The volume fraction the packing follows across the channel (y from 0 to width) for --start
    (packing.profiled_channel_packing), or None for a uniform start: the SBM's steady phi(y) over the whole width
    at phi_bulk (sbm.solve), with the paper's material functions (or `material`) or the Table 8 rows'
    (`table8`)."""
    if start == "uniform":
        return None
    chosen = material if start == "sbm" else table8
    if start == "sbm-table8" and chosen is None:
        raise sbm.SBMError("the Table 8 rows are 'none' (--table8): no material functions to start from")
    model = sbm.solve(chosen or sbm.MaterialFunctions.maron_pierce_power_law(), phi_bulk, y_edge=0.5)
    return lambda y: np.nan_to_num(model.at((np.asarray(y, dtype=float) - 0.5 * width) / width)[0])


def table8_material(paths: Sequence[str]):
    """The SBM's material functions fitted to Couette rows (sbm.from_couette_results), the files named
    relative to the project; None for 'none'."""
    if [p.lower() for p in paths] == ["none"]:
        return None
    material = sbm.from_couette_results(paths)
    material.describe["fitted_from"] = [os.path.relpath(os.path.abspath(p), PROJECT) for p in paths]
    return material


def compare(run_a: str, run_b: str, material=None, from_time=None, table8=None) -> dict:
    """The differences of the coarse (bins of a1) phi and u_p* profiles of two runs of one channel,
    averaged over the same window: from from_time, else from the later of their steady starts."""
    analysed = [poiseuille.analyse(r, material, from_time, table8) for r in (run_a, run_b)]
    if from_time is None:
        # the later steady start; the run that set it is already averaged from there
        from_time = max(res["steady_from"] for res, _ in analysed)
        analysed = [a if a[0]["steady_from"] == from_time else poiseuille.analyse(r, material, from_time, table8)
                    for a, r in zip(analysed, (run_a, run_b))]
    (ra, fa), (rb, fb) = analysed
    if len(fa["coarse"].y) != len(fb["coarse"].y):
        raise SystemExit("poiseuille --compare: the runs have different channels (%s, %s)" % (ra["L"], rb["L"]))
    u = [f["coarse"].u_p[:, 0] / (2 * f["scales"].u_c) for f in (fa, fb)]
    dphi = fa["coarse"].phi - fb["coarse"].phi
    du = u[0] - u[1]
    out = dict(from_time=from_time, phi_rms_diff=float(np.sqrt(np.mean(dphi ** 2))), phi_max_diff=float(np.abs(dphi).max()),
               u_rms_diff=float(np.sqrt(np.mean(du ** 2))), u_max_diff=float(np.abs(du).max()),
               phi_err_typical=float(np.nanmedian(np.hypot(fa["coarse"].phi_error, fb["coarse"].phi_error))),
               phi_center=[ra["phi_center"], rb["phi_center"]], u_center_star=[ra["u_center_star"], rb["u_center_star"]],
               dt=[ra["dt"], rb["dt"]], core_seconds=[ra["core_seconds"], rb["core_seconds"]],
               inner_iterations_mean=[ra["inner_iterations_mean"], rb["inner_iterations_mean"]])
    for k, v in out.items():
        print("%-24s %s" % (k, v))
    return out


# The run's measures the report shows (rows of fdmsubgrid.results): key, quantity, a fraction shown in per cent,
# the key of its error bar (or None) and the paper's value
MEASURES = (("phi_center", "φ at the centre plane", False, "phi_center_err", "Figs. 23–25"),
            ("u_center_star", "u_p*/(2 U_c) at the centre plane", False, None, "Figs. 23–25"),
            ("migration_time", "migration time (φ_center's exponential approach)", False, "migration_time_err", "—"),
            ("plateau_width_over_a1", "central plateau's width / a1 (φ above plateau_threshold, 0.6)", False, "plateau_width_over_a1_err",
             "about 6 (Fig. 23)"),
            ("plateau_phi", "central plateau's φ", False, "plateau_phi_err", "about 0.63 (Fig. 23)"),
            ("sbm_phi_rms_diff", "φ profile against the SBM (rms difference)", False, None, "Figs. 23–25"),
            ("sbm_u_rms_diff", "u_p* profile against the SBM (rms difference)", False, None, "Figs. 23–25"),
            ("sbm_table8_phi_rms_diff", "φ profile against the SBM with the Table 8 rows (rms difference)", False,
             None, "—"),
            ("shear_stress_linearity_rel_error", "shear stress against the walls' line (largest, core)", True, None,
             "—"),
            ("shear_stress_exact_line_rel_error", "shear stress against (dP0/dx)(y − L_y/2) (largest, core)", True,
             None, "—"),
            ("wall_force_balance_rel_error", "force balance on the walls", True, None, "—"))


# the steady state's keys the report prints (poiseuille.steady_results)
STEADY_KEYS = ("steady_detected", "steady_reason", "steady_from_mser", "migration_time", "migration_time_err",
               "migration_time_profile", "migration_time_profile_err", "phi_center_slope", "phi_center_slope_err",
               "phi_center_window_change", "plateau_threshold", "plateau_width_over_a1", "plateau_width_over_a1_err",
               "plateau_phi", "plateau_phi_err", "shear_stress_exact_line_rel_error",
               "momentum_balance_core_within_5pct", "wall_force_balance_within_1pct", "sbm_table8_phi_m",
               "sbm_table8_phi_rms_diff", "sbm_table8_phi_rms_diff_jammed", "sbm_table8_phi_rms_diff_outside_jammed",
               "sbm_table8_u_rms_diff", "sbm_table8_jammed_width_over_a1")


def validation_rows(results: dict) -> List[Row]:
    """The run's measures (MEASURES) in one configuration, with their error bars where they have one; no
    tabulated reference (the paper's Figs. 23-25 are plots): the SBM's profiles are the comparison."""
    config = "φ_bulk %g, channel %s a1, dt %g, averaged from t %g%s" % (
        results["phi_bulk"], " × ".join("%g" % v for v in results["L"]), results["dt"], results["steady_from"],
        "" if results.get("steady_detected", True) else " (not steady)")

    def finite(v):
        return v if v is not None and math.isfinite(v) else None

    return [Row(quantity, config, finite(results[key]), paper=paper, percent=percent,
                spread=finite(results.get(err)) if err else None)
            for key, quantity, percent, err, paper in MEASURES if finite(results.get(key)) is not None]


def report(run_dir: str, out: str, material=None, from_time=None, argv: Optional[Sequence[str]] = None,
           options: Any = None, started: Optional[float] = None, table8=None,
           plateau_threshold: float = poiseuille.PLATEAU_THRESHOLD, segments: Sequence[dict] = ()) -> dict:
    """Analyse a run folder (fdmsubgrid.poiseuille.analyse; segments: the run's kept history before it), write
    `out` (fdmsubgrid.results: argv and options are the command's) and the figure beside it."""
    started = time.time() if started is None else started
    results, fig = poiseuille.analyse(run_dir, material, from_time, table8, plateau_threshold, segments)
    results.update(case="poiseuille", run=os.path.basename(os.path.normpath(run_dir)), run_dir=os.path.abspath(run_dir))
    figure = os.path.join(os.path.dirname(os.path.abspath(out)), "results_poiseuille.png")
    poiseuille.plot(figure, fig)
    results["figure"] = os.path.basename(figure)
    write_results(out, __file__, argv, options if options is not None else {}, validation_rows, results,
                  started)
    for k in ("phi_bulk", "time", "steady_from", "phi_center", "phi_center_initial", "phi_wall_layer",
              "jammed_width_over_a1", "u_center_star", "shear_stress_linearity_rel_error",
              "shear_stress_linearity_wall_layer_rel_error", "wall_force_balance_rel_error", "wall_shear_stress_asymmetry", "sbm_phi_rms_diff",
              "sbm_u_rms_diff", "inner_iterations_mean", "unconverged_steps", "wall_seconds"):
        print("%-45s %s" % (k, results[k]))
    for k in STEADY_KEYS:
        if k in results:
            print("%-45s %s" % (k, results[k]))
    print("wrote %s and %s" % (out, figure))
    return results


if __name__ == "__main__":
    try:
        main()
    except poiseuille.PoiseuilleRunError as e:   # the run (if any) is whole: only its analysis could not be made
        sys.exit("poiseuille.py: %s" % e)
