"""Stokes flow through a periodic array of spheres (paper 5.1), run with the real fdmFoam and
fdmDEM: drag against Hasimoto, the momentum balance of Eq. (43), rigid-body motion inside the
particle, symmetries, and serial/parallel agreement."""
import math

import pytest

from conftest import FULL


@pytest.fixture(scope="module")
def array8(periodic_array, tmp_path_factory, env):
    """The issue's scene: L/a = 8, a/Delta = 5, (b, c) = (5, 0.3), the paper's 64 positions (8 computed)."""
    return periodic_array.run_configuration(str(tmp_path_factory.mktemp("array8")), 8.0, 5.0, 64)


@pytest.fixture(scope="module")
def small(periodic_array, tmp_path_factory, env):
    """A cheap scene (L/a = 6, a/Delta = 4, one position on the cell diagonal) for the symmetry
    and parallel tests, in x and y and on 2 fluid ranks. The linear solves are converged to 1e-9:
    at the usual tol_u, tol_p (1e-6) the decomposed GAMG solve differs from the serial one at that
    level, and the accelerated iteration carries it into K (4.5e-6 between 1 and 2 ranks; 2e-8
    at 1e-9)."""
    work = str(tmp_path_factory.mktemp("small"))
    run = lambda **kw: periodic_array.run_configuration(work, 6.0, 4.0, 1, tol_lambda=1e-6, tol_u=1e-9, tol_p=1e-9,
                                                        **kw)
    # a position off every mid-plane of its cell, and its mirror images (Delta = 0.25, centre node 3)
    c, d = 3.0, 0.25
    mirrors = [(c + 0.3 * d, c + 0.1 * d, c + 0.2 * d), (c + 0.7 * d, c + 0.1 * d, c + 0.2 * d),
               (c + 0.3 * d, c + 0.9 * d, c + 0.8 * d)]
    return {"x": run(direction=0), "y": run(direction=1), "x_np2": run(direction=0, np_fluid=2),
            "mirrors": run(direction=0, points=mirrors)}


def test_hasimoto_drag(array8):
    # Issue 2: within 0.3 % averaged over at least 8 positions (the paper: 0.11 % over 64)
    assert array8["converged"]
    assert abs(array8["rel_error"]) < 3e-3, array8
    # each position within the paper's scatter (sigma_K / K about 1 %)
    assert all(abs(k / array8["K_hasimoto"] - 1) < 0.03 for k in array8["K_positions"])


def test_momentum_balance_eq43(array8):
    # The total force of lambda on the liquid equals V0 grad P0 once lambda has converged
    assert array8["eq43_rel_error"] < 1e-4, array8["eq43_rel_error"]


def test_rigid_motion_inside_particle(array8):
    # u* departs from U + Omega x r in the particle core by much less than the slip velocity
    assert array8["core_slip"] < 1e-3, array8["core_slip"]


def test_no_lift_no_rotation(array8, small):
    # A sphere in a cubic array dragged along a lattice axis neither drifts sideways nor spins.
    # At the cell centre (on every mid-plane of the mesh) this holds to solver tolerance:
    assert small["x"]["lateral_velocity"] < 1e-6, small["x"]["lateral_velocity"]
    assert small["x"]["rotation"] < 1e-6, small["x"]["rotation"]
    # Off the mid-planes the mesh breaks the symmetry at the scale of the drag's own scatter
    # (measured: lateral 0.38 %, rotation a|Omega| 1.2 % of U_s; sigma_K/K 0.7 %)
    assert array8["lateral_velocity"] < 1e-2, array8["lateral_velocity"]
    assert array8["rotation"] < 2e-2, array8["rotation"]


def test_cubic_symmetry(small):
    # The same sphere on the cell diagonal, flow along x or y: the same drag
    assert abs(small["x"]["K"] / small["y"]["K"] - 1) < 1e-5, (small["x"]["K"], small["y"]["K"])


def test_mirror_symmetry_of_the_cell(small):
    # The drag is the same at mirror-image positions in a cell: what lets periodicArray compute
    # one octant of the paper's 64-point lattice
    # (measured: 5e-7 for the y-z mirror, 9e-5 for the x mirror, which reverses the flow relative
    # to the mesh: the distance to convergence left by tolLambda 1e-6 at a convergence rate of
    # ~0.98 per inner iteration; 100 times below the scatter sigma_K/K = 0.7 % it averages).
    K = small["mirrors"]["K_positions"]
    assert max(K) / min(K) - 1 < 3e-4, K
    assert min(K) > 0


def test_parallel_equals_serial(small):
    # Issue 2: fluid on 2 MPI ranks gives K equal to the serial run within 1e-6 relative
    assert abs(small["x_np2"]["K"] / small["x"]["K"] - 1) < 1e-6, (small["x_np2"]["K"], small["x"]["K"])


@pytest.mark.full
@pytest.mark.parametrize("L_over_a", [8.0, 10.0, 20.0])
def test_hasimoto_drag_full(periodic_array, tmp_path, L_over_a):
    r = periodic_array.run_configuration(str(tmp_path), L_over_a, 5.0, 64)
    paper = {8.0: 0.0011, 10.0: 0.0011, 20.0: 0.0021}[L_over_a]   # Table 4
    assert abs(r["rel_error"]) < max(3e-3, 2 * paper), r
