#!/usr/bin/env python3
"""A free sphere in simple shear next to one wall (paper section 5.2.1, Figs. 6-8; issue 15 item 1).

Wall y = 0 at rest, wall y = L_y moving at gamma_dot L_y along x (gamma_dot = 1, eta = 1), x and z
periodic. One sphere of radius a (a1 = 1 or a2 = 1.4; lengths in units of a1 = 1) with its centre at
d = (1 + eps) a from the wall y = 0, in the middle of the box in x and z shifted by an offset inside
one mesh cell. The sphere is held in place but free in force and torque (fix fdm/couple ... move no):
each (eps, offset) is one coupled time step whose velocities are those of the fixed configuration
(quasi-static), the fluid starting from the undisturbed profile u = gamma_dot y e_x (the far field
starts converged) and every later step warm-started from the previous configuration (largest eps
first). Measured per eps, averaged over the offsets (mean and standard deviation):

  Ux_norm = U_x / (gamma_dot d)          (+1 far from the wall)
  Wz_norm = Omega_z / (gamma_dot / 2)    (-1 far from the wall: the flow's vorticity is -gamma_dot e_z,
                                          a free sphere turns clockwise seen from +z; Fig. 7 plots -Wz_norm)
  S_star  = S_xy / ((10/3) pi eta a^3 gamma_dot)   (the hydrodynamic stresslet S^H = S^FDM + S^SG, Eq. 12)
and the symmetry: U_y, U_z, Omega_x, Omega_y (zero for the exact problem). The reference
(freeSphereWall.py; wallSphereData.json holds its numbers with their sources): U and Omega of the free
sphere from the exact wall resistance functions (bipolar-coordinate tables) and Goldman, Cox & Brenner's
(1967) fixed sphere in shear, S* from Sangani et al.'s (2011) fit, paper Eq. (46).

The sub-grid wall correction (pair_style fdm/subgrid with both walls declared, Eq. D.6) is on; by default
every scene is also run with it off (lubrication no), to show what it does. The cut-off model (`--model
cutoff`) over-corrects the tangential wall functions: measured at a1/Delta = 3, the free sphere is
11-17 % too slow for eps 0.001-0.1 with the correction; without it U is within 3 % at eps = 0.1 (Omega 17 %
too fast) and stops decreasing below eps ~ 0.03 (the mesh does not resolve the gap). With the default
calibrated model (the tangential wall functions measured with the solver, a/Delta 3, 4 and 5:
docs/resistance.md) U is within -4.4 ... +2.2 % and Omega within -9 ... +5 % at eps 1e-3 ... 0.54, S* within 0.5 % near
contact and 1-7 % at eps 0.07-0.3 (docs/validation.md).

Offsets: the three quantities are unchanged by the mirror z -> -z and by x -> -x with the flow reversed
(Stokes flow is linear: mirror, then reverse every velocity; the walls are back, U_x, Omega_z and S_xy
unchanged), and so is the mesh about the vertex at the box centre: [0, 1/2) x [0, 1/2) cells in (x, z)
holds every offset once (d sets y). `--positions N` stands for N offsets spread over the cell: an even
square m^2 (4, 16: the paper's 4 x 4) at its m^2/4 lattice points (i + 1/2)/m in that quarter, any other
count at N Halton points (bases 2, 3) there. The standard deviation is over the computed offsets.
The wall-normal position in the cell is set by d and is not averaged: Omega_z depends on it by up to
+-10 % at a1/Delta = 3 (+-15 % for a = 1.4; also at the centre of a channel, cases/shearedSphere), much
more than on the x, z offsets (about 1 %): a scan dense in eps shows that scatter (docs/validation.md).

The box: the paper's is 50^3 a1. A smaller box adds its share, of two kinds (measured at eps = 0.01,
docs/validation.md). (1) The plane-averaged flow: the sphere's stresslet raises the shear of the fluid
between the walls by S_xy/(eta V) (V the box volume; fdmFoam's mean-flow correction makes this mode
exact), so U, Omega and S grow by about (10/3) pi a^3 S*/V (`mean_shear_share` per row, 1.7 % at
eps = 0.01 in 12^3 a1): raising L_y from 12 to 18 a1 changes U by -0.51 % (this estimate: -0.57 %).
(2) The periodic images in x and z slow the sphere and lower S, more than (1) raises them: widening L_x = L_z from
12 to 18 a1 changes U by +1.46 % (where (1) alone would give -0.95 %). In cubes both go as 1/V: U, Omega
and S from 12^3, 18^3 and 24^3 a1 follow Q_inf + c/L^3 (24^3 predicted from the other two within
1.3e-4); `--boxes` with proportional boxes gives the extrapolated values and their errors against the
reference (`box_comparison`); in 12^3 a1 the box takes 1.6 % off U at eps = 0.01.

  wallShear.py                       a = 1, eps = 3 1 0.3 0.1 0.03 0.01 0.003 0.001, box 12 x 12 x 12 a1,
                                     a1/Delta = 3, 2 offsets; with and without the correction (a few minutes)
  wallShear.py --radius 1 1.4        both radii
  wallShear.py --boxes               the same in 12^3 and 18^3 a1 (the box effect)
  wallShear.py --boxes 12 12 12 24 12 24   any boxes, LX LY LZ each
  wallShear.py --no-subgrid          the correction off only; --subgrid-only: on only
  wallShear.py --full                the paper's: 50^3 a1, a1/Delta = 5, 16 offsets (4 computed), both radii
                                     (15.6 M cells: out of reach of this 2-core machine)
  wallShear.py --reference           no solver: the reference at --eps
  wallShear.py --help                every option
Writes results.json and results_wallShear.png here (docs/cases.md, docs/validation.md).
"""
from __future__ import annotations

import argparse
import math
import os
import shutil
import time
from typing import List, Sequence

import numpy as np

from fdmsubgrid import case, output
from fdmsubgrid.results import Row, write_results
import freeSphereWall

HERE = os.path.dirname(os.path.abspath(__file__))

ETA = 1.0
SHEAR_RATE = 1.0
A1 = 1.0
EPS_DEFAULT = [3.0, 1.0, 0.3, 0.1, 0.03, 0.01, 3e-3, 1e-3]
RADII_DEFAULT = [1.0]
RADII_PAPER = [1.0, 1.4]
BOX_DEFAULT = (12.0, 12.0, 12.0)
BOXES_DEFAULT = [(12.0, 12.0, 12.0), (18.0, 18.0, 18.0)]
PAPER_BOX = (50.0, 50.0, 50.0)
MIN_TOP_GAP = 2.0            # a1: the least surface gap to the moving wall (the reference has one wall)
MIN_IMAGE_GAP = 2.0          # a1: the least surface gap to a periodic image in x and z
QUANTITIES = ("Ux_norm", "Wz_norm", "S_star")
SYMMETRY = ("Uy_norm", "Uz_norm", "Wx_norm", "Wy_norm")


def cell_offsets(n_positions: int) -> tuple[list[tuple[float, float]], int]:
    """(x, z) offsets of the centre in one mesh cell, in cells, standing for n_positions offsets over
    the cell (module docstring: the quarter [0, 1/2)^2 holds every offset once; the lattice listed x by x).
    Returns (offsets to compute, offsets they stand for)."""
    return case.symmetric_cell_offsets(n_positions, "wallShear", mirror_x=True, x_fastest=False)


def check_scene(eps_values: Sequence[float], radii: Sequence[float], size: Sequence[float], a_over_delta: float) -> None:
    """Refuse, naming the value, a scene the solver cannot run or this case cannot compare: eps <= 0, a
    radius not positive or below 2 cells, a box side not a whole number of cells (x and z: even, the
    centre on a vertex), the sphere within MIN_TOP_GAP of the moving wall or MIN_IMAGE_GAP of its
    periodic images."""
    if not a_over_delta > 0:
        raise ValueError("wallShear: --a-over-delta must be positive, got %g" % a_over_delta)
    if not eps_values:
        raise ValueError("wallShear: no eps given")
    for eps in eps_values:
        if not eps > 0:
            raise ValueError("wallShear: eps = %g: the sphere touches or crosses the wall (eps must be positive)" % eps)
        if eps < freeSphereWall.EPS_MIN:
            raise ValueError("wallShear: eps = %g is below %g, where the reference stops" % (eps, freeSphereWall.EPS_MIN))
    delta = A1 / a_over_delta
    for a in radii:
        if not a > 0:
            raise ValueError("wallShear: --radius %g must be positive" % a)
        if a / delta < 2.0 - 1e-12:
            raise ValueError("wallShear: --radius %g is %.3g mesh cells at a1/Delta = %g (at least 2: the sub-grid "
                             "model's range)" % (a, a / delta, a_over_delta))
    for name, length, even in (("L_x", size[0], True), ("L_y", size[1], False), ("L_z", size[2], True)):
        cells = length / delta
        whole = cells / 2 if even else cells
        if not length > 0 or abs(whole - round(whole)) > 1e-9 * max(cells, 1.0):
            raise ValueError("wallShear: %s = %g a1 is not %s number of cells of a1/%g%s" % (
                name, length, "an even" if even else "a whole", a_over_delta,
                " (the centre sits on the mesh vertex at the box centre)" if even else ""))
    a_max = max(radii)
    top = size[1] - (1.0 + max(eps_values)) * a_max - a_max
    if top < MIN_TOP_GAP - 1e-12:
        raise ValueError("wallShear: L_y = %g a1 leaves the sphere of radius %g at eps = %g only %.3g a1 from the moving "
                         "wall (at least %g a1: the reference has one wall): make L_y at least %g a1 or eps smaller"
                         % (size[1], a_max, max(eps_values), top, MIN_TOP_GAP,
                            (2.0 + max(eps_values)) * a_max + MIN_TOP_GAP))
    for name, length in (("L_x", size[0]), ("L_z", size[2])):
        if length - 2 * a_max - delta < MIN_IMAGE_GAP - 1e-12:
            raise ValueError("wallShear: %s = %g a1 puts the periodic images of the sphere of radius %g within %.3g a1 "
                             "(at least %g a1)" % (name, length, a_max, length - 2 * a_max - delta, MIN_IMAGE_GAP))


def run_scene(workdir: str, size: Sequence[float], radius: float, subgrid: bool, eps_values: Sequence[float],
              offsets: Sequence[Sequence[float]], options, loads: str = "", load_name: str = "",
              calibration: case.SceneCalibration | None = None) -> dict:
    """One coupled run: the sphere of `radius` at every eps (largest first) and every offset, one step each.
    Returns dict(per_step=[...], wall_seconds, cells). With `loads` (LIGGGHTS lines: fix addforce, fix
    fdm/torque; `load_name` tags the run folder) both walls are at rest and the fluid starts at rest: the
    sphere driven by the loads alone (shearStresslet.py), U_x/(gamma_dot d) and the like then in units of
    gamma_dot = 1. calibration: the table the scene runs with (case.scene_calibration; None: the shipped one),
    written into the run's dem/ when it holds interpolated blocks."""
    delta = A1 / options.a_over_delta
    lx, ly, lz = (float(v) for v in size)
    wall_speed = 0.0 if loads else SHEAR_RATE * ly
    box = case.Box((0, 0, 0), (lx, ly, lz), delta, faces=("cyclic", ((0, 0, 0), (wall_speed, 0, 0)), "cyclic"))
    tag = "%gx%gx%g_ad%g_a%g_n%d_%s%s" % (lx, ly, lz, options.a_over_delta, radius, len(offsets),
                                          "subgrid" if subgrid else "nosubgrid", "_" + load_name if loads else "")
    run_dir = os.path.join(workdir, tag)
    if os.path.isdir(run_dir):
        shutil.rmtree(run_dir)
    labels, positions = [], []
    for eps in sorted(eps_values, reverse=True):
        for offset in offsets:
            labels.append((eps, tuple(offset)))
            positions.append((lx / 2 + offset[0] * delta, (1.0 + eps) * radius, lz / 2 + offset[1] * delta))
    fluid = os.path.join(run_dir, "fluid")
    case.write_fluid_case(fluid, box, nu=ETA, rho=1.0, tol_lambda=options.tol_lambda, n_max=options.n_max,
                          first_step=(options.tol_lambda / 10, 4 * options.n_max), n_particles=1,
                          acceleration=options.acceleration)
    # the undisturbed flow: the far field starts converged, the inner iterations build the sphere's disturbance
    case.write_initial_velocity(fluid, box, lambda c: np.column_stack(
        [wall_speed / ly * c[:, 1], np.zeros(len(c)), np.zeros(len(c))]))
    runs = case.held_step_runs([[p] for p in positions])
    # the calibration table the scene runs with: the shipped one, or with the interpolated wall blocks it needs
    table = calibration.table() if calibration is not None and subgrid else None
    if table is not None:
        calibration.write(os.path.join(run_dir, "dem"))
    case.write_dem_input(os.path.join(run_dir, "dem"), box, [positions[0] + (radius,)], dt=1.0,
                         fix_options="move no stresslets yes",
                         # the walls as in the fluid case: y = 0 at rest, y = L_y at gamma_dot L_y along x
                         pair_style=case.subgrid_pair_style((("ylo", (0, 0, 0)), ("yhi", (wall_speed, 0, 0))),
                                                            subgrid, options.model, options.cutoff, options.wall_cutoff,
                                                            calibration=table),
                         before_run=case.RECORD_EVERY_STEP + ("\n" + loads if loads else ""),
                         runs=runs, name="in.wallShear")
    wall = case.run(run_dir, np_fluid=options.np_fluid)
    rec = output.read_particle_records(os.path.join(run_dir, "dem", "particles.records"), mmap=False)
    steps = output.steps(fluid)
    if len(rec) != len(labels) or len(steps["step"]) != len(labels):
        raise RuntimeError("wallShear: %d records and %d steps for %d configurations in %s"
                           % (len(rec), len(steps["step"]), len(labels), run_dir))
    fluid_seconds = np.asarray(steps["fluidSeconds"], dtype=float)
    per_step = []
    for k, (eps, offset) in enumerate(labels):
        d = (1.0 + eps) * radius
        u, w = rec["U"][k, 0], rec["omega"][k, 0]
        s_xy = float(rec["S_fluid"][k, 0, 1] + rec["S_subgrid"][k, 0, 1])
        x = rec["x"][k, 0]
        if abs(x[1] - d) > 1e-9 * d:
            raise RuntimeError("wallShear: step %d has the centre at y = %r, expected %r" % (k + 1, x[1], d))
        per_step.append(dict(
            eps=eps, offset=list(offset), d=d,
            Ux_norm=float(u[0] / (SHEAR_RATE * d)), Wz_norm=float(w[2] / (0.5 * SHEAR_RATE)),
            S_star=s_xy / (10.0 / 3.0 * math.pi * ETA * radius ** 3 * SHEAR_RATE),
            S_subgrid_star=float(rec["S_subgrid"][k, 0, 1]) / (10.0 / 3.0 * math.pi * ETA * radius ** 3 * SHEAR_RATE),
            Uy_norm=float(u[1] / (SHEAR_RATE * d)), Uz_norm=float(u[2] / (SHEAR_RATE * d)),
            Wx_norm=float(w[0] / (0.5 * SHEAR_RATE)), Wy_norm=float(w[1] / (0.5 * SHEAR_RATE)),
            velocity=[float(v) for v in u], angular_velocity=[float(v) for v in w],
            inner_iterations=int(steps["innerIterations"][k]), converged=bool(steps["converged"][k]),
            wall_seconds=float(wall * fluid_seconds[k] / max(fluid_seconds.sum(), 1e-300))))
    if not options.keep:
        case.delete_fields(run_dir)
    return dict(per_step=per_step, wall_seconds=wall, cells=int(np.prod(box.n)), run_dir=run_dir)


def _mean_std(values: Sequence[float]) -> tuple[float, float]:
    """Mean and (population) standard deviation over the computed offsets (each stands for the same
    number of offsets of the cell)."""
    v = np.asarray(values, dtype=float)
    return float(v.mean()), float(v.std())


def summarise(scene: dict, radius: float, subgrid: bool, size: Sequence[float], represented: int, options) -> list[dict]:
    """Per eps of one scene: the means and standard deviations, the reference, the relative errors
    measured/reference - 1, the symmetry, the box's mean-shear share."""
    rows = []
    volume = float(np.prod(size))
    for eps in sorted({s["eps"] for s in scene["per_step"]}, reverse=True):
        group = [s for s in scene["per_step"] if s["eps"] == eps]
        ref = freeSphereWall.reference(eps)
        row = dict(eps=eps, radius=radius, d=(1.0 + eps) * radius, subgrid=subgrid, box=list(size),
                   a_over_delta=options.a_over_delta, n_positions=represented, positions_computed=len(group))
        for q in QUANTITIES:
            row[q], row[q + "_std"] = _mean_std([s[q] for s in group])
            row[q + "_ref"] = ref[q]
            row[q + "_rel_error"] = row[q] / ref[q] - 1.0
        row["Ux_norm_ref_uncertainty"] = ref["Ux_norm_uncertainty"]
        row["Wz_norm_ref_uncertainty"] = ref["Wz_norm_uncertainty"]
        row["S_subgrid_star"] = float(np.mean([s["S_subgrid_star"] for s in group]))
        for q in SYMMETRY:
            row[q + "_max"] = float(max(abs(s[q]) for s in group))
        # the plane-averaged flow's share of the box (module docstring): the sphere's stresslet raises the
        # shear between the walls by S_xy/(eta V), and U, Omega, S by this fraction (the images act the other way)
        row["mean_shear_share"] = 10.0 / 3.0 * math.pi * radius ** 3 * row["S_star"] / volume
        row.update(inner_iterations=[s["inner_iterations"] for s in group], converged=all(s["converged"] for s in group),
                   wall_seconds=float(sum(s["wall_seconds"] for s in group)), positions=group,
                   reference_source=ref["velocity_source"])
        rows.append(row)
    return rows


def run_box(workdir: str, size: Sequence[float], radii: Sequence[float], subgrid_modes: Sequence[bool],
            eps_values: Sequence[float], offsets, represented: int, options,
            calibration: case.SceneCalibration | None = None) -> dict:
    """Every radius with every sub-grid mode in one box: one coupled run each (with the sub-grid correction on
    the calibration table `calibration`, run_scene). Returns the rows."""
    t0 = time.time()
    rows, cells = [], None
    for radius in radii:
        for subgrid in subgrid_modes:
            scene = run_scene(workdir, size, radius, subgrid, eps_values, offsets, options, calibration=calibration)
            cells = scene["cells"]
            rows += summarise(scene, radius, subgrid, size, represented, options)
            print("  radius %g, sub-grid %s: %.0f s" % (radius, "on" if subgrid else "off", scene["wall_seconds"]))
    return dict(box=list(size), cells=cells, rows=rows, wall_seconds=time.time() - t0)


def box_comparison(boxes: list[dict]) -> list[dict]:
    """Per (radius, sub-grid, eps), from the first box to each other: the relative change of each
    quantity, and that of the plane-averaged flow's share alone (mean_shear_share). For a box
    proportional to the first (scale s) each quantity is also extrapolated to an infinite box as
    Q = Q_inf + c/V (measured: 12^3, 18^3, 24^3 a1 follow it, module docstring), Q_inf = Q_b + (Q_b - Q_a)/(s^3 - 1),
    with its error against the reference."""
    out = []
    first = {(r["radius"], r["subgrid"], r["eps"]): r for r in boxes[0]["rows"]}
    for other in boxes[1:]:
        scales = np.array(other["box"]) / np.array(boxes[0]["box"])
        proportional = bool(np.allclose(scales, scales[0], rtol=1e-9)) and scales[0] != 1
        for row in other["rows"]:
            base = first.get((row["radius"], row["subgrid"], row["eps"]))
            if base is None:
                continue
            entry = dict(radius=row["radius"], subgrid=row["subgrid"], eps=row["eps"], box_a=base["box"],
                         box_b=row["box"], mean_shear_model_change=row["mean_shear_share"] - base["mean_shear_share"])
            for q in QUANTITIES:
                entry[q + "_rel_change"] = row[q] / base[q] - 1.0
                if proportional:
                    extrapolated = row[q] + (row[q] - base[q]) / (float(scales[0]) ** 3 - 1.0)
                    entry[q + "_extrapolated_1_over_V"] = extrapolated
                    entry[q + "_extrapolated_rel_error"] = extrapolated / row[q + "_ref"] - 1.0
            out.append(entry)
    return out


def print_rows(rows: list[dict]) -> None:
    """The table of one box: means +- standard deviations, the reference, the errors."""
    print("  %-4s %-3s %-7s %-18s %-18s %-18s %-8s %-8s %-8s %-7s %s" % (
        "a", "SG", "eps", "Ux/(gd)", "Wz/(g/2)", "S*", "err U", "err W", "err S*", "sym", "iterations"))
    for r in rows:
        print("  %-4g %-3s %-7g %s %+7.2f%% %+7.2f%% %+7.2f%% %-7.1e %s" % (
            r["radius"], "on" if r["subgrid"] else "off", r["eps"],
            " ".join("%8.5f+-%-7.5f" % (r[q], r[q + "_std"]) for q in QUANTITIES),
            100 * r["Ux_norm_rel_error"], 100 * r["Wz_norm_rel_error"], 100 * r["S_star_rel_error"],
            max(r[q + "_max"] for q in SYMMETRY), " ".join(str(n) for n in r["inner_iterations"])))
        print("  %-16s %-18.5f %-18.5f %-18.4f   (reference)" % ("", r["Ux_norm_ref"], r["Wz_norm_ref"], r["S_star_ref"]))


def plot(rows: list[dict], path: str, title: str) -> None:
    """Figs. 7-8 of the paper: U_x/(gamma d), -Omega_z/(gamma/2) and S* against eps (log x), the
    reference lines, the means with the standard deviations as error bars, with (filled) and without
    (open) the sub-grid correction, per radius; and the relative errors."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    eps_all = [r["eps"] for r in rows]
    grid = np.logspace(math.log10(min(eps_all)) - 0.2, math.log10(max(eps_all)) + 0.2, 200)
    ref = [freeSphereWall.reference(e) for e in grid]
    fig, axes = plt.subplots(2, 2, figsize=(11, 8))
    panels = (("Ux_norm", 1, r"$U_x/(\dot\gamma d)$"), ("Wz_norm", -1, r"$-\Omega_z/(\dot\gamma/2)$"),
              ("S_star", 1, r"$S^* = S_{xy}/(\frac{10}{3}\pi\eta a^3\dot\gamma)$"))
    for ax, (q, sign, label) in zip(axes.flat, panels):
        ax.semilogx(grid, [sign * r[q] for r in ref], "k-", lw=1,
                    label="Eq. (46), Sangani et al. 2011" if q == "S_star" else "exact wall resistance + GCB 1967")
        ax.set_xlabel(r"$\varepsilon = d/a - 1$")
        ax.set_ylabel(label)
    errors = axes[1, 1]
    for k, radius in enumerate(sorted({r["radius"] for r in rows})):
        for subgrid in (True, False):
            sel = [r for r in rows if r["radius"] == radius and r["subgrid"] == subgrid]
            if not sel:
                continue
            e = [r["eps"] for r in sel]
            style = dict(color="C%d" % k, marker="o" if subgrid else "s", mfc="C%d" % k if subgrid else "none",
                         ls="none", capsize=2)
            name = "a = %g, sub-grid %s" % (radius, "on" if subgrid else "off")
            for ax, (q, sign, _) in zip(axes.flat, panels):
                ax.errorbar(e, [sign * r[q] for r in sel], yerr=[r[q + "_std"] for r in sel], label=name, **style)
            for q, ls in (("Ux_norm", "-"), ("Wz_norm", "--"), ("S_star", ":")):
                errors.semilogx(e, [100 * r[q + "_rel_error"] for r in sel], ls=ls, color="C%d" % k,
                                marker="o" if subgrid else "s", mfc="C%d" % k if subgrid else "none",
                                label="%s: %s" % (q, name))
    errors.axhline(0, color="k", lw=0.5)
    for v in (-2, 2):
        errors.axhline(v, color="grey", lw=0.5, ls=":")
    errors.set_xlabel(r"$\varepsilon$")
    errors.set_ylabel("error against the reference [%]")
    errors.legend(fontsize=6, ncol=2)
    axes[0, 0].legend(fontsize=7)
    axes[1, 0].legend(fontsize=7)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def validation_rows(r: dict) -> List[Row]:
    """U_x/(gamma d), Omega_z/(gamma/2) against the free sphere of the wall resistance functions, S* against
    Sangani's fit (Eq. 46), with and without the sub-grid wall correction."""
    rows = []
    for row in r["rows"]:
        config = "a %g, ε %g, %s, box %s a1, a1/Δ %g, %d positions" % (
            row["radius"], row["eps"], "sub-grid on (%s model)" % (r.get("model") or "cutoff") if row["subgrid"]
            else "FDM alone", "×".join("%g" % v for v in row["box"]), row["a_over_delta"], row["n_positions"])
        for q, key, paper in (("U_x/(γ̇d)", "Ux_norm", "Fig. 7: very good agreement"),
                              ("Ω_z/(γ̇/2)", "Wz_norm", "Fig. 7: very good agreement"),
                              ("S* (Eq. 46)", "S_star", "Fig. 8: very good agreement")):
            rows.append(Row(q, config, row[key], row[key + "_ref"], paper, row[key + "_rel_error"],
                            spread=row[key + "_std"] or None, headline=row["subgrid"]))
    return rows


def main(argv: Sequence[str] | None = None) -> dict:
    """Parse the options (module docstring), run every box, print the tables, write --out and the plot."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--eps", type=float, nargs="+", default=EPS_DEFAULT, help="reduced gaps eps = d/a - 1")
    p.add_argument("--radius", type=float, nargs="+", default=None,
                   help="sphere radii in units of a1 (default 1; the paper: 1 1.4)")
    p.add_argument("--size", type=float, nargs=3, default=None, metavar=("LX", "LY", "LZ"),
                   help="box in units of a1 (walls normal to y; default %g %g %g)" % BOX_DEFAULT)
    p.add_argument("--boxes", type=float, nargs="*", default=None, metavar="L",
                   help="run in several boxes, LX LY LZ per box (no numbers: %s): the box effect"
                        % ", ".join("%g x %g x %g" % b for b in BOXES_DEFAULT))
    p.add_argument("--a-over-delta", type=float, default=None, help="a1/Delta, mesh cells per radius a1 (default 3)")
    p.add_argument("--positions", type=int, default=None,
                   help="offsets of the centre in one mesh cell: an even square m^2 (4, 16) is the m x m lattice, "
                        "computed at its m^2/4 points in the quarter cell the symmetries make the whole cell; other "
                        "counts are Halton points there (default 2)")
    p.add_argument("--offset", type=float, nargs=2, action="append", default=None, metavar=("X", "Z"),
                   help="an explicit (x, z) offset in cells (repeatable), instead of --positions; 0 0 puts the centre "
                        "on a mesh vertex, where the mesh has the flow's mirror symmetries")
    p.add_argument("--full", action="store_true",
                   help="the paper's scene: box 50^3 a1, a1/Delta = 5, 16 offsets, radii 1 and 1.4")
    sg = p.add_mutually_exclusive_group()
    sg.add_argument("--no-subgrid", dest="subgrid_modes", action="store_const", const=[False],
                    help="only without the sub-grid correction (pair_style fdm/subgrid lubrication no)")
    sg.add_argument("--subgrid-only", dest="subgrid_modes", action="store_const", const=[True],
                    help="only with the correction (default: both, the correction's effect side by side)")
    p.add_argument("--wall-cutoff", type=float, default=None,
                   help="pair_style fdm/subgrid wall_cutoff (mesh cells; default: the pair style's, 0.75)")
    p.add_argument("--n-max", type=int, default=2000, help="fdmFoam's innerIterations nMax (4x on the first step)")
    p.add_argument("--reference", action="store_true", help="print the reference at --eps and stop: no solver")
    case.add_run_options(p, HERE, tol_lambda=1e-4, cutoff=True)
    args = p.parse_args(argv)

    if args.full:
        paper = dict(size=list(PAPER_BOX), a_over_delta=5.0, positions=16, radius=list(RADII_PAPER))
        for key, value in paper.items():
            if getattr(args, key) is None:
                setattr(args, key, value)
    args.size = list(BOX_DEFAULT) if args.size is None else args.size
    args.a_over_delta = 3.0 if args.a_over_delta is None else args.a_over_delta
    args.positions = 2 if args.positions is None else args.positions
    args.radius = list(RADII_DEFAULT) if args.radius is None else args.radius
    subgrid_modes = args.subgrid_modes or [True, False]

    for eps in args.eps:
        if not eps > 0:
            p.error("--eps %g: the sphere touches or crosses the wall (eps must be positive)" % eps)
    if args.reference:
        rows = [freeSphereWall.reference(e) for e in args.eps]
        freeSphereWall.main(["--eps"] + ["%r" % e for e in args.eps])
        return dict(case="wallShear", reference=rows)
    boxes, offsets, represented = case.boxes_and_offsets(p, args, BOXES_DEFAULT, cell_offsets)
    if args.n_max < 1:
        p.error("--n-max must be at least 1, got %d" % args.n_max)
    if args.wall_cutoff is not None and not args.wall_cutoff > 0:
        p.error("--wall-cutoff must be positive, got %g" % args.wall_cutoff)
    try:
        for size in boxes:
            check_scene(args.eps, args.radius, size, args.a_over_delta)
    except ValueError as e:
        p.error(str(e))
    calibration = None
    if True in subgrid_modes:
        # one sphere at a time: each radius against the walls needs a calibration (or an interpolated one)
        try:
            calibration = case.scene_calibration("wallShear", args.radius, A1 / args.a_over_delta, walls=True,
                                                 model=args.model, pairs=False)
        except case.UncalibratedScene as e:
            p.error(str(e))
        if calibration.line():
            print(calibration.line(), flush=True)

    os.makedirs(args.workdir, exist_ok=True)
    t0 = time.time()
    results = []
    for size in boxes:
        print("box %g x %g x %g a1, a1/Delta %g, %d offsets (%d computed)" % (*size, args.a_over_delta, represented,
                                                                            len(offsets)))
        result = run_box(args.workdir, size, args.radius, subgrid_modes, args.eps, offsets, represented, args,
                         calibration)
        print_rows(result["rows"])
        results.append(result)
    comparison = box_comparison(results) if len(results) > 1 else []
    for entry in comparison:
        print("  a %g sub-grid %-3s eps %-6g %s -> %s a1: %s (plane-averaged flow alone %+.2f %%)%s" % (
            entry["radius"], "on" if entry["subgrid"] else "off", entry["eps"],
            "x".join("%g" % v for v in entry["box_a"]), "x".join("%g" % v for v in entry["box_b"]),
            ", ".join("%s %+.2f %%" % (q, 100 * entry[q + "_rel_change"]) for q in QUANTITIES),
            100 * entry["mean_shear_model_change"],
            "; infinite box (c/V): %s" % ", ".join("%s %.5f (%+.2f %%)" % (q, entry[q + "_extrapolated_1_over_V"],
                                                                           100 * entry[q + "_extrapolated_rel_error"])
                                                  for q in QUANTITIES) if "Ux_norm_extrapolated_1_over_V" in entry else ""))
    out = dict(case="wallShear", paper_section="5.2.1",
               conventions="Ux_norm = U_x/(gamma_dot d), Wz_norm = Omega_z/(gamma_dot/2) (-1 far from the wall), "
                           "S_star = S_xy/((10/3) pi eta a^3 gamma_dot); d = (1 + eps) a from the wall y = 0 at rest; "
                           "rel_error = measured/reference - 1 (for Wz_norm too: negative when the sphere turns slower than the reference)",
               rows=results[0]["rows"], box=results[0]["box"], cells=results[0]["cells"],
               a_over_delta=args.a_over_delta, n_positions=represented, offsets=[list(o) for o in offsets],
               radii=args.radius, subgrid_modes=subgrid_modes, model=args.model, cutoff_cells=args.cutoff or "default",
               wall_cutoff_cells=args.wall_cutoff or "default", tol_lambda=args.tol_lambda, boxes=results,
               box_comparison=comparison)
    write_results(args.out, __file__, argv, args, validation_rows, out, t0)
    png = os.path.join(os.path.dirname(os.path.abspath(args.out)), "results_wallShear.png")
    plot(results[0]["rows"], png, "Free sphere in shear near a wall (paper 5.2.1): box %g x %g x %g a1, a1/Delta %g, "
         "%d offsets" % (*results[0]["box"], args.a_over_delta, represented))
    print("wrote %s and %s (%.0f s)" % (args.out, png, out["wall_seconds"]))
    return out


if __name__ == "__main__":
    main()
