"""The accelerated inner iteration (fdmFoam innerIterations acceleration anderson, the default)
against the plain fixed-point iteration of paper 4.3 (acceleration none): the same answers, in
fewer fluid solves. docs/fluid.md, docs/benchmarks.md."""
import numpy as np
import pytest

from conftest import load_case_module


@pytest.fixture(scope="module")
def array_pair(periodic_array, tmp_path_factory, env):
    """One position of the cheap periodic array (L/a = 6, a/Delta = 4), converged tightly both ways."""
    work = str(tmp_path_factory.mktemp("inner"))
    return {accel: periodic_array.run_configuration(work + "/" + accel, 6.0, 4.0, 1, tol_lambda=1e-6,
                                                    acceleration=accel)
            for accel in ("none", "anderson")}


def test_anderson_gives_the_plain_drag(array_pair):
    plain, anderson = array_pair["none"], array_pair["anderson"]
    assert plain["converged"] and anderson["converged"]
    # the plain iteration stops ~1e-4 short of its limit at tolLambda 1e-6 (convergence rate
    # ~0.98 per iteration, test_periodic_array.py): the two agree to that
    assert abs(anderson["K"] / plain["K"] - 1) < 3e-4, (anderson["K"], plain["K"])
    # and the same momentum balance (Eq. 43)
    assert anderson["eq43_rel_error"] < 1e-4, anderson["eq43_rel_error"]


def test_anderson_needs_fewer_fluid_solves(array_pair):
    # deterministic counts, not timings: the first position from rest
    plain, anderson = array_pair["none"]["inner_iterations"][0], array_pair["anderson"]["inner_iterations"][0]
    assert anderson < 0.5 * plain, (anderson, plain)


@pytest.fixture(scope="module")
def pair_shear(tmp_path_factory, env):
    """The smooth equal pair in shear (paper 5.3), the first 30 steps both ways, tolLambda 1e-4."""
    module = load_case_module("pairShear")
    work = str(tmp_path_factory.mktemp("innerPair"))
    return {accel: module.run_trajectory(work + "/" + accel, ratio=1.0, r_y0=0.5, max_steps=30, tol_lambda=1e-4,
                                         n_max=200, acceleration=accel)
            for accel in ("none", "anderson")}


def test_anderson_gives_the_plain_pair_trajectory(pair_shear):
    plain, anderson = pair_shear["none"], pair_shear["anderson"]
    assert plain["unconverged_steps"] == 0 and anderson["unconverged_steps"] == 0
    for c in ("r_x", "r_y", "r_z"):
        difference = np.abs(np.array(anderson[c]) - np.array(plain[c])).max()
        assert difference < 2e-3, (c, difference)     # in units of a1; measured 2026-11-23: see the docs
    assert anderson["inner_iterations_mean"] < plain["inner_iterations_mean"]


def _cold_start(run_dir, mean_flow, tol_lambda=0.0, tol_velocity=0.0, tol_solve=1e-6, n_max=2000):
    """One free sphere (a = 1, a/Delta = 3) in a 24^3-cell channel sheared by its top wall, the flow
    starting from rest: the first step's fluid solves and the sphere's velocities."""
    from fdm import case
    delta = 1.0 / 3.0
    L = 24 * delta
    box = case.Box((0, 0, 0), (L, L, L), delta, faces=("cyclic", ((0, 0, 0), (1.0, 0, 0)), "cyclic"))
    case.write_fluid_case(run_dir + "/fluid", box, tol_lambda=tol_lambda, tol_velocity=tol_velocity,
                          n_max=n_max, first_step=(tol_lambda, n_max), tol_u=tol_solve, tol_p=tol_solve,
                          n_particles=1, mean_flow_correction=mean_flow)
    centre = (L / 2 + 0.3 * delta, L / 2 + 0.1 * delta, L / 2 + 0.2 * delta)
    case.write_dem_input(run_dir + "/dem", box, [centre + (1.0,)], dt=0.01,
                         pair_style="fdm/subgrid wall ylo 0 0 0 wall yhi 1.0 0 0", runs=("run 1",),
                         name="in.coldStart")
    _, parts, steps = case.run_and_read(run_dir)
    return dict(solves=int(steps["innerIterations"][0]), converged=bool(steps["converged"][0]),
                velocities=np.array([float(parts[c][0]) for c in ("Ux", "Uy", "Uz", "Wx", "Wy", "Wz")]))


@pytest.fixture(scope="module")
def cold_start(tmp_path_factory, env):
    work = str(tmp_path_factory.mktemp("coldStart"))
    return {
        "tight, corrected": _cold_start(work + "/tight_mf", True, tol_lambda=1e-8, tol_solve=1e-10),
        "tight, uncorrected": _cold_start(work + "/tight", False, tol_lambda=1e-8, tol_solve=1e-10),
        "loose, corrected": _cold_start(work + "/loose_mf", True, tol_velocity=1e-4),
        "loose, uncorrected": _cold_start(work + "/loose", False, tol_velocity=1e-4),
    }


def test_mean_flow_correction_keeps_the_answer(cold_start):
    # the plane-averaged profile it imposes is the one the converged iteration reaches anyway
    corrected, uncorrected = cold_start["tight, corrected"], cold_start["tight, uncorrected"]
    assert corrected["converged"] and uncorrected["converged"]
    scale = 0.5   # the undisturbed flow at the sphere, U/2
    difference = np.abs(corrected["velocities"] - uncorrected["velocities"]).max() / scale
    # measured 2026-11-23: 1.4e-8, in 56 solves against 80
    assert difference < 1e-6, (corrected["velocities"], uncorrected["velocities"])


def test_mean_flow_correction_settles_the_channel_sooner(cold_start):
    # from rest the Couette profile develops by pseudo-time diffusion across 24 cells without it;
    # with it the profile is exact from the first iteration: fewer solves, and closer to the answer
    reference = cold_start["tight, corrected"]["velocities"]
    corrected, uncorrected = cold_start["loose, corrected"], cold_start["loose, uncorrected"]
    assert corrected["converged"] and uncorrected["converged"]
    assert corrected["solves"] < 0.6 * uncorrected["solves"], (corrected["solves"], uncorrected["solves"])
    error = np.abs(corrected["velocities"] - reference).max() / 0.5
    # measured 2026-11-23: 14 solves, error 1.1e-4, against 30 solves, error 4.6e-4 without it
    assert error < 5e-4, error
