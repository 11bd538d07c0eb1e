"""The steady-state analysis of a pressure-driven channel (fdmsubgrid.poiseuille, issue 48) on synthetic data
with exact answers: the exponential approach and its time constant (with error bars that cover the truth),
the trend over a window, the steady window (and a stall before a rise, which MSER takes as steady), the
central plateau's width, the shear stress against the exact line, the contact normal stress's uniformity,
and the SBM fed with this project's Table 8 rows. The analysis of a real run: test_poiseuille.py."""
import math
import os

import numpy as np
import pytest

from conftest import PROJECT
from fdmsubgrid import poiseuille, profiles, sbm

TABLE8 = os.path.join(PROJECT, "docs", "data", "validation_table8_fluidEvery.json")


def ar1(n: int, sigma: float, rho: float, rng: np.random.Generator) -> np.ndarray:
    """Correlated noise: an AR(1) series of standard deviation sigma and lag-1 correlation rho."""
    e = rng.standard_normal(n) * sigma * math.sqrt(1 - rho ** 2)
    x = np.empty(n)
    x[0] = sigma * rng.standard_normal()
    for k in range(1, n):
        x[k] = rho * x[k - 1] + e[k]
    return x


def test_fit_approach_recovers_the_time_constant_and_its_error_covers_it():
    """phi_center(t) = 0.6 - 0.14 exp(-t/60) with correlated noise (rho 0.9, as the snapshots of a run):
    tau within two error bars of 60 in at least 16 of 20 noise draws (the inefficiency-scaled error
    covers the truth; the plain least-squares error, sqrt(g) ~ 4 times smaller, would not)."""
    t = np.arange(750) * 0.4
    rng = np.random.default_rng(7)
    covered, errors = 0, []
    for _ in range(20):
        y = 0.6 - 0.14 * np.exp(-t / 60.0) + ar1(len(t), 0.005, 0.9, rng)
        fit = poiseuille.fit_approach(t, y)
        assert fit.ok and fit.inefficiency > 5
        covered += abs(fit.tau - 60.0) < 2 * fit.tau_err
        errors.append(fit.tau_err)
        assert fit.plateau == pytest.approx(0.6, abs=4 * fit.plateau_err)
    assert covered >= 16 and np.median(errors) < 6
    # without noise the fit is exact
    exact = poiseuille.fit_approach(t, 0.6 - 0.14 * np.exp(-t / 60.0))
    assert exact.tau == pytest.approx(60.0, rel=1e-6) and exact.plateau == pytest.approx(0.6, abs=1e-8)
    assert exact(t[100]) == pytest.approx(0.6 - 0.14 * math.exp(-t[100] / 60), rel=1e-8)


def test_fit_approach_of_a_falling_rms_with_its_floor_held_non_negative():
    t = np.arange(400) * 0.5
    y = 0.01 + 0.09 * np.exp(-t / 40.0)
    fit = poiseuille.fit_approach(t, y, plateau_min=0.0)
    assert fit.tau == pytest.approx(40.0, rel=1e-6) and fit.plateau == pytest.approx(0.01, abs=1e-8)
    # a straight rise has no time scale within 10 times the duration: no approach
    assert not poiseuille.fit_approach(t, 0.45 + 1e-4 * t).ok
    assert not poiseuille.fit_approach(t[:5], y[:5]).ok


def test_trend_is_exact_on_a_line_and_its_error_scales_with_the_correlation():
    t = np.linspace(100, 300, 501)
    tr = poiseuille.trend(t, 0.58 + 2e-4 * (t - 100))
    assert tr.slope == pytest.approx(2e-4, rel=1e-12) and tr.slope_err < 1e-15
    assert tr.change == pytest.approx(0.04, rel=1e-12)
    rng = np.random.default_rng(3)
    white = poiseuille.trend(t, 0.58 + 0.005 * rng.standard_normal(t.size))
    red = poiseuille.trend(t, 0.58 + ar1(t.size, 0.005, 0.95, rng))
    assert red.slope_err > 2.5 * white.slope_err
    with pytest.raises(ValueError, match="at least 3"):
        poiseuille.trend(t[:2], t[:2])


def test_steady_window_starts_three_migration_times_in_and_finds_the_plateau_flat():
    t = np.arange(1500) * 0.4
    rng = np.random.default_rng(11)
    pc = 0.6 - 0.13 * np.exp(-t / 50.0) + ar1(t.size, 0.004, 0.9, rng)
    rms = 0.015 + 0.09 * np.exp(-t / 50.0) + ar1(t.size, 0.003, 0.9, rng)
    w = poiseuille.steady_window(t, pc, rms)
    assert w.steady and w.reason == ""
    assert w.start_time == pytest.approx(3 * w.center.tau, abs=0.4)
    assert abs(w.center.tau - 50) < 2 * w.center.tau_err and abs(w.profile.tau - 50) < 3 * w.profile.tau_err
    assert abs(w.trend.slope) <= poiseuille.SLOPE_SIGMAS * w.trend.slope_err


def test_steady_window_spans_a_migration_time_at_least():
    """A flat window from 3 tau that is shorter than tau (+ its error bar) cannot tell a slow rise from the
    centre's swings: not steady until the series holds one more migration time, then steady."""
    rng = np.random.default_rng(11)   # the series of the test above
    t = np.arange(1500) * 0.4
    pc = 0.6 - 0.13 * np.exp(-t / 50.0) + ar1(t.size, 0.004, 0.9, rng)
    rms = 0.015 + 0.09 * np.exp(-t / 50.0) + ar1(t.size, 0.003, 0.9, rng)
    short = t <= 3.5 * 50
    w = poiseuille.steady_window(t[short], pc[short], rms[short])
    assert not w.steady and "less than 1 migration time" in w.reason and "run longer" in w.reason, w.reason
    assert w.start_time == pytest.approx(3 * w.center.tau, abs=0.2)
    assert w.end_time - w.start_time < w.center.tau + w.center.tau_err
    w = poiseuille.steady_window(t, pc, rms)
    assert w.steady and w.end_time - w.start_time >= poiseuille.STEADY_WINDOW_TAUS * (w.center.tau + w.center.tau_err)


def test_steady_window_is_not_fooled_by_a_stall_before_a_rise():
    """phi_center rises to 0.55, stalls from t 100 to 200, rises again to 0.60 by the end (t 300): MSER
    puts the start in the stall; steady_window says not steady (the run too short for its migration time,
    or phi_center still rising over the window)."""
    t = np.arange(750) * 0.4
    rng = np.random.default_rng(5)
    pc = 0.46 + 0.09 * (1 - np.exp(-t / 20.0)) + 0.05 * np.clip((t - 200) / 100, 0, 1) + ar1(t.size, 0.003, 0.9, rng)
    rms = np.abs(pc - pc[-1]) + 0.01
    w = poiseuille.steady_window(t, pc, rms)
    assert w.mser_start_time < 200
    assert not w.steady and ("rises" in w.reason or "run longer" in w.reason), w.reason
    assert w.start_time >= 150   # averaged over the latest part, the second half at least


@pytest.mark.parametrize("spacing", [0.5, 1.0])
def test_plateau_width_of_a_trapezoid_is_exact(spacing):
    """phi = 0.63 over |y| < 3, falling linearly to 0.45 at |y| = 6: above 0.6 over |y| < 3.5 (width 7),
    above 0.5 over |y| < 5 + 1/6 (the crossings are between points, on the straight flanks)."""
    y = np.arange(-6, 6 + 1e-9, spacing)
    phi = np.where(np.abs(y) < 3, 0.63, 0.63 - 0.18 * (np.abs(y) - 3) / 3)
    assert poiseuille.plateau_width(y, phi, 0.0, 0.6) == pytest.approx((7.0, -3.5, 3.5), abs=1e-12)
    assert poiseuille.plateau_width(y, phi, 0.0, 0.5)[0] == pytest.approx(2 * (3 + 0.13 / 0.18 * 3), abs=1e-12)
    # shifted and asymmetric: the crossings follow
    assert poiseuille.plateau_width(y + 10, np.where(y > 0, 0.63, phi), 10.0, 0.6)[1:] == pytest.approx((6.5, 16.0))
    # the centre below the threshold: no plateau
    assert poiseuille.plateau_width(y, phi - 0.05, 0.0, 0.6)[0] == 0.0


def test_central_plateau_of_identical_snapshots_has_no_spread():
    """A layered snapshot repeated 16 times: the width is that of its own profile in bins of a1, the block
    error zero, the plateau's phi its exact volume fraction over the bounds."""
    ch = profiles.Channel((0, 0, 0), (6, 12, 6))
    xs = []
    for layer in np.arange(4.2, 8.0, 0.55):       # a dense band in the middle (the spheres may overlap: geometry
        for x in np.arange(0.5, 6, 1.05):         # only), sparse layers outside
            for z in np.arange(0.5, 6, 1.05):
                xs.append((x, layer, z))
    for layer in (1.5, 10.5):
        for x in np.arange(0.5, 6, 2.0):
            xs.append((x, layer, 3.0))
    snap = profiles.Snapshot(np.array(xs), np.full(len(xs), 0.5))
    snaps = [profiles.Snapshot(snap.positions, snap.radii, time=float(k)) for k in range(16)]
    coarse = profiles.average_profiles(snaps, ch, edges=ch.bin_edges(1.0))
    plateau = poiseuille.central_plateau(snaps, ch, coarse, threshold=0.6)
    assert plateau.width == pytest.approx(poiseuille.plateau_width(coarse.y, coarse.phi, 6.0, 0.6)[0], rel=1e-12)
    assert 2 < plateau.width < 6 and plateau.width_err == 0.0
    assert plateau.phi == pytest.approx(profiles.volume_fraction(snap, ch, plateau.y_lo, plateau.y_hi), rel=1e-12)
    assert plateau.phi_err == pytest.approx(0.0, abs=1e-12)


def test_exact_line_deviation_reads_the_core_only():
    ch = profiles.Channel((0, 0, 0), (8, 12, 8))
    sc = poiseuille.Scales(grad=-1 / 6, u_c=3.0, tau_w=1.0, time_unit=2.0, width=12.0)
    y = np.arange(12) + 0.5
    core = np.abs(y - 6) < 3.5
    total = sc.grad * (y - 6) + np.where(core, 0.03 * np.cos(y), 0.4)
    assert poiseuille.exact_line_deviation(y, total, sc, ch, core) == pytest.approx(np.max(np.abs(0.03 * np.cos(y[core]))))
    # a line through the walls' stresses shifted by an asymmetry 0.2 tau_w: 0.2 off the exact one
    assert poiseuille.exact_line_deviation(y, sc.grad * (y - 6) + 0.2, sc, ch, core) == pytest.approx(0.2)


def average_of(y_edges: np.ndarray, phi: np.ndarray, u: np.ndarray, sigma_c_yy: np.ndarray, err: float):
    """A ProfileAverage in bins with the given phi, u_x and Sigma^c_yy (errors err on Sigma^c)."""
    n = len(phi)
    z3, z6 = np.zeros((n, 3)), np.zeros((n, 6))
    u3 = z3.copy()
    u3[:, 0] = u
    sc6 = z6.copy()
    sc6[:, 3] = sigma_c_yy
    return profiles.ProfileAverage(y=0.5 * (y_edges[1:] + y_edges[:-1]), edges=y_edges, phi=phi, u_p=u3, omega_p=z3,
                                   sigma_h=z6, sigma_c=sc6, sigma_p=sc6, phi_error=np.zeros(n), u_p_error=z3,
                                   omega_p_error=z3, sigma_h_error=z6, sigma_c_error=np.full((n, 6), err),
                                   sigma_p_error=np.full((n, 6), err), n_snapshots=10, start_time=0.0)


def test_sbm_fitted_to_the_table8_rows_on_its_own_channel():
    """The SBM fed with the Table 8 summary (seven rows): the Maron-Pierce fit is the summary's own (alpha,
    phi_m), Eq. 63 holds, the first integral Sigma_hat_22(phi) |y*| is constant outside the jammed zone,
    and sbm_differences of the model's own bin averages is zero, the jammed bins counted apart."""
    import json
    rows = sbm.couette_rows(TABLE8)
    assert len(rows) == 7 and max(r["phi_core"] for r in rows) < 0.56
    material = sbm.from_couette_results([TABLE8])
    fit = json.load(open(TABLE8))["fit"]
    assert material.phi_m == pytest.approx(fit["phi_m"], rel=1e-6)
    assert material.describe["alpha"] == pytest.approx(fit["alpha"], rel=1e-6)
    assert material.describe["phi_m_err"] == pytest.approx(fit["phi_m_error"], rel=1e-3)
    width = 40.0
    y_edge = 0.5 - sbm.LAYER_OVER_A1 / width
    model = sbm.solve(material, 0.47, y_edge=y_edge, u_edge=0.02)
    assert np.trapezoid(model.phi, model.y) / (2 * y_edge) == pytest.approx(0.47, rel=1e-4)
    outside = np.abs(model.y) > model.y_jammed * 1.001
    first = -material.sigma22(model.phi_r[outside]) * np.abs(model.y[outside])
    assert np.ptp(first) < 1e-6 * first.mean() and first.mean() == pytest.approx(model.invariant, rel=1e-6)
    assert model.y_jammed > 0 and np.all(model.phi[np.abs(model.y) <= model.y_jammed] == pytest.approx(material.phi_m))
    # the model against its own bin averages: no difference
    ch = profiles.Channel((0, 0, 0), (40, width, 20))
    sc = poiseuille.Scales(grad=-1 / 20, u_c=10.0, tau_w=1.0, time_unit=2.0, width=width)
    edges = ch.bin_edges(1.0)
    phi, u = [], []
    for a, b in zip(edges[:-1], edges[1:]):
        p, v = model.at(np.clip(np.linspace(a - 20, b - 20, 201) / width, -y_edge, y_edge))
        phi.append(p.mean())
        u.append(np.sum(p * v) / np.sum(p) * 2 * sc.u_c)
    d = poiseuille.sbm_differences(model, average_of(edges, np.array(phi), np.array(u), np.zeros(40), 0.1), ch, sc)
    assert d["phi_rms_diff"] < 1e-12 and d["u_rms_diff"] < 1e-12
    assert d["bins_compared"] == 34 and 0 < d["bins_jammed"] < 34   # the bins wholly 2.5 a1 from the walls


def test_contact_normal_stress_uniformity():
    """Sigma^c_yy uniform within its error bars in the SBM's region: mean exact, chi^2 per dof ~ 1 for
    noise of the stated errors, large for a gradient; the wall layers are left out."""
    ch = profiles.Channel((0, 0, 0), (8, 12, 8))
    sc = poiseuille.Scales(grad=-1 / 6, u_c=3.0, tau_w=1.0, time_unit=2.0, width=12.0)
    edges = ch.bin_edges(1.0)
    flat = np.full(12, -0.8)
    flat[[0, 1, -1, -2]] = -3.0           # the wall layers: ignored
    r = poiseuille.contact_normal_stress(average_of(edges, np.ones(12), np.ones(12), flat, 0.05), ch, sc)
    assert r["contact_normal_stress_core"] == pytest.approx(-0.8) and r["contact_normal_stress_core_chi2"] < 1e-20
    assert r["contact_normal_stress_core_err"] == pytest.approx(0.05 / math.sqrt(6))   # the 6 bins wholly in 2.5 < y < 9.5
    slope = -0.8 + 0.1 * (np.arange(12) - 5.5)
    assert poiseuille.contact_normal_stress(average_of(edges, np.ones(12), np.ones(12), slope, 0.05), ch,
                                            sc)["contact_normal_stress_core_chi2"] > 10


def test_steady_window_of_the_shipped_small_channel_run():
    """The real series of the L_y 12 a1 channel at its defaults to t = 300 (750 snapshots, shipped in its
    results): the window refitted from them is the one recorded, and says what docs/validation.md says: tau
    about 120 with an error bar near 40 % of it, 3 tau beyond the run (not steady), MSER's start in the stall
    before the rise of t 180-230, and the rise still within 2 error bars of flat over the second half."""
    from fdmsubgrid import results
    path = os.path.join(PROJECT, "docs", "data", "validation_poiseuille_L12_fluidEvery4.json")
    record = results.read_data(path)
    s = record["series"]
    w = poiseuille.steady_window(np.array(s["time"]), np.array(s["phi_center"]), np.array(s["rms_change"]))
    assert w.center.tau == pytest.approx(record["migration_time"], rel=1e-4)
    assert w.center.tau_err == pytest.approx(record["migration_time_err"], rel=1e-3)
    assert 80 < w.center.tau < 170 and 0.2 < w.center.tau_err / w.center.tau < 0.6
    assert not w.steady and "run longer" in w.reason and w.start_time == pytest.approx(150.4)
    assert 120 < w.mser_start_time < 180
    assert 0 < w.trend.slope < poiseuille.SLOPE_SIGMAS * w.trend.slope_err
