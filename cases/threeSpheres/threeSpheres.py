#!/usr/bin/env python3
"""Three spheres in a liquid at rest (paper section 5.5, Fig. 19; issue 15 item 5).

Three equal spheres (a = 1, eta = 1) on an equilateral triangle of side r in the (x, y) plane:
sphere 1 pushed toward the centroid by a force F along +x (no torque), spheres 2 and 3 free
(force- and torque-free), mirror images of each other about the x axis through sphere 1. Walls at
rest at y = 0 and y = L_y (the paper's y = +-L_y/2, shifted), periodic in x and z. The triangle is
held (fix fdm/couple ... move no): each configuration is one coupled time step whose velocities are
those of the fixed configuration (quasi-static), warm-started from the previous one. Sub-grid
lubrication of pairs (pair_style fdm/subgrid, calibrated model by default) as in the other cases; the
walls are declared to it (they are far: no wall block acts). Units: F = 6 pi eta a, so that
velocities come out in F/(6 pi eta a) and angular velocities in F/(6 pi eta a^2).

The centroid sits at the box centre shifted by an offset inside one mesh cell; each r is run at
--positions offsets and averaged (mean and standard deviation, as the paper's 64; the mirror
symmetries of the scene halve the cell twice, cell_offsets):

  U1x                 velocity of sphere 1 along the force
  U23x                mean x velocity of spheres 2 and 3
  dU = U1x - U23x     their relative velocity (paper Table 6)
  U23y                |U2y - U3y| / 2, the velocity normal to the force (Table 7)
  W23z                |Omega2z - Omega3z| / 2, the angular velocity (Table 7)
and the mirror symmetry at each position: |U2x - U3x|, |U2y + U3y|, |W2z + W3z| (0 for a mesh
symmetric about the triangle's axis: offset y = 0; otherwise the discretisation's share).

The box: the force on the triangle makes a Stokeslet between two walls whose images (the walls,
the periodic copies, the mean flow the force drives through the periodic channel) change U1x and U23x
by several per cent (paper: 3.5-5.5 % in its (60, 40, 50) a box) and, in a small box, U23y and W23z
too (the mean flow is a tent profile whose shear, F/(2 eta L_x L_z), turns spheres 2 and 3). Three
estimates of it:
  * the point-force model (channelImages.py): the exact flow of a point force in this periodic
    channel minus the Stokeslet, at the spheres (Eq. I1 there): the box's share of every quantity,
    `box_effect_model` per row;
  * the single sphere: one free sphere pushed by the same F at the same centroid positions in the
    same box and mesh: U_single - 1 = the images at the force plus the solver's own single-sphere
    error (the model tells them apart);
  * two boxes (--boxes): every quantity's change between them, beside the model's; for proportional
    boxes U1x and U23x also extrapolated as U_inf + c/L.
`unbounded_estimate` per row (from r/a = 2.5): U1x - (U_single - 1), U23x, U23y, W23z minus the model's share,
dU = U1x - U23x of these. The reference (farField.py): far-field reflections with exact pairs in
unbounded fluid (error below 0.6 % at r/a = 4, 0.1 % at 6), compared at r/a >= 4.

  threeSpheres.py                   r/a = 2.01 2.1 2.5 3 4 6, box 16 x 16 x 12 a, a/Delta = 3,
                                    8 centroid positions (2 computed; about 3 minutes here)
  threeSpheres.py --boxes           the same in 16 x 16 x 12 and 24 x 24 x 18 a (box independence)
  threeSpheres.py --boxes 16 16 12 20 20 16   any boxes (LX LY LZ per box)
  threeSpheres.py --full            the paper's: box 60 x 40 x 50 a, a/Delta = 5, 64 positions (16 computed)
                                    (15 M cells: out of reach of this 2-core machine)
  threeSpheres.py --a-over-delta 3 4 5 --r 2.01 2.1 2.5 4
                                    the resolution study: every r at each a/Delta in one box, each quantity's
                                    change from the next coarser a/Delta and its error against the reference
                                    (the far field, box taken off, from r/a = 4; the finest a/Delta below);
                                    writes results_resolution.json and results_resolution.png (about 40
                                    minutes here for these 12 scenes, 8 positions)
  threeSpheres.py --combine A.json B.json ...
                                    the same study from the results of single-a/Delta runs of the same scene
                                    (no solver)
  threeSpheres.py --reference [--full | --size LX LY LZ]
                                    no solver: the far-field reference and the box's share in that box
  threeSpheres.py --help            every option
Writes results.json here (docs/cases.md, docs/validation.md "Three spheres (paper 5.5)").
"""
from __future__ import annotations

import argparse
import math
import os
import shutil
import time
from typing import List, Sequence

import numpy as np

from fdmsubgrid import case
from fdmsubgrid import convergence
from fdmsubgrid.results import Row, read_data, relative, write_results
import channelImages
import farField

HERE = os.path.dirname(os.path.abspath(__file__))

RADIUS = 1.0
ETA = 1.0
FORCE = 6 * math.pi * ETA * RADIUS          # velocities in F/(6 pi eta a) are then plain numbers
R_DEFAULT = [2.01, 2.1, 2.5, 3.0, 4.0, 6.0]
BOX_DEFAULT = (16.0, 16.0, 12.0)
BOXES_DEFAULT = [(16.0, 16.0, 12.0), (24.0, 24.0, 18.0)]
PAPER_BOX = (60.0, 40.0, 50.0)
FAR_FIELD_FROM = 4.0                        # r/a from which the far-field reference is compared
MODEL_FROM = 2.5                            # r/a from which the spheres follow the images' flow as tracers
QUANTITIES = ("U1x", "U23x", "dU", "U23y", "W23z")
RESOLUTION_QUANTITIES = ("dU", "U23y", "W23z")   # the resolution study's: the box leaves them near contact
RESOLUTION_R_DEFAULT = [2.01, 2.1, 2.5, 4.0]
MIN_WALL_GAP = 1.0                          # a: the smallest surface gap to a wall the case accepts
MIN_IMAGE_GAP = 1.0                         # a: ... and to a periodic image


def cell_offsets(n_positions: int) -> tuple[list[tuple[float, float, float]], int]:
    """Centroid offsets inside one mesh cell, in cells, standing for n_positions positions spread over
    the cell. The five quantities are unchanged by the mirrors y -> -y (spheres 2 and 3 swap) and
    z -> -z of the scene, and so is the mesh about the cell's vertex at the box centre (to the walls'
    shift by one cell): an offset o and its mirror images (o_x, 1 - o_y, o_z), (o_x, o_y, 1 - o_z)
    give the same values, so [0, 1) x [0, 1/2) x [0, 1/2) holds every position once (x, the force's
    direction, has no such mirror). For a cube n_positions = m^3 with m even (8, 64: the paper's
    4 x 4 x 4 lattice) the lattice points (i + 1/2)/m in that part, m^3/4 of them, whose mean is the
    lattice's; for n_positions = 1, (1/2, 1/4, 1/4); otherwise n_positions points of the Halton
    sequence (bases 2, 3, 5) in it. Returns (offsets to compute, positions they stand for)."""
    if n_positions < 1:
        raise ValueError("threeSpheres: --positions must be at least 1, got %d" % n_positions)
    if n_positions == 1:
        return [(0.5, 0.25, 0.25)], 1
    m = round(n_positions ** (1.0 / 3.0))
    if m ** 3 == n_positions and m % 2 == 0:
        g = [(i + 0.5) / m for i in range(m)]
        return [(x, y, z) for z in g[:m // 2] for y in g[:m // 2] for x in g], n_positions

    h = case.halton_points(n_positions, 3)
    return [(float(x), 0.5 * float(y), 0.5 * float(z)) for x, y, z in h], n_positions


def check_scene(r_values: Sequence[float], size: Sequence[float], a_over_delta: float) -> None:
    """Refuse, with a message naming the value, a scene the solver cannot run or this case cannot
    measure: overlapping spheres, a box that is not a whole (even) number of cells, walls or periodic
    images closer than MIN_WALL_GAP / MIN_IMAGE_GAP to a sphere's surface."""
    if not a_over_delta > 0:
        raise ValueError("threeSpheres: --a-over-delta must be positive, got %g" % a_over_delta)
    if not r_values:
        raise ValueError("threeSpheres: no r given")
    for r in r_values:
        if not r > 2 * RADIUS:
            raise ValueError("threeSpheres: r/a = %g: the spheres overlap or touch (r/a must exceed 2)" % r)
    delta = RADIUS / a_over_delta
    for name, length in zip(("L_x", "L_y", "L_z"), size):
        cells = length / delta
        if abs(cells / 2 - round(cells / 2)) > 1e-9 * cells:
            raise ValueError("threeSpheres: %s = %g a is not an even number of cells of a/%g (the centroid sits on "
                             "the mesh vertex at the box centre)" % (name, length, a_over_delta))
    r_max = max(r_values)
    wall_gap = size[1] / 2 - (r_max / 2 + RADIUS) - delta     # the largest offset is one cell
    if wall_gap < MIN_WALL_GAP:
        raise ValueError("threeSpheres: L_y = %g a leaves spheres 2 and 3 of r/a = %g only %.3g a from a wall "
                         "(at least %g a): make L_y at least %g a" % (size[1], r_max, wall_gap, MIN_WALL_GAP,
                                                                  r_max + 2 * RADIUS + 2 * delta + 2 * MIN_WALL_GAP))
    width_x = r_max * math.sqrt(3.0) / 2 + 2 * RADIUS     # x extent of the triangle's spheres
    for name, length, width in (("L_x", size[0], width_x), ("L_z", size[2], 2 * RADIUS)):
        if length - width < MIN_IMAGE_GAP:
            raise ValueError("threeSpheres: %s = %g a puts the periodic images of the triangle of r/a = %g within "
                             "%.3g a (at least %g a)" % (name, length, r_max, length - width, MIN_IMAGE_GAP))


def _fresh(run_dir: str) -> str:
    """run_dir, emptied of an earlier run."""
    if os.path.isdir(run_dir):
        shutil.rmtree(run_dir)
    return run_dir


def _write_and_run(run_dir: str, box: case.Box, configurations: list[np.ndarray], pushed: int, options) -> tuple[
        float, dict, dict]:
    """One coupled run: the spheres at each configuration (n, 3) in turn, one step each, the sphere
    of index `pushed` with the force FORCE along +x (fix addforce), all held (move no). Returns (wall
    seconds, particle records, step records)."""
    n = len(configurations[0])
    case.write_fluid_case(os.path.join(run_dir, "fluid"), box, nu=ETA, rho=1.0, tol_lambda=options.tol_lambda,
                          n_max=options.n_max, first_step=(options.tol_lambda / 10, 4 * options.n_max),
                          n_particles=n, acceleration=options.acceleration)
    runs = case.held_step_runs(configurations)
    spheres = [tuple(map(float, p)) + (RADIUS,) for p in configurations[0]]
    case.write_dem_input(os.path.join(run_dir, "dem"), box, spheres, dt=1.0,
                         pair_style=case.subgrid_pair_style((("ylo", (0, 0, 0)), ("yhi", (0, 0, 0))),
                                                            options.subgrid, options.model, options.cutoff),
                         before_run="group           pushed id %d\n"
                                    "fix             push pushed addforce %r 0 0" % (pushed + 1, FORCE),
                         runs=runs, name="in.threeSpheres")
    wall, particles, steps = case.run_and_read(run_dir, np_fluid=options.np_fluid, keep=options.keep)
    return wall, particles, steps


def _by_step(particles: dict, n_spheres: int) -> tuple[np.ndarray, np.ndarray]:
    """Velocities and angular velocities per step, (steps, spheres, 3), in tag order."""
    order = np.lexsort((particles["tag"], particles["step"]))
    u = np.column_stack([particles[c][order] for c in ("Ux", "Uy", "Uz")]).reshape(-1, n_spheres, 3)
    w = np.column_stack([particles[c][order] for c in ("Wx", "Wy", "Wz")]).reshape(-1, n_spheres, 3)
    return u / (FORCE / (6 * math.pi * ETA * RADIUS)), w / (FORCE / (6 * math.pi * ETA * RADIUS ** 2))


def _mean_std(values: Sequence[float]) -> tuple[float, float]:
    """Mean and standard deviation over the positions (population: each computed offset stands for
    the same number of positions of the cell, cell_offsets)."""
    v = np.asarray(values, dtype=float)
    return float(v.mean()), float(v.std())


def run_box(workdir: str, size: Sequence[float], r_values: Sequence[float], offsets: Sequence[Sequence[float]],
            represented: int, options) -> dict:
    """Every r at every centroid offset in one box: one coupled run of the triangles (largest r first,
    each step warm-started from the previous configuration) and one of the single sphere at the same
    offsets. Returns dict(rows=[per r], single=..., box, cells, wall_seconds, ...)."""
    delta = RADIUS / options.a_over_delta
    box = case.Box((0, 0, 0), tuple(size), delta, faces=("cyclic", ((0, 0, 0), (0, 0, 0)), "cyclic"))
    centre = np.array(size, dtype=float) / 2
    tag = "%gx%gx%g_ad%g_n%d%s" % (*size, options.a_over_delta, len(offsets), "" if options.subgrid else "_nosubgrid")
    r_sorted = sorted(r_values, reverse=True)
    t0 = time.time()
    u_all, w_all, iterations, converged, labels = [], [], [], [], []
    wall = 0.0
    for r in r_sorted:
        # one coupled run per r (its positions warm-started from one another): each run stays short
        configurations = [farField.triangle_positions(r, centre + np.asarray(offset) * delta) for offset in offsets]
        seconds, particles, steps = _write_and_run(_fresh(os.path.join(workdir, "triangle_%s_r%g" % (tag, r))), box,
                                                   configurations, 0, options)
        u, w = _by_step(particles, 3)
        if len(u) != len(configurations):
            raise RuntimeError("threeSpheres: %d steps recorded for %d configurations" % (len(u), len(configurations)))
        wall += seconds
        u_all += list(u)
        w_all += list(w)
        iterations += [int(n) for n in steps["innerIterations"]]
        converged += [bool(c) for c in steps["converged"]]
        labels += [(r, tuple(offset)) for offset in offsets]
    u, w = np.array(u_all), np.array(w_all)
    steps = dict(innerIterations=iterations, converged=converged)
    rows = []
    for r in r_sorted:
        picks = [k for k, (rk, _) in enumerate(labels) if rk == r]
        per_position = []
        for k in picks:
            uk, wk = u[k], w[k]
            q = farField.summary(uk, wk)
            q.update(offset=list(labels[k][1]), inner_iterations=int(steps["innerIterations"][k]),
                     converged=bool(steps["converged"][k]),
                     mirror_U2x_U3x=float(abs(uk[1, 0] - uk[2, 0])), mirror_U2y_U3y=float(abs(uk[1, 1] + uk[2, 1])),
                     mirror_W2z_W3z=float(abs(wk[1, 2] + wk[2, 2])),
                     out_of_plane=float(max(np.abs(uk[:, 2]).max(), np.abs(wk[:, :2]).max())),
                     velocities=uk.tolist(), angular_velocities=wk.tolist())
            per_position.append(q)
        row = dict(r=r)
        for name in QUANTITIES:
            row[name], row[name + "_std"] = _mean_std([p[name] for p in per_position])
        row.update(box=list(size), a_over_delta=options.a_over_delta, n_positions=represented,
                   positions_computed=len(per_position),
                   mirror_max=max(max(p["mirror_U2x_U3x"], p["mirror_U2y_U3y"], p["mirror_W2z_W3z"])
                                  for p in per_position),
                   out_of_plane_max=max(p["out_of_plane"] for p in per_position),
                   inner_iterations=[p["inner_iterations"] for p in per_position],
                   converged=all(p["converged"] for p in per_position), positions=per_position)
        rows.append(row)
    single = None
    if not options.no_single:
        single_configurations = [(centre + np.asarray(offset) * delta)[None, :] for offset in offsets]
        wall_single, p_single, s_single = _write_and_run(_fresh(os.path.join(workdir, "single_" + tag)), box,
                                                         single_configurations, 0, options)
        us, ws = _by_step(p_single, 1)
        mean, std = _mean_std(us[:, 0, 0])
        mean_offset = np.mean(np.asarray(offsets, dtype=float), axis=0)
        force = np.array([FORCE, 0.0, 0.0])
        image = float(channelImages.self_image(centre + mean_offset * delta, force, tuple(size))[0]
                      / (FORCE / (6 * math.pi * ETA * RADIUS)))
        single = dict(U=mean, U_std=std, box_effect=mean - 1.0, image_model=image, solver_error=mean - 1.0 - image,
                      U_positions=[float(v) for v in us[:, 0, 0]],
                      lateral_max=float(np.abs(us[:, 0, 1:]).max()), rotation_max=float(np.abs(ws).max()),
                      inner_iterations=[int(n) for n in s_single["innerIterations"]],
                      converged=bool(np.all(s_single["converged"])), wall_seconds=wall_single)
    rows = sorted(rows, key=lambda row: row["r"])
    mean_offset = np.mean(np.asarray(offsets, dtype=float), axis=0)
    for row in rows:
        model = channelImages.triangle_box_effect(
            farField.triangle_positions(row["r"], centre + mean_offset * delta), tuple(size), FORCE)
        row["box_effect_model"] = model
        # near contact the lubrication locks the triangle: its relative motions do not follow the images'
        # gradients (measured: dU and U23y change by < 1 % between boxes at r/a = 2.01, 2.1 where the
        # tracer model says 9 % and 41 %): no box-free estimate there
        row["unbounded_estimate"] = unbounded_estimate(row, model, single) if row["r"] >= MODEL_FROM - 1e-12 else None
    return dict(box=list(size), a_over_delta=options.a_over_delta, cells=int(np.prod(box.n)), n_positions=represented,
                positions_computed=len(offsets),
                subgrid=options.subgrid, rows=rows, single=single,
                triangle_wall_seconds=wall, wall_seconds=time.time() - t0)


def unbounded_estimate(row: dict, model: dict, single: dict | None) -> dict:
    """The measured quantities with the box taken off: the images' share of the point-force model
    (channelImages, Eq. I1) off U23x, U23y, W23z; off U1x the single sphere's U_single - 1 (the same
    images at the force plus the solver's own single-sphere error, so that what is left of U1x is the
    interaction), or the model's self image without a single-sphere run; dU = U1x - U23x of these."""
    estimate = {}
    estimate["U1x"] = row["U1x"] - (single["box_effect"] if single else model["U1x"])
    estimate["U23x"] = row["U23x"] - model["U23x"]
    estimate["dU"] = estimate["U1x"] - estimate["U23x"]
    estimate["U23y"] = row["U23y"] - model["U23y"]
    estimate["W23z"] = row["W23z"] - model["W23z"]
    return estimate


def far_field_comparison(rows: list[dict]) -> list[dict]:
    """Per row with r >= FAR_FIELD_FROM: the far-field reference (farField.three_spheres, exact pairs
    plus reflections, unbounded fluid) beside the measured values as they are (`*_rel_diff`) and with
    the box taken off (unbounded_estimate, `*_unbounded_rel_diff`)."""
    out = []
    for row in rows:
        if row["r"] < FAR_FIELD_FROM - 1e-12:
            continue
        ref = farField.three_spheres(row["r"])
        entry = dict(r=row["r"], reference={k: ref[k] for k in QUANTITIES},
                     reference_three_body={k: ref["three_body"][k] for k in QUANTITIES})
        for name in QUANTITIES:
            entry[name + "_rel_diff"] = (row[name] - ref[name]) / ref[name]
            entry[name + "_unbounded_rel_diff"] = (row["unbounded_estimate"][name] - ref[name]) / ref[name]
        out.append(entry)
    return out


def box_comparison(boxes: list[dict]) -> list[dict]:
    """Per r, from the first box to each other one: the measured relative change of each quantity
    (`*_rel_change`: dU and U23y should hardly move, U1x and U23x do), the change the point-force model
    predicts (`*_model_rel_change`) and that of the box-free estimates (`*_unbounded_rel_change`); the
    single sphere's change. For boxes proportional to the first (scale s), U1x, U23x and the single
    sphere also extrapolated to an infinite box with U = U_inf + c/L (the images of a Stokeslet: Faxen's
    a/h and the mean flow F L_y/(4 eta L_x L_z) both go as 1/L; the gradients that move U23y and W23z
    go as 1/L^2, so these are not extrapolated)."""
    first = boxes[0]
    out = []
    for other in boxes[1:]:
        scales = np.array(other["box"]) / np.array(first["box"])
        proportional = bool(np.allclose(scales, scales[0], rtol=1e-9)) and scales[0] != 1
        for row_a, row_b in zip(first["rows"], other["rows"]):
            entry = dict(r=row_a["r"], box_a=first["box"], box_b=other["box"])
            for name in QUANTITIES:
                entry[name + "_rel_change"] = (row_b[name] - row_a[name]) / row_a[name]
                entry[name + "_model_rel_change"] = (row_b["box_effect_model"][name]
                                                     - row_a["box_effect_model"][name]) / row_a[name]
                if row_a["unbounded_estimate"] and row_b["unbounded_estimate"]:
                    entry[name + "_unbounded_rel_change"] = (row_b["unbounded_estimate"][name] - row_a[
                        "unbounded_estimate"][name]) / row_a["unbounded_estimate"][name]
            if proportional:
                s = float(scales[0])
                for name in ("U1x", "U23x"):
                    entry[name + "_extrapolated_1_over_L"] = row_b[name] + (row_b[name] - row_a[name]) / (s - 1)
            if first["single"] and other["single"]:
                entry["single_rel_change"] = (other["single"]["U"] - first["single"]["U"]) / first["single"]["U"]
                if proportional:
                    entry["single_extrapolated_1_over_L"] = other["single"]["U"] + (
                        other["single"]["U"] - first["single"]["U"]) / (float(scales[0]) - 1)
            out.append(entry)
    return out


def resolution_study(boxes: Sequence[dict]) -> list[dict]:
    """The resolution study from one run_box result per a/Delta (the same box, r, positions and model,
    any order): per r, the measured quantities at each a/Delta (convergence.resolution_series: value,
    spread over the positions, change from the next coarser a/Delta, error against the reference).
    The reference: at every r the finest a/Delta, compared with the values as measured in the box
    (`series`: near contact no independent reference exists, and the box changes dU, U23y, W23z by less
    than 1 % there); from r/a = FAR_FIELD_FROM also the far field (farField.three_spheres, unbounded
    fluid, as the runs' far_field_comparison holds it), compared with the box-free estimates
    (`far_field`). A mismatch between the runs is a ValueError naming it."""
    if len(boxes) < 2:
        raise ValueError("threeSpheres: the resolution study needs at least two a/Delta, got %d" % len(boxes))
    boxes = sorted(boxes, key=lambda b: b["a_over_delta"])
    first = boxes[0]
    r_first = [row["r"] for row in first["rows"]]
    for b in boxes[1:]:
        for key in ("box", "n_positions", "positions_computed", "subgrid"):
            if b[key] != first[key]:
                raise ValueError("threeSpheres: the runs at a/Delta %g and %g differ in %s (%s, %s)"
                                 % (first["a_over_delta"], b["a_over_delta"], key, first[key], b[key]))
        if [row["r"] for row in b["rows"]] != r_first:
            raise ValueError("threeSpheres: the runs at a/Delta %g and %g have different r/a (%s, %s)" % (
                first["a_over_delta"], b["a_over_delta"], r_first, [row["r"] for row in b["rows"]]))
    resolutions = [b["a_over_delta"] for b in boxes]
    for coarse, fine in zip(resolutions, resolutions[1:]):
        if fine == coarse:
            raise ValueError("threeSpheres: a/Delta %g appears twice in the resolution study" % fine)
    # the far field at each r from FAR_FIELD_FROM, as each run compared with it (far_field_comparison)
    references = {f["r"]: f["reference"] for f in first.get("far_field") or []}
    out = []
    for k, r in enumerate(r_first):
        measured = [b["rows"][k] for b in boxes]
        entry = dict(r=r, a_over_delta=resolutions, reference_below="finest a/Delta %g" % resolutions[-1],
                     series=convergence.resolution_series(resolutions, measured, QUANTITIES,
                                                          reference={q: measured[-1][q] for q in QUANTITIES}))
        ref = references.get(r)
        if ref is not None and all(row.get("unbounded_estimate") for row in measured):
            entry["far_field"] = convergence.resolution_series(
                resolutions, [row["unbounded_estimate"] for row in measured], QUANTITIES,
                reference={q: ref[q] for q in QUANTITIES})
        out.append(entry)
    return out


def resolution_rows(data: dict) -> List[Row]:
    """The results rows of the resolution study: per r, a/Delta and quantity (RESOLUTION_QUANTITIES),
    the value against the far field (box taken off, r/a >= FAR_FIELD_FROM) or, below, as measured
    against the finest a/Delta (a comparison, not a headline)."""
    rows = []
    box = "×".join("%g" % v for v in data["box"])
    for entry in data["resolution"]:
        far = entry.get("far_field")
        for k, s in enumerate(entry["series"]):
            for q in RESOLUTION_QUANTITIES:
                config = "r/a %g, box %s a, a/Δ %g, %d positions" % (entry["r"], box, s["a_over_delta"],
                                                                     data["n_positions"])
                if far:
                    f = far[k]
                    rows.append(Row(q + " (box removed)", config, f[q], f[q + "_reference"], "Tables 6–7",
                                    f[q + "_error"], spread=s[q + "_std"] or None))
                else:
                    rows.append(Row(q, config + ", against the finest a/Δ", s[q], s[q + "_reference"],
                                    "Tables 6–7", s[q + "_error"], spread=s[q + "_std"] or None, headline=False))
    return rows


def shown_series(entry: dict) -> tuple[list[dict], str]:
    """The series of one r the study reports, and what it is compared with: from r/a = FAR_FIELD_FROM
    the box-free estimates against the far field, below the values as measured against the finest a/Delta."""
    if entry.get("far_field"):
        return entry["far_field"], "box taken off, against the far field (unbounded)"
    return entry["series"], "as measured, against the %s" % entry["reference_below"]


def print_resolution(study: list[dict]) -> None:
    """The resolution study's table: per r and a/Delta each quantity +- its spread over the positions,
    its change from the next coarser a/Delta and its error against the reference, in %."""
    for entry in study:
        series, what = shown_series(entry)
        print("r/a %g (%s)" % (entry["r"], what))
        for k, s in enumerate(series):
            cells = []
            for q in RESOLUTION_QUANTITIES:
                change = "%+.2f %%" % (100 * s[q + "_rel_change"]) if s[q + "_rel_change"] is not None else "—"
                error = "%+.2f %%" % (100 * s[q + "_error"]) if s[q + "_error"] is not None else "—"
                spread = entry["series"][k][q + "_std"] or 0.0
                cells.append("%s %.5f +- %.5f (change %s, error %s)" % (q, s[q], spread, change, error))
            print("  a/Delta %-3g %s" % (s["a_over_delta"], "; ".join(cells)))


def plot_resolution(study: list[dict], path: str) -> None:
    """One panel per r (rows) and quantity (columns, RESOLUTION_QUANTITIES): the value +- its spread over
    the positions against a/Delta with its reference (shown_series): below r/a = FAR_FIELD_FROM as
    measured, the finest a/Delta dotted; from it the box-free estimate, the far field drawn."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    labels = dict(dU="dU = U1x - U23x", U23y="U23y", W23z="W23z")
    fig, axes = plt.subplots(len(study), len(RESOLUTION_QUANTITIES), figsize=(10, 2.3 * len(study) + 0.6),
                             squeeze=False)
    for i, entry in enumerate(study):
        series, _ = shown_series(entry)
        far = bool(entry.get("far_field"))
        n = [s["a_over_delta"] for s in series]
        for j, q in enumerate(RESOLUTION_QUANTITIES):
            ax = axes[i][j]
            ax.errorbar(n, [s[q] for s in series], yerr=[s[q + "_std"] or 0 for s in entry["series"]],
                        marker="o", capsize=3, label="box taken off" if far else "measured")
            ax.axhline(series[-1][q + "_reference"], color="k", lw=1, ls="-" if far else ":",
                       label="far field (unbounded)" if far else entry["reference_below"])
            ax.set_xticks(n)
            ax.set_title("r/a %g: %s%s" % (entry["r"], labels[q], " (box taken off)" if far else ""), fontsize=9)
            if i == len(study) - 1:
                ax.set_xlabel("a/Δ")
            ax.tick_params(labelsize=8)
            if j == 0:
                ax.legend(fontsize=7)
    fig.suptitle("three spheres: velocities (F/(6πηa)) and angular velocity (F/(6πηa²)) against a/Δ, "
                 "± spread over the centroid positions", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def combine_runs(paths: Sequence[str]) -> tuple[list[dict], dict]:
    """The single-a/Delta results files of a resolution study: their box results (run_box's) and the
    scene they share (model, cut-off, tolLambda, offsets); a file of another case or study, or runs that
    differ in the scene, is a ValueError naming the file."""
    boxes, shared = [], None
    for path in paths:
        data = read_data(path)
        if data.get("case") != "threeSpheres" or "boxes" not in data:
            raise ValueError("threeSpheres --combine: %s is not a single-a/Delta threeSpheres results file" % path)
        if len(data["boxes"]) != 1:
            raise ValueError("threeSpheres --combine: %s holds %d boxes (a run of one box is combined)"
                             % (path, len(data["boxes"])))
        scene = {k: data.get(k) for k in ("model", "cutoff_cells", "tol_lambda", "offsets", "subgrid")}
        if shared is None:
            shared = scene
        elif scene != shared:
            differ = sorted(k for k in scene if scene[k] != shared[k])
            raise ValueError("threeSpheres --combine: %s differs from %s in %s" % (path, paths[0], ", ".join(differ)))
        boxes.append(data["boxes"][0])
    return boxes, shared


def print_box(result: dict) -> None:
    """The table of one box: measured means +- standard deviations over the positions, the largest
    mirror asymmetry, the inner iterations; the box's share (point-force model) and the box-free
    estimate; the single sphere."""
    print("box %g x %g x %g a, a/Delta %g, %d cells, %d centroid positions (%d computed), sub-grid %s (%.0f s)"
          % (*result["box"], result["a_over_delta"], result["cells"], result["n_positions"],
             result["positions_computed"], "on" if result["subgrid"] else "off", result["wall_seconds"]))
    print("  %-5s %-19s %-19s %-19s %-19s %-19s %-8s %s" % ("r/a", "U1x", "U23x", "dU", "U23y", "W23z", "mirror",
                                                          "iterations"))
    for row in result["rows"]:
        print("  %-5g %s %-8.1e %s" % (row["r"], " ".join("%.5f +- %.5f" % (row[q], row[q + "_std"])
                                                          for q in QUANTITIES),
                                        row["mirror_max"], " ".join(str(n) for n in row["inner_iterations"])))
        print("  %-5s %s   (box's share, point-force images)" % ("", " ".join(
            "%+-19.5f" % row["box_effect_model"][q] for q in QUANTITIES)))
        if row["unbounded_estimate"]:
            print("  %-5s %s   (box taken off)" % ("", " ".join("%-19.5f" % row["unbounded_estimate"][q]
                                                               for q in QUANTITIES)))
        else:
            print("  %-5s (near contact: the triangle does not follow the images as tracers, no box-free estimate)"
                  % "")
    if result["single"]:
        s = result["single"]
        print("  single sphere, same force and positions: U = %.5f +- %.5f: U - 1 = %+.2f %% (images, point-force "
              "model: %+.2f %%; the solver's own: %+.2f %%)" % (s["U"], s["U_std"], 100 * s["box_effect"],
                                                                100 * s["image_model"], 100 * s["solver_error"]))


def print_far_field(entries: list[dict]) -> None:
    """Each far-field comparison: relative differences as measured and with the box taken off."""
    for entry in entries:
        print("  r/a %g against the far field (unbounded): as measured %s; box taken off %s" % (
            entry["r"], ", ".join("%s %+.2f %%" % (q, 100 * entry[q + "_rel_diff"]) for q in QUANTITIES),
            ", ".join("%s %+.2f %%" % (q, 100 * entry[q + "_unbounded_rel_diff"]) for q in QUANTITIES)))


def print_reference(r_values: Sequence[float], size: Sequence[float]) -> list[dict]:
    """The far-field reference (both methods) at each r and the box's share in the box `size` by the
    point-force model, printed (no solver); returns the rows."""
    rows = []
    print("far field, unbounded fluid (farField.py): exact pairs + reflections [reflections alone] "
          "(leading three-body part); box %g x %g x %g a: the images' share (channelImages.py)" % tuple(size))
    for r in r_values:
        ref = farField.three_spheres(r)
        refl = farField.three_spheres(r, "reflections")
        x = farField.triangle_positions(r, np.array(size, dtype=float) / 2)
        model = channelImages.triangle_box_effect(x, tuple(size), FORCE)
        mean_change = (model["U1x"] + 2 * model["U23x"]) / (ref["U1x"] + 2 * ref["U23x"])
        rows.append(dict(r=r, far_field_valid=r >= FAR_FIELD_FROM - 1e-12, reference={k: ref[k] for k in QUANTITIES},
                         reflections_alone={k: refl[k] for k in QUANTITIES},
                         three_body={k: ref["three_body"][k] for k in QUANTITIES}, box=list(size),
                         box_effect_model=model, mean_velocity_rel_change=mean_change))
        valid = r >= FAR_FIELD_FROM - 1e-12
        print("  r/a %-5g %s%s" % (r, "  ".join("%s %.5f [%.5f] (%.1e)" % (q, ref[q], refl[q], ref["three_body"][q])
                                               for q in QUANTITIES),
                                  "" if valid else "  (near field: not a reference below r/a = %g)" % FAR_FIELD_FROM))
        print("  %-9s box's share: %s; mean velocity of the three %+.2f %%%s" % (
            "", "  ".join("%s %+.5f (%+.2f %%)" % (q, model[q], 100 * model[q] / ref[q]) for q in QUANTITIES),
            100 * mean_change, "" if valid else " (percentages of the approximate values above)"))
    return rows


def validation_rows(r: dict) -> List[Row]:
    rows = []
    references = {f["r"]: f["reference"] for f in r.get("far_field", [])}
    for row in r["rows"]:
        ref = references.get(row["r"], {})
        unbounded = row.get("unbounded_estimate") or {}
        for q in ("U1x", "U23x", "dU", "U23y", "W23z"):
            config = "r/a %g, box %s a, a/Δ %g, %d positions" % (row["r"], "×".join("%g" % v for v in row["box"]),
                                                                 row["a_over_delta"], row["n_positions"])
            rows.append(Row(q + (" (box removed)" if q in unbounded else ""), config,
                            unbounded.get(q, row[q]), ref.get(q),
                            "box effect 3.5–5.5 % on U1x, U23x (Tables 6–7)" if q in ("U1x", "U23x") else "Tables 6–7",
                            relative(unbounded.get(q, row[q]), ref.get(q)), spread=row.get(q + "_std") or None))
    return rows


def main(argv: Sequence[str] | None = None) -> dict:
    """Parse the options (module docstring), run every box, print the tables and write --out."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--r", type=float, nargs="+", default=R_DEFAULT, help="triangle sides r/a")
    p.add_argument("--size", type=float, nargs=3, default=list(BOX_DEFAULT), metavar=("LX", "LY", "LZ"),
                   help="box in units of a (walls normal to y; default %g %g %g)" % BOX_DEFAULT)
    p.add_argument("--boxes", type=float, nargs="*", default=None, metavar="L",
                   help="run every r in several boxes, LX LY LZ per box (default, no numbers: %s): the box "
                        "independence of dU, U23y, W23z" % ", ".join("%g x %g x %g" % b for b in BOXES_DEFAULT))
    p.add_argument("--a-over-delta", type=float, nargs="+", default=[3.0],
                   help="a/Delta, mesh cells per radius; several values: the resolution study, every r at each "
                        "a/Delta in one box (--out defaults to results_resolution.json, and a PNG beside it)")
    p.add_argument("--combine", nargs="+", default=None, metavar="FILE",
                   help="the resolution study from the results files of single-a/Delta runs of one scene (the same "
                        "box, r, positions and model): no solver")
    p.add_argument("--no-plot", action="store_true", help="the resolution study without its PNG")
    p.add_argument("--positions", type=int, default=8,
                   help="centroid positions in one mesh cell: an even cube m^3 (8, 64) is the m x m x m lattice, "
                        "computed at its m^3/4 points in the half-cell that the mirror symmetries make the whole "
                        "cell (8: 2 runs); other counts are Halton points there (default 8)")
    p.add_argument("--offset", type=float, nargs=3, action="append", default=None, metavar=("X", "Y", "Z"),
                   help="a centroid offset in the cell (in cells; repeatable), instead of --positions; Y = 0 makes "
                        "the mesh mirror-symmetric about the triangle's axis")
    p.add_argument("--full", action="store_true", help="the paper's scene: box 60 x 40 x 50 a, a/Delta = 5, 64 "
                                                       "positions")
    p.add_argument("--no-subgrid", dest="subgrid", action="store_false",
                   help="pair_style fdm/subgrid with lubrication no (the FDM alone)")
    p.add_argument("--no-single", action="store_true", help="skip the single-sphere runs (the box effect)")
    p.add_argument("--n-max", type=int, default=2000, help="fdmFoam's innerIterations nMax (4x on the first step)")
    p.add_argument("--reference", action="store_true",
                   help="print the far-field reference and the box's share (point-force model) in the box of --size "
                        "(or --full's) and stop: no solver")
    case.add_run_options(p, HERE, tol_lambda=1e-4, cutoff=True)
    args = p.parse_args(argv)

    if args.full:
        args.size, args.a_over_delta, args.positions = list(PAPER_BOX), [5.0], 64
    resolutions = sorted(args.a_over_delta)
    if len(set(resolutions)) != len(resolutions):
        p.error("--a-over-delta %s: a value appears twice" % " ".join("%g" % n for n in args.a_over_delta))
    study = len(resolutions) > 1 or args.combine is not None
    if study and args.out == os.path.join(HERE, "results.json"):
        args.out = os.path.join(HERE, "results_resolution.json")
    if args.combine is not None:
        if len(resolutions) > 1 or args.reference or args.boxes is not None:
            p.error("--combine takes the scene from its files: no --a-over-delta list, --boxes or --reference")
        try:
            runs, shared = combine_runs(args.combine)
            study_result = resolution_study(runs)
        except (OSError, ValueError) as e:
            p.error(str(e))
        args.a_over_delta = sorted(b["a_over_delta"] for b in runs)
        args.r, args.size = [row["r"] for row in runs[0]["rows"]], runs[0]["box"]
        args.positions = runs[0]["n_positions"]
        args.model, args.tol_lambda, args.subgrid = shared["model"], shared["tol_lambda"], shared["subgrid"]
        args.offset = shared["offsets"]
        args.cutoff = None if shared["cutoff_cells"] == "default" else shared["cutoff_cells"]
        return write_study(args, argv, runs, study_result, shared["offsets"], time.time())
    if study and (args.boxes is not None or args.reference):
        p.error("several --a-over-delta (the resolution study) run in one box: no --boxes or --reference")
    args.a_over_delta = resolutions if study else resolutions[0]
    if args.reference:
        for r in args.r:
            if not r > 2 * RADIUS:
                p.error("r/a = %g: the spheres overlap or touch (r/a must exceed 2)" % r)
        return dict(case="threeSpheres", reference=print_reference(args.r, args.size))
    boxes, offsets, represented = case.boxes_and_offsets(p, args, BOXES_DEFAULT, cell_offsets)
    if args.n_max < 1:
        p.error("--n-max must be at least 1")
    try:
        for size in boxes:
            for n in resolutions:
                check_scene(args.r, size, n)
    except ValueError as e:
        p.error(str(e))

    os.makedirs(args.workdir, exist_ok=True)
    t0 = time.time()
    if study:
        runs = []
        for n in resolutions:
            result = run_box(args.workdir, boxes[0], args.r, offsets, represented,
                             argparse.Namespace(**dict(vars(args), a_over_delta=n)))
            print_box(result)
            result["far_field"] = far_field_comparison(result["rows"])
            print_far_field(result["far_field"])
            runs.append(result)
        return write_study(args, argv, runs, resolution_study(runs), [list(o) for o in offsets], t0)
    results = []
    for size in boxes:
        result = run_box(args.workdir, size, args.r, offsets, represented, args)
        print_box(result)
        result["far_field"] = far_field_comparison(result["rows"])
        print_far_field(result["far_field"])
        results.append(result)
    comparison = box_comparison(results) if len(results) > 1 else []
    for entry in comparison:
        print("  r/a %-5g %s -> %s a: %s%s" % (
            entry["r"], "x".join("%g" % v for v in entry["box_a"]), "x".join("%g" % v for v in entry["box_b"]),
            ", ".join("%s %+.2f %% (model %+.2f %%%s)" % (
                q, 100 * entry[q + "_rel_change"], 100 * entry[q + "_model_rel_change"],
                ", box off %+.2f %%" % (100 * entry[q + "_unbounded_rel_change"])
                if q + "_unbounded_rel_change" in entry else "") for q in QUANTITIES),
            "; single sphere %+.2f %%" % (100 * entry["single_rel_change"]) if "single_rel_change" in entry else ""))
    out = dict(case="threeSpheres", paper_section="5.5", units="velocities in F/(6 pi eta a), angular velocities in "
               "F/(6 pi eta a^2)", rows=results[0]["rows"], box=results[0]["box"], a_over_delta=args.a_over_delta,
               n_positions=represented, offsets=[list(o) for o in offsets], subgrid=args.subgrid, model=args.model,
               cutoff_cells=args.cutoff or "default", tol_lambda=args.tol_lambda, single=results[0]["single"],
               far_field=results[0]["far_field"], boxes=results, box_comparison=comparison)
    write_results(args.out, __file__, argv, args, validation_rows, out, t0)
    print("wrote %s (%.0f s)" % (args.out, out["wall_seconds"]))
    return out


def write_study(args, argv: Sequence[str] | None, runs: list[dict], study: list[dict], offsets: list,
                started: float) -> dict:
    """Print the resolution study, write its results file (--out) and, without --no-plot, its PNG beside
    it; returns the record."""
    print_resolution(study)
    runs = sorted(runs, key=lambda b: b["a_over_delta"])
    first = runs[0]
    out = dict(case="threeSpheres", study="resolution", paper_section="5.5",
               units="velocities in F/(6 pi eta a), angular velocities in F/(6 pi eta a^2)", box=first["box"],
               r=[row["r"] for row in first["rows"]], a_over_delta=[b["a_over_delta"] for b in runs],
               cells=[b["cells"] for b in runs], wall_seconds_per_resolution=[b["wall_seconds"] for b in runs],
               n_positions=first["n_positions"], positions_computed=first["positions_computed"], offsets=offsets,
               subgrid=args.subgrid, model=args.model, cutoff_cells=getattr(args, "cutoff", None) or "default",
               tol_lambda=args.tol_lambda, resolution=study, boxes=runs,
               wall_seconds=float(sum(b["wall_seconds"] for b in runs)))
    write_results(args.out, __file__, argv, args, resolution_rows, out, started)
    if not args.no_plot:
        png = os.path.splitext(args.out)[0] + ".png"
        plot_resolution(study, png)
        print("wrote %s" % png)
    print("wrote %s (%.0f s of runs)" % (args.out, out["wall_seconds"]))
    return out


if __name__ == "__main__":
    main()
