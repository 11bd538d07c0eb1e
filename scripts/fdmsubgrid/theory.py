"""Theoretical references from the project's resistance library, through its command-line tool
fdmResistance (dem/resistance/, docs/resistance.md): one source of resistance functions for the solver,
the tests and the post-processing."""
import functools
import json
import math
import subprocess
from typing import Optional

import numpy as np

from .environment import program, run_environment


def resistance(*args: object) -> dict:
    """JSON output of `fdmResistance args...` as a dict."""
    out = subprocess.run([program("fdmResistance")] + [str(a) for a in args], check=True, stdout=subprocess.PIPE,
                         text=True, env=run_environment()).stdout
    return json.loads(out)


def pair_squeeze_velocity(a1, a2, xi):
    """Closing velocity of two spheres pushed together along their line of centres by equal and
    opposite forces F, in units of F/(6 pi eta a1): full-range two-sphere theory (Jeffrey & Onishi)."""
    return resistance("squeeze", "--a1", a1, "--a2", a2, "--xi", xi)["closing_velocity_normalised"]


def wall_squeeze_velocity(a, eps):
    """Velocity of a sphere pushed toward a plane wall by a force F, in units of F/(6 pi eta a):
    1/X^A_wall (Brenner 1961)."""
    return resistance("squeeze", "--a", a, "--eps", eps, "--wall")["closing_velocity_normalised"]


@functools.lru_cache(maxsize=4096)
def pair_full_range(a1: float, a2: float, xi: float) -> dict:
    """Every full-range two-sphere function (X^A ... Z^M, ab = 11, 12, 21, 22; dimensional / eta, d from
    sphere 1 to sphere 2) at the reduced gap xi: `fdmResistance pair --theory --full` (docs/resistance.md)."""
    return resistance("pair", "--a1", a1, "--a2", a2, "--xi", "%.17g" % xi, "--theory", "--full")["dimensional_over_eta"]


def relative_errors(values, reference):
    """(value - reference) / reference, element by element."""
    return [(v - r) / r for v, r in zip(values, reference)]


@functools.lru_cache(maxsize=1)
def pair_style_cutoffs() -> tuple[float, float]:
    """pair_style fdm/subgrid's default cut-offs in mesh cells, (pair, wall), as the resistance library
    defines them (`fdmResistance defaults`; docs/dem.md)."""
    out = resistance("defaults")
    return float(out["pair_cutoff_cells"]), float(out["wall_cutoff_cells"])


def subgrid_options(model: str, wall: bool = False) -> tuple:
    """The fdmResistance options (with --subgrid or --delta) that give pair_style fdm/subgrid's sub-grid
    `model` ('calibrated' or 'cutoff') at its default cut-offs, for a pair or (wall) a sphere and a wall."""
    if model == "calibrated":
        return ("--calibrated",)
    return ("--cutoff", pair_style_cutoffs()[1 if wall else 0])


def wall_subgrid_range(a: float, delta: float, model: str = "calibrated") -> float:
    """eps = h/a - 1 below which pair_style fdm/subgrid's wall block acts on a sphere of radius a at mesh size
    delta, with its default cut-offs: the cut-off model's wall_cutoff Delta/a, or the calibrated model's range
    (the larger of its table's and the cut-off's; fdmResistance wall --calibrated)."""
    return resistance("wall", "--a", a, "--eps", 1.0, "--delta", delta, *subgrid_options(model, wall=True))["eps_cut"]


@functools.lru_cache(maxsize=4096)
def pair_mode_resistances(a_i: float, a_j: float, gap: float, delta: float, eta: float = 1.0,
                          cutoff: Optional[float] = None, subgrid: bool = True,
                          contact_in_mid_gap: bool = False, model: str = "cutoff") -> tuple[float, float]:
    """(zeta_n, zeta_t) of two free spheres at surface gap `gap`: the force per unit closing speed
    under equal and opposite loads along the line of centres, and per unit slip speed of the contact
    points under equal and opposite tangential loads there (with their torques). The resistance is
    the isolated Stokes drag (6 pi eta a, 8 pi eta a^3) plus, if subgrid, the sub-grid pair block of
    fdmResistance (Eq. 21) at mesh size delta: Eq. (31) without the fluid's resolved part
    (docs/contact.md, 3c). The contact points sit on the spheres' surfaces (a_i, a_j from the
    centres), or with contact_in_mid_gap in the middle of the gap (docs/contact.md 2). Without the
    sub-grid block, zeta_t of two equal spheres is 12/7 pi eta a. cutoff: the cut-off model's k in mesh
    cells (None: the pair style's default). model: pair_style fdm/subgrid's sub-grid model, 'cutoff' or
    'calibrated' (the shipped table; the functions it lacks from the cut-off model at `cutoff`)."""
    if model not in ("cutoff", "calibrated"):
        raise ValueError("model must be 'cutoff' or 'calibrated', got %r" % (model,))
    if cutoff is None:
        cutoff = pair_style_cutoffs()[0]
    drag = [6 * math.pi * eta * a_i] * 3 + [8 * math.pi * eta * a_i ** 3] * 3 \
        + [6 * math.pi * eta * a_j] * 3 + [8 * math.pi * eta * a_j ** 3] * 3
    resistance_matrix = np.diag(drag)
    if subgrid:
        out = resistance("matrix", "--x1", 0, 0, 0, "--x2", "%.17g" % (a_i + a_j + gap), 0, 0, "--a1", a_i,
                         "--a2", a_j, "--delta", "%.17g" % delta, "--eta", eta, "--cutoff", cutoff,
                         *(("--calibrated",) if model == "calibrated" else ()))
        resistance_matrix = resistance_matrix + np.array(out["R"])
    d = np.array([1.0, 0.0, 0.0])       # from sphere i to sphere j
    t = np.array([0.0, 1.0, 0.0])
    zero = np.zeros(3)
    lever_i, lever_j = (a_i + 0.5 * gap, a_j + 0.5 * gap) if contact_in_mid_gap else (a_i, a_j)
    u = np.linalg.solve(resistance_matrix, np.concatenate([-d, zero, d, zero]))   # pulled apart
    zeta_n = 1.0 / float((u[6:9] - u[0:3]) @ d)
    u = np.linalg.solve(resistance_matrix, np.concatenate([t, np.cross(lever_i * d, t), -t,
                                                           np.cross(-lever_j * d, -t)]))
    slip = u[0:3] + np.cross(u[3:6], lever_i * d) - u[6:9] - np.cross(u[9:12], -lever_j * d)
    zeta_t = 1.0 / float(slip @ t)
    return zeta_n, zeta_t
