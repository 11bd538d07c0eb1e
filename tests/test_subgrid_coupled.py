"""The sub-grid lubrication in the coupled code (real fdmFoam + real fdmDEM with pair_style fdm/subgrid):
squeeze flow of an unequal pair and of a sphere toward a wall against theory (cases pairSqueeze,
wallSqueeze, small meshes), frame invariance of the coupled system (Eq. 24), and a pair in shear."""
import math
import os

import numpy as np
import pytest

from conftest import load_case_module
from fdmsubgrid import case, output, squeeze


def test_pair_squeeze_unequal_spheres(tmp_path, env):
    # a2/a1 = 1.4: the closing velocity under equal and opposite forces, against Jeffrey & Onishi
    from fdmsubgrid import theory
    xis = [1e-2, 1e-3, 1e-4]
    ref = [theory.pair_squeeze_velocity(1.0, 1.4, xi) for xi in xis]
    on = squeeze.run_pair(str(tmp_path), 1.4, xis, True, a_over_delta=4.0, L_over_a=8.0, tol_lambda=1e-4)
    assert on["converged"]
    errors = [(v - r) / r for v, r in zip(on["velocity"], ref)]
    assert max(abs(e) for e in errors) < 0.05, errors
    # without the correction the FDM alone cannot resolve the gap: the pair closes far too fast
    off = squeeze.run_pair(str(tmp_path), 1.4, [1e-3], False, a_over_delta=4.0, L_over_a=8.0, tol_lambda=1e-4)
    assert (off["velocity"][0] - ref[1]) / ref[1] > 1.0, (off["velocity"], ref[1])


def test_wall_squeeze(tmp_path, env):
    from fdmsubgrid import theory
    epss = [1e-2, 1e-3]
    ref = [theory.wall_squeeze_velocity(1.0, e) for e in epss]
    on = squeeze.run_wall(str(tmp_path), epss, True, a_over_delta=4.0, L_over_a=8.0, H_over_a=10.0,
                               tol_lambda=1e-4)
    errors = [(v - r) / r for v, r in zip(on["velocity"], ref)]
    assert max(abs(e) for e in errors) < 0.05, errors
    off = squeeze.run_wall(str(tmp_path), [1e-3], False, a_over_delta=4.0, L_over_a=8.0, H_over_a=10.0,
                                tol_lambda=1e-4)
    assert (off["velocity"][0] - ref[1]) / ref[1] > 1.0, (off["velocity"], ref[1])


def run_sheared_pair(root, frame_velocity):
    """Two close unequal spheres (xi = 0.01, oblique to the flow) held in a Couette cell whose walls
    move at (-U + V, U + V): the same scene seen from a frame translating at -V along x."""
    H, U, V = 6.0, 3.0, frame_velocity
    box = case.Box((0, 0, 0), (8.0, H, 6.0), 1.0 / 3.0,
                   faces=("cyclic", ((-U + V, 0, 0), (U + V, 0, 0)), "cyclic"))
    a1, a2, xi = 1.0, 1.4, 0.01
    r = (a1 + a2) * (1 + xi / 2)
    d = np.array([0.8, 0.6, 0.0])
    x1 = np.array([3.1, 2.4, 3.05])
    x2 = x1 + r * d
    case.write_fluid_case(os.path.join(root, "fluid"), box, tol_lambda=1e-7, n_max=6000, n_particles=2)
    case.write_dem_input(os.path.join(root, "dem"), box, [tuple(x1) + (a1,), tuple(x2) + (a2,)],
                         pair_style="fdm/subgrid wall ylo %r 0 0 wall yhi %r 0 0" % (-U + V, U + V))
    case.run(root)
    parts = output.particles(os.path.join(root, "fluid"))
    return {c: parts[c] for c in ("Ux", "Uy", "Uz", "Wx", "Wy", "Wz")}


@pytest.mark.full  # about 10 minutes: two tightly converged runs
def test_frame_invariance_of_the_coupled_system(tmp_path, env):
    # Eq. (24): the sub-grid correction sees only relative motion, so the same scene in a frame
    # translating along the walls gives the same relative velocities and the same rotations, and
    # velocities shifted by the frame velocity.
    V = 0.7
    a = run_sheared_pair(str(tmp_path / "rest"), 0.0)
    b = run_sheared_pair(str(tmp_path / "moving"), V)
    scale = 1.0  # shear rate 1 x a1
    rel_a = np.array([a[c][1] - a[c][0] for c in ("Ux", "Uy", "Uz")])
    rel_b = np.array([b[c][1] - b[c][0] for c in ("Ux", "Uy", "Uz")])
    assert np.abs(rel_a).max() > 1e-3  # the pair does move relative to itself
    # measured: the relative velocities agree to 0.36 % of |U2 - U1| (3.1e-3 in the smallest
    # component): the fluid of the moving frame is not converged to the same point in 6000 inner
    # iterations from rest; a frame-dependent sub-grid term would be of the order of the squeeze
    # and shear resistances at xi = 0.01, i.e. of |U2 - U1| itself
    tolerance = 0.01 * np.linalg.norm(rel_a)
    assert np.abs(rel_a - rel_b).max() < tolerance, (rel_a, rel_b)
    for c in ("Wx", "Wy", "Wz"):
        assert np.abs(a[c] - b[c]).max() < tolerance, (c, a[c], b[c])
    assert np.abs(b["Ux"] - a["Ux"] - V).max() < tolerance


@pytest.fixture(scope="module")
def pair_shear():
    return load_case_module("pairShear")


def test_pair_in_shear_is_fore_aft_symmetric(tmp_path, env, pair_shear):
    # Equal smooth spheres, r_y0 = 0.5, dt = 0.05 / shear rate (paper 5.3 at CI size, about 3 min):
    # Stokes flow is reversible, so the relative trajectory comes back to its initial offset (2 %, the
    # issue's tolerance) with its closest approach at r_x = 0, and the spheres never touch. The
    # straight Adams-Bashforth step (gap_update none) misses this by +68 % at the same dt, Euler by
    # +198 % (docs/validation.md): the log-gap position update is what this test checks.
    t = pair_shear.run_trajectory(str(tmp_path), ratio=1.0, r_y0=0.5, contact=None, a_over_delta=3.0,
                                  size=(12.0, 8.0, 6.0), dt=0.05)
    s = pair_shear.summarise(t)
    assert np.isfinite(t["xi"]).all()
    assert "r_y_end" in s, "the trajectory did not come back to |r_x| = %g" % -s["r_x_start"]
    assert abs(s["fore_aft_asymmetry"]) < 0.02, s
    assert abs(s["r_x_at_min_gap"]) < 0.3, s
    assert 0 < s["min_gap_over_a1"] < 1e-3, s


@pytest.mark.full  # about 16 minutes
def test_pair_in_shear_minimum_gap_in_a_larger_box(tmp_path, env, pair_shear):
    # The minimum gap of the paper's smallest open trajectory (about 4e-5 a1 in a 40^3 box) needs
    # room: in the CI box (12 x 8 x 6, walls 4 a1 away) the confined pair comes to 1e-6 a1; in
    # 20 x 12 x 10 from r_x = -6 it is 3.2e-5 a1 at r_x = -0.02 (docs/validation.md).
    t = pair_shear.run_trajectory(str(tmp_path), ratio=1.0, r_y0=0.5, contact=None, a_over_delta=3.0,
                                  size=(20.0, 12.0, 10.0), dt=0.05)
    s = pair_shear.summarise(t)
    assert "r_y_end" in s, s
    assert abs(s["fore_aft_asymmetry"]) < 0.02, s
    assert 1e-5 < s["min_gap_over_a1"] < 1e-3, s


def test_pair_in_shear_with_contact_leaves_on_a_higher_streamline(tmp_path, env, pair_shear):
    # The paper's contact case (a2/a1 = 1.4, r0 = (-3.48, 0.93), h_r = 5e-3 a1, mu_s = 0.5) at CI
    # size (12 x 8 x 6, about 2 min). Physics checked: the springs hold the surfaces inside the
    # roughness layer (no overlap, no creeping inside it: the gap stays within [h_r/2, h_r]); the
    # spheres part where the normal load of the shear turns from compressive to tensile, at r_x = 0
    # (the quadrant of the shear's straining axes), so the window ends near r_x = 0; and contact
    # breaks the reversibility: the pair leaves on a higher streamline. The onset is earlier than
    # the paper's -1.39 here (-1.80: the walls, 4 a1 away, press the pair together on the approach);
    # the larger box of the --full test below brings it to the paper's.
    kn, kt, mu_s, h_r = pair_shear.paper_contact()
    t = pair_shear.run_trajectory(str(tmp_path), ratio=pair_shear.PAPER_CONTACT_RATIO,
                                  r_y0=pair_shear.PAPER_CONTACT_R_Y0, r_x0=pair_shear.PAPER_CONTACT_R_X0,
                                  contact=(kn, kt, mu_s, h_r), a_over_delta=3.0, size=(12.0, 8.0, 6.0), dt=0.05)
    s = pair_shear.summarise(t, h_r)
    assert np.isfinite(t["xi"]).all()
    assert s.get("contact_r_x_from") is not None, "no contact: %s" % s
    assert 0.5 * h_r < s["min_gap_over_a1"] < h_r, s
    assert -2.1 < s["contact_r_x_from"] < -1.2, s
    assert abs(s["contact_r_x_to"]) < 0.3, s
    assert "r_y_end" in s, s
    assert s["fore_aft_asymmetry"] > 0.2, s
    # every step's lambda iteration converges (nMax 50): where the two discrete spheres overlap,
    # the residual is the change of the cell's lambda, which vanishes at convergence (before the
    # fix it summed the two particles' opposite shares, and 38 of the 150 steps stalled at nMax)
    assert t["unconverged_steps"] == 0, (t["unconverged_steps"], t["inner_iterations_mean"])


@pytest.mark.full  # about 8 minutes
def test_pair_in_shear_contact_window_in_a_larger_box(tmp_path, env, pair_shear):
    # With the walls 6 a1 away (20 x 12 x 10) the contact window is the paper's (-1.39 <~ r_x <~ 0,
    # 40^3 box, dt = 1e-4): measured -1.45 ... -0.01 at dt = 0.05 (docs/validation.md).
    contact = pair_shear.paper_contact()
    t = pair_shear.run_trajectory(str(tmp_path), ratio=pair_shear.PAPER_CONTACT_RATIO,
                                  r_y0=pair_shear.PAPER_CONTACT_R_Y0, r_x0=pair_shear.PAPER_CONTACT_R_X0,
                                  contact=contact, a_over_delta=3.0, size=(20.0, 12.0, 10.0), dt=0.05)
    s = pair_shear.summarise(t, contact[3])
    assert s.get("contact_r_x_from") is not None, s
    assert abs(s["contact_r_x_from"] - (-1.39)) < 0.15, s
    assert abs(s["contact_r_x_to"] - 0.0) < 0.15, s
    assert s["fore_aft_asymmetry"] > 0.2, s
