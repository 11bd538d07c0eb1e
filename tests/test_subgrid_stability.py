"""Stability of the particle solve, Eq. (31) with the sub-grid lubrication matrix R^SG (issue 4,
"Stability"): fdmDEM with pair_style fdm/subgrid (lubrication + frictional contact, h_r = 5e-3 a1)
and fix fdm/couple transport none (each sphere's isolated Stokes drag in place of the fluid: the
same R^SG, a weaker diagonal than with the fluid, so a harder system), DEM only, a few seconds each:

* a pair at the smallest gap the resistance functions resolve, xi = 1e-5 (below it they are frozen,
  paper 4.2), equal and unequal (a2/a1 = 1.4) spheres, held in place and free (a normal load that
  balances the contact spring at that gap plus a tangential couple that turns the pair), 1000 steps;
* a random packing (fdmsubgrid.packing, overlap relaxation: ~1.7 pairs per sphere at gaps ~1.5e-4 a1) of
  100 bidisperse spheres at phi = 0.5 sheared between two walls, 500 steps.

Checked: every step done, no NaN/inf, speeds bounded, no overlap beyond the roughness height, and
the solver iterations bounded. Thresholds from the measurements of docs/benchmarks.md ("Sub-grid
lubrication: stability and cost of the particle solve", scripts/benchmarkSubgrid.py). The full
version (`./Alltest --full`) shears the same kind of packing with the real fluid."""
import math
import os

import numpy as np
import pytest

from fdmsubgrid import case, demonly, output, packing

# a1/Delta = 3, the suspensions' mesh: its pairs (a2/a1 = 1, 1.4) are in the calibration table that the pair
# style's default model (calibrated) uses, whose range (xi up to 1) puts more pairs in R^SG than the cut-off's
ETA, DELTA, HR, KN = 1.0, 1.0 / 3.0, 5e-3, 1e4
CONTACT = (KN, KN, 0.5, HR)
CG_CAP = 1000  # fix fdm/couple: CG stops after max(1000, 6N) iterations (N <= 166 here)


def pair(a2, xi=1e-5, L=12.0):
    gap = xi * (1.0 + a2) / 2
    c = L / 2
    x = np.array([[c - 1.0 - gap / 2, c + 0.01, c + 0.02], [c + gap / 2 + a2, c + 0.01, c + 0.02]])
    return packing.Packing(x, [1.0, a2], [1, 1 if a2 == 1.0 else 2], [L] * 3)


def check_run(r, scene):
    assert r["ok"], r["log"]
    assert r["completed"], "stopped at step %s of %d" % (r["step"][-1] if len(r["step"]) else 0, scene.steps)
    assert r["finite"], "non-finite values in the record:\n" + r["log"]


@pytest.mark.parametrize("solver,tol", [("cg", None), ("cg", 1e-6), ("ldlt", None)])
@pytest.mark.parametrize("a2", [1.0, 1.4])
@pytest.mark.parametrize("move", [False, True], ids=["held", "free"])
def test_pair_at_minimum_gap(tmp_path, env, a2, solver, tol, move):
    p = pair(a2)
    gap0 = p.min_gap
    # free: kn (h_r - gap0) balances the contact spring at gap0, the couple of 5 N turns the pair
    fn = KN * (HR - gap0) if move else 10.0
    ft = 5.0
    scene = demonly.Scene(p, solver, tol, steps=1000, dt=1e-3, eta=ETA, delta=DELTA, contact=CONTACT, move=move,
                          forces={"one": ([1], (fn, ft, 0)), "two": ([2], (-fn, -ft, 0))}, dump_every=50)
    r = demonly.run(scene, str(tmp_path / "run"))
    check_run(r, scene)
    # no sphere is faster than an isolated one under the whole load (lubrication and contact only resist)
    assert r["max_speed"].max() < math.hypot(fn, ft) / (6 * math.pi * ETA * 1.0)
    assert r["max_speed"].max() > 1e-3  # it is driven: the solve is not trivial
    # 12 unknowns: CG converges in at most 12 iterations in exact arithmetic; measured 3 (equal), 7 (unequal)
    assert r["iterations"].max() <= 12
    # the pair stays near contact without overlapping (measured: gaps 0.43-1 gap0)
    gaps = [g for _, g in r["gap_history"]]
    assert 0 < min(gaps) and max(gaps) < HR, gaps


def sheared_packing(n=100, seed=1, box_multiple=None):
    p = packing.random_packing(n, 0.5, bidisperse=True, seed=seed, walls=(1,), box_multiple=box_multiple)
    assert p.min_gap >= 1e-4
    return p


@pytest.mark.parametrize("solver,tol", [
    ("ldlt", None),
    ("cg", 1e-6),
    pytest.param("cg", None, marks=pytest.mark.xfail(strict=True, reason=(
        "fix fdm/couple's default (Jacobi CG, tolerance 1e-10) hits its cap of max(1000, 6N) iterations at "
        "every step of a phi = 0.5 packing (its residual stays above 1e-10; accepted silently below 1e-6, "
        "and a 150-sphere packing stops at step 482 with 'did not converge'): docs/benchmarks.md"))),
], ids=["ldlt", "cg1e-6", "cg-default"])
def test_dense_packing_in_shear(tmp_path, env, solver, tol):
    p = sheared_packing()
    U = 0.5 * p.box[1]  # walls at -U and +U: shear rate 1/s
    scene = demonly.Scene(p, solver, tol, steps=500, dt=1e-3, eta=ETA, delta=DELTA, contact=CONTACT,
                          walls={"ylo": (-U, 0, 0), "yhi": (U, 0, 0)}, dump_every=50)
    r = demonly.run(scene, str(tmp_path / "run"))
    check_run(r, scene)
    # driven by the walls alone: measured max speed 0.73 U; a blow-up would be orders of magnitude above
    assert r["max_speed"].max() < 1.5 * U
    assert r["max_spin"].max() < 1.5 * U / 1.0
    # contacts (kn = 1e4 N/m) keep overlaps well inside the roughness height (measured -0.1 h_r)
    assert r["min_gap"] > -HR
    assert r["pair_blocks"].min() > p.n  # dense: more close pairs than spheres
    if solver == "cg":
        # measured (500 steps): median ~650, max ~760 with tolerance 1e-6; a solve at the cap has not converged
        assert r["iterations"].max() < 0.95 * CG_CAP, (np.median(r["iterations"]), r["iterations"].max())
    else:
        assert r["iterations"].max() == 1
    # the run-end line is read whole: one solve per step without the fluid, each at least one
    # back-substitution (one per Coulomb round), no solve stopped at the 100-round cap
    t = r["timing"]
    assert t is not None and t["solves"] == scene.steps, t
    assert t["back_substitutions"] >= t["solves"] and t["coulomb_rounds_max"] < 100, t


@pytest.mark.full
@pytest.mark.parametrize("solver,tol", [("ldlt", None), ("cg", 1e-6)])
def test_dense_packing_in_shear_with_fluid(tmp_path, env, solver, tol):
    # the same scene with the real fluid (fdmFoam, a1/Delta = 5, the paper's suspension tolerances)
    p = sheared_packing(box_multiple=DELTA)
    U = 0.5 * p.box[1]
    root = str(tmp_path / "run")
    box = case.Box((0, 0, 0), tuple(p.box), DELTA, faces=("cyclic", ((-U, 0, 0), (U, 0, 0)), "cyclic"))
    case.write_fluid_case(os.path.join(root, "fluid"), box, nu=ETA, rho=1.0, tol_lambda=1e-3, n_max=30, n_min=3,
                          tol_u=1e-5, tol_p=1e-3, n_particles=p.n)
    scene = demonly.Scene(p, solver, tol, steps=20, dt=1e-3, eta=ETA, delta=DELTA, contact=CONTACT,
                          walls={"ylo": (-U, 0, 0), "yhi": (U, 0, 0)}, fluid="portfile ../fluid/coupling.port")
    scene.write(os.path.join(root, "dem"))
    case.run(root)
    with open(os.path.join(root, "log.dem")) as f:
        r = demonly.analyse(scene, os.path.join(root, "dem"), f.read())
    check_run(r, scene)
    parts = output.particles(os.path.join(root, "fluid"))
    speed = np.sqrt(parts["Ux"] ** 2 + parts["Uy"] ** 2 + parts["Uz"] ** 2)
    assert np.all(np.isfinite(speed)) and speed.max() < 1.5 * U
    if solver == "cg":
        assert r["iterations"].max() < 0.95 * CG_CAP
