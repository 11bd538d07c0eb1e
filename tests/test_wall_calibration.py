"""The tangential sphere-wall calibration of Appendix B (scripts/fdmsubgrid/wallcalibration.py, the
wall_YA ... wall_XC blocks of dem/resistance/data/subgrid_calibration.dat) and the torque it drives a
sphere with (fix fdm/torque): the box extrapolation and the fit on synthetic data, the dissipation rule
of the table, the shipped fits against their own measurements, and a torque on a free sphere in the
real coupled solver."""
import json
import math
import os

import numpy as np
import pytest

from conftest import PROJECT
from fdmsubgrid import case, output, wallcalibration as wc

DATA = os.path.join(PROJECT, "dem", "resistance", "data")
SHIPPED = os.path.join(DATA, "wall_tangential_calibration.json")


def test_three_box_extrapolation_is_exact_for_its_form():
    m_inf = np.array([0.02, -0.001, 0.03])
    c2, c3 = np.array([0.1, 0.02, -0.05]), np.array([0.4, -0.3, 0.2])
    boxes = (8.0, 12.0, 16.0)
    at = [m_inf + c2 / L ** 2 + c3 / L ** 3 for L in boxes]
    assert np.allclose(wc.extrapolate3(at, boxes), m_inf, rtol=0, atol=1e-15)


def test_mobility_frame_turns_the_torque_about_x_into_one_about_z():
    # a response built from a known tangential mobility [[m11, m12], [m12, m22]] and X^C mobility:
    # F e_x gives (U_x, Omega_z) = F (m11, m12); T e_x gives U_z = -T m12, Omega_x = T m22; T e_y Omega_y = T mxc
    m11, m12, m22, mxc = 0.02, -0.002, 0.03, 0.035
    F, T = 6 * math.pi, 8 * math.pi
    U = [[F * m11, 0.0, -T * m12]]
    W = [[T * m22, T * mxc, F * m12]]
    assert np.allclose(wc.mobility(U, W)[0], [m11, m12, m12, m22, mxc], rtol=1e-14)
    r = wc.resistance_from_mobility(wc.mobility(U, W))[0]
    assert np.allclose(np.array([[r[0], r[1]], [r[1], r[2]]]) @ np.array([[m11, m12], [m12, m22]]), np.eye(2))
    # Kim-Karrila units, wall below (d = -e_y): Y^B < 0 when a torque-free sphere sliding along the wall
    # rolls (m12 < 0)
    f = wc.functions_from_resistance(np.array([r]))[0]
    assert f[1] < 0 and f[0] > 0 and f[2] > 0


def test_fit_recovers_the_gap_the_solver_sees():
    gaps = np.array(wc.GAPS)
    truth = dict(eps_c=0.06, p=3.0)
    fdm = wc.theory_at("YA", wc.seen_gap(gaps, **truth))
    fit = wc.fit_function("YA", gaps, fdm)
    for k, v in truth.items():
        assert fit[k] == pytest.approx(v, rel=1e-4), k
    assert fit["f_0"] == pytest.approx(float(wc.theory_at("YA", 0.06)), rel=1e-6) and fit["max"] < 1e-6
    # the correction is the theory's singular part below eps_c, nothing far away
    assert wc.correction("YA", 1e-4, fit) == pytest.approx(wc.theory_functions(1e-4)["YA"] - fit["f_0"], rel=1e-3)
    assert 0 <= wc.correction("YA", 1.0, fit) < 1e-3


def _table_corrections(fits):
    rows = {k: np.array(v) for k, v in wc.table_blocks(3.0, fits).items()}
    eps = rows["YA"][:, 0]
    th = {k: np.array([wc.theory_functions(float("%.6g" % e))[k] for e in eps]) for k in wc.FUNCTIONS}
    return eps, {k: rows[k][:, 1] / eps for k in rows}, th, rows


def test_table_blocks_obey_the_dissipation_rule():
    """R_th + R_SG positive semi-definite: a correction that takes away the solver's excess coupling (Y^B_SG
    of the other sign than the theory, Y^A_SG = Y^C_SG = 0 there: indefinite alone) is kept as it is; one
    that would take away more than the theory has is clipped at the bound, the sign of Y^B_th + Y^B_SG kept."""
    base = {"YA": dict(eps_c=0.06, p=3.0), "YC": dict(eps_c=0.09, p=3.5), "XC": dict(eps_c=1e-4, p=8.0)}
    # the solver's measured excess (a/Delta 3): kept
    eps, s, th, rows = _table_corrections(dict(base, YB=dict(eps_c=0.036, p=8.0, bump=-0.23, eps_b=0.105, width=0.5)))
    assert eps[0] == pytest.approx(1e-5) and eps[-1] == pytest.approx(1.0)
    assert np.all(s["YA"] >= 0) and np.all(s["YC"] >= 0) and np.all(s["XC"] < 1e-3)
    k = int(np.argmin(np.abs(eps - 0.105)))
    fit = dict(eps_c=0.036, p=8.0, bump=-0.23, eps_b=0.105, width=0.5)
    assert s["YB"][k] == pytest.approx(wc.correction("YB", float(eps[k]), fit), rel=1e-9) and s["YB"][k] > 0.2
    alone = wc.SCALE["YA"] * s["YA"] * wc.SCALE["YC"] * s["YC"] - (wc.SCALE["YB"] * s["YB"]) ** 2
    assert alone[k] < 0                                        # indefinite on its own
    # ten times the excess, of the theory's sign: clipped
    eps, s, th, rows = _table_corrections(dict(base, YB=dict(eps_c=0.036, p=8.0, bump=3.0, eps_b=0.105, width=0.5)))
    coupled = {n: th[n] + s[n] for n in wc.FUNCTIONS}
    bound = np.sqrt(wc.SCALE["YA"] * coupled["YA"] * wc.SCALE["YC"] * coupled["YC"]) / wc.SCALE["YB"]
    assert np.all(np.abs(coupled["YB"]) <= bound * (1 + 1e-12))
    assert np.any(np.abs(coupled["YB"]) >= bound * (1 - 1e-12)) and np.all(coupled["YB"][:-1] <= 0)
    assert all(r[-1, 1] == 0 for r in rows.values())


@pytest.fixture(scope="module")
def shipped():
    with open(SHIPPED) as f:
        return json.load(f)


def test_shipped_calibration_covers_the_suspension_resolutions(shipped):
    # a1/Delta = 3 (the suspension runs), 4 and 5: a2 = 1.4 a1 at a1/Delta = 3 (a/Delta 4.2) lies between
    assert {3.0, 4.0, 5.0} <= {s["a_over_delta"] for s in shipped}
    for s in shipped:
        assert len(s["boxes"]) == 3 and len(s["offsets"]) >= 2
        # the table was made from these fits: analysing the kept measurements again gives them
        # (the same curve: a fit's parameters are only as sharp as the optimizer's stopping rule, and p moves
        # by 2e-6 between machines' rounding while the curve stays put)
        again = wc.summary(wc.from_summary(s))
        eps = np.geomspace(1e-3, 1, 61)
        for name in wc.FUNCTIONS:
            moved = ((wc.fdm_fit(name, eps, again["fits"][name]) - wc.fdm_fit(name, eps, s["fits"][name]))
                     / wc.residual_scale(name, eps))
            assert np.max(np.abs(moved)) < 1e-5, (s["a_over_delta"], name)
            assert again["fits"][name]["rms"] == pytest.approx(s["fits"][name]["rms"], abs=1e-7)


def test_shipped_fits_reproduce_their_measurements(shipped):
    """Y^A, Y^B and Y^C (the functions that set how fast a sphere slides and turns next to a wall): the fit
    within 3 % rms of the box-extrapolated, position-averaged measurements (residuals over the theory)."""
    for s in shipped:
        for name in ("YA", "YB", "YC"):
            assert s["fits"][name]["rms"] < 0.03, (s["a_over_delta"], name, s["fits"][name])
        # the solver's excess coupling sits where the sphere's surface is about 0.3 cell from the wall
        assert 0.25 < s["fits"]["YB"]["eps_b"] * s["a_over_delta"] < 0.4 and s["fits"]["YB"]["bump"] < 0


def test_shipped_corrections_end_in_the_lubrication_singularity(shipped):
    # far below a cell the solver sees a plateau, so the correction is the theory's ln(1/eps) growth:
    # between eps = 1e-4 and 1e-3 Y^A_SG grows by (8/15) ln 10 and Y^C_SG by (2/5) ln 10 (the leading terms)
    for s in shipped:
        gaps = s["gaps"]
        i3, i4 = gaps.index(1e-3), gaps.index(1e-4)
        c = np.array(s["correction"])
        assert c[i4, 0] - c[i3, 0] == pytest.approx(8 / 15 * math.log(10), rel=0.05)
        assert c[i4, 2] - c[i3, 2] == pytest.approx(2 / 5 * math.log(10), rel=0.05)


def torque_step(root, torque, a_over_delta=3.0, L=8.0):
    """One coupled step: a free sphere (a = 1) in a periodic cube of side L, eta = 1, driven by the
    torque `torque` of fix fdm/torque; returns (U, Omega)."""
    box = case.Box((0, 0, 0), (L, L, L), 1.0 / a_over_delta)
    case.write_fluid_case(os.path.join(root, "fluid"), box, nu=1.0, rho=1.0, tol_lambda=1e-6, n_max=500,
                          n_particles=1)
    centre = (0.5 * L + 0.17 / a_over_delta, 0.5 * L + 0.31 / a_over_delta, 0.5 * L + 0.05 / a_over_delta)
    case.write_dem_input(os.path.join(root, "dem"), box, [centre + (1.0,)], fix_options="move no",
                         before_run="fix             turn all fdm/torque %r %r %r" % tuple(torque),
                         runs=[case.RECORD_EVERY_STEP, "run 1"],
                         name="in.torque")
    case.run(root)
    records = output.read_particle_records(os.path.join(root, "dem", "particles.records"))
    return records["U"][-1, 0], records["omega"][-1, 0], records["T_dem"][-1, 0]


def test_fix_fdm_torque_turns_a_free_sphere(tmp_path, env):
    """fix fdm/torque's torque reaches Eq. (31) and is in LIGGGHTS's own torque (T_dem): the sphere turns
    about the torque's axis at T/(8 pi eta a^3) within the resolution's error (a/Delta = 3, box 8 a:
    measured Omega_z 0.963, Omega_x 0.977 under the same torque about -x; the other components below
    9e-4). It also translates by U = Omega x (x_p - x_c), measured |U| 0.034 a Omega: the discrete sphere
    (I_u) has its centroid x_c about 0.1 cell from the particle centre x_p at this offset, and Eq. (31)'s
    rigid-body block turns it about x_p."""
    T = 8 * math.pi
    U, W, T_dem = torque_step(str(tmp_path / "z"), (0.0, 0.0, T))
    assert np.allclose(T_dem, [0, 0, T], rtol=0, atol=1e-12)
    assert W[2] == pytest.approx(1.0, rel=0.05)
    assert np.abs(W[:2]).max() < 0.005 and np.linalg.norm(U) < 0.05
    U2, W2, _ = torque_step(str(tmp_path / "x"), (-T, 0.0, 0.0))
    assert W2[0] == pytest.approx(-W[2], rel=0.03)    # about x as about z, within the offset's anisotropy
    assert np.abs(W2[1:]).max() < 0.01


def test_fix_fdm_torque_refuses_a_bad_value(tmp_path, env):
    from test_bad_input import make_case, run_fdm, logs
    root = make_case(tmp_path, runs=("fix turn all fdm/torque 0 abc 0", "run 2"))
    status, out, wall = run_fdm(root, env)
    assert status != 0
    assert "fix fdm/torque: Ty must be a finite number, got 'abc'" in out + logs(root)
    assert wall < 30
