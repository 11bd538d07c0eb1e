#!/usr/bin/env python3
"""A pair of free spheres in a confined plane Poiseuille flow (paper section 5.4, Figs. 16-18).

Two identical spheres of radius a (a = 1, eta = 1, U_c = 1) between walls at rest at y = 0 and y = H = 4a,
x and z periodic (L_x, L_z), the flow driven by the uniform pressure gradient dP0/dx = -8 eta U_c / H^2
(Eq. 48; fdmFoam's gradP0, as cases/poiseuilleSphere), so that the undisturbed flow is
u0 = U_c (1 - (2y'/H)^2) e_x (Eq. 47, y' = y - H/2). Sphere 1 on the centre line (y1 = H/2), sphere 2 at
d/a = 1.33 from the lower wall (y2 = 1.33 a), both in the same plane z, sphere 2 DOWNSTREAM of sphere 1:
x2 = x1 + rho12 (rho12 the lateral distance, Fig. 16). The reduced gap is
xi = 2|x2 - x1|/(a1 + a2) - 2 = sqrt(rho12^2 + (y1 - y2)^2)/a - 2. Both spheres are free in force and torque
but held in place (fix fdm/couple ... move no): each configuration is one coupled time step whose velocities
are those of the fixed configuration (quasi-static), warm-started from the previous one (rho12 decreasing,
the positions in the cell in turn). The walls are declared to pair_style fdm/subgrid (wall ylo/yhi at rest)
as in the other wall cases; `lubrication no` gives the FDM alone ("without the correction").

Measured per rho12/H (mean and standard deviation over the positions of the pair in the plane section
(x, z) of one mesh cell, both spheres shifted together), for sphere i = 1, 2:
  Ux{i}   = U_x/U_c                  Ux{i}_shifted = U_x/U_c - (Delta/H)^2 (below)
  Uy{i}   = U_y/U_c
  Wz{i}   = 2 a Omega_z / U_c        (the paper's Fig. 17 normalisation)
  Un      = (U_2 - U_1).n / U_c, n = (x2 - x1)/|x2 - x1|: the relative velocity along the line of centres
            (negative: approaching), and Un_ratio = Un / Un_single, against the same projection of the
            isolated spheres' velocities: the lubrication drives it to zero as xi -> 0 (O(xi) with the
            sub-grid correction); the FDM alone cannot resolve the gap and leaves it finite.
and the same for each sphere ALONE in the same box, mesh and positions (`single`): the far-field limit.

U_c is that of Eq. (47). fdmFoam's own undisturbed profile is the parabola plus the constant U_c (Delta/H)^2
(the wall flux of the first cell, docs/fluid.md; poiseuilleSphere.Scene.discrete_profile): its centre-line
velocity is U_c (1 + (Delta/H)^2), 1 + 1/144 at a/Delta = 3. As in cases/poiseuilleSphere the fluid starts
from that discrete profile and U_x less (Delta/H)^2 is the velocity in the flow of Eq. (47); U_y and Omega_z
are not shifted (a uniform translation of the whole flow moves the spheres along x only).

Symmetries (exact in Stokes flow, checked where the mesh keeps them):
 (i)  z -> -z: the spheres share one z plane, so U_z = Omega_x = Omega_y = 0 (to tolerance at o_z = 0 or 1/2,
      to the discretisation elsewhere) and the offsets o_z and 1 - o_z are equivalent: the positions are
      taken in [0, 1) x [0, 1/2) cells.
 (ii) x -> -x combined with the reversal of the flow (Stokes reversibility; the mirror maps u0 e_x to
      -u0 e_x, the reversal restores it): the pair with sphere 2 UPSTREAM (x2 = x1 - rho12) has, sphere by
      sphere, (U_x, -U_y, Omega_z) of the pair with sphere 2 downstream. It relates two configurations, not
      the two spheres of one: sphere 1 and sphere 2 sit at different y, and no symmetry of the channel maps
      one onto the other (y -> H - y sends sphere 2 to the upper half, y2 = H - 1.33 a, with (U_x, -U_y,
      -Omega_z)), so U_y1 + U_y2 = 0 or U_y1 = U_y2 hold for no reason here. --mirror computes the mirror
      image of every configuration about a vertex plane of the mesh (mesh included): `mirror` in the rows
      gives max |U_x - U_x'|, |U_y + U_y'|, |Omega_z - Omega_z'| (solver tolerance if the solver is right).
 (iii) y -> H - y maps sphere 1 (alone on the centre line) onto itself: alone it has U_y = Omega_z = 0, so in
      the pair its U_y1 and Omega_z1 are entirely the interaction's and must vanish as rho12 -> infinity.
 There is no exact relation within one configuration; U_y = 0 for each ISOLATED sphere (reversibility + (ii)).

Offsets: sphere 1 at x1 = X0 + o_x Delta, z = Z0 + o_z Delta (X0, Z0 mesh vertices, the pair centred in the
box), o_x in [0, 1), o_z in [0, 1/2): --positions N = m^2 with m even (4, 16: the paper's 4 x 4) are the lattice
points ((i + 1/2)/m, (k + 1/2)/m), of which the m^2/2 with o_z < 1/2 are computed (the others are their z
mirror images); other N: N Halton points in [0, 1) x [0, 1/2).

The mesh: H = 4a must be whole cubic cells, Delta = H / round(H a/Delta); L_x, L_z rounded to whole cells.

  pairPoiseuille.py                   xi = 1e-5 (rho12/H = 0.4711) and rho12/H = 0.48 0.5 0.55 0.6 0.65 0.7 0.8 1
                                      1.25 1.5, with and without the correction, a/Delta = 3, box 16 a x 8 a,
                                      4 positions (2 computed), the single spheres (about 4 minutes here)
  pairPoiseuille.py --convergence     a/Delta 3 -> 4 and box 16 x 8 -> 24 x 12 a at rho12/H = 0.5 and 1.5
                                      (with the correction); writes results_convergence.json
  pairPoiseuille.py --rho 0.5 1.5 --mirror --positions 1    a small scene and its mirror image
  pairPoiseuille.py --full            the paper's: a/Delta = 5, 60 a x 40 a, 16 positions (out of reach here)
  pairPoiseuille.py --help            every option
Writes results.json and results_pairPoiseuille.png here (docs/cases.md).
"""
from __future__ import annotations

import argparse
import math
import os
import shutil
import time
from typing import List, Sequence

import numpy as np

from fdmsubgrid import case, channelscenes
from fdmsubgrid.results import Row, relative, write_results
from fdmsubgrid import convergence as convergence_study

HERE = os.path.dirname(os.path.abspath(__file__))

ETA = 1.0                         # Pa s
U_C = 1.0                         # m/s, centre-line velocity of Eq. (47)
A = 1.0                           # m, the spheres' radius (the length unit)
H_OVER_A = 4.0                    # paper 5.4
D2_OVER_A = 1.33                  # sphere 2's distance from the lower wall (paper 5.4)
XI_DEFAULT = [1e-5]               # the near-contact end of the paper's scan
RHO_DEFAULT = [0.48, 0.5, 0.55, 0.6, 0.65, 0.7, 0.8, 1.0, 1.25, 1.5]
FULL_RHO = [0.48, 0.49, 0.5, 0.52, 0.55, 0.6, 0.65, 0.7, 0.8, 0.9, 1.0, 1.1, 1.25, 1.5]
BOX_DEFAULT = (16.0, 8.0)         # L_x/a, L_z/a
PAPER_BOX = (60.0, 40.0)
PAPER_A_OVER_DELTA = 5.0
PAPER_POSITIONS = 16
POSITIONS_DEFAULT = 4
CONVERGENCE_RHO = (0.5, 1.5)
CONVERGENCE_A_OVER_DELTA = (3.0, 4.0)
CONVERGENCE_BOXES = ((16.0, 8.0), (24.0, 12.0))
SPHERES = (1, 2)
QUANTITIES = tuple("%s%d" % (q, i) for i in SPHERES for q in ("Ux", "Ux_shifted", "Uy", "Wz")) + ("Un",)


# ------------------------------------------------------------------------------------------------
# Geometry
# ------------------------------------------------------------------------------------------------

def dy_over_a(d2_over_a: float = D2_OVER_A, H_over_a: float = H_OVER_A) -> float:
    """(y1 - y2)/a: sphere 1 on the centre line, sphere 2 at d2 from the lower wall."""
    return 0.5 * H_over_a - d2_over_a


def xi_of_rho(rho_over_H: float, d2_over_a: float = D2_OVER_A, H_over_a: float = H_OVER_A) -> float:
    """xi = |x2 - x1|/a - 2 (equal radii) at the lateral distance rho12 = rho_over_H H."""
    rho = rho_over_H * H_over_a
    return math.hypot(rho, dy_over_a(d2_over_a, H_over_a)) - 2.0


def rho_of_xi(xi: float, d2_over_a: float = D2_OVER_A, H_over_a: float = H_OVER_A) -> float:
    """rho12/H at the reduced gap xi (inverse of xi_of_rho)."""
    r2 = (2.0 + xi) ** 2 - dy_over_a(d2_over_a, H_over_a) ** 2
    if r2 <= 0:
        raise ValueError("pairPoiseuille: xi = %g is reached with sphere 2 above sphere 1 (rho12 = 0)" % xi)
    return math.sqrt(r2) / H_over_a


class Scene(channelscenes.PoiseuilleChannel):
    """The channel H = 4a on its mesh (channelscenes.PoiseuilleChannel): Delta the nearest to a/a_over_delta
    that makes H whole cells, L_x, L_z (size, in units of a) rounded to whole cells."""

    def __init__(self, a_over_delta: float, size: Sequence[float], d2_over_a: float = D2_OVER_A) -> None:
        super().__init__(A, H_OVER_A * A, a_over_delta, size, eta=ETA, centre_velocity=U_C, a1=A)
        self.d2_over_a = float(d2_over_a)

    def pair(self, rho_over_H: float, offset: Sequence[float], mirror: bool = False) -> np.ndarray:
        """Centres (2, 3) of spheres 1 and 2: sphere 2 at x1 + rho12 (downstream), sphere 1 at the vertex
        X0 nearest to (L_x - rho12)/2 plus o_x cells, both at z = Z0 + o_z cells (Z0 the vertex at L_z/2).
        mirror: the image of that configuration in the vertex plane x = X0 (sphere 2 upstream)."""
        rho = rho_over_H * self.H
        i0 = int(round((self.Lx - rho) / 2 / self.delta))
        x0 = i0 * self.delta
        z = (self.nz // 2 + offset[1]) * self.delta
        x1 = x0 + offset[0] * self.delta
        x2 = x1 + rho
        if mirror:
            # the image in the vertex plane x = xm nearest the pair's middle (the periodic mesh is symmetric
            # about every vertex plane): the mirrored pair stays centred in the box
            xm = round((x0 + rho / 2) / self.delta) * self.delta
            x1, x2 = 2 * xm - x1, 2 * xm - x2
        return np.array([[x1, self.H / 2, z], [x2, self.d2_over_a * A, z]])

    def single(self, sphere: int, offset: Sequence[float]) -> np.ndarray:
        """The centre (1, 3) of sphere 1 or 2 alone, at the offset from the vertex nearest the box centre."""
        y = self.H / 2 if sphere == 1 else self.d2_over_a * A
        return np.array([[(self.nx // 2 + offset[0]) * self.delta, y, (self.nz // 2 + offset[1]) * self.delta]])

    def describe(self) -> str:
        return ("H = 4 a (%d cells), d2/a = %g, a/Delta = %.4g, box %g x %g x %g a (%d cells)"
                % (self.ny, self.d2_over_a, self.a_over_delta, *self.size_over_a, self.cells))


def check_scene(scene: Scene, rho_list: Sequence[float]) -> None:
    """Refuse, with a message naming the value, overlapping spheres, a sphere in a wall, a box too short."""
    if not 1.0 < scene.d2_over_a < H_OVER_A - 1.0:
        raise ValueError("pairPoiseuille: d2/a = %g puts sphere 2 into a wall (1 < d2/a < 3)" % scene.d2_over_a)
    for r in rho_list:
        xi = xi_of_rho(r, scene.d2_over_a)
        if not xi > 0:
            raise ValueError("pairPoiseuille: rho12/H = %g overlaps the spheres (xi = %.3g)" % (r, xi))
        rho = r * scene.H
        if scene.Lx - rho < rho + 2 * A:
            raise ValueError("pairPoiseuille: rho12/H = %g: L_x = %g a puts sphere 1 nearer to sphere 2's periodic "
                             "image than to sphere 2 (need L_x >= 2 rho12 + 2a = %g a): raise --box"
                             % (r, scene.Lx / A, 2 * rho / A + 2))
    if scene.Lz < 2 * A + 2 * scene.delta:
        raise ValueError("pairPoiseuille: L_z = %g a leaves no room for a sphere: raise --box" % (scene.Lz / A))


def cell_offsets(n_positions: int) -> tuple[list[tuple[float, float]], int]:
    """Offsets (o_x, o_z) in cells standing for n_positions positions of the pair in a cell (module
    docstring: [0, 1) x [0, 1/2), the z mirror only; case.symmetric_cell_offsets). Returns (offsets to
    compute, positions they stand for)."""
    return case.symmetric_cell_offsets(n_positions, "pairPoiseuille", mirror_x=False, x_fastest=True)


# ------------------------------------------------------------------------------------------------
# Running
# ------------------------------------------------------------------------------------------------

def _fresh(run_dir: str) -> str:
    if os.path.isdir(run_dir):
        shutil.rmtree(run_dir)
    return run_dir


def run_configurations(run_dir: str, scene: Scene, configurations: Sequence[np.ndarray], subgrid: bool,
                       options) -> dict:
    """One coupled run: each configuration (n, 3) in turn, one step each, all spheres held (move no), the
    fluid started from the solver's undisturbed profile. Returns the per-step velocities (steps, n, 3),
    angular velocities, sub-grid forces, inner iterations, convergence flags and the wall time."""
    channelscenes.write_poiseuille_channel(
        run_dir, scene, configurations, [A] * len(configurations[0]), "in.pairPoiseuille",
        case.subgrid_pair_style(scene.walls, subgrid, options.model, options.cutoff, options.wall_cutoff),
        options.tol_lambda, options.n_max, options.acceleration)
    wall = case.run(run_dir, np_fluid=options.np_fluid)
    m = len(configurations)
    rec, steps = case.read_held_steps(run_dir, m, "pairPoiseuille")
    x = np.asarray(rec["x"][-m:], dtype=float)
    want = np.array([np.asarray(c, dtype=float) for c in configurations])
    # positions are wrapped into the box by LIGGGHTS: compare modulo the periods
    diff = x - want
    diff[..., 0] -= scene.Lx * np.round(diff[..., 0] / scene.Lx)
    diff[..., 2] -= scene.Lz * np.round(diff[..., 2] / scene.Lz)
    if np.abs(diff).max() > 1e-9 * scene.H:
        raise RuntimeError("pairPoiseuille: %s: the recorded centres are not the configurations'" % run_dir)
    out = dict(U=np.asarray(rec["U"][-m:], dtype=float), W=np.asarray(rec["omega"][-m:], dtype=float),
               F_subgrid=np.asarray(rec["F_subgrid"][-m:], dtype=float),
               iterations=[int(v) for v in steps["innerIterations"][-m:]],
               converged=[bool(v) for v in steps["converged"][-m:]], wall_seconds=wall)
    if not options.keep:
        case.delete_fields(run_dir)
    return out


def _stats(values: Sequence[float]) -> tuple[float, float]:
    """Mean and (population) standard deviation over the positions: every computed offset stands for the
    same number of positions of the cell."""
    v = np.asarray(values, dtype=float)
    return float(v.mean()), float(v.std())


def normalise(u: np.ndarray, w: np.ndarray, scene: Scene) -> dict:
    """Per-sphere normalised quantities of one step: u, w (n, 3)."""
    q = {}
    for i in range(len(u)):
        s = i + 1
        q["Ux%d" % s] = float(u[i, 0] / U_C)
        q["Ux_shifted%d" % s] = float(u[i, 0] / U_C - scene.discrete_offset)
        q["Uy%d" % s] = float(u[i, 1] / U_C)
        q["Wz%d" % s] = float(2 * A * w[i, 2] / U_C)
    return q


def run_single(workdir: str, scene: Scene, offsets: Sequence[Sequence[float]], subgrid: bool, options,
               tag: str) -> dict:
    """Each sphere alone in the same box and mesh at the same offsets: one coupled run of one sphere moved
    between the two heights. Returns per sphere the means, standard deviations and per-position values."""
    configurations = [scene.single(s, o) for s in SPHERES for o in offsets]
    res = run_configurations(_fresh(os.path.join(workdir, "single_" + tag)), scene, configurations, subgrid, options)
    out: dict = dict(wall_seconds=res["wall_seconds"], converged=all(res["converged"]),
                     inner_iterations=res["iterations"])
    n = len(offsets)
    for k, s in enumerate(SPHERES):
        per = [normalise(res["U"][j], res["W"][j], scene) for j in range(k * n, (k + 1) * n)]
        for name in ("Ux", "Ux_shifted", "Uy", "Wz"):
            vals = [p[name + "1"] for p in per]
            out["%s%d" % (name, s)], out["%s%d_std" % (name, s)] = _stats(vals)
            out["%s%d_positions" % (name, s)] = vals
        out["out_of_plane%d" % s] = float(max(np.abs(res["U"][k * n:(k + 1) * n, 0, 2]).max(),
                                              np.abs(res["W"][k * n:(k + 1) * n, 0, :2]).max()))
    return out


def run_scene(workdir: str, scene: Scene, rho_list: Sequence[float], offsets: Sequence[Sequence[float]],
              represented: int, subgrid: bool, options, single: dict | None = None) -> dict:
    """Every rho12/H (decreasing) at every offset in one coupled run (and the mirror images with
    options.mirror), and the single spheres unless given. Returns dict(rows, single, ...)."""
    tag = "ad%g_%gx%g_n%d%s" % (options.a_over_delta, options.box[0], options.box[1], len(offsets),
                                "" if subgrid else "_nosubgrid")
    rho_sorted = sorted(rho_list, reverse=True)
    labels = [(r, tuple(o), False) for r in rho_sorted for o in offsets]
    if options.mirror:
        labels += [(r, tuple(o), True) for r in rho_sorted for o in offsets]
    configurations = [scene.pair(r, o, mirror) for r, o, mirror in labels]
    t0 = time.time()
    res = run_configurations(_fresh(os.path.join(workdir, "pair_" + tag)), scene, configurations, subgrid, options)
    if single is None and not options.no_single:
        single = run_single(workdir, scene, offsets, subgrid, options, tag)
    rows = []
    for r in rho_sorted:
        picks = [k for k, (rk, _, m) in enumerate(labels) if rk == r and not m]
        per = []
        for k in picks:
            u, w = res["U"][k], res["W"][k]
            q = normalise(u, w, scene)
            x = configurations[k]
            n_vec = (x[1] - x[0]) / np.linalg.norm(x[1] - x[0])
            q["Un"] = float(np.dot(u[1] - u[0], n_vec) / U_C)
            if single is not None:
                # the isolated spheres' relative velocity along the same line of centres
                us = np.array([[single["Ux1"], single["Uy1"], 0.0], [single["Ux2"], single["Uy2"], 0.0]]) * U_C
                q["Un_single"] = float(np.dot(us[1] - us[0], n_vec) / U_C)
            q["out_of_plane"] = float(max(np.abs(u[:, 2]).max(), np.abs(w[:, :2]).max()) / U_C)
            q["F_subgrid1"] = [float(v) for v in res["F_subgrid"][k, 0]]
            q.update(offset=list(labels[k][1]), inner_iterations=res["iterations"][k], converged=res["converged"][k])
            per.append(q)
        row = dict(rho_over_H=r, xi=xi_of_rho(r, scene.d2_over_a), rho_over_a=r * scene.H / A,
                   gap_over_delta=xi_of_rho(r, scene.d2_over_a) * A / scene.delta, subgrid=subgrid)
        for name in QUANTITIES:
            row[name], row[name + "_std"] = _stats([p[name] for p in per])
        if single is not None:
            row["Un_single"] = float(np.mean([p["Un_single"] for p in per]))
            row["Un_ratio"] = row["Un"] / row["Un_single"]
            for s in SPHERES:
                for name in ("Ux", "Uy", "Wz"):
                    key = "%s%d" % (name, s)
                    row[key + "_minus_single"] = row[key] - single[key]
        row["subgrid_force_max"] = float(max(np.linalg.norm(p["F_subgrid1"]) for p in per))
        row["out_of_plane_max"] = max(p["out_of_plane"] for p in per)
        if options.mirror:
            mpicks = [k for k, (rk, _, m) in enumerate(labels) if rk == r and m]
            d = []
            for k, km in zip(picks, mpicks):
                d.append(max(np.abs(res["U"][k][:, 0] - res["U"][km][:, 0]).max(),
                             np.abs(res["U"][k][:, 1] + res["U"][km][:, 1]).max(),
                             2 * A * np.abs(res["W"][k][:, 2] - res["W"][km][:, 2]).max()) / U_C)
            row["mirror_max"] = float(max(d))
            row["mirror_Uy"] = [[float(res["U"][km][i, 1] / U_C) for i in range(2)] for km in mpicks]
        row.update(box=scene.size_over_a, a_over_delta=scene.a_over_delta, cells=scene.cells,
                   n_positions=represented, positions_computed=len(picks), discrete_offset=scene.discrete_offset,
                   inner_iterations=[p["inner_iterations"] for p in per],
                   converged=all(p["converged"] for p in per),
                   per_position={name: [p[name] for p in per] for name in QUANTITIES},
                   offsets=[p["offset"] for p in per])
        rows.append(row)
    rows.sort(key=lambda row: row["rho_over_H"])
    return dict(rows=rows, single=single, subgrid=subgrid, description=scene.describe(), cells=scene.cells,
                box=scene.size_over_a, a_over_delta=scene.a_over_delta, wall_seconds=time.time() - t0,
                pair_wall_seconds=res["wall_seconds"])


# ------------------------------------------------------------------------------------------------
# Analysis
# ------------------------------------------------------------------------------------------------

def sign_changes(rows: Sequence[dict], key: str) -> list[float]:
    """rho12/H where the mean of key changes sign between consecutive rows (linear interpolation)."""
    out = []
    for a, b in zip(rows, rows[1:]):
        if a[key] == 0 or a[key] * b[key] < 0:
            t = a[key] / (a[key] - b[key]) if a[key] != b[key] else 0.0
            out.append(a["rho_over_H"] + t * (b["rho_over_H"] - a["rho_over_H"]))
    return out


def summary(scenes: Sequence[dict]) -> dict:
    """The headline numbers: U_y sign changes of each sphere, the near-contact relative normal velocity
    with and without the correction, the far-field departure from the single spheres."""
    out: dict = {}
    for sc in scenes:
        mode = "subgrid" if sc["subgrid"] else "no_subgrid"
        rows = sc["rows"]
        entry = {"Uy%d_sign_change_rho_over_H" % s: sign_changes(rows, "Uy%d" % s) for s in SPHERES}
        near = rows[0]
        entry["nearest"] = dict(rho_over_H=near["rho_over_H"], xi=near["xi"], Un=near["Un"],
                                Un_ratio=near.get("Un_ratio"))
        far = rows[-1]
        if sc["single"] is not None:
            entry["farthest"] = dict(rho_over_H=far["rho_over_H"], xi=far["xi"],
                                     **{k: far[k] for k in far if k.endswith("_minus_single")})
        out[mode] = entry
    return out


def print_scene(sc: dict) -> None:
    print("%s, %s: %.0f s" % (sc["description"], "with the sub-grid correction" if sc["subgrid"] else
                              "without the correction (lubrication no)", sc["wall_seconds"]))
    print("  %-7s %-9s %-17s %-17s %-17s %-17s %-17s %-17s %-10s %-8s %s" % (
        "rho/H", "xi", "Ux1/Uc", "Ux2/Uc", "Uy1/Uc", "Uy2/Uc", "2aWz1/Uc", "2aWz2/Uc", "Un/Uc", "Un/Un_1", "iter"))
    for r in sc["rows"]:
        f = ["%+.4f+-%.4f" % (r[q], r[q + "_std"]) for q in ("Ux1", "Ux2", "Uy1", "Uy2", "Wz1", "Wz2")]
        print("  %-7.4f %-9.3g %s %+.3e %-8s %s" % (r["rho_over_H"], r["xi"], " ".join(f), r["Un"],
                                                  "%.4f" % r["Un_ratio"] if "Un_ratio" in r else "-",
                                                  " ".join(str(i) for i in r["inner_iterations"]))
              + ("  mirror %.1e" % r["mirror_max"] if "mirror_max" in r else ""))
    s = sc["single"]
    if s is not None:
        print("  single: sphere 1 Ux %.4f Uy %+.1e 2aWz %+.1e; sphere 2 Ux %.4f Uy %+.1e 2aWz %+.4f" % (
            s["Ux1"], s["Uy1"], s["Wz1"], s["Ux2"], s["Uy2"], s["Wz2"]))


def plot(scenes: Sequence[dict], path: str) -> None:
    """Figs. 17-18 of the paper: U_x/U_c, U_y/U_c and 2a Omega_z/U_c against rho12/H for both spheres, with
    (filled) and without (open) the sub-grid correction, error bars the standard deviation over the
    positions, the single spheres dashed; and |Un| against xi."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 4, figsize=(19, 4.6))
    for sc in scenes:
        rows = sc["rows"]
        rho = [r["rho_over_H"] for r in rows]
        for s, colour in zip(SPHERES, ("C0", "C3")):
            for ax, q in zip(axes[:3], ("Ux", "Uy", "Wz")):
                key = "%s%d" % (q, s)
                ax.errorbar(rho, [r[key] for r in rows], yerr=[r[key + "_std"] for r in rows],
                            fmt="o-" if sc["subgrid"] else "s--", color=colour, ms=4, lw=0.8, capsize=2,
                            mfc=colour if sc["subgrid"] else "none",
                            label="sphere %d, %s" % (s, "sub-grid" if sc["subgrid"] else "no correction"))
                if sc["single"] is not None and sc["subgrid"]:
                    ax.axhline(sc["single"][key], color=colour, ls=":", lw=0.8)
        axes[3].loglog([r["xi"] for r in rows], [abs(r["Un"]) for r in rows], "o-" if sc["subgrid"] else "s--",
                       color="k", mfc="k" if sc["subgrid"] else "none",
                       label="sub-grid" if sc["subgrid"] else "no correction")
    for ax, lab in zip(axes[:3], ("$U_x/U_c$", "$U_y/U_c$", r"$2a\Omega_z/U_c$")):
        ax.set_xlabel(r"$\rho_{12}/H$")
        ax.set_ylabel(lab)
        ax.grid(alpha=0.3)
    axes[1].axhline(0, color="k", lw=0.5)
    axes[0].legend(fontsize=7)
    axes[0].set_title("dotted: each sphere alone (same box, mesh)", fontsize=9)
    axes[3].set_xlabel(r"$\xi$")
    axes[3].set_ylabel(r"$|(\mathbf{U}_2-\mathbf{U}_1)\cdot\mathbf{n}|/U_c$")
    axes[3].grid(alpha=0.3, which="both")
    axes[3].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def convergence(options, offsets, represented: int) -> tuple[list[dict], list[dict]]:
    """a/Delta 3 -> 4 (first box) and box CONVERGENCE_BOXES[0] -> [1] (a/Delta 3) at options.rho, with the
    correction (options.subgrid). Returns (scenes, the changes from the base per rho and quantity)."""
    combos = convergence_study.variants(CONVERGENCE_A_OVER_DELTA, CONVERGENCE_BOXES)
    scenes = []
    for study, ad, box in combos:
        opts = argparse.Namespace(**vars(options))
        opts.a_over_delta, opts.box = ad, list(box)
        scene = Scene(ad, box, options.d2_over_a)
        check_scene(scene, options.rho)
        sc = run_scene(options.workdir, scene, options.rho, offsets, represented, options.subgrid, opts)
        sc["study"] = study
        print("[%s]" % study, end=" ")
        print_scene(sc)
        scenes.append(sc)
    changes = []
    base = scenes[0]
    for other in scenes[1:]:
        for rb, ro in zip(base["rows"], other["rows"]):
            e = convergence_study.change_entry(dict(change=other["study"], rho_over_H=rb["rho_over_H"]), base, other,
                                               rb, ro, ("Ux1", "Ux_shifted1", "Uy1", "Wz1", "Ux2", "Ux_shifted2", "Uy2",
                                                        "Wz2", "Un"))
            for s in SPHERES:
                if base["single"] and other["single"]:
                    e["single_Ux%d_change" % s] = other["single"]["Ux%d" % s] - base["single"]["Ux%d" % s]
                    e["single_Wz%d_change" % s] = other["single"]["Wz%d" % s] - base["single"]["Wz%d" % s]
            changes.append(e)
            print("  rho/H %.4g, %s: %s" % (e["rho_over_H"], e["change"], ", ".join(
                "%s %+.4f" % (q, e[q + "_change"]) for q in ("Ux_shifted1", "Ux_shifted2", "Uy1", "Uy2", "Wz1",
                                                              "Wz2"))))
    return scenes, changes


def validation_rows(r: dict) -> List[Row]:
    """cases/pairPoiseuille (5.4): no tabulated reference (Bhattacharya et al. 2006 are plots in the
    paper): the sign change of the centre-line sphere's U_y beside the paper's ~0.6, the near-contact
    relative normal velocity with and without the correction (lubrication: -> 0), and the far pair
    against the isolated spheres."""
    rows = []
    config = "H = 4a, d2/a %g, a/Δ %g, box %s a, %d positions" % (
        r["d2_over_a"], r["a_over_delta"], "×".join("%g" % v for v in r["box"]), r["n_positions"])
    for scene in r["scenes"]:
        mode = "subgrid" if scene["subgrid"] else "no_subgrid"
        summary = r["summary"][mode]
        with_block = scene["subgrid"]
        label = "with the correction" if with_block else "FDM alone"
        crossings = summary.get("Uy1_sign_change_rho_over_H") or []
        if with_block and crossings:
            rows.append(Row("ρ12/H where U_y1 changes sign", config, crossings[0], paper="≈ 0.6 (Fig. 18)"))
        near = summary["nearest"]
        rows.append(Row("(U2 − U1)·n / isolated pair's, ξ = %.0e (%s)" % (near["xi"], label), config,
                        near["Un_ratio"], paper="→ 0 with the correction (Figs. 17–18)", headline=with_block))
        if with_block:
            far = summary["farthest"]
            single = scene["single"]
            rows.append(Row("U_x2/U_c at ρ12/H %g against sphere 2 alone" % far["rho_over_H"], config,
                            single["Ux2"] + far["Ux2_minus_single"], single["Ux2"], "far field: the isolated sphere",
                            relative(single["Ux2"] + far["Ux2_minus_single"], single["Ux2"])))
    return rows


def main(argv: Sequence[str] | None = None) -> dict:
    """Parse the options (module docstring), run, print the tables, write --out and the figure."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--rho", type=float, nargs="+", default=None, metavar="RHO/H",
                   help="lateral distances rho12/H (default %s; --xi adds more)"
                        % " ".join("%g" % v for v in RHO_DEFAULT))
    p.add_argument("--xi", type=float, nargs="*", default=None, metavar="XI",
                   help="reduced gaps xi, converted to rho12/H and added to --rho (default %s when --rho is not "
                        "given; '--xi' alone: none)" % " ".join("%g" % v for v in XI_DEFAULT))
    p.add_argument("--d2-over-a", type=float, default=D2_OVER_A,
                   help="sphere 2's distance from the lower wall d/a (default %g, the paper's)" % D2_OVER_A)
    p.add_argument("--a-over-delta", type=float, default=3.0,
                   help="a/Delta (nominal: Delta is adjusted so that H = 4a is whole cells)")
    p.add_argument("--box", type=float, nargs=2, default=None, metavar=("LX", "LZ"),
                   help="periodic lengths L_x, L_z in units of a (default %g %g; the paper 60 40)" % BOX_DEFAULT)
    p.add_argument("--positions", type=int, default=POSITIONS_DEFAULT,
                   help="positions of the pair in a cell: m^2 (m even) lattices computed at half their points "
                        "(the z mirror), other counts Halton points (default %d; the paper 16)" % POSITIONS_DEFAULT)
    p.add_argument("--offset", type=float, nargs=2, action="append", default=None, metavar=("OX", "OZ"),
                   help="explicit offsets of sphere 1 from a mesh vertex in cells (repeatable), instead of --positions")
    p.add_argument("--full", action="store_true",
                   help="the paper's: a/Delta = 5, 60 a x 40 a, 16 positions, rho12/H = %s and xi = 1e-5 (millions "
                        "of cells: not on a small machine)" % " ".join("%g" % v for v in FULL_RHO))
    g = p.add_mutually_exclusive_group()
    g.add_argument("--no-subgrid", dest="modes", action="store_const", const=[False],
                   help="only without the correction (pair_style fdm/subgrid lubrication no)")
    g.add_argument("--subgrid-only", dest="modes", action="store_const", const=[True],
                   help="only with the correction")
    p.add_argument("--mirror", action="store_true",
                   help="also compute every configuration's mirror image x -> -x (sphere 2 upstream): symmetry (ii)")
    p.add_argument("--convergence", action="store_true",
                   help="a/Delta %g -> %g and box %s a at rho12/H = %s with the correction; --out defaults to "
                        "results_convergence.json" % (*CONVERGENCE_A_OVER_DELTA,
                                                      " -> ".join("%g x %g" % b for b in CONVERGENCE_BOXES),
                                                      " ".join("%g" % v for v in CONVERGENCE_RHO)))
    p.add_argument("--no-single", action="store_true", help="skip the single-sphere runs")
    p.add_argument("--wall-cutoff", type=float, default=None,
                   help="pair_style fdm/subgrid wall_cutoff (mesh cells; default the pair style's, 0.75)")
    p.add_argument("--no-plot", action="store_true", help="do not draw results_pairPoiseuille.png")
    p.add_argument("--n-max", type=int, default=2000, help="fdmFoam's innerIterations nMax (4x on the first step)")
    case.add_run_options(p, HERE, tol_lambda=1e-4, cutoff=True)
    args = p.parse_args(argv)

    if args.full:
        args.a_over_delta, args.positions = PAPER_A_OVER_DELTA, PAPER_POSITIONS
        args.box = args.box or list(PAPER_BOX)
        args.rho = args.rho or list(FULL_RHO)
    if args.convergence:
        args.rho = args.rho or list(CONVERGENCE_RHO)
        if args.xi is None:
            args.xi = []
        args.modes = args.modes or [True]
        if args.out == os.path.join(HERE, "results.json"):
            args.out = os.path.join(HERE, "results_convergence.json")
    xi_list = list(XI_DEFAULT) if args.xi is None and args.rho is None else list(args.xi or [])
    rho = list(args.rho) if args.rho is not None else (list(RHO_DEFAULT) if args.xi is None else [])
    args.box = list(args.box or BOX_DEFAULT)
    args.modes = args.modes or [True, False]
    try:
        for x in xi_list:
            if not x > 0:
                raise ValueError("pairPoiseuille: --xi %g: the gap must be positive" % x)
            rho.append(rho_of_xi(x, args.d2_over_a))
        if not rho:
            raise ValueError("pairPoiseuille: no rho12/H to compute (--rho and --xi both empty)")
        if not args.a_over_delta > 0:
            raise ValueError("pairPoiseuille: --a-over-delta %g must be positive" % args.a_over_delta)
        for v, name in zip(args.box, ("L_x", "L_z")):
            if not v > 0:
                raise ValueError("pairPoiseuille: --box %s = %g must be positive" % (name, v))
        args.rho = sorted(set(round(r, 12) for r in rho))
        scene = Scene(args.a_over_delta, args.box, args.d2_over_a)
        check_scene(scene, args.rho)
        if args.offset:
            for o in args.offset:
                if not all(0.0 <= v < 1.0 for v in o):
                    raise ValueError("pairPoiseuille: --offset %g %g: each offset must be in [0, 1) cells" % tuple(o))
            offsets, represented = [tuple(o) for o in args.offset], len(args.offset)
        else:
            offsets, represented = cell_offsets(args.positions)
    except ValueError as e:
        p.error(str(e))
    if args.n_max < 1:
        p.error("--n-max %d: must be at least 1" % args.n_max)
    if args.tol_lambda <= 0:
        p.error("--tol-lambda %g: must be positive" % args.tol_lambda)

    os.makedirs(args.workdir, exist_ok=True)
    t0 = time.time()
    common = dict(case="pairPoiseuille", paper_section="5.4",
                  units="U_c = 1 (Eq. 47), eta = 1, a = 1; UxN = U_x/U_c, Ux_shiftedN = UxN - (Delta/H)^2, "
                        "UyN = U_y/U_c, WzN = 2 a Omega_z/U_c, Un = (U_2 - U_1).n/U_c (n from 1 to 2)",
                  H_over_a=H_OVER_A, d1_over_a=H_OVER_A / 2, d2_over_a=args.d2_over_a,
                  orientation="sphere 2 downstream: x2 = x1 + rho12", n_positions=represented,
                  offsets=[list(o) for o in offsets], tol_lambda=args.tol_lambda, model=args.model,
                  cutoff_cells=args.cutoff or "default")
    if args.convergence:
        args.subgrid = args.modes[0]
        scenes, changes = convergence(args, offsets, represented)
        out = dict(common, study="convergence", scenes=scenes, changes=changes)
    else:
        scenes = []
        for subgrid in args.modes:
            # each mode has its own single spheres (the same unless a wall block acts on sphere 2)
            sc = run_scene(args.workdir, scene, args.rho, offsets, represented, subgrid, args)
            print_scene(sc)
            scenes.append(sc)
        out = dict(common, scenes=scenes, summary=summary(scenes), box=scene.size_over_a,
                   a_over_delta=scene.a_over_delta, cells=scene.cells)
        for mode, e in out["summary"].items():
            print("%s: U_y1 changes sign at rho12/H = %s, U_y2 at %s; nearest (xi %.2g): Un/Uc %+.3e (%s of the "
                  "isolated spheres')" % (mode, ", ".join("%.3f" % v for v in e["Uy1_sign_change_rho_over_H"]) or "-",
                                          ", ".join("%.3f" % v for v in e["Uy2_sign_change_rho_over_H"]) or "-",
                                          e["nearest"]["xi"], e["nearest"]["Un"],
                                          "-" if e["nearest"]["Un_ratio"] is None else
                                          "%.4f" % e["nearest"]["Un_ratio"]))
    write_results(args.out, __file__, argv, args, None if args.convergence else validation_rows, out, t0)
    if not args.no_plot and not args.convergence:
        png = os.path.join(os.path.dirname(os.path.abspath(args.out)), "results_pairPoiseuille.png")
        plot(scenes, png)
        print("wrote", png)
    print("wrote %s (%.0f s)" % (args.out, out["wall_seconds"]))
    return out


if __name__ == "__main__":
    main()
