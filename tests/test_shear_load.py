"""cases/wallShear/shearLoad.py: the shear's own load on a sphere next to a wall (Goldman, Cox & Brenner's
Fs, Ts) as the solver resolves it, split from its resistance by linearity. First the split's conventions
without a solver (the theory's resistance and free sphere give back the theory's factors); then one small
coupled scene (8^3 a1, a1/Delta = 3, one offset, eps = 0.1 and 0.01: about 15 s): the solver's load is
GCB's within the box's share, its resistance misses the gap's singular part, which the correction supplies."""
import math

import numpy as np
import pytest

from conftest import assert_refused, load_case_module


@pytest.fixture(scope="module")
def shear_load():
    return load_case_module("wallShear", "shearLoad")


@pytest.mark.parametrize("eps", [0.001, 0.01, 0.1, 0.54, 2.0])
def test_split_gives_back_the_theory(shear_load, eps):
    # the theory's mobility (wallcalibration.mobility's layout [M11, M12, M21, M22, MXC]) and the theory's free
    # sphere V0: load_factors must return Ft, Fr, Tt, Tr, Fs, Ts of the theory (signs and normalisations)
    th = shear_load.theory_factors(eps)
    r = np.array([[6 * math.pi * th["Ft"], 6 * math.pi * th["Fr"]], [8 * math.pi * th["Tt"], 8 * math.pi * th["Tr"]]])
    assert r[0, 1] == pytest.approx(r[1, 0], rel=1e-6)          # 6 Fr = 8 Tt: the theory's reciprocity
    m = np.linalg.inv(r)
    u, w = shear_load.freeSphereWall.free_sphere(eps, th["Ft"], th["Tt"], th["Fr"], th["Tr"], th["Fs"], th["Ts"])
    v0 = (u * (1 + eps), -w / 2)                                # U_x = u gamma_dot d, Omega_z = -w gamma_dot/2
    got = shear_load.load_factors(v0, [m[0, 0], m[0, 1], m[1, 0], m[1, 1], 1.0], eps)
    for q in shear_load.FACTORS:
        assert got[q] == pytest.approx(th[q], rel=1e-6), q


@pytest.fixture(scope="module")
def small_scene(shear_load, tmp_path_factory, env):
    work = tmp_path_factory.mktemp("shearLoad")
    out = shear_load.main(["--boxes", "8", "--eps", "0.1", "0.01", "--positions", "1", "--workdir", str(work),
                           "--out", str(work / "shearLoad.json")])
    return {r["eps"]: r for r in out["rows"]}


def test_solver_load_is_gcb_within_the_small_box(small_scene):
    # measured (8^3 a1, one offset): Fs -7.4 %, -11.7 %, Ts -4.3 %, -3.6 % at eps 0.1, 0.01; the box lowers the
    # load (its mean flow slows); boxes 8, 12, 16 extrapolated put it at Fs -3 %, Ts +5 % near contact
    for eps, row in small_scene.items():
        assert -0.16 < row["Fs_rel_error"] < 0.0, (eps, row["Fs_rel_error"])
        assert abs(row["Ts_rel_error"]) < 0.1, (eps, row["Ts_rel_error"])


def test_solver_misses_the_gap_but_not_the_load(small_scene):
    # at eps = 0.01 the gap is a thirtieth of a cell: the solver's translational and rotational resistance
    # stops growing (a third below the theory's), while the shear's load, finite at contact, it keeps
    row = small_scene[0.01]
    assert row["Ft_rel_error"] < -0.2 and row["Tr_rel_error"] < -0.2, (row["Ft_rel_error"], row["Tr_rel_error"])
    assert abs(row["Fs_rel_error"]) < abs(row["Ft_rel_error"]) / 2


def test_split_predicts_the_corrected_sphere(small_scene):
    # linearity in one box: the solver's R and F^s (correction off) plus the model's R^SG must give the free sphere
    # the corrected solver computes. Measured: within 0.003 % (U) and 0.12 % (Omega) at eps 0.1; 0.8 % and 1.7 % at
    # 0.01 (likely the off-plane motion the 2 x 2 split leaves out, docs/validation.md)
    for eps, tol in ((0.1, 0.005), (0.01, 0.03)):
        row = small_scene[eps]
        for q in ("Ux", "Wz"):
            measured, split = row[q + "_norm_corrected_rel_error"], row[q + "_norm_split_fits_rel_error"]
            assert abs(measured - split) < tol, (eps, q, measured, split)


@pytest.mark.parametrize("options, message", [
    (["--boxes", "8", "12"], "three to extrapolate"),
    (["--eps", "4"], "exact wall table"),
    (["--eps", "0"], "exact wall table"),
    (["--boxes", "4"], "from the moving wall"),
])
def test_bad_options_refused(shear_load, tmp_path, capsys, options, message):
    assert_refused(shear_load.main, options, message, tmp_path, capsys)
