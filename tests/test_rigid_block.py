"""Eq. (31)'s rigid-body block (docs/validation.md, "A free sphere in shear next to one wall"): a free
sphere carried by a uniform flow moves with it and does not turn, wherever it sits in its mesh cell.
The discrete sphere of the indicator function has a first moment m1 = int I_u (x - x_p) dV that
vanishes only on the mesh's symmetry points; with the paper's diagonal block (m1 taken as 0) the
converged lambda of a free sphere carries the torque m1 x U / alpha, and the sphere turned at
Omega_z = -0.0089 U0/a at the offset 0.1 cell in y (a/Delta = 3). Galilean invariance: one coupled
step of the real fdmFoam and fdmDEM per offset, about 10 s each."""
import os

import numpy as np
import pytest

from fdmsubgrid import case, output

U0 = 1.0


def uniform_flow_step(root, offset, a_over_delta=3.0, L=8.0):
    delta = 1.0 / a_over_delta
    box = case.Box((0, 0, 0), (L, L, L), delta)
    fluid = os.path.join(root, "fluid")
    # lambda is ~0 here, so its relative residual is round-off: a fixed 20 inner iterations (the
    # velocities stop changing at 1e-12 long before)
    case.write_fluid_case(fluid, box, nu=1.0, rho=1.0, tol_lambda=1e-12, n_max=20, first_step=(1e-12, 20),
                          n_particles=1, tol_u=1e-10, tol_p=1e-10)
    case.write_initial_velocity(fluid, box, lambda c: np.column_stack(
        [U0 * np.ones(len(c)), np.zeros(len(c)), np.zeros(len(c))]))
    centre = tuple(0.5 * L + o * delta for o in offset)
    case.write_dem_input(os.path.join(root, "dem"), box, [centre + (1.0,)], dt=0.01, fix_options="move no",
                         runs=[case.RECORD_EVERY_STEP, "run 1"],
                         name="in.uniform")
    case.run(root)
    records = output.read_particle_records(os.path.join(root, "dem", "particles.records"))
    return records["U"][-1, 0], records["omega"][-1, 0]


@pytest.mark.parametrize("offset", [(0.0, 0.1, 0.0), (0.17, 0.23, 0.31)])
def test_free_sphere_in_uniform_flow_moves_with_it_and_does_not_turn(tmp_path, env, offset):
    # measured: U = (1, 0, 0) and Omega = 0 to 1e-9 at both offsets (with the diagonal block: Omega_z
    # -0.0089 at the first)
    U, W = uniform_flow_step(str(tmp_path / "run"), offset)
    assert np.abs(U - [U0, 0.0, 0.0]).max() < 1e-6
    assert np.abs(W).max() < 1e-6
