"""Wall boundaries in a coupled run: a free sphere at the centre of a simple shear flow between two
walls moving in opposite directions (the set-up of paper 5.2.2), and a slip-walled box."""
import os

import numpy as np
import pytest

from fdmsubgrid import case, output


def run_shear(tmp_path, faces_y, wall_speed):
    H = 4.0
    box = case.Box((0, 0, 0), (6.0, H, 4.0), 0.25, faces=("cyclic", faces_y, "cyclic"))
    root = str(tmp_path / "shear")
    case.write_fluid_case(os.path.join(root, "fluid"), box, tol_lambda=1e-6, n_max=3000, n_particles=1)
    # free sphere (no external force): it translates and rotates with the flow
    case.write_dem_input(os.path.join(root, "dem"), box, [(3.0, H / 2, 2.0, 1.0)], fix_options="move no")
    case.run(root)
    return output.steps(os.path.join(root, "fluid")), output.particles(os.path.join(root, "fluid"))


def test_free_sphere_in_wall_driven_shear(tmp_path, env):
    U, H = 1.0, 4.0
    steps, parts = run_shear(tmp_path, ((-U, 0, 0), (U, 0, 0)), U)
    shear_rate = 2 * U / H
    assert steps["converged"].all()
    # Symmetry: a sphere at the centre of the channel does not translate
    for c in ("Ux", "Uy", "Uz"):
        assert abs(parts[c][-1]) < 1e-4 * U, (c, parts[c][-1])
    assert abs(parts["Wx"][-1]) < 1e-4 * shear_rate and abs(parts["Wy"][-1]) < 1e-4 * shear_rate
    # It spins against the vorticity sign convention of u = gamma_dot y e_x: Omega_z = -gamma_dot/2
    # unbounded; the walls at H = 4a slow it a little (Sangani et al. 2011, paper Fig. 10)
    ratio = -2 * parts["Wz"][-1] / shear_rate
    assert 0.75 < ratio <= 1.0, ratio
    # The mean flow of a symmetric Couette cell is zero
    assert abs(steps["meanUx"][-1]) < 1e-3 * U


def test_slip_walls_hold_a_sphere_at_rest(tmp_path, env):
    # Walls that only forbid normal flow, nothing driving: everything stays at rest, no NaN
    steps, parts = run_shear(tmp_path, "slip", 0.0)
    assert np.isfinite(parts["Ux"]).all()
    assert max(abs(parts[c][-1]) for c in ("Ux", "Uy", "Uz", "Wx", "Wy", "Wz")) < 1e-10
