#!/usr/bin/env python3
"""The stresslet of a free sphere next to a wall, split into the shear's own load and the resistance
(issue 15: S* near contact; paper Appendix D, Eqs. D.1-D.6).

In the case's frame (a = eta = gamma_dot = 1, wall y = 0 at rest), the stresslet S* = S_xy/((10/3) pi) of
the sphere moving at V = (U_x, Omega_z) in the shear is, by linearity (Eq. D.1),

    S* = S^s - (g U_x + h Omega_z),

S^s the stresslet of the sphere held fixed in the shear (Appendix D's S-hat^gamma-dot, Eq. D.5: 1 far from
the wall, 0.5325 at contact by the lubrication approximation) and (g, h) the stresslet per velocity of a
sphere moving in fluid at rest (the Y^G, Y^H row). The sub-grid correction adds to (g, h) what Eq. (D.4)
derives from the corrected Y^A, Y^B, Y^C, and nothing to S^s: Appendix D leaves the shear's load to the
solver. This script measures the pieces, one box and offset at a time:

1. the sphere in fluid at rest pushed by F = 6 pi e_x, then turned by T = 8 pi e_z (both walls at rest),
   with the correction off and on: two equations S = -(g U_x + h Omega_z) give (g, h) of the solver and of
   the solver plus the correction;
2. the free sphere in the shear, the correction off: S^s = S* + g U_x + h Omega_z with the solver's (g, h);
3. the free sphere in the shear with the correction on: its S* against S^s - (g U_x + h Omega_z) with the
   corrected (g, h) (linearity, a check of the split), and against Eq. (46).

Near contact S^s has a reference, the lubrication limit 0.5325 (paper Appendix D): if the solver's S^s is
off there, the corrected S* is off by as much whatever the correction does.

    shearStresslet.py                              a1/Delta 3, 12^3 and 16^3 a1, 2 offsets
    shearStresslet.py --a-over-delta 4 --eps 0.01 0.001
Writes --out (JSON) and prints the table (docs/validation.md, "The stresslet split").
"""
from __future__ import annotations

import argparse
import math
import os
import time
from typing import Sequence

import numpy as np

from fdmsubgrid import squeeze
from fdmsubgrid.results import write_results
import freeSphereWall
import shearLoad
import wallShear

HERE = os.path.dirname(os.path.abspath(__file__))

EPS_DEFAULT = [0.54, 0.1, 0.01, 0.0032, 0.001]
BOXES_DEFAULT = [12.0, 16.0]
# the held sphere's stresslet at contact, lubrication approximation (paper Appendix D, after Eq. D.5)
HELD_STRESSLET_CONTACT = 0.5325
LOADS = {"Fx": "fix             push all addforce %r 0 0" % (6 * math.pi),
         "Tz": "fix             turn all fdm/torque 0 0 %r" % (8 * math.pi)}


def stresslet_row(force_step: dict, torque_step: dict) -> tuple[float, float]:
    """(g, h) from the sphere pushed (force_step) and turned (torque_step) in fluid at rest:
    S* = -(g U_x + h Omega_z) in both (per_step entries of wallShear.run_scene)."""
    a = np.array([[force_step["velocity"][0], force_step["angular_velocity"][2]],
                  [torque_step["velocity"][0], torque_step["angular_velocity"][2]]])
    g, h = np.linalg.solve(a, -np.array([force_step["S_star"], torque_step["S_star"]]))
    return float(g), float(h)


def run_box(workdir: str, L: float, eps_values: Sequence[float], offsets, options) -> list[dict]:
    """Per gap, averaged over the offsets in the cube L^3: the solver's (g, h) and S^s, the corrected
    (g, h), the corrected free sphere's S* and its prediction from the split."""
    size = (L, L, L)
    epss = sorted(eps_values, reverse=True)

    def scene(subgrid: bool, load: str = "") -> dict:
        steps = wallShear.run_scene(workdir, size, 1.0, subgrid, epss, offsets, options,
                                    loads=LOADS.get(load, ""), load_name=load)["per_step"]
        return {(s["eps"], tuple(s["offset"])): s for s in steps}

    free_off, free_on = scene(False), scene(True)
    pushed = {sub: (scene(sub, "Fx"), scene(sub, "Tz")) for sub in (False, True)}
    rows = []
    for eps in epss:
        per_offset = []
        for offset in offsets:
            key = (eps, tuple(offset))
            g0, h0 = stresslet_row(pushed[False][0][key], pushed[False][1][key])
            g1, h1 = stresslet_row(pushed[True][0][key], pushed[True][1][key])
            off, on = free_off[key], free_on[key]
            held = off["S_star"] + g0 * off["velocity"][0] + h0 * off["angular_velocity"][2]
            predicted = held - (g1 * on["velocity"][0] + h1 * on["angular_velocity"][2])
            per_offset.append(dict(g_fdm=g0, h_fdm=h0, g_corrected=g1, h_corrected=h1, held=held,
                                   S_star_corrected=on["S_star"], S_star_predicted=predicted,
                                   S_star_fdm=off["S_star"]))
        row = dict(eps=eps, S_star_reference=freeSphereWall.stresslet_eq46(eps))
        for q in per_offset[0]:
            values = [p[q] for p in per_offset]
            row[q], row[q + "_std"] = float(np.mean(values)), float(np.std(values))
        rows.append(row)
    return rows


def infinite_box(boxes: Sequence[list[dict]], sizes: Sequence[float]) -> list[dict]:
    """Two boxes: each quantity extrapolated as Q_inf + c L^-3 (cubes: the box's share goes as 1/V,
    docs/validation.md "The box"); one box: as it is."""
    if len(boxes) == 1:
        return [dict(r) for r in boxes[0]]
    (L1, L2), out = sizes, []
    for r1, r2 in zip(*boxes):
        row = dict(eps=r1["eps"], S_star_reference=r1["S_star_reference"])
        for q in r1:
            if q in row or q.endswith("_std"):
                continue
            row[q] = float(squeeze.extrapolate_box(r1[q], r2[q], L1, L2))
        out.append(row)
    return out


def print_rows(title: str, rows: Sequence[dict]) -> None:
    print(title)
    print("  %-7s %-9s %-9s %-9s %-9s | %-9s %-9s %-9s | %-9s %-9s %s" % (
        "eps", "g FDM", "h FDM", "g corr", "h corr", "S^s FDM", "S* FDM", "S* corr", "predicted", "Eq. 46",
        "err S* corr, err S^s at contact"))
    for r in rows:
        contact = " %+.1f %%" % (100 * (r["held"] / HELD_STRESSLET_CONTACT - 1)) if r["eps"] <= 1e-3 else ""
        print("  %-7g %-9.4f %-9.4f %-9.4f %-9.4f | %-9.4f %-9.4f %-9.4f | %-9.4f %-9.4f %+.2f %%%s" % (
            r["eps"], r["g_fdm"], r["h_fdm"], r["g_corrected"], r["h_corrected"], r["held"], r["S_star_fdm"],
            r["S_star_corrected"], r["S_star_predicted"], r["S_star_reference"],
            100 * (r["S_star_corrected"] / r["S_star_reference"] - 1), contact))


def main(argv: Sequence[str] | None = None) -> dict:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    shearLoad.add_split_options(p, EPS_DEFAULT, BOXES_DEFAULT, "two: extrapolated as Q_inf + c L^-3")
    p.set_defaults(out=os.path.join(HERE, "results_shearStresslet.json"))   # a study: not the case's results.json
    args = p.parse_args(argv)
    shearLoad.check_split_options(p, args, (1, 2))
    offsets, _ = wallShear.cell_offsets(args.positions)
    os.makedirs(args.workdir, exist_ok=True)
    t0 = time.time()
    boxes = []
    for L in args.boxes:
        boxes.append(run_box(args.workdir, L, args.eps, offsets, args))
        print_rows("box %g^3 a1, a1/Delta %g (%.0f s so far)" % (L, args.a_over_delta, time.time() - t0), boxes[-1])
    rows = infinite_box(boxes, args.boxes)
    if len(boxes) == 2:
        print_rows("extrapolated to an infinite box", rows)
    out = dict(case="wallShear/shearStresslet", a_over_delta=args.a_over_delta, boxes=args.boxes,
               offsets=[list(o) for o in offsets], tol_lambda=args.tol_lambda, model=args.model, rows=rows,
               by_box=boxes, held_stresslet_contact=HELD_STRESSLET_CONTACT,
               conventions="S* = S_xy/((10/3) pi eta a^3 gamma_dot) = held - (g U_x + h Omega_z); held: the sphere "
                           "held fixed in the shear (S-hat^gamma-dot, Eq. D.5); g, h per U_x, Omega_z (a = eta = 1); "
                           "_fdm: the correction off, _corrected: on (model)")
    write_results(args.out, __file__, argv, args, [], out, t0)
    print("wrote %s (%.0f s)" % (args.out, out["wall_seconds"]))
    return out


if __name__ == "__main__":
    main()
