#!/usr/bin/env python3
"""The shear's own load on a sphere next to a wall, as the solver resolves it (issues 14 and 15).

The free sphere of cases/wallShear balances two things (freeSphereWall.py, Eq. R3): the resistance R
to its own translation and rotation (Goldman, Cox & Brenner's Ft, Tt, Fr, Tr) and the load of the shear
on the sphere held fixed (their Fs, Ts). In the case's frame (a = eta = gamma_dot = 1, d = 1 + eps):

    (F_x, T_z) = -R (U_x, Omega_z) + F^s,   R = [[6 pi Ft, 6 pi Fr], [8 pi Tt, 8 pi Tr]],
    F^s = (6 pi d Fs, -4 pi Ts).

The sub-grid correction adds R^SG = R^th - R^FDM to R (the calibrated model measures R^FDM), and
nothing to F^s: the shear load is the solver's alone. If the solver's F^s is off, no correction of R
can put the free sphere on the reference. This script measures that load without a new option in the
solver, by linearity, in one box and at one offset at a time, the correction off:

1. the free sphere in the shear (cases/wallShear's scene): velocities V0 = (U_x, Omega_z), so that
   0 = -R_FDM V0 + F^s_FDM;
2. the same sphere in the same box with both walls at rest, loaded by a force along x and torques about
   x and y (fdmsubgrid.wallcalibration.run_loaded_sphere): the mobility M, R_FDM = M^-1;
3. F^s_FDM = R_FDM V0, exactly the load on the sphere held fixed in that box's shear;
4. beside it, the free sphere with the correction on (`--model`, default calibrated) in the same boxes
   and offsets (`--no-corrected` skips it).
5. with the calibrated model, the free sphere the split predicts with the model's R^SG (its fits, and
   the calibration's measured points instead): it accounts for the corrected sphere of 4 (within 0.5 % for
   eps >= 0.01; 1-1.5 % below, likely the off-plane motion
   at a generic offset, which the 2 x 2 block leaves out).

Over the offsets it averages Fs, Ts and the four resistance factors; over three cubic boxes L^3 it
extrapolates them to an infinite box as Q(L) = Q_inf + c2 L^-2 + c3 L^-3 (the calibration's rule for the
mobility; wallcalibration.extrapolate3). It prints, per gap, the solver's Fs, Ts and Ft, Fr, Tt, Tr against
the theory, and the free sphere that the exact R with the solver's F^s would give: the best the
calibrated correction can reach at that resolution (its error against the reference), next to what the
corrected solver does.

    shearLoad.py                          a1/Delta 3, boxes 8 12 16 a1, 2 offsets, GCB's gaps
    shearLoad.py --a-over-delta 4 --boxes 8 12 16 --eps 0.1 0.01
Writes --out (JSON) and prints the table (docs/validation.md, "The shear's own load").
"""
from __future__ import annotations

import argparse
import json
import math
import os
import time
from typing import Sequence

import numpy as np
from scipy.interpolate import CubicSpline

from fdmsubgrid import case, squeeze, wallcalibration
from fdmsubgrid.results import write_results
import freeSphereWall
import wallShear

HERE = os.path.dirname(os.path.abspath(__file__))

EPS_DEFAULT = [0.54, 0.128, 0.1, 0.045, 0.01, 0.0032, 0.001]
# the tangential wall calibration the library's table was written from (fdmsubgrid.wallcalibration)
CALIBRATION = os.path.join(HERE, "..", "..", "dem", "resistance", "data", "wall_tangential_calibration.json")
BOXES_DEFAULT = [8.0, 12.0, 16.0]
FACTORS = ("Ft", "Fr", "Tt", "Tr", "Fs", "Ts")


def load_factors(velocities: Sequence[float], mobility: Sequence[float], eps: float) -> dict:
    """GCB's factors of the solver at one gap and offset: R = M^-1 in the frame (U_x, Omega_z) (the
    symmetrised 2x2 block of wallcalibration.mobility's [M11, M12, M21, M22, MXC]) and the held
    sphere's load F^s = R V0 from the free sphere's V0 = (U_x, Omega_z)."""
    d = 1.0 + eps
    r11, r12, r22, _ = wallcalibration.resistance_from_mobility(np.asarray(mobility, dtype=float))[0]
    r = np.array([[r11, r12], [r12, r22]])
    fs_x, ts_z = r @ np.asarray(velocities, dtype=float)
    return dict(Ft=r11 / (6 * math.pi), Fr=r12 / (6 * math.pi), Tt=r12 / (8 * math.pi), Tr=r22 / (8 * math.pi),
                Fs=fs_x / (6 * math.pi * d), Ts=-ts_z / (4 * math.pi))


def theory_factors(eps: float) -> dict:
    """The same factors from the exact wall functions and GCB's fixed sphere (freeSphereWall)."""
    ft, tt, fr, tr = freeSphereWall.exact_factors(eps)
    fs, ts = freeSphereWall.shear_factors(eps)
    return dict(Ft=ft, Fr=fr, Tt=tt, Tr=tr, Fs=fs, Ts=ts)


def _kept(path: str, scene_key: dict) -> dict | None:
    """The result a call kept as <path>.json for the same scene, else None (a killed run resumes)."""
    if os.path.isfile(path + ".json"):
        with open(path + ".json") as f:
            kept = json.load(f)
        if kept.get("scene") == scene_key:
            return kept
    return None


def run_box(workdir: str, L: float, eps_values: Sequence[float], offsets, options) -> dict:
    """Per gap, the factors averaged over the offsets in the cube L^3 (a1/Delta of options): one
    coupled run of the free sphere in the shear (all offsets) and one loaded run per offset. The
    result is kept as <workdir>/box<L>_ad<A>.json and read back by a later call with the same scene."""
    kept_path = os.path.join(workdir, "box%g_ad%g" % (L, options.a_over_delta))
    scene_key = dict(eps=sorted(eps_values, reverse=True), offsets=[list(o) for o in offsets],
                     a_over_delta=options.a_over_delta, tol_lambda=options.tol_lambda)
    kept = _kept(kept_path, scene_key)
    if kept is not None:
        return kept
    t0 = time.time()
    epss = scene_key["eps"]
    shear = wallShear.run_scene(workdir, (L, L, L), 1.0, False, epss, offsets, options)
    per_gap = {eps: [] for eps in epss}
    for offset in offsets:
        loaded = wallcalibration.run_loaded_sphere(os.path.join(workdir, "loaded"), epss, options.a_over_delta, L, L,
                                                   offset, tol_lambda=options.tol_lambda / 10,
                                                   np_fluid=options.np_fluid)
        m = wallcalibration.mobility(loaded["U"], loaded["W"])
        for k, eps in enumerate(epss):
            step = next(s for s in shear["per_step"] if s["eps"] == eps and s["offset"] == list(offset))
            v0 = (step["velocity"][0], step["angular_velocity"][2])
            per_gap[eps].append(load_factors(v0, m[k], eps))
    rows = []
    for eps in epss:
        row = dict(eps=eps)
        for q in FACTORS:
            values = [f[q] for f in per_gap[eps]]
            row[q], row[q + "_std"] = float(np.mean(values)), float(np.std(values))
        rows.append(row)
    result = dict(scene=scene_key, box=L, rows=rows, wall_seconds=time.time() - t0)
    squeeze.keep_result(kept_path, result)
    return result


def run_corrected(workdir: str, L: float, eps_values: Sequence[float], offsets, options) -> dict:
    """The free sphere with the sub-grid correction on (options.model) in the cube L^3, the same gaps and
    offsets: per gap the mean Ux_norm and Wz_norm, to set beside what the exact R with the solver's F^s
    gives. Kept as <workdir>/box<L>_ad<A>_<model>.json like run_box."""
    kept_path = os.path.join(workdir, "box%g_ad%g_%s" % (L, options.a_over_delta, options.model))
    scene_key = dict(eps=sorted(eps_values, reverse=True), offsets=[list(o) for o in offsets],
                     a_over_delta=options.a_over_delta, tol_lambda=options.tol_lambda, model=options.model)
    kept = _kept(kept_path, scene_key)
    if kept is not None:
        return kept
    t0 = time.time()
    scene = wallShear.run_scene(os.path.join(workdir, "corrected"), (L, L, L), 1.0, True, scene_key["eps"],
                                offsets, options)
    rows = []
    for eps in scene_key["eps"]:
        group = [s for s in scene["per_step"] if s["eps"] == eps]
        rows.append(dict(eps=eps, Ux_norm=float(np.mean([s["Ux_norm"] for s in group])),
                         Wz_norm=float(np.mean([s["Wz_norm"] for s in group]))))
    result = dict(scene=scene_key, box=L, rows=rows, wall_seconds=time.time() - t0)
    squeeze.keep_result(kept_path, result)
    return result


def model_corrections(a_over_delta: float):
    """Per gap, the calibrated model's tangential wall corrections R^SG at a1/Delta (Kim-Karrila Y^A, Y^B,
    Y^C, after the dissipation rule), two ways: `fits`, the model's (f_th minus the fitted FDM function, as
    the library's table holds them at a calibrated a1/Delta), and `points`, f_th minus the calibration's
    measured FDM means (box-extrapolated, 4 offsets) interpolated by a cubic spline in ln eps. None when
    a1/Delta has no calibration."""
    with open(CALIBRATION) as f:
        found = [c for c in json.load(f) if abs(c["a_over_delta"] - a_over_delta) < 1e-9]
    if not found:
        return None
    cal = found[0]
    gaps = np.asarray(cal["gaps"], dtype=float)
    order = np.argsort(gaps)
    measured = {name: CubicSpline(np.log(gaps[order]), np.asarray(cal["fdm"], dtype=float)[order, k])
                for k, name in enumerate(cal["functions"])}

    def corrections(eps: float, way: str) -> dict:
        values = {}
        for name in cal["functions"]:
            if way == "fits":
                values[name] = wallcalibration.correction(name, eps, cal["fits"][name])
            else:
                values[name] = wallcalibration.theory_functions(float("%.6g" % eps))[name] - float(measured[name](math.log(eps)))
        return wallcalibration.dissipative(values, eps)
    return corrections


def split_prediction(row: dict, correction: dict) -> tuple[float, float]:
    """(U_x/(gamma_dot d), Omega_z/(gamma_dot/2)) of the free sphere from the split: the solver's R plus the
    correction R^SG against the solver's load F^s, by the reference's own Eq. (R3) (freeSphereWall.free_sphere).
    R^SG in GCB's factors (Kim-Karrila: R11 += 6 pi Y^A, R12 += -4 pi Y^B, R22 += 8 pi Y^C, wallcalibration's
    frame): Ft + Y^A, Fr - (2/3) Y^B, Tt = (3/4) Fr (reciprocity), Tr + Y^C."""
    fr = row["Fr"] - 2.0 / 3.0 * correction["YB"]
    u, w = freeSphereWall.free_sphere(row["eps"], row["Ft"] + correction["YA"], 0.75 * fr, fr, row["Tr"] + correction["YC"],
                                      row["Fs"], row["Ts"])
    return u, -w


def _infinite_box(values: Sequence[float], sizes: Sequence[float]) -> float:
    """A quantity at an infinite box from its values in the boxes (three: wallcalibration.extrapolate3;
    else the largest box's value)."""
    return float(wallcalibration.extrapolate3(values, sizes)) if len(values) == 3 else float(values[-1])


def extrapolated_rows(boxes: Sequence[dict], corrected: Sequence[dict] = (), corrections=None) -> list[dict]:
    """Per gap: each factor at an infinite box (three boxes: wallcalibration.extrapolate3), the theory,
    the errors, and the free sphere from the exact R with the solver's Fs, Ts (and with the solver's R
    and the theory's Fs, Ts: the other half of the split); with `corrections` (model_corrections), the
    free sphere the split predicts with the model's R^SG, from its fits and from its measured points."""
    sizes = [b["box"] for b in boxes]
    out = []
    for k, eps in enumerate(r["eps"] for r in boxes[0]["rows"]):
        th = theory_factors(eps)
        ref = freeSphereWall.reference(eps)
        row = dict(eps=eps)
        for q in FACTORS:
            values = [b["rows"][k][q] for b in boxes]
            inf = _infinite_box(values, sizes)
            row[q] = inf
            row[q + "_by_box"] = values
            row[q + "_theory"] = th[q]
            row[q + "_rel_error"] = inf / th[q] - 1.0
        # the exact resistance with the solver's shear load: what a perfect R^SG leaves
        u, w = freeSphereWall.free_sphere(eps, th["Ft"], th["Tt"], th["Fr"], th["Tr"], row["Fs"], row["Ts"])
        row.update(Ux_norm_exactR=u, Wz_norm_exactR=-w,
                   Ux_norm_exactR_rel_error=u / ref["Ux_norm"] - 1.0, Wz_norm_exactR_rel_error=-w / ref["Wz_norm"] - 1.0)
        # the solver's resistance with the exact shear load: what a perfect F^s would leave
        u, w = freeSphereWall.free_sphere(eps, row["Ft"], row["Tt"], row["Fr"], row["Tr"], th["Fs"], th["Ts"])
        row.update(Ux_norm_exactFs_fdmR_rel_error=u / ref["Ux_norm"] - 1.0,
                   Wz_norm_exactFs_fdmR_rel_error=-w / ref["Wz_norm"] - 1.0)
        for way in ("fits", "points") if corrections else ():
            u, w = split_prediction(row, corrections(eps, way))
            row.update({"Ux_norm_split_%s_rel_error" % way: u / ref["Ux_norm"] - 1.0,
                        "Wz_norm_split_%s_rel_error" % way: w / ref["Wz_norm"] - 1.0})
        # the free sphere with the correction, measured in the same boxes and extrapolated the same way
        for q in ("Ux_norm", "Wz_norm") if corrected else ():
            values = [c["rows"][k][q] for c in corrected]
            inf = _infinite_box(values, sizes)
            row.update({q + "_corrected": inf, q + "_corrected_by_box": values,
                        q + "_corrected_rel_error": inf / ref[q] - 1.0})
        out.append(row)
    return out


def print_rows(rows: Sequence[dict]) -> None:
    """The table: the solver's factors (infinite box) and their errors, and the free sphere with the exact R."""
    print("  %-7s %s | %-22s | %s" % ("eps", " ".join("%-16s" % q for q in FACTORS), "exact R, solver's F^s: U, Omega",
                                      "corrected (measured): U, Omega | split + R^SG fits: U, Omega | "
                                      "split + R^SG measured points: U, Omega"))
    for r in rows:
        print("  %-7g %s | %+6.2f %% %+6.2f %%%s" % (
            r["eps"], " ".join("%7.4f (%+5.1f%%)" % (r[q], 100 * r[q + "_rel_error"]) for q in FACTORS),
            100 * r["Ux_norm_exactR_rel_error"], 100 * r["Wz_norm_exactR_rel_error"],
            "       | %+6.2f %% %+6.2f %%" % (100 * r["Ux_norm_corrected_rel_error"], 100 * r["Wz_norm_corrected_rel_error"])
            if "Ux_norm_corrected_rel_error" in r else "")
            + ("  | %+6.2f %% %+6.2f %% | %+6.2f %% %+6.2f %%" % tuple(
                100 * r["%s_norm_split_%s_rel_error" % (q, way)] for way in ("fits", "points") for q in ("Ux", "Wz"))
               if "Ux_norm_split_fits_rel_error" in r else ""))


def add_split_options(p: argparse.ArgumentParser, eps_default: Sequence[float], boxes_default: Sequence[float],
                      boxes_help: str) -> None:
    """The options of the scripts that split the free sphere by linearity (this one, shearStresslet.py)."""
    p.add_argument("--eps", type=float, nargs="+", default=list(eps_default), help="reduced gaps eps = d/a - 1")
    p.add_argument("--boxes", type=float, nargs="+", default=list(boxes_default), metavar="L",
                   help="cube sides in a1 (%s; default %s)" % (boxes_help, " ".join("%g" % b for b in boxes_default)))
    p.add_argument("--a-over-delta", type=float, default=3.0, help="a1/Delta (default 3)")
    p.add_argument("--positions", type=int, default=2, help="offsets in the cell, as cases/wallShear (default 2)")
    p.add_argument("--n-max", type=int, default=2000, help="fdmFoam's innerIterations nMax (4x on the first step)")
    case.add_run_options(p, HERE, tol_lambda=1e-4, cutoff=True)


def check_split_options(p: argparse.ArgumentParser, args: argparse.Namespace, box_counts: Sequence[int],
                        corrected: bool = True) -> None:
    """Refuses (p.error) a box count not in box_counts, a gap outside the exact wall table, a box too small
    for the sphere, and with `corrected` a resolution the model has no calibration for."""
    args.wall_cutoff, args.keep = None, False
    if len(args.boxes) not in box_counts:
        p.error("--boxes: one box, or %s to extrapolate, got %d"
                % (" or ".join({2: "two", 3: "three"}[n] for n in box_counts if n > 1), len(args.boxes)))
    for eps in args.eps:
        if not 0 < eps <= 3:
            p.error("--eps %g: the exact wall table covers 0 < eps <= 3" % eps)
    for L in args.boxes:
        try:
            wallShear.check_scene(args.eps, [1.0], (L, L, L), args.a_over_delta)
        except ValueError as e:
            p.error(str(e))
    if corrected:
        missing = case.uncalibrated([1.0], 1.0 / args.a_over_delta, walls=True, model=args.model, pairs=False)
        if missing:
            p.error(case.refusal("shearLoad", missing))


def main(argv: Sequence[str] | None = None) -> dict:
    """Parse the options (module docstring), run every box, print the table, write --out."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_split_options(p, EPS_DEFAULT, BOXES_DEFAULT, "three: extrapolated to an infinite box")
    p.set_defaults(out=os.path.join(HERE, "results_shearLoad.json"))   # a study: not the case's results.json
    p.add_argument("--no-corrected", action="store_true",
                   help="skip the free sphere with the correction on (run by default beside the split)")
    args = p.parse_args(argv)
    check_split_options(p, args, (1, 3), corrected=not args.no_corrected)
    offsets, _ = wallShear.cell_offsets(args.positions)
    os.makedirs(args.workdir, exist_ok=True)
    t0 = time.time()
    boxes, corrected = [], []
    for L in args.boxes:
        boxes.append(run_box(args.workdir, L, args.eps, offsets, args))
        print("box %g^3 a1: %.0f s" % (L, boxes[-1]["wall_seconds"]))
        if not args.no_corrected:
            corrected.append(run_corrected(args.workdir, L, args.eps, offsets, args))
            print("box %g^3 a1, the correction on (%s): %.0f s" % (L, args.model, corrected[-1]["wall_seconds"]))
    rows = extrapolated_rows(boxes, corrected, model_corrections(args.a_over_delta) if args.model == "calibrated" else None)
    print_rows(rows)
    out = dict(case="wallShear/shearLoad", a_over_delta=args.a_over_delta, boxes=args.boxes,
               offsets=[list(o) for o in offsets], tol_lambda=args.tol_lambda, model=args.model, rows=rows,
               by_box=boxes, corrected_by_box=corrected,
               conventions="GCB's factors in the case's frame (module docstring); rel_error = solver/theory - 1; "
                           "Ux_norm_exactR, Wz_norm_exactR: the free sphere with the exact R and the solver's Fs, Ts")
    write_results(args.out, __file__, argv, args, [], out, t0)
    print("wrote %s (%.0f s)" % (args.out, out["wall_seconds"]))
    return out


if __name__ == "__main__":
    main()
