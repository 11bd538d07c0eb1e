"""Squeeze flows with the coupled solver: two spheres pushed together along their line of centres,
and a sphere pushed toward a plane wall, held at a list of gaps (one coupled step per gap,
`fix fdm/couple ... move no`, each step warm-started from the previous one).

The one runner of these scenes: cases/pairSqueeze and cases/wallSqueeze compare them with theory,
the calibration of the solver's own squeeze resistance (calibration.py, paper Appendix B) measures
them with the sub-grid lubrication switched off, and the stresslet probe (pairstresslet.py) reads
the spheres' stresslets from them.

Velocities are returned in units of F/(6 pi eta a1) (pair: the closing velocity (U1 - U2).d; wall:
the velocity toward the wall).
"""
from __future__ import annotations

import json
import math
import os
import shutil
from typing import List, Sequence

import numpy as np

from . import deminput, files, foamcase, runner
from .results import Row, relative
from .theory import relative_errors

# Where the scene sits inside its first mesh cell (fractions of Delta along x, y, z): off the mesh's
# symmetry planes, as the squeeze cases have always used.
DEFAULT_OFFSET = (0.1, 0.2, 0.3)


def add_options(parser) -> None:
    """The options the squeeze cases share: --offset (the position in the cell) and --box-extrapolate."""
    parser.add_argument("--offset", type=float, nargs=3, default=list(DEFAULT_OFFSET), metavar=("X", "Y", "Z"),
                        help="where the gap centre sits in its mesh cell, fractions of Delta (default %s)"
                             % " ".join("%g" % o for o in DEFAULT_OFFSET))
    parser.add_argument("--box-extrapolate", type=float, metavar="L2", default=None,
                        help="also run in a box of side L2 (> L; a wall scene's H scaled with it) and report the "
                             "velocities extrapolated to an infinite box (V = V_inf + c L^-3)")


def _fresh_run_dir(workdir: str, name: str) -> str:
    """<workdir>/<name>, emptied of an earlier run."""
    run_dir = os.path.join(workdir, name)
    if os.path.isdir(run_dir):
        shutil.rmtree(run_dir)
    return run_dir


def kept_result(run_dir: str, gaps: Sequence[float], tol_lambda: float) -> dict | None:
    """The result an earlier call kept as <run_dir>.json for the same gaps and tolerance, else None (a killed
    calibration resumes where it stopped)."""
    kept = run_dir + ".json"
    if os.path.isfile(kept):
        with open(kept) as f:
            result = json.load(f)
        if result.get("gaps") == [float(g) for g in gaps] and result.get("tol_lambda") == tol_lambda:
            return result
    return None


def keep_result(run_dir: str, result: dict) -> None:
    """Write `result` as <run_dir>.json, whole or absent (through a temporary file)."""
    files.write_json(run_dir + ".json", result, indent=None)


def _result(velocity, wall_seconds: float, box, steps) -> dict:
    """What run_pair and run_wall return."""
    return dict(velocity=[float(v) for v in velocity], wall_seconds=wall_seconds, cells=box.n[0] * box.n[1] * box.n[2],
                inner_iterations=[int(n) for n in steps["innerIterations"]], converged=bool(steps["converged"].all()))


def _pair_style(subgrid: bool, cutoff: float | None, extra: str) -> str:
    words = ["fdm/subgrid"]
    if cutoff is not None:
        words.append("cutoff %g" % cutoff)
    if extra:
        words.append(extra)
    if not subgrid:
        words.append("lubrication no")
    return " ".join(words)


def _tag(subgrid: bool, offset: Sequence[float]) -> str:
    name = "subgrid" if subgrid else "nosubgrid"
    if tuple(offset) != DEFAULT_OFFSET:
        name += "_off%g_%g_%g" % tuple(offset)
    return name


def pair_centres(ratio: float, xi: float, centre: Sequence[float]) -> tuple:
    """The centres of spheres of radii 1 and `ratio` along x at the reduced gap xi = 2r/(a1+a2) - 2, the
    middle of their gap at `centre` (the pair scenes of this module and of pairtangential.py)."""
    a1, a2 = 1.0, ratio
    gap = xi * (a1 + a2) / 2
    return ((centre[0] - gap / 2 - a1, centre[1], centre[2]), (centre[0] + gap / 2 + a2, centre[1], centre[2]))


def run_pair(workdir: str, ratio: float, xis: Sequence[float], subgrid: bool, a_over_delta: float = 4.0,
             L_over_a: float = 8.0, tol_lambda: float = 1e-5, cutoff: float | None = None, np_fluid: int = 1,
             keep: bool = False, offset: Sequence[float] = DEFAULT_OFFSET, pair_options: str = "",
             stresslets: bool = False) -> dict:
    """Spheres of radii 1 and `ratio` in a periodic cube of side L_over_a, pushed together by forces
    F = 6 pi eta a1 along x, at the reduced gaps `xis` (xi = 2r/(a1+a2) - 2, largest first).
    `offset`: the centre of the gap inside its mesh cell (fractions of Delta); `pair_options`: more
    pair_style fdm/subgrid keywords. Returns dict(velocity=[closing velocity / (F/(6 pi eta a1))],
    wall_seconds, cells, inner_iterations, converged). With `stresslets` (fix fdm/couple ... stresslets
    yes, the particle records of fix fdm/output read) also, per gap, U1 and U2 (velocities along x,
    eta = a1 = 1) and the stresslets S1_fluid, S2_fluid, S1_subgrid, S2_subgrid (xx xy xz yy yz zz, the
    records' sign: the force the fluid exerts)."""
    a1, a2 = 1.0, ratio
    delta = a1 / a_over_delta
    L = L_over_a * a1
    eta = 1.0
    F = 6 * math.pi * eta * a1
    run_dir = _fresh_run_dir(workdir, "lambda%g_ad%g_L%g_%s%s" % (ratio, a_over_delta, L_over_a, _tag(subgrid, offset),
                                                                  "_stresslets" if stresslets else ""))
    box = foamcase.Box((0, 0, 0), (L, L, L), delta)
    centre = [L / 2 + o * delta for o in offset]
    foamcase.write_fluid_case(os.path.join(run_dir, "fluid"), box, nu=eta, rho=1.0, tol_lambda=tol_lambda, n_max=3000,
                          n_particles=2)
    runs = deminput.held_step_runs([pair_centres(ratio, xi, centre) for xi in xis])
    if stresslets:
        runs = [deminput.RECORD_EVERY_STEP] + runs
    p1, p2 = pair_centres(ratio, xis[0], centre)
    deminput.write_dem_input(os.path.join(run_dir, "dem"), box, [p1 + (a1,), p2 + (a2,)], dt=1.0,
                         fix_options="move no stresslets yes" if stresslets else "move no",
                         pair_style=_pair_style(subgrid, cutoff, pair_options),
                         before_run="group           one id 1\ngroup           two id 2\n"
                                    "fix             push1 one addforce %r 0 0\n"
                                    "fix             push2 two addforce %r 0 0" % (F, -F),
                         runs=runs, name="in.pairSqueeze")
    wall, parts, steps = runner.run_and_read(run_dir, np_fluid=np_fluid, keep=keep)
    U1 = parts["Ux"][parts["tag"] == 1]
    U2 = parts["Ux"][parts["tag"] == 2]
    result = _result((U1 - U2) / (F / (6 * math.pi * eta * a1)), wall, box, steps)
    if stresslets:
        n = len(xis)
        records, _ = runner.read_held_steps(run_dir, n, "squeeze.run_pair")
        U = np.array(records["U"][-n:, :, 0], dtype=float)
        fluid = np.array(records["S_fluid"][-n:], dtype=float)
        subgrid_part = np.array(records["S_subgrid"][-n:], dtype=float)
        result.update(U1=U[:, 0], U2=U[:, 1], S1_fluid=fluid[:, 0], S2_fluid=fluid[:, 1],
                      S1_subgrid=subgrid_part[:, 0], S2_subgrid=subgrid_part[:, 1])
    return result


def run_wall_scene(run_dir: str, epss: Sequence[float], a_over_delta: float, L_over_a: float, H_over_a: float,
                   offset_xz: Sequence[float], tol_lambda: float, pair_style: str, loads: str, name: str,
                   np_fluid: int = 1, keep: bool = False):
    """The scene of the wall runs: one sphere (a = 1, eta = 1) above the wall y = 0 of a channel L x H x L
    (walls at rest at y = 0 and H, periodic x and z), its centre at x, z = L/2 + offset_xz Delta, held at
    each gap eps = h/a - 1 of `epss` for one coupled step (largest first), driven by the LIGGGHTS lines
    `loads` (fix addforce, fix fdm/torque), in run_dir (emptied first). Returns (wall seconds, particles,
    steps) of runner.run_and_read and the box."""
    a = 1.0
    delta = a / a_over_delta
    L, H = L_over_a * a, H_over_a * a
    _fresh_run_dir(os.path.dirname(run_dir), os.path.basename(run_dir))
    box = foamcase.Box((0, 0, 0), (L, H, L), delta, faces=("cyclic", ((0, 0, 0), (0, 0, 0)), "cyclic"))
    x, z = L / 2 + offset_xz[0] * delta, L / 2 + offset_xz[1] * delta

    def position(eps: float):
        return (x, a * (1 + eps), z)

    foamcase.write_fluid_case(os.path.join(run_dir, "fluid"), box, nu=1.0, rho=1.0, tol_lambda=tol_lambda, n_max=3000,
                          n_particles=1)
    deminput.write_dem_input(os.path.join(run_dir, "dem"), box, [position(epss[0]) + (a,)], dt=1.0, pair_style=pair_style,
                         before_run=loads, runs=deminput.held_step_runs([[position(eps)] for eps in epss]), name=name)
    wall, parts, steps = runner.run_and_read(run_dir, np_fluid=np_fluid, keep=keep)
    return wall, parts, steps, box


def run_wall(workdir: str, epss: Sequence[float], subgrid: bool, a_over_delta: float = 4.0, L_over_a: float = 8.0,
             H_over_a: float = 16.0, tol_lambda: float = 1e-5, cutoff: float | None = None, np_fluid: int = 1,
             keep: bool = False, offset: Sequence[float] = DEFAULT_OFFSET, pair_options: str = "") -> dict:
    """A sphere of radius 1 between walls at rest at y = 0 and y = H_over_a, periodic in x and z
    (side L_over_a), pushed toward y = 0 by F = 6 pi eta a at eps = h/a - 1 (largest first).
    `offset`: the centre's x and z inside its mesh cell (fractions of Delta; the y entry is unused:
    the gap sets y). Returns dict(velocity=[velocity toward the wall / (F/(6 pi eta a))], ...)."""
    F = 6 * math.pi     # eta = a = 1
    run_dir = os.path.join(workdir, "ad%g_L%g_H%g_%s" % (a_over_delta, L_over_a, H_over_a, _tag(subgrid, offset)))
    pair = _pair_style(subgrid, cutoff, ("wall ylo 0 0 0 wall yhi 0 0 0 " + pair_options).strip())
    wall, parts, steps, box = run_wall_scene(run_dir, epss, a_over_delta, L_over_a, H_over_a, (offset[0], offset[2]),
                                             tol_lambda, pair, "fix             push all addforce 0 %r 0" % (-F),
                                             "in.wallSqueeze", np_fluid, keep)
    return _result(-parts["Uy"] / (F / (6 * math.pi)), wall, box, steps)


def extrapolate_box(v1: np.ndarray, v2: np.ndarray, L1: float, L2: float) -> np.ndarray:
    """V at an infinite box from the sizes L1 < L2, with V(L) = V_inf + c L^-3."""
    return v2 + (v2 - v1) * L1 ** 3 / (L2 ** 3 - L1 ** 3)


def box_extrapolated(first: dict, second: dict, L1: float, L2: float) -> dict:
    """The runs of one scene in boxes of side L1 < L2 (the wall scene: L and H scaled together)
    combined into the infinite-box velocities, V(L) = V_inf + c L^-3 (the images of a force dipole;
    checked against a third size in docs/validation.md): velocity is V_inf, velocity_by_box the two."""
    v_inf = extrapolate_box(np.array(first["velocity"]), np.array(second["velocity"]), L1, L2)
    return dict(velocity=[float(v) for v in v_inf], velocity_by_box={"%g" % L1: first["velocity"],
                                                                     "%g" % L2: second["velocity"]},
                wall_seconds=first["wall_seconds"] + second["wall_seconds"], cells=[first["cells"], second["cells"]],
                inner_iterations=first["inner_iterations"] + second["inner_iterations"],
                converged=first["converged"] and second["converged"])


def box_text(results: dict) -> str:
    """The mesh and box of a squeeze case's results: 'a1/Δ 4, L 8 a1', and ' (→ ∞ with L 12)' if the box effect
    was extrapolated away with a second box."""
    text = "a1/Δ %g, L %g a1" % (results["a_over_delta"], results["L_over_a"])
    return text + (" (→ ∞ with L %g)" % results["box_extrapolated_with"] if results.get("box_extrapolated_with")
                   else "")


def against_theory(run, gaps: Sequence[float], gap_name: str, reference: Sequence[float], options,
                   label: str = "") -> dict:
    """A squeeze case's measurement: run(L_over_a, subgrid, pair_options) with the sub-grid correction
    (pair_options 'model MODEL') and, unless options.no_reference, without it; with options.box_extrapolate
    each also in that second box and extrapolated (box_extrapolated). Each result gets its rel_error against
    `reference` and is printed gap by gap. Returns {'subgrid': result, 'nosubgrid': result}."""
    out = {}
    for subgrid in ([True] if options.no_reference else [True, False]):
        pair_options = "model %s" % options.model if subgrid else ""
        r = run(options.L_over_a, subgrid, pair_options)
        if options.box_extrapolate:
            r = box_extrapolated(r, run(options.box_extrapolate, subgrid, pair_options), options.L_over_a,
                                 options.box_extrapolate)
        r["rel_error"] = relative_errors(r["velocity"], reference)
        out["subgrid" if subgrid else "nosubgrid"] = r
        print("%ssub-grid %s: %.0f s" % (label, "on" if subgrid else "off", r["wall_seconds"]))
        for gap, v, ref, e in zip(gaps, r["velocity"], reference, r["rel_error"]):
            print("  %s %-8g V %-12.6g theory %-12.6g error %+7.2f %%" % (gap_name, gap, v, ref, 100 * e))
    return out


def validation_rows(label: str, gaps: Sequence[float], gap_name: str, reference: Sequence[float],
                    entry: dict) -> List[Row]:
    """The closing velocity at each gap against theory (fdmsubgrid.results rows), with the sub-grid
    correction (entry['subgrid']) and, as comparison rows, without it (entry['nosubgrid'])."""
    rows = []
    for switch, name in (("subgrid", "with the sub-grid correction"), ("nosubgrid", "FDM alone")):
        if switch not in entry:
            continue
        for gap, v, ref in zip(gaps, entry[switch]["velocity"], reference):
            rows.append(Row("closing velocity, %s" % name, "%s%s %g" % (label, gap_name, gap), v, ref,
                            error=relative(v, ref), headline=switch == "subgrid"))
    return rows
