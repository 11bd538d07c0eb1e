"""The direct solver for box meshes (FFTBox, fluid/boxSolvers) inside fdmFoam, for p and U (the cases'
linear_solver "FFTBox-all"; their default leaves U to symGaussSeidel): on every kind of box the
cases write it solves the real OpenFOAM matrices to round-off in one iteration (the residual is
OpenFOAM's own, of the matrix it was given), serial or decomposed over processors, the coupled answer
is the iterative solvers' one, and where it cannot solve (walls on two pairs of faces, a decomposed
fully periodic box) it says why and the fallback gives the same answer. The box solve as a preconditioner of OpenFOAM's PCG (`preconditioner FFTBox;`)
is what the solver runs, and falls back to DIC with its reason. The separable solve itself is tested
without OpenFOAM in fluid/tests/test_separable_box_solver.cpp."""
import os
import re

import numpy as np
import pytest

from fdmsubgrid import case, output

# A free sphere off-centre in a small box, a mean pressure gradient and the walls driving the flow: every
# matrix of fdmFoam is assembled and solved (the momentum predictor on, to solve U too)
U_WALL = 0.5
BOXES = {
    "periodic": ("cyclic", "cyclic", "cyclic"),
    "moving walls across y": ("cyclic", ((-U_WALL, 0, 0), (U_WALL, 0, 0)), "cyclic"),
    "slip walls across y": ("cyclic", "slip", "cyclic"),
    "walls across z": ("cyclic", "cyclic", ((0, 0, 0), (U_WALL, 0, 0))),
    "walls across y and z": ("cyclic", ((0, 0, 0), (0, 0, 0)), ((0, 0, 0), (U_WALL, 0, 0))),
}
SOLVE = re.compile(r"^(\w+):\s+Solving for (\w+), Initial residual = ([0-9.eE+-]+), "
                   r"Final residual = ([0-9.eE+-]+), No Iterations (\d+)", re.M)


GRAD_P0 = (-0.1, 0, 0)


def run_free_sphere(tmp_path, name, faces, linear_solver, np_fluid=1, tol_lambda=1e-9, edit=None, held=False):
    """edit(fvSolution text) -> text: the written fvSolution changed before the run; held: the sphere
    carries the force V0 grad P0 that balances the mean pressure gradient (Eq. 43), which a box
    without walls holding the fluid needs for its steady flow to exist"""
    box = case.Box((0, 0, 0), (4.0, 4.0, 4.0), 0.25, faces=faces)
    root = str(tmp_path / ("%s_%s_np%d%s" % (name.replace(" ", "_"), linear_solver, np_fluid,
                                             "_" + edit.__name__ if edit else "")))
    # the inner iteration converged far below the comparison's 1e-6, the linear solves tight (relTol 0)
    case.write_fluid_case(os.path.join(root, "fluid"), box, grad_p0=GRAD_P0, tol_lambda=tol_lambda, n_max=300,
                          n_particles=1, tol_u=1e-10, tol_p=1e-10, linear_solver=linear_solver,
                          momentum_predictor=True)
    case.write_dem_input(os.path.join(root, "dem"), box, [(1.9, 2.1, 2.05, 1.0)], fix_options="move no",
                         before_run=case.balancing_force_line(box, GRAD_P0) if held else "")
    if edit:
        path = os.path.join(root, "fluid", "system", "fvSolution")
        with open(path) as f:
            text = f.read()
        with open(path, "w") as f:
            f.write(edit(text))
    case.run(root, np_fluid=np_fluid)
    with open(os.path.join(root, "log.fluid")) as f:
        log = f.read()
    return log, output.particles(os.path.join(root, "fluid"))


def velocities(particles):
    """The free sphere's velocity and angular velocity (it is force-free: fix fdm/couple ... move no
    keeps its place, not its velocity)"""
    return np.array([particles[c][-1] for c in ("Ux", "Uy", "Uz", "Wx", "Wy", "Wz")])


def assert_same_motion(particles, reference):
    """The free sphere's U and Omega equal the reference run's within 1e-6 of its largest component."""
    got, want = velocities(particles), velocities(reference)
    assert np.abs(got - want).max() < 1e-6 * np.abs(want).max(), (got, want)


def assert_every_solve_exact(log):
    assert "FFTBox: p solved directly" in log and "pressure reference solved exactly" in log, log[-3000:]
    assert "fallback" not in log
    solves = [m for m in SOLVE.finditer(log) if m.group(1) == "FFTBox"]
    assert len(solves) > 40
    solved = 0
    for m in solves:
        final, iterations = float(m.group(4)), int(m.group(5))
        # OpenFOAM's own (normalised) residual of the matrix it assembled, after one preconditioned CG
        # step; none where the initial residual was already below the tolerance
        assert iterations <= 1, m.group(0)
        if iterations:
            assert final < 1e-11, m.group(0)
        solved += iterations
    assert solved > 40


@pytest.mark.parametrize("name", ["periodic", "slip walls across y"])
def test_direct_solve_is_exact_where_no_wall_holds_the_fluid(tmp_path, env, name):
    # along slip walls or through a fully periodic box nothing holds the fluid back but the sphere: held
    # by the force that balances the mean pressure gradient (Eq. 43) it has a steady flow, which the
    # inner iteration reaches (a free sphere has none: the uniform flow grows by grad P0 alpha_lambda
    # per inner iteration and Anderson's extrapolation of it reached 1e11); with slip walls the
    # wall-normal velocity component has a matrix of its own
    log, _ = run_free_sphere(tmp_path, name, BOXES[name], "FFTBox-all", tol_lambda=1e-6, held=True)
    assert_every_solve_exact(log)
    assert "NOT converged" not in log, log[-3000:]


@pytest.mark.parametrize("name", ["moving walls across y", "walls across z"])
def test_direct_solve_is_exact_and_gives_the_iterative_answer(tmp_path, env, name):
    log, direct = run_free_sphere(tmp_path, name, BOXES[name], "FFTBox-all")
    assert_every_solve_exact(log)
    log_iterative, iterative = run_free_sphere(tmp_path, name, BOXES[name], "GAMG")
    assert_same_motion(direct, iterative)


def test_walls_on_two_pairs_of_faces_fall_back_with_the_reason(tmp_path, env):
    name = "walls across y and z"
    log, fallback = run_free_sphere(tmp_path, name, BOXES[name], "FFTBox-all")
    assert ("FFTBox: p is solved by GAMG (the fallback): walls across y and z: FFTBox solves boxes with walls "
            "on at most one pair of faces") in log, log[-3000:]
    assert "FFTBox: Ux is solved by smoothSolver (the fallback)" in log
    _, iterative = run_free_sphere(tmp_path, name, BOXES[name], "GAMG")
    assert_same_motion(fallback, iterative)


@pytest.mark.parametrize("np_fluid", [2, 3])
def test_a_decomposed_box_is_solved_directly_and_keeps_the_serial_answer(tmp_path, env, np_fluid):
    """fdmRun -f N: each processor transforms a slab of planes across the walls (3 processors: slabs of
    5, 5 and 6 of the 16 planes, whatever way fdmRun split the mesh); p and U are solved in one
    iteration to round-off and the sphere moves as in the serial run."""
    name = "moving walls across y"
    log, parallel = run_free_sphere(tmp_path, name, BOXES[name], "FFTBox-all", np_fluid=np_fluid)
    for field in ("p", "Ux"):
        assert ("FFTBox: %s solved directly on 16 x 16 x 16 cells, walls across y, decomposed over %d processors"
                % (field, np_fluid)) in log, log[-3000:]
    solves = [m.groups() for m in SOLVE.finditer(log)]
    assert len(solves) > 40 and {s[0] for s in solves} == {"FFTBox"}, log[-3000:]
    # one iteration, or none where the start is already within the tolerance 1e-10
    assert {s[4] for s in solves} <= {"0", "1"}
    assert max(float(s[3]) for s in solves if s[4] == "1") < 1e-12
    _, serial = run_free_sphere(tmp_path, name, BOXES[name], "FFTBox-all")
    assert_same_motion(parallel, serial)


def test_a_decomposed_periodic_box_falls_back_with_the_reason(tmp_path, env):
    """(Only the message: the fallback's answer is compared above, on the box where FFTBox also solves.)"""
    name = "periodic"
    log, _ = run_free_sphere(tmp_path, name, BOXES[name], "FFTBox", np_fluid=2, held=True)
    assert ("FFTBox: p is solved by GAMG (the fallback): the mesh is decomposed over 2 processors and is periodic "
            "along every axis: FFTBox solves a decomposed box only with walls across one axis") in log, log[-3000:]


def pcg_preconditioned_by_fftbox(fv_solution):
    """Every `solver FFTBox; fallback {...}` of fvSolution written as OpenFOAM's PCG with the FFTBox
    preconditioner"""
    text, n = re.subn(r"solver\s+FFTBox;\s*fallback\s*\{[^}]*\}",
                      "solver          PCG;\n        preconditioner  FFTBox;", fv_solution)
    assert n == 2, fv_solution
    return text


def test_the_preconditioner_in_openfoams_pcg_is_what_the_solver_runs(tmp_path, env):
    """`solver PCG; preconditioner FFTBox;` (the box solve as an lduMatrix::preconditioner in OpenFOAM's own
    PCG) is what `solver FFTBox;` runs: every solve the same residuals and iterations, the same answer bit
    for bit; where the box solve cannot serve, the preconditioner says why and preconditions with its
    fallback (DIC), and the answer is the iterative solvers' one."""
    name = "moving walls across y"
    log_solver, solver = run_free_sphere(tmp_path, name, BOXES[name], "FFTBox-all")
    log_pcg, pcg = run_free_sphere(tmp_path, name, BOXES[name], "FFTBox-all", edit=pcg_preconditioned_by_fftbox)
    assert "FFTBox: p preconditioned by the box solve on 16 x 16 x 16 cells, walls across y" in log_pcg, log_pcg[-3000:]
    by_solver = [m.groups() for m in SOLVE.finditer(log_solver)]
    by_pcg = [m.groups() for m in SOLVE.finditer(log_pcg)]
    assert len(by_solver) > 40 and {s[0] for s in by_solver} == {"FFTBox"} and {s[0] for s in by_pcg} == {"FFTBoxPCG"}
    assert [s[1:] for s in by_pcg] == [s[1:] for s in by_solver]
    assert np.array_equal(velocities(pcg), velocities(solver))

    name = "walls across y and z"
    log, fallback = run_free_sphere(tmp_path, name, BOXES[name], "FFTBox-all", edit=pcg_preconditioned_by_fftbox)
    assert ("FFTBox: p is preconditioned by DIC (the fallback): walls across y and z: FFTBox solves boxes with "
            "walls on at most one pair of faces") in log, log[-3000:]
    assert "FFTBox: Ux is preconditioned by DIC (the fallback)" in log
    _, iterative = run_free_sphere(tmp_path, name, BOXES[name], "GAMG")
    assert_same_motion(fallback, iterative)
