#!/usr/bin/env python3
"""A free sphere in plane Poiseuille flow (paper section 5.2.3, Eqs. 47-48, Figs. 11-13; issue 15 item 3).

Walls at rest at y = 0 and y = H, x and z periodic (L_x, L_z), the uniform pressure gradient
dP0/dx = -8 eta U_c / H^2 (Eq. 48) in the whole domain, so that the undisturbed flow is
u0 = U_c (1 - (2y'/H)^2) e_x (Eq. 47, y' = y - H/2 measured from the centre plane). One sphere of radius a,
its centre at the distance d from the lower wall, free in force and torque but held in place
(fix fdm/couple ... move no): each configuration is one coupled time step whose velocities are those
of the fixed configuration (quasi-static). The fluid starts from the undisturbed profile (the far field
is converged from the start; fdmFoam's mean-flow correction keeps the plane averages exact), each
configuration warm-started from the previous one. The walls are declared to pair_style fdm/subgrid:
its wall blocks (Eq. D.6) act below a gap of wall_cutoff mesh cells (0.75 by default), i.e. at d/a = 1.1
for a/Delta = 3; --no-subgrid switches the lubrication off (the FDM alone).
Units: eta = 1 Pa s, U_c = 1 m/s, lengths in units of a1 = 1 m (the sphere's radius a = --radius).

Measured per configuration (2a/H, d/a, a), mean and standard deviation over the positions of the centre
in the plane section (x, z) of one mesh cell at fixed d (the paper's 16):
  Ux_norm = U_x / U_c
  Wz_norm = Omega_z a / U_c      (also Wz_H = Omega_z H / U_c = Wz_norm * 2 / (2a/H))
  S_star  = S_xy / (4 U_c eta a^3 / H)   (S_xy of the hydrodynamic stresslet S^H, Eq. 12; Fig. 13)
  Uy_norm = U_y / U_c            (0 for a free sphere in Stokes flow, by reversibility: below)
against Faxen's laws for the quadratic flow (unbounded fluid, faxen()), the same with the leading wall
reflections (wall_estimate()) and, on the centre plane at 2a/H = 0.6, Staben, Zinchenko & Davis (2003)
Table 1: U/U_c = 0.871 (staben_2003.csv here). Ux_norm_shifted = Ux_norm - (Delta/H)^2 takes off the
solver's own undisturbed-flow offset (Scene.discrete_profile): the velocity in the flow of Eq. (47).

  poiseuilleSphere.py                 2a/H = 0.1 0.2 0.4 0.6; d/a = 1.1 1.5 3, quarter (d = H/4) and centre
                                      (d = H/2), those of each channel between the wall and its centre plane;
                                      a = 1, a/Delta = 3, box L_x x L_z = 12 a x 12 a, 2 positions of the
                                      centre in a cell (17 configurations, 2.5-4 minutes here)
  poiseuilleSphere.py --two-a-over-H 0.6 --d-over-a centre 1.3 --positions 16
  poiseuilleSphere.py --offset 0 0 --offset 0.35 0      explicit offsets (cells) instead of --positions
  poiseuilleSphere.py --convergence   the mesh (a1/Delta 3, 4) and the box (12 x 12 a, 24 x 24 a) at
                                      2a/H = 0.6 (centre, d/a = 1.3) and 0.4 (centre, H/4, d/a = 1.1);
                                      writes results_convergence.json (about 3 minutes)
  poiseuilleSphere.py --reference     no solver: Faxen's values of every configuration
  poiseuilleSphere.py --full          the paper's: a = 1 and 1.4, a1/Delta = 5, 60 a x 40 a, 16 positions,
                                      2a/H = 0.1 ... 0.7 (millions of cells: out of reach of this machine)
  poiseuilleSphere.py --help          every option
Writes results.json and results_poiseuilleSphere.png here (docs/cases.md, docs/validation.md).

Faxen's laws (Kim & Karrila 1991, ch. 3; Happel & Brenner) for u0 of Eq. (47), at the centre x_c:
  U      = u0(x_c) + (a^2/6) lap u0,   lap u0 = -8 U_c/H^2 e_x   ->  U/U_c = 1 - (2y'/H)^2 - (1/3)(2a/H)^2
  Omega  = (1/2) curl u0(x_c) = -(1/2) du0/dy' e_z = 4 U_c y'/H^2 e_z  ->  Omega_z a/U_c = 2 (y'/H)(2a/H)
  S      = (20/3) pi eta a^3 (E + (a^2/10) lap E)(x_c), lap E = 0 (E is linear in a quadratic flow),
           E_xy = (1/2) du0/dy' = -4 U_c y'/H^2  ->  S* = -(20 pi/3) y'/H
with y'/H = (d/a)(2a/H)/2 - 1/2. On the centre plane: U/U_c = 1 - (2a/H)^2/3 = 1 - 4a^2/(3H^2) (the
(a^2/6) lap u0 lag), Omega = 0, S = 0. The quadratic u0 = U_c(1 - 4y'^2/H^2) about the centre is
u0(x_c) + linear + quadratic part -4U_c (y-y_c)^2/H^2 e_x; its isotropic share -(4U_c/3H^2) r^2 e_x is
uniform on the sphere's surface (it is exactly the Faxen lag), the rest is a traceless (l = 2) harmonic
whose disturbance decays as r^-3 (no Stokeslet: force-free; no stresslet on the centre plane). The walls
reflect it at r ~ H/2: on the centre plane the wall correction to U/U_c is O((a/H)^5) (as for a sphere on
the axis of a tube, Haberman & Sayre 1958: U/U_c = (1 - (2/3)lambda^2 - 0.20217 lambda^5)/(1 - 0.75857
lambda^5)); off the centre plane the stresslet (r^-2) reflects, O((a/H)^3) at fixed y'/H (the shear-flow
analogue is Goldman, Cox & Brenner's 1 - (5/16)(a/h)^3). Near a wall at fixed d/a the correction does not
vanish as 2a/H -> 0: Faxen is then no reference.

Symmetries used and checked: (i) Stokes flow is reversible and the scene is mirror-symmetric in x, so a
free sphere has U_y = 0 at any d (u0 -> -u0 reverses U, the mirror x -> -x restores u0 and gives
(U_x, -U_y, Omega_z)); (ii) on the centre plane y' -> -y' gives Omega_z = 0 and S_xy = 0 (the mesh is
symmetric about y = H/2 too, so these hold to the solver's tolerance); (iii) U_x, Omega_z and S_xy are
even under the mirrors x -> -x (with the reversal) and z -> -z of the scene, and so is the mesh about a
vertex: the offsets in [0, 1/2) x [0, 1/2) cells hold every position of the cell once (U_y is odd in the
x offset: its mean over the cell is 0, its size at each offset is the discretisation's).

The mesh: H must be a whole number of cubic cells. For each (a, 2a/H), H = 2a/(2a/H) and
Delta = H / round(H a1_over_delta / a1): Delta is the nearest to a1/--a-over-delta that fits (the rows
report the actual a/Delta); L_x, L_z are rounded to whole cells.
"""
from __future__ import annotations

import argparse
import csv
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
U_C = 1.0                         # m/s, centre-line velocity of the undisturbed flow (Eq. 47)
A1 = 1.0                          # m, the length unit (the paper's a1)
TWO_A_OVER_H_DEFAULT = [0.1, 0.2, 0.4, 0.6]
D_OVER_A_DEFAULT = ["1.1", "1.5", "3", "quarter", "centre"]
RADII_DEFAULT = [1.0]
BOX_DEFAULT = (12.0, 12.0)        # L_x/a, L_z/a
PAPER_BOX = (60.0, 40.0)          # paper 5.2.3
PAPER_RADII = [1.0, 1.4]          # a1, a2 (paper 4: all lengths in a1, Delta = a1/5)
PAPER_A_OVER_DELTA = 5.0
PAPER_POSITIONS = 16
FULL_TWO_A_OVER_H = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7]
FULL_D_OVER_A = ["1.1", "1.25", "1.5", "2", "3", "5", "quarter", "centre"]
CONVERGENCE_A_OVER_DELTA = (3.0, 4.0)
CONVERGENCE_BOXES = ((12.0, 12.0), (24.0, 24.0))
CONVERGENCE_CONFIGS = ((0.6, ("centre", "1.3")), (0.4, ("centre", "quarter", "1.1")))
CENTRE_WORDS = ("centre", "center", "c")
QUARTER_WORDS = ("quarter", "q")     # d = H/4: half-way between the lower wall and the centre plane, y'/H = -1/4
MIN_CELLS_ACROSS_GAP = 2          # the channel must hold the sphere's diameter plus this many cells
QUANTITIES = ("Ux_norm", "Wz_norm", "S_star", "Uy_norm")
STABEN_FILE = os.path.join(HERE, "staben_2003.csv")


# ------------------------------------------------------------------------------------------------
# References (no solver)
# ------------------------------------------------------------------------------------------------

def y_prime_over_H(two_a_over_H: float, d_over_a: float) -> float:
    """y'/H of the centre, measured from the centre plane (negative below it): (d/a)(2a/H)/2 - 1/2."""
    return 0.5 * d_over_a * two_a_over_H - 0.5


def undisturbed(two_a_over_H: float, d_over_a: float) -> float:
    """u0(x_c)/U_c of Eq. (47) at the sphere's centre."""
    return 1.0 - (2.0 * y_prime_over_H(two_a_over_H, d_over_a)) ** 2


def faxen(two_a_over_H: float, d_over_a: float) -> dict:
    """Faxen's laws for the quadratic flow of Eq. (47) (unbounded fluid; module docstring):
    Ux_norm = U/U_c, Wz_norm = Omega_z a/U_c, Wz_H = Omega_z H/U_c, S_star = S_xy/(4 U_c eta a^3/H),
    and the undisturbed velocity at the centre u0_norm = u0(x_c)/U_c."""
    yp = y_prime_over_H(two_a_over_H, d_over_a)
    u0 = undisturbed(two_a_over_H, d_over_a)
    return dict(u0_norm=u0, Ux_norm=u0 - two_a_over_H ** 2 / 3.0, Wz_norm=2.0 * yp * two_a_over_H, Wz_H=4.0 * yp,
                S_star=-20.0 * math.pi / 3.0 * yp, Uy_norm=0.0)


# The least distance from the centre to either wall, in radii, at which wall_estimate() is taken as a
# reference (the report's "Faxen + walls" rows; nearer, it is listed without one). Its one-wall forms
# against the exact free sphere in simple shear next to one wall (cases/wallShear/freeSphereWall.py):
# at h = 2 a within 0.4 % (U, Omega) and 1.6 % (S*), at h = 1.5 a 4.3 % (S*), at 1.25 a 5.3 %; the
# quadratic part of the flow and the second wall reflect beyond that (tests/test_poiseuille_sphere.py).
WALL_ESTIMATE_MIN_H = 2.0


def wall_estimate_applies(two_a_over_H: float, d_over_a: float) -> bool:
    """Whether wall_estimate() is a reference here: the centre at least WALL_ESTIMATE_MIN_H radii from both
    walls (d/a and H/a - d/a)."""
    return min(d_over_a, 2.0 / two_a_over_H - d_over_a) >= WALL_ESTIMATE_MIN_H - 1e-9


def wall_estimate(two_a_over_H: float, d_over_a: float) -> dict:
    """Faxen's values with the leading far-field reflection of the stresslet from each wall added, the two
    walls superposed (a sphere far from both, d >> a and H - d >> a): the far-field forms of a free sphere
    in a shear flow gamma near one wall at the distance h, U = gamma h (1 - (5/16)(a/h)^3) and
    Omega = -(gamma/2)(1 - (5/16)(a/h)^3) (Goldman, Cox & Brenner 1967), S = S_inf (1 + (15/16)(a/h)^3)
    (Sangani et al. 2011, paper Eq. 46 expanded), with gamma the local shear du0/dy at the centre. The
    velocity correction, -(5/16) a^3 gamma / h^2 from the lower wall, changes sign for the upper one (the
    mirror y -> -y turns the stresslet); the relative corrections of Omega and S add. On the centre plane
    gamma = 0: no correction at this order (the next one is O((a/H)^5), module docstring). Off it, at fixed
    y'/H, the corrections are O((a/H)^3). Error: O((a/h)^5) and the walls' mutual reflections."""
    f = dict(faxen(two_a_over_H, d_over_a))
    a_over_H = 0.5 * two_a_over_H
    lo, hi = 1.0 / d_over_a, a_over_H / (1.0 - a_over_H * d_over_a)         # a/d and a/(H - d)
    gamma_a_over_uc = -8.0 * y_prime_over_H(two_a_over_H, d_over_a) * a_over_H  # (du0/dy) a / U_c
    f["Ux_norm"] += -5.0 / 16.0 * gamma_a_over_uc * (lo ** 2 - hi ** 2)
    f["Wz_norm"] *= 1.0 - 5.0 / 16.0 * (lo ** 3 + hi ** 3)
    f["S_star"] *= 1.0 + 15.0 / 16.0 * (lo ** 3 + hi ** 3)
    f["Wz_H"] = f["Wz_norm"] / a_over_H
    return f


def read_staben(path: str = STABEN_FILE) -> list[dict]:
    """The Staben et al. (2003) values kept in the case folder (staben_2003.csv: 2a/H, d/a, U/U_c)."""
    with open(path) as f:
        rows = [line for line in f if not line.startswith("#")]
    return [dict(two_a_over_H=float(r["two_a_over_H"]), d_over_a=float(r["d_over_a"]),
                 U_over_Uc=float(r["U_over_Uc"])) for r in csv.DictReader(rows)]


def staben_at(two_a_over_H: float, d_over_a: float, table: list[dict]) -> float | None:
    """Staben's U/U_c at this configuration, or None where the table has none."""
    for r in table:
        if abs(r["two_a_over_H"] - two_a_over_H) < 1e-9 and abs(r["d_over_a"] - d_over_a) < 1e-6:
            return r["U_over_Uc"]
    return None


# ------------------------------------------------------------------------------------------------
# The scene
# ------------------------------------------------------------------------------------------------

def parse_d_over_a(words: Sequence[str]) -> list[str]:
    """--d-over-a values as strings: numbers greater than 1, 'centre' (the centre plane, d = H/2) or
    'quarter' (d = H/4, y'/H = -1/4: the same relative place in every channel, for Faxen's limit).
    Raises ValueError naming a bad value."""
    out = []
    for w in words:
        if w.lower() in CENTRE_WORDS:
            out.append("centre")
            continue
        if w.lower() in QUARTER_WORDS:
            out.append("quarter")
            continue
        try:
            v = float(w)
        except ValueError:
            raise ValueError("poiseuilleSphere: --d-over-a %r is neither a number nor 'centre' or 'quarter'"
                             % w) from None
        if not v > 1.0 or not math.isfinite(v):
            raise ValueError("poiseuilleSphere: --d-over-a %s: the sphere touches or crosses the wall (d/a must "
                             "exceed 1)" % w)
        out.append(repr(v))
    return out


def d_values(two_a_over_H: float, words: Sequence[str]) -> tuple[list[float], list[float]]:
    """The d/a of this channel from --d-over-a: 'centre' -> 1/(2a/H), 'quarter' -> 1/(2 (2a/H));
    numbers up to the centre plane (above it a configuration is the mirror image of one below; a
    'quarter' at d/a <= 1 does not fit). Returns (kept, skipped), kept in decreasing order (the centre
    first: each step warm-starts the next)."""
    centre = 1.0 / two_a_over_H
    kept, skipped = set(), []
    for w in words:
        v = centre if w == "centre" else 0.5 * centre if w == "quarter" else float(w)
        if v > centre * (1 + 1e-12) or not v > 1.0:
            skipped.append(v)
        else:
            kept.add(round(v, 12))
    return sorted(kept, reverse=True), skipped


class Scene(channelscenes.PoiseuilleChannel):
    """The channel of one (radius a, 2a/H) on its mesh (channelscenes.PoiseuilleChannel): H = 2a/(2a/H), Delta
    the nearest to a1/a1_over_delta giving H a whole number of cells, L_x and L_z (size, in units of a)
    rounded to whole cells; the sphere's centre at the mesh vertex nearest to (L_x/2, L_z/2) plus the offset."""

    def __init__(self, radius: float, two_a_over_H: float, a1_over_delta: float, size: Sequence[float]) -> None:
        self.two_a_over_H = float(two_a_over_H)
        super().__init__(radius, 2.0 * float(radius) / self.two_a_over_H, a1_over_delta, size, eta=ETA,
                         centre_velocity=U_C, a1=A1)

    def centre(self, d_over_a: float, offset: Sequence[float]) -> tuple[float, float, float]:
        """The sphere's centre at d = d_over_a a from the lower wall, offset (o_x, o_z) cells from a vertex."""
        return ((self.nx // 2 + offset[0]) * self.delta, d_over_a * self.radius,
                (self.nz // 2 + offset[1]) * self.delta)

    def describe(self) -> str:
        return ("a = %g, 2a/H = %g: H = %g a1 (%d cells), a/Delta = %.4g, box %g x %g x %g a (%d cells)"
                % (self.radius, self.two_a_over_H, self.H, self.ny, self.a_over_delta, *self.size_over_a, self.cells))


INDICATOR_C = 0.3                 # the stencil's reach a + c Delta (case.write_fluid_case's indicator (b, c))


def stencil_ties(scene: Scene, centre: Sequence[float], c: float = INDICATOR_C) -> int:
    """The number of cell centres at exactly the stencil's reach a + c Delta from the sphere's centre (to
    1e-9 Delta). fdmFoam's particleForcing used to keep a cell when its distance was not above the reach
    (I_lambda = 1, I_u = (1 - tanh(b c))/2 = 0.047): a cell exactly on the reach was kept or dropped by the
    last bit of the floating-point distance, two mirror-image cells could fall on different sides and the
    mirror symmetries of the scene broke by O(1e-4) (measured: 2a/H = 0.2, d/a = 2.5 at o_x = 0.3, 0:
    Omega_x = 6e-4 U_c/a, U_x differing by 5e-4 U_c from the mirror offset 0.7). It now leaves out every
    cell within 1e-9 Delta of the reach; a row still reports how many of its positions have such cells."""
    reach = (scene.radius + c * scene.delta) / scene.delta
    x = np.asarray(centre, dtype=float) / scene.delta
    ranges = [np.arange(np.floor(v - reach) - 1, np.floor(v + reach) + 2) + 0.5 for v in x]
    gx, gy, gz = np.meshgrid(*ranges, indexing="ij")
    r = np.sqrt((gx - x[0]) ** 2 + (gy - x[1]) ** 2 + (gz - x[2]) ** 2)
    return int(np.count_nonzero(np.abs(r - reach) < 1e-9))


def check_scene(scene: Scene, d_list: Sequence[float]) -> None:
    """Refuse, with a message naming the value, a channel too narrow for the mesh or a box too small."""
    if scene.H < 2 * scene.radius + MIN_CELLS_ACROSS_GAP * scene.delta - 1e-12:
        raise ValueError("poiseuilleSphere: 2a/H = %g at a/Delta = %.3g leaves less than %d cells beside the sphere "
                         "(H = %d cells)" % (scene.two_a_over_H, scene.a_over_delta, MIN_CELLS_ACROSS_GAP, scene.ny))
    for name, L in (("L_x", scene.Lx), ("L_z", scene.Lz)):
        if L < 2 * scene.radius + 2 * scene.delta:
            raise ValueError("poiseuilleSphere: %s = %g a1 leaves no room for the sphere of radius %g (2 a plus two "
                             "cells): raise --size" % (name, L, scene.radius))
    for d in d_list:
        if not d > 1.0:
            raise ValueError("poiseuilleSphere: d/a = %g: the sphere touches the wall" % d)


def cell_offsets(n_positions: int) -> tuple[list[tuple[float, float]], int]:
    """Offsets (o_x, o_z) of the centre from a mesh vertex, in cells, standing for n_positions positions
    in the plane section of one cell at fixed d (module docstring, symmetry iii: [0, 1/2)^2 holds every
    position once; case.symmetric_cell_offsets). Returns (offsets to compute, positions they stand for)."""
    return case.symmetric_cell_offsets(n_positions, "poiseuilleSphere", mirror_x=True, x_fastest=True)


# ------------------------------------------------------------------------------------------------
# Running
# ------------------------------------------------------------------------------------------------

def run_channel(workdir: str, scene: Scene, d_list: Sequence[float], offsets: Sequence[Sequence[float]],
                represented: int, options, staben: list[dict]) -> dict:
    """Every d/a at every offset in one channel: one coupled run, one time step per configuration (d
    decreasing, the offsets in turn), each warm-started from the previous one. Returns dict(rows=[per
    d], scene description, wall_seconds)."""
    tag = "a%g_2aH%g_ad%g_%gx%g_n%d%s" % (scene.radius, scene.two_a_over_H, options.a_over_delta, options.size[0],
                                         options.size[1], len(offsets), "" if options.subgrid else "_nosubgrid")
    run_dir = os.path.join(workdir, tag)
    if os.path.isdir(run_dir):
        shutil.rmtree(run_dir)
    configurations = [(d, tuple(o)) for d in d_list for o in offsets]
    # the far field starts converged: the solver's own undisturbed profile (Scene.discrete_profile)
    channelscenes.write_poiseuille_channel(
        run_dir, scene, [[scene.centre(d, o)] for d, o in configurations], [scene.radius], "in.poiseuilleSphere",
        case.subgrid_pair_style(scene.walls, options.subgrid, options.model, options.cutoff, options.wall_cutoff),
        options.tol_lambda, options.n_max, options.acceleration, fix_options="move no stresslets yes")
    wall = case.run(run_dir, np_fluid=options.np_fluid)
    n = len(configurations)
    rec, steps = case.read_held_steps(run_dir, n, "poiseuilleSphere")
    u = np.asarray(rec["U"][-n:, 0], dtype=float)
    w = np.asarray(rec["omega"][-n:, 0], dtype=float)
    s_xy = np.asarray(rec["S_fluid"][-n:, 0, 1] + rec["S_subgrid"][-n:, 0, 1], dtype=float)
    s_sub = np.asarray(rec["S_subgrid"][-n:, 0, 1], dtype=float)
    f_sub = np.asarray(rec["F_subgrid"][-n:, 0], dtype=float)
    x = np.asarray(rec["x"][-n:, 0], dtype=float)
    iterations = [int(v) for v in steps["innerIterations"][-n:]]
    converged = [bool(v) for v in steps["converged"][-n:]]
    seconds = steps["fluidSeconds"][-n:] + steps["particleSeconds"][-n:] + steps["exchangeSeconds"][-n:]
    if not options.keep:
        case.delete_fields(run_dir)

    a, H = scene.radius, scene.H
    rows = []
    for d in d_list:
        picks = [k for k, (dk, _) in enumerate(configurations) if dk == d]
        if np.abs(x[picks, 1] - d * a).max() > 1e-9 * H:
            raise RuntimeError("poiseuilleSphere: the recorded centres are not at d/a = %g" % d)
        per = dict(Ux_norm=u[picks, 0] / U_C, Uy_norm=u[picks, 1] / U_C, Wz_norm=w[picks, 2] * a / U_C,
                   S_star=s_xy[picks] / (4 * U_C * ETA * a ** 3 / H))
        ref = faxen(scene.two_a_over_H, d)
        row = dict(radius=a, two_a_over_H=scene.two_a_over_H, d_over_a=d,
                   centre_plane=bool(abs(d - 1.0 / scene.two_a_over_H) < 1e-9),
                   y_prime_over_H=y_prime_over_H(scene.two_a_over_H, d), gap_over_delta=(d - 1.0) * a / scene.delta)
        for q in QUANTITIES:
            row[q] = float(np.mean(per[q]))
            row[q + "_std"] = float(np.std(per[q]))
        row["Wz_H"] = row["Wz_norm"] * H / a
        row["Uy_abs_max"] = float(np.abs(per["Uy_norm"]).max())
        row["out_of_plane_max"] = float(max(np.abs(u[picks, 2]).max(), np.abs(w[picks, :2]).max()) / U_C)
        row["S_star_subgrid"] = float(np.mean(s_sub[picks]) / (4 * U_C * ETA * a ** 3 / H))
        row["subgrid_force_max"] = float(np.abs(f_sub[picks]).max())
        row["u0_norm"] = ref["u0_norm"]
        row["u0_discrete_norm"] = float(scene.discrete_profile(np.array([d * a]))[0] / U_C)
        # the solver's undisturbed flow is Eq. (47) plus U_c (Delta/H)^2 everywhere (Scene.discrete_profile):
        # U_x less that offset is the velocity in the flow of Eq. (47)
        row["discrete_offset"] = (scene.delta / H) ** 2
        row["Ux_norm_shifted"] = row["Ux_norm"] - row["discrete_offset"]
        row["lag_norm"] = row["Ux_norm"] - ref["u0_norm"]
        row["faxen"] = ref
        row["faxen_wall"] = wall_estimate(scene.two_a_over_H, d)
        row["faxen_wall_applies"] = wall_estimate_applies(scene.two_a_over_H, d)
        for q in ("Ux_norm", "Wz_norm", "S_star"):
            row[q + "_minus_faxen"] = row[q] - ref[q]
            row[q + "_minus_faxen_wall"] = row[q] - row["faxen_wall"][q]
        row["Ux_rel_error_faxen"] = (row["Ux_norm"] - ref["Ux_norm"]) / ref["Ux_norm"]
        st = staben_at(scene.two_a_over_H, d, staben)
        row["staben_Ux_norm"] = st
        row["Ux_rel_error_staben"] = None if st is None else (row["Ux_norm"] - st) / st
        row["Ux_shifted_rel_error_staben"] = None if st is None else (row["Ux_norm_shifted"] - st) / st
        row["Ux_shifted_rel_error_faxen"] = (row["Ux_norm_shifted"] - ref["Ux_norm"]) / ref["Ux_norm"]
        row["stencil_ties"] = [stencil_ties(scene, scene.centre(d, configurations[k][1])) for k in picks]
        row.update(box=scene.size_over_a, box_a1=[scene.Lx, scene.H, scene.Lz], a_over_delta=scene.a_over_delta,
                   a1_over_delta_requested=options.a_over_delta, cells=scene.cells, n_positions=represented,
                   positions_computed=len(picks), offsets=[list(configurations[k][1]) for k in picks],
                   subgrid=options.subgrid, inner_iterations=[iterations[k] for k in picks],
                   converged=all(converged[k] for k in picks), wall_seconds=float(np.sum(seconds[picks])),
                   per_position={q: [float(v) for v in per[q]] for q in QUANTITIES})
        rows.append(row)
    return dict(rows=rows, run_dir=run_dir, wall_seconds=wall, cells=scene.cells, description=scene.describe())


def print_rows(rows: Sequence[dict]) -> None:
    """The measured table beside Faxen's values (and Staben's where there is one)."""
    print("  %-4s %-6s %-7s %-6s %-22s %-9s %-22s %-9s %-22s %-9s %-9s %s" % (
        "a", "2a/H", "d/a", "a/D", "Ux/Uc +- std", "Faxen", "Omega_z a/Uc +- std", "Faxen", "S* +- std", "Faxen",
        "|Uy|max", "iterations, s"))
    for r in rows:
        print("  %-4g %-6g %-7.4g %-6.3g %.5f +- %.5f   %-9.5f %+.5f +- %.5f  %+-9.5f %+.4f +- %.4f   %+-9.4f "
              "%-9.1e %s, %.0f s%s" % (
                  r["radius"], r["two_a_over_H"], r["d_over_a"], r["a_over_delta"], r["Ux_norm"], r["Ux_norm_std"],
                  r["faxen"]["Ux_norm"], r["Wz_norm"], r["Wz_norm_std"], r["faxen"]["Wz_norm"], r["S_star"],
                  r["S_star_std"], r["faxen"]["S_star"], r["Uy_abs_max"],
                  " ".join(str(i) for i in r["inner_iterations"]), r["wall_seconds"],
                  "" if r["staben_Ux_norm"] is None else "   Staben %.3f: %+.2f %% (less the discrete offset "
                  "%.4f: %+.2f %%)" % (r["staben_Ux_norm"], 100 * r["Ux_rel_error_staben"], r["discrete_offset"],
                                      100 * r["Ux_shifted_rel_error_staben"])))


def print_reference(radii: Sequence[float], two_a_over_H: Sequence[float], d_words: Sequence[str],
                    staben: list[dict]) -> list[dict]:
    """Faxen's values of every configuration (no solver); returns them."""
    out = []
    print("Faxen's laws for u0 = U_c (1 - (2y'/H)^2) e_x (unbounded fluid; radius-independent in these units):")
    print("  %-6s %-8s %-8s %-9s %-9s %-10s %-9s %s" % ("2a/H", "d/a", "y'/H", "u0/Uc", "Ux/Uc", "Om_z a/Uc",
                                                       "S*", "Staben U/Uc"))
    for t in two_a_over_H:
        kept, _ = d_values(t, d_words)
        for d in kept:
            f = faxen(t, d)
            st = staben_at(t, d, staben)
            out.append(dict(two_a_over_H=t, d_over_a=d, faxen=f, staben_Ux_norm=st, radii=list(radii)))
            print("  %-6g %-8.4g %-+8.4f %-9.5f %-9.5f %-+10.5f %-+9.4f %s" % (
                t, d, y_prime_over_H(t, d), f["u0_norm"], f["Ux_norm"], f["Wz_norm"], f["S_star"],
                "" if st is None else "%.3f" % st))
    return out


def plot(rows: Sequence[dict], path: str, staben: list[dict]) -> None:
    """Fig. 12 (and 13) of the paper: U_x/U_c, Omega_z a/U_c and S* against d/a for each 2a/H (symbols,
    error bars the standard deviation over the positions), Faxen's laws (lines), Staben's point."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6))
    keys = sorted({(r["two_a_over_H"], r["radius"]) for r in rows})
    for k, (t, a) in enumerate(keys):
        colour = "C%d" % (k % 10)
        sel = sorted((r for r in rows if r["two_a_over_H"] == t and r["radius"] == a), key=lambda r: r["d_over_a"])
        d = [r["d_over_a"] for r in sel]
        dd = np.linspace(1.0, 1.0 / t, 100)
        f = [faxen(t, v) for v in dd]
        label = "2a/H = %g%s" % (t, "" if len({r["radius"] for r in rows}) == 1 else ", a = %g" % a)
        for ax, q in zip(axes, ("Ux_norm", "Wz_norm", "S_star")):
            ax.errorbar(d, [r[q] for r in sel], yerr=[r[q + "_std"] for r in sel], fmt="o", color=colour,
                        mfc="none", capsize=3, label=label)
            ax.plot(dd, [v[q] for v in f], "-", color=colour, lw=0.8)
    for s in staben:
        axes[0].plot([s["d_over_a"]], [s["U_over_Uc"]], "k*", ms=11, label="Staben et al. 2003 (2a/H = %g)"
                     % s["two_a_over_H"])
    axes[0].set_ylabel("$U_x/U_c$")
    axes[1].set_ylabel(r"$\Omega_z a/U_c$")
    axes[2].set_ylabel(r"$S^* = S_{xy}/(4U_c\eta a^3/H)$")
    for ax in axes:
        ax.set_xlabel("$d/a$")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    axes[1].set_title("symbols: FDM (std over positions); lines: Faxen's laws", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def run_all(workdir: str, radii: Sequence[float], two_a_over_H: Sequence[float], d_words: Sequence[str],
            offsets, represented: int, options, staben: list[dict]) -> tuple[list[dict], list[dict]]:
    """Every channel (radius, 2a/H): their rows and a summary per channel."""
    rows, channels = [], []
    for a in radii:
        for t in two_a_over_H:
            scene = Scene(a, t, options.a_over_delta, options.size)
            kept, skipped = d_values(t, d_words)
            if skipped:
                print("  2a/H = %g: d/a = %s above the centre plane (%.4g: mirror images) or not above 1: skipped"
                      % (t, " ".join("%.4g" % v for v in skipped), 1.0 / t))
            result = run_channel(workdir, scene, kept, offsets, represented, options, staben)
            print("%s: %d configurations x %d positions, %.0f s" % (result["description"], len(kept), len(offsets),
                                                                 result["wall_seconds"]))
            print_rows(result["rows"])
            rows += result["rows"]
            channels.append(dict(radius=a, two_a_over_H=t, description=result["description"], cells=result["cells"],
                                 wall_seconds=result["wall_seconds"], run_dir=result["run_dir"]))
    return rows, channels


def convergence(options, offsets, represented: int, staben: list[dict]) -> tuple[list[dict], list[dict]]:
    """The mesh and the box at the configurations CONVERGENCE_CONFIGS: the first box of
    CONVERGENCE_BOXES with both a1/Delta of CONVERGENCE_A_OVER_DELTA, and the first a1/Delta in the
    second box. Returns (rows, the changes from the base (first mesh, first box) per configuration)."""
    rows = []
    combos = convergence_study.variants(CONVERGENCE_A_OVER_DELTA, CONVERGENCE_BOXES)
    for t, words in CONVERGENCE_CONFIGS:
        kept, _ = d_values(t, parse_d_over_a(words))
        for study, ad, box in combos:
            opts = argparse.Namespace(**vars(options))
            opts.a_over_delta, opts.size = ad, list(box)
            scene = Scene(options.radius[0], t, ad, box)
            result = run_channel(options.workdir, scene, kept, offsets, represented, opts, staben)
            print("%s [%s]: %.0f s" % (result["description"], study, result["wall_seconds"]))
            print_rows(result["rows"])
            for r in result["rows"]:
                r["study"] = study
            rows += result["rows"]
    changes = []
    for base in (r for r in rows if r["study"] == "base"):
        for other in rows:
            if other["study"] == "base" or other["two_a_over_H"] != base["two_a_over_H"] or \
                    abs(other["d_over_a"] - base["d_over_a"]) > 1e-9:
                continue
            entry = convergence_study.change_entry(
                dict(two_a_over_H=base["two_a_over_H"], d_over_a=base["d_over_a"], change=other["study"]),
                base, other, base, other, ("Ux_norm", "Ux_norm_shifted", "Wz_norm", "S_star"))
            changes.append(entry)
            print("  2a/H %g, d/a %.4g, %s (a/Delta %.3g -> %.3g, box %g x %g -> %g x %g a): Ux/Uc %+.4f (less the "
                  "offset %+.4f), Omega_z a/Uc %+.4f, S* %+.4f" % (
                      entry["two_a_over_H"], entry["d_over_a"], entry["change"], entry["from_a_over_delta"],
                      entry["to_a_over_delta"], base["box"][0], base["box"][2], other["box"][0], other["box"][2],
                      entry["Ux_norm_change"], entry["Ux_norm_shifted_change"], entry["Wz_norm_change"],
                      entry["S_star_change"]))
    return rows, changes


def validation_rows(r: dict) -> List[Row]:
    """U_x/U_c against Staben et al. (2003) where it applies, else against Faxen's laws with the leading wall
    reflections where those are a reference (the centre 2 radii or more from both walls: the case's
    wall_estimate_applies; nearer, the row has no reference), Omega_z a/U_c and S* likewise."""
    rows = []
    for row in r["rows"]:
        config = "a %g, 2a/H %g, d/a %s, a/Δ %.3g, box %s a, %d positions" % (
            row["radius"], row["two_a_over_H"], "%.4g (centre)" % row["d_over_a"] if row["centre_plane"] else
            "%g" % row["d_over_a"], row["a_over_delta"], "×".join("%g" % v for v in row["box"]), row["n_positions"])
        faxen = row["faxen_wall"] if row.get("faxen_wall_applies") else {}
        if row.get("staben_Ux_norm") is not None:
            rows.append(Row("U_x/U_c (Staben)", config, row["Ux_norm"], row["staben_Ux_norm"],
                            "%g (Staben et al. 2003; Fig. 12: very good agreement)" % row["staben_Ux_norm"],
                            relative(row["Ux_norm"], row["staben_Ux_norm"]), spread=row["Ux_norm_std"] or None))
        else:
            rows.append(Row("U_x/U_c (Faxén + walls)", config, row["Ux_norm"], faxen.get("Ux_norm"), "Fig. 12",
                            relative(row["Ux_norm"], faxen.get("Ux_norm")), spread=row["Ux_norm_std"] or None))
        if not row["centre_plane"]:
            rows.append(Row("Ω_z a/U_c (Faxén + walls)", config, row["Wz_norm"], faxen.get("Wz_norm"), "Fig. 12",
                            relative(row["Wz_norm"], faxen.get("Wz_norm")), spread=row["Wz_norm_std"] or None))
            rows.append(Row("S* (Faxén + walls)", config, row["S_star"], faxen.get("S_star"), "Fig. 13 (2a/H 0.4)",
                            relative(row["S_star"], faxen.get("S_star")), spread=row["S_star_std"] or None))
    return rows


def main(argv: Sequence[str] | None = None) -> dict:
    """Parse the options (module docstring), run every channel, print the table, write --out and the figure."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--two-a-over-H", type=float, nargs="+", default=None, metavar="2A/H",
                   help="confinements 2a/H, each in (0, 1) (default %s)"
                        % " ".join("%g" % v for v in TWO_A_OVER_H_DEFAULT))
    p.add_argument("--d-over-a", nargs="+", default=None, metavar="D/A",
                   help="centre-to-lower-wall distances d/a (> 1), or 'centre' for the centre plane; values above the "
                        "centre plane of a channel are skipped (default %s)" % " ".join(D_OVER_A_DEFAULT))
    p.add_argument("--radius", type=float, nargs="+", default=None, metavar="A",
                   help="sphere radii in units of a1 (the mesh is set by a1/Delta; default 1; the paper: 1 1.4)")
    p.add_argument("--a-over-delta", type=float, default=3.0,
                   help="a1/Delta, mesh cells per a1 (nominal: Delta is adjusted so that H is a whole number of cells)")
    p.add_argument("--size", type=float, nargs=2, default=None, metavar=("LX", "LZ"),
                   help="periodic lengths L_x, L_z in units of the sphere's radius (default %g %g; the paper 60 40)"
                        % BOX_DEFAULT)
    p.add_argument("--positions", type=int, default=2,
                   help="positions of the centre in the plane section of a cell at fixed d: 4, 16 (the paper's "
                        "4 x 4) are lattices computed at their quarter (1, 4 steps); other counts are Halton points "
                        "there (default 2)")
    p.add_argument("--full", action="store_true",
                   help="the paper's: a = 1 and 1.4, a1/Delta = 5, 60 a x 40 a, 16 positions, 2a/H = %s, d/a = %s "
                        "(not feasible on a small machine)" % (" ".join("%g" % v for v in FULL_TWO_A_OVER_H),
                                                               " ".join(FULL_D_OVER_A)))
    p.add_argument("--no-subgrid", dest="subgrid", action="store_false",
                   help="pair_style fdm/subgrid with lubrication no: the FDM alone, no wall correction")
    p.add_argument("--offset", type=float, nargs=2, action="append", default=None, metavar=("OX", "OZ"),
                   help="an offset of the centre from a mesh vertex in x and z, in cells (repeatable), instead of "
                        "--positions; OX = 0 makes the mesh mirror-symmetric in x about the sphere")
    p.add_argument("--convergence", action="store_true",
                   help="mesh (a1/Delta %g, %g) and box (%s a) at %s; --out defaults to results_convergence.json" % (
                       *CONVERGENCE_A_OVER_DELTA, ", ".join("%g x %g" % b for b in CONVERGENCE_BOXES),
                       "; ".join("2a/H = %g, d/a = %s" % (t, " ".join(w)) for t, w in CONVERGENCE_CONFIGS)))
    p.add_argument("--wall-cutoff", type=float, default=None,
                   help="pair_style fdm/subgrid wall_cutoff (mesh cells; default: the pair style's, 0.75)")
    p.add_argument("--reference", action="store_true", help="print Faxen's values of every configuration and stop")
    p.add_argument("--no-plot", action="store_true", help="do not draw results_poiseuilleSphere.png")
    p.add_argument("--n-max", type=int, default=2000, help="fdmFoam's innerIterations nMax (4x on the first step)")
    case.add_run_options(p, HERE, tol_lambda=1e-4, cutoff=True)
    args = p.parse_args(argv)

    if args.full:
        args.radius = args.radius or list(PAPER_RADII)
        args.two_a_over_H = args.two_a_over_H or list(FULL_TWO_A_OVER_H)
        args.d_over_a = args.d_over_a or list(FULL_D_OVER_A)
        args.size = args.size or list(PAPER_BOX)
        args.a_over_delta, args.positions = PAPER_A_OVER_DELTA, PAPER_POSITIONS
    args.radius = args.radius or list(RADII_DEFAULT)
    args.two_a_over_H = args.two_a_over_H or list(TWO_A_OVER_H_DEFAULT)
    args.size = list(args.size or BOX_DEFAULT)
    try:
        d_words = parse_d_over_a(args.d_over_a or D_OVER_A_DEFAULT)
    except ValueError as e:
        p.error(str(e))
    for t in args.two_a_over_H:
        if not 0.0 < t < 1.0:
            p.error("--two-a-over-H %g: the sphere must fit in the channel, 0 < 2a/H < 1" % t)
    for a in args.radius:
        if not a > 0:
            p.error("--radius %g: must be positive" % a)
    if not args.a_over_delta > 0:
        p.error("--a-over-delta %g: must be positive" % args.a_over_delta)
    for v, name in zip(args.size, ("LX", "LZ")):
        if not v > 0:
            p.error("--size %s = %g: must be positive" % (name, v))
    if args.n_max < 1:
        p.error("--n-max %d: must be at least 1" % args.n_max)
    if args.tol_lambda <= 0:
        p.error("--tol-lambda %g: must be positive" % args.tol_lambda)
    staben = read_staben()
    if args.reference:
        return dict(case="poiseuilleSphere", reference=print_reference(args.radius, args.two_a_over_H, d_words, staben))
    if args.offset:
        for o in args.offset:
            if not all(0.0 <= v < 1.0 for v in o):
                p.error("--offset %g %g: each offset must be in [0, 1) cells" % tuple(o))
        offsets, represented = [tuple(o) for o in args.offset], len(args.offset)
    else:
        try:
            offsets, represented = cell_offsets(args.positions)
        except ValueError as e:
            p.error(str(e))
    if args.convergence and args.out == os.path.join(HERE, "results.json"):
        args.out = os.path.join(HERE, "results_convergence.json")
    try:
        for a in args.radius:
            for t in args.two_a_over_H:
                kept, _ = d_values(t, d_words)
                if not kept:
                    raise ValueError("poiseuilleSphere: 2a/H = %g: every --d-over-a is above its centre plane "
                                     "d/a = %.4g or not above 1" % (t, 1.0 / t))
                check_scene(Scene(a, t, args.a_over_delta, args.size), kept)
    except ValueError as e:
        p.error(str(e))

    os.makedirs(args.workdir, exist_ok=True)
    t0 = time.time()
    if args.convergence:
        rows, changes = convergence(args, offsets, represented, staben)
        out = dict(case="poiseuilleSphere", study="convergence", rows=rows, changes=changes, n_positions=represented,
                   offsets=[list(o) for o in offsets], tol_lambda=args.tol_lambda, subgrid=args.subgrid)
    else:
        rows, channels = run_all(args.workdir, args.radius, args.two_a_over_H, d_words, offsets, represented, args,
                                 staben)
        out = dict(case="poiseuilleSphere", paper_section="5.2.3",
                   units="U_c = 1, eta = 1, a1 = 1; Ux_norm = U_x/U_c, Wz_norm = Omega_z a/U_c, Wz_H = Omega_z H/U_c, "
                         "S_star = S_xy/(4 U_c eta a^3/H), Uy_norm = U_y/U_c",
                   rows=rows, channels=channels, size_over_a=args.size, a1_over_delta=args.a_over_delta,
                   n_positions=represented, offsets=[list(o) for o in offsets], subgrid=args.subgrid,
                   model=args.model, cutoff_cells=args.cutoff or "default", tol_lambda=args.tol_lambda,
                   staben=staben)
    write_results(args.out, __file__, argv, args, None if args.convergence else validation_rows, out, t0)
    if not args.no_plot and not args.convergence:
        png = os.path.join(os.path.dirname(os.path.abspath(args.out)), "results_poiseuilleSphere.png")
        plot(rows, png, staben)
        print("wrote", png)
    print("wrote %s (%.0f s)" % (args.out, out["wall_seconds"]))
    return out


if __name__ == "__main__":
    main()
