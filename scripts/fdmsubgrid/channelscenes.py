"""Spheres held in a channel between two walls normal to y (x and z periodic), the scenes several cases
share: each configuration of the spheres is one coupled time step (`fix fdm/couple ... move no`: free in
force and torque, held in place, their velocities those of the fixed configuration), the fluid started
from the undisturbed flow so that the far field is converged from the start.

  ShearedChannel      walls at -U and +U along x (shear rate 2U/H), the flow gamma_dot (y - H/2) e_x:
                      cases/channelShear (the gap scan) and cases/shearedSphere (the dilute stresslet)
  PoiseuilleChannel   walls at rest, the flow driven by dP0/dx = -8 eta U_c/H^2 (paper Eqs. 47-48), H a
                      whole number of cubic cells: cases/poiseuilleSphere and cases/pairPoiseuille

Units: lengths in a1 = 1 m, eta = 1 Pa s."""
from __future__ import annotations

import math
import os
from typing import Sequence

import numpy as np

from . import deminput, foamcase


def unbounded_shear_stresslet(radius: float, eta: float, shear_rate: float) -> float:
    """S_xy of a free sphere in unbounded simple shear, (10/3) pi eta a^3 gamma_dot: the unit of S*."""
    return 10.0 / 3.0 * math.pi * eta * radius ** 3 * shear_rate


class ShearedChannel:
    """The box (L_x, H, L_z) meshed with cells of side delta, the walls y = 0 and y = H moving at -U and +U
    along x, U = shear_rate H/2."""

    def __init__(self, length_x: float, height: float, length_z: float, delta: float,
                 shear_rate: float = 1.0) -> None:
        self.length_x, self.height, self.length_z = length_x, height, length_z
        self.delta, self.shear_rate = delta, shear_rate
        self.wall_speed = shear_rate * height / 2                  # gamma_dot = 2U/H
        U = self.wall_speed
        self.box = foamcase.Box((0, 0, 0), (length_x, height, length_z), delta,
                                faces=("cyclic", ((-U, 0, 0), (U, 0, 0)), "cyclic"))

    @property
    def walls(self) -> tuple:
        """Both walls as pair_style fdm/subgrid declares them (deminput.subgrid_pair_style)."""
        U = self.wall_speed
        return (("ylo", (-U, 0, 0)), ("yhi", (U, 0, 0)))

    def undisturbed(self, centres: np.ndarray) -> np.ndarray:
        """The flow gamma_dot (y - H/2) e_x at the (n, 3) points."""
        return np.column_stack([self.shear_rate * (centres[:, 1] - self.height / 2), np.zeros(len(centres)),
                                np.zeros(len(centres))])


def write_sheared_channel(run_dir: str, channel: ShearedChannel, spheres: Sequence[tuple], runs: Sequence[str],
                          name: str, tol_lambda: float = 1e-5, eta: float = 1.0, pair_style: str = "none") -> None:
    """fluid/ and dem/ of one sheared channel in run_dir: the spheres [(x, y, z, a), ...] held (stresslets
    recorded), the fluid started from the undisturbed shear, every step solved to tol_lambda (nMax 3000, the
    linear solves to 1e-8 and 1e-7), dt = 0.01; runs: the LIGGGHTS lines after fix fdm/couple (the records and
    the held configurations, deminput.held_step_runs); name: the input file's."""
    fluid = os.path.join(run_dir, "fluid")
    foamcase.write_fluid_case(fluid, channel.box, nu=eta, rho=1.0, tol_lambda=tol_lambda, n_max=3000,
                              first_step=(tol_lambda, 3000), n_particles=len(spheres), tol_u=1e-8, tol_p=1e-7)
    foamcase.write_initial_velocity(fluid, channel.box, channel.undisturbed)
    deminput.write_dem_input(os.path.join(run_dir, "dem"), channel.box, list(spheres), dt=0.01,
                             fix_options="move no stresslets yes", runs=list(runs), pair_style=pair_style, name=name)


class PoiseuilleChannel:
    """The channel of height H between walls at rest on its mesh: Delta the nearest to a1/a1_over_delta that
    makes H a whole number of cells, L_x and L_z (size, in units of the length `radius`) rounded to whole
    cells; the flow driven by dP0/dx = -8 eta U_c/H^2 (Eq. 48), U_c the centre-line velocity of Eq. (47)."""

    def __init__(self, radius: float, height: float, a1_over_delta: float, size: Sequence[float],
                 eta: float = 1.0, centre_velocity: float = 1.0, a1: float = 1.0) -> None:
        self.radius, self.H = float(radius), float(height)
        self.eta, self.centre_velocity = eta, centre_velocity
        self.ny = max(1, int(round(self.H * a1_over_delta / a1)))
        self.delta = self.H / self.ny
        self.nx = max(1, int(round(size[0] * self.radius / self.delta)))
        self.nz = max(1, int(round(size[1] * self.radius / self.delta)))
        self.Lx, self.Lz = self.nx * self.delta, self.nz * self.delta
        self.box = foamcase.Box((0, 0, 0), (self.Lx, self.H, self.Lz), self.delta,
                                faces=("cyclic", ((0, 0, 0), (0, 0, 0)), "cyclic"))

    walls = (("ylo", (0, 0, 0)), ("yhi", (0, 0, 0)))

    @property
    def a_over_delta(self) -> float:
        return self.radius / self.delta

    @property
    def size_over_a(self) -> list[float]:
        return [self.Lx / self.radius, self.H / self.radius, self.Lz / self.radius]

    @property
    def cells(self) -> int:
        return self.nx * self.ny * self.nz

    @property
    def grad_p0(self) -> float:
        """dP0/dx of Eq. (48)."""
        return -8.0 * self.eta * self.centre_velocity / self.H ** 2

    @property
    def discrete_offset(self) -> float:
        """(Delta/H)^2: the solver's undisturbed flow is Eq. (47) plus U_c times this (discrete_profile)."""
        return (self.delta / self.H) ** 2

    def discrete_profile(self, y: np.ndarray) -> np.ndarray:
        """The solver's own undisturbed flow at the cell centres: the finite-volume Laplacian is exact for
        the parabola inside, and the wall flux (u_1 - 0)/(Delta/2) of the first cell is short of du0/dy
        by 2 U_c Delta/H^2: the discrete steady profile is the parabola plus the constant U_c (Delta/H)^2
        (docs/fluid.md's mean-flow correction solves the same stencil)."""
        return self.centre_velocity * (1.0 - (2.0 * (y - self.H / 2) / self.H) ** 2 + self.discrete_offset)

    def undisturbed(self, centres: np.ndarray) -> np.ndarray:
        """The solver's undisturbed flow (discrete_profile) along x at the (n, 3) points."""
        return np.column_stack([self.discrete_profile(centres[:, 1]), np.zeros(len(centres)),
                                np.zeros(len(centres))])


def write_poiseuille_channel(run_dir: str, channel: PoiseuilleChannel, configurations: Sequence, radii: Sequence[float],
                             name: str, pair_style: str, tol_lambda: float, n_max: int, acceleration: str = "anderson",
                             fix_options: str = "move no") -> None:
    """fluid/ and dem/ of one Poiseuille channel in run_dir: the spheres of `radii` held at each of the
    configurations (each a list of centres, one per sphere) in turn, one step each, every particle recorded
    every step; the fluid started from the solver's undisturbed profile, the inner iterations to tol_lambda
    (nMax n_max; the first step to tol_lambda/10, 4 n_max), dt = 1; name: the input file's."""
    fluid = os.path.join(run_dir, "fluid")
    foamcase.write_fluid_case(fluid, channel.box, nu=channel.eta, rho=1.0, grad_p0=(channel.grad_p0, 0.0, 0.0),
                              tol_lambda=tol_lambda, n_max=n_max, first_step=(tol_lambda / 10, 4 * n_max),
                              n_particles=len(radii), acceleration=acceleration)
    foamcase.write_initial_velocity(fluid, channel.box, channel.undisturbed)
    runs = deminput.held_step_runs(configurations)
    spheres = [tuple(map(float, centre)) + (float(a),) for centre, a in zip(configurations[0], radii)]
    deminput.write_dem_input(os.path.join(run_dir, "dem"), channel.box, spheres, dt=1.0, fix_options=fix_options,
                             pair_style=pair_style, before_run=deminput.RECORD_EVERY_STEP, runs=runs, name=name)
