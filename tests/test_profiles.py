"""fdmsubgrid.profiles, fdmsubgrid.timeseries, fdmsubgrid.rheology (paper 6.1, 6.2): exact profiles of hand-computed
configurations, block-averaging errors, the transient rule, the Maron-Pierce fit. Pure Python, no
solver; a few seconds."""
import math

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.signal import lfilter

from fdmsubgrid import profiles as P
from fdmsubgrid import rheology as R
from fdmsubgrid import timeseries as T


def cap(a, h):
    """Volume of a spherical cap of height h (0 <= h <= 2a): the textbook formula, independent of
    the module's F(s)."""
    return math.pi * h * h * (3 * a - h) / 3


def ball(a):
    return 4 / 3 * math.pi * a ** 3


def snap(ys, radii, **kw):
    """Spheres on the y axis at x = z = 1."""
    pos = np.array([[1.0, y, 1.0] for y in ys])
    return P.Snapshot(pos, radii, **kw)


# ---- exact profiles, hand-computed configurations --------------------------------------------

def test_one_sphere_planes_bins_and_integral():
    ch = P.Channel.centred((4, 6, 5))                   # area L_x L_z = 20
    s = snap([0.0], [1.0])
    y = np.array([-1.5, -1.0, -0.5, 0.0, 0.3, 0.999, 1.0, 2.0])
    expected = np.pi * np.maximum(1 - y ** 2, 0) / 20
    assert np.allclose(P.profiles_on_planes(s, ch, y).phi, expected, rtol=1e-14, atol=1e-16)
    # bins: the halves of the sphere, nothing elsewhere
    b = P.profiles_in_bins(s, ch, [-3, -1, 0, 1, 3])
    assert np.allclose(b.phi, [0, ball(1) / 2 / 20, ball(1) / 2 / 20, 0], rtol=1e-14, atol=1e-16)
    # slab volumes: caps by the textbook formula
    v = P.slab_volumes([0.0, 0.3], [1.0, 1.0], [-3.0, 0.0, 0.5], [-0.6, 3.0, 0.5])
    assert np.allclose(v, [[cap(1, 0.4), ball(1) / 2, 0], [cap(1, 0.1), ball(1) - cap(1, 0.7), 0]], rtol=1e-13)
    # the integral of phi over the channel / L_y = phi_bulk
    assert P.volume_fraction(s, ch) == pytest.approx(ball(1) / 120, rel=1e-14)
    assert P.bulk_volume_fraction(s, ch) == pytest.approx(ball(1) / 120, rel=1e-14)
    # an off-centre sphere across two bin edges: caps by the textbook formula
    s = snap([0.3], [1.0])
    b = P.profiles_in_bins(s, ch, [-3, 0, 1, 3])
    below, above = cap(1, 0.7), cap(1, 0.3)
    assert np.allclose(b.phi * 20 * np.diff(b.edges), [below, ball(1) - below - above, above], rtol=1e-13)


def test_two_spheres_across_a_bin_edge():
    ch = P.Channel((0, -2, 0), (3, 2, 2))                 # area 6, bins [-2, 0], [0, 2]
    U = np.array([[1.0, 0.1, 0.0], [-2.0, 0.0, 0.5]])
    SH = np.array([[1, 2, 3, 4, 5, 6], [-6, 5, -4, 3, -2, 1]], dtype=float)
    SC = np.array([[0, 1, 0, 0, 0, 0], [0, 3, 0, 2, 0, 0]], dtype=float)
    s = snap([0.3, -0.5], [1.0, 1.4], velocities=U, stresslet_h=SH, stresslet_c=SC)
    b = P.profiles_in_bins(s, ch, [-2, 0, 2])
    # sphere A (a = 1, y = 0.3): cap of height 0.7 below the plane y = 0
    # sphere B (a = 1.4, y = -0.5): cap of height 1.4 - 0.5 = 0.9 above the plane y = 0
    vA = np.array([cap(1, 0.7), ball(1) - cap(1, 0.7)])
    vB = np.array([ball(1.4) - cap(1.4, 0.9), cap(1.4, 0.9)])
    bin_volume = 6 * 2
    assert np.allclose(b.phi, (vA + vB) / bin_volume, rtol=1e-13)
    u_expected = (vA[:, None] * U[0] + vB[:, None] * U[1]) / (vA + vB)[:, None]
    assert np.allclose(b.u_p, u_expected, rtol=1e-13)
    sh = (vA[:, None] * SH[0] / ball(1) + vB[:, None] * SH[1] / ball(1.4)) / bin_volume
    sc = (vA[:, None] * SC[0] / ball(1) + vB[:, None] * SC[1] / ball(1.4)) / bin_volume
    assert np.allclose(b.sigma_h, sh, rtol=1e-13)
    assert np.allclose(b.sigma_c, sc, rtol=1e-13, atol=1e-16)
    assert np.allclose(b.sigma_p, sh + sc, rtol=1e-13)


def test_bin_values_are_the_integrals_of_the_plane_values():
    rng = np.random.default_rng(3)
    ch = P.Channel.centred((6, 8, 6))
    n = 12
    a = rng.choice([1.0, 1.4], n)
    y = rng.uniform(-4 + a, 4 - a)
    s = P.Snapshot(np.column_stack([rng.uniform(-3, 3, n), y, rng.uniform(-3, 3, n)]), a,
                   velocities=rng.normal(size=(n, 3)), stresslet_h=rng.normal(size=(n, 6)))
    edges = np.array([-4, -2.5, -1.0, 0.2, 1.7, 4])
    b = P.profiles_in_bins(s, ch, edges)
    breaks = np.concatenate([y - a, y + a])
    for k in range(len(edges) - 1):
        lo, hi = edges[k], edges[k + 1]
        pts = breaks[(breaks > lo) & (breaks < hi)]

        def f(yy, col):
            p = P.profiles_on_planes(s, ch, [yy])
            return p.phi[0] if col is None else p.phi_u[0, 0] if col == "u" else p.sigma_h[0, 1]
        for col, value in ((None, b.phi[k]), ("u", b.phi[k] * b.u_p[k, 0]), ("s", b.sigma_h[k, 1])):
            integral = quad(f, lo, hi, args=(col,), points=pts, epsabs=1e-13, epsrel=1e-12, limit=200)[0]
            assert integral / (hi - lo) == pytest.approx(value, rel=1e-9, abs=1e-13)


def test_bulk_integral_of_a_random_packing_is_exact():
    rng = np.random.default_rng(7)
    ch = P.Channel((0, 0, 0), (20, 25, 20))
    n = 1000
    a = np.where(rng.random(n) < 0.5, 1.0, 1.4)
    pos = np.column_stack([rng.uniform(0, 20, n), rng.uniform(a, 25 - a), rng.uniform(0, 20, n)])
    s = P.Snapshot(pos, a)
    bulk = P.bulk_volume_fraction(s, ch)
    assert abs(P.volume_fraction(s, ch) - bulk) <= 1e-12 * bulk
    b = P.profiles_in_bins(s, ch)                           # 25 bins of width a1 = 1
    assert len(b.phi) == 25
    assert abs(b.phi.mean() - bulk) <= 1e-12 * bulk
    assert abs(P.core_values(s, ch, h_layer=0.0).phi - bulk) <= 1e-12 * bulk
    # the fine profile integrates to it too (trapezoid on a fine grid: second order)
    f = P.profiles_on_planes(s, ch, ch.planes(0.005))
    assert np.trapezoid(f.phi, f.y) / 25 == pytest.approx(bulk, rel=1e-5)
    # the two species' profiles add up to the total
    s1, s2 = s.select(a == 1.0), s.select(a == 1.4)
    assert s1.n + s2.n == n
    assert np.allclose(P.profiles_in_bins(s1, ch, b.edges).phi + P.profiles_in_bins(s2, ch, b.edges).phi, b.phi, rtol=1e-13)


def test_sphere_cut_by_the_core_boundary():
    ch = P.Channel.centred((10, 20, 10))                  # core [-5, 5] with H_layer = 5 a1, a1 = 1
    S = np.array([[0, 2.0, 0, 1.0, 0, 0]] * 3)
    Sc = np.array([[0, 0.5, 0, -1.0, 0, 0]] * 3)
    s = snap([4.6, 0.0, 8.0], [1.0, 1.0, 1.4], stresslet_h=S, stresslet_c=Sc)
    c = P.core_values(s, ch)                               # default H_layer = 5 x smallest radius
    assert c.bounds == (-5.0, 5.0) and c.h_layer == 5.0
    inside = ball(1) - cap(1, 0.6) + ball(1)               # cut sphere, whole sphere, wall-layer sphere 0
    v_core = 100 * 10
    assert c.phi == pytest.approx(inside / v_core, rel=1e-14)
    share = (ball(1) - cap(1, 0.6)) / ball(1) + 1.0       # stresslet share of each particle in the core
    assert np.allclose(c.sigma_h, share * S[0] / v_core, rtol=1e-14)
    assert np.allclose(c.sigma_c, share * Sc[0] / v_core, rtol=1e-14)
    assert c.n_particles == 2


def test_core_shear_rate_recovered_exactly():
    rng = np.random.default_rng(11)
    ch = P.Channel.centred((20, 20, 20))
    n = 300
    a = rng.choice([1.0, 1.4], n)
    pos = rng.uniform(-10, 10, (n, 3))
    pos[:, 1] = rng.uniform(-10 + a, 10 - a)
    U = rng.normal(size=(n, 3))                            # random in the wall layers
    core = np.abs(pos[:, 1]) < 5
    U[core, 0] = 0.923 * pos[core, 1] + 0.2
    s = P.Snapshot(pos, a, velocities=U)
    assert P.core_shear_rate(s, ch) == pytest.approx(0.923, rel=1e-12)
    assert P.core_shear_rate(s, ch, weighting="volume") == pytest.approx(0.923, rel=1e-12)
    assert P.core_values(s, ch).gamma_dot == pytest.approx(0.923, rel=1e-12)
    assert math.isnan(P.core_shear_rate(snap([0.0], [1.0]), ch))


def test_profiles_invariant_under_shifts_and_relabelling():
    rng = np.random.default_rng(5)
    ch = P.Channel((0, 0, 0), (12, 10, 8))
    n = 80
    a = rng.choice([1.0, 1.4], n)
    pos = np.column_stack([rng.uniform(0, 12, n), rng.uniform(a, 10 - a), rng.uniform(0, 8, n)])
    kw = dict(velocities=rng.normal(size=(n, 3)), omegas=rng.normal(size=(n, 3)),
              stresslet_h=rng.normal(size=(n, 6)), stresslet_c=rng.normal(size=(n, 6)))
    s = P.Snapshot(pos, a, **kw)
    shifted = pos.copy()
    shifted[:, 0] = np.mod(shifted[:, 0] + 5.3, 12)
    shifted[:, 2] = shifted[:, 2] - 17.1                    # unwrapped is fine too
    perm = rng.permutation(n)
    variants = [P.Snapshot(shifted, a, **kw),
                P.Snapshot(pos[perm], a[perm], **{k: v[perm] for k, v in kw.items()})]
    y = ch.planes(0.05)
    ref_f, ref_b, ref_c = P.profiles_on_planes(s, ch, y), P.profiles_in_bins(s, ch), P.core_values(s, ch, 2.0)
    for v in variants:
        f, b, c = P.profiles_on_planes(v, ch, y), P.profiles_in_bins(v, ch), P.core_values(v, ch, 2.0)
        for x, r in ((f, ref_f), (b, ref_b)):
            for name in ("phi", "phi_u", "phi_omega", "sigma_h", "sigma_c"):
                assert np.allclose(getattr(x, name), getattr(r, name), rtol=1e-12, atol=1e-14)
        assert c.phi == pytest.approx(ref_c.phi, rel=1e-13)
        assert c.gamma_dot == pytest.approx(ref_c.gamma_dot, rel=1e-12)
        assert np.allclose(c.sigma_h, ref_c.sigma_h, rtol=1e-12, atol=1e-15)


def test_wall_normal_axis_is_general():
    """The same configuration with the walls normal to z and the flow along y gives the same profiles."""
    rng = np.random.default_rng(9)
    n = 40
    a = rng.choice([1.0, 1.4], n)
    pos = np.column_stack([rng.uniform(0, 8, n), rng.uniform(a, 10 - a), rng.uniform(0, 6, n)])
    U = rng.normal(size=(n, 3))
    S = rng.normal(size=(n, 6))
    ch = P.Channel((0, 0, 0), (8, 10, 6))                                # walls y, flow x
    # relabel axes: new (x, y, z) = old (z, x, y): walls along z, flow along y
    perm = [2, 0, 1]
    ch2 = P.Channel((0, 0, 0), (6, 8, 10), wall_axis=2, flow_axis=1)
    S2 = np.stack([S[:, [P.component(perm[i], perm[j]) for i, j in
                         ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))]]], 0)[0]
    s1 = P.Snapshot(pos, a, velocities=U, stresslet_h=S)
    s2 = P.Snapshot(pos[:, perm], a, velocities=U[:, perm], stresslet_h=S2)
    b1, b2 = P.profiles_in_bins(s1, ch), P.profiles_in_bins(s2, ch2)
    assert np.allclose(b1.phi, b2.phi, rtol=1e-13)
    assert np.allclose(b1.u_p[:, perm], b2.u_p, rtol=1e-12)
    assert np.allclose(P.tensor(b1.sigma_h)[:, perm][:, :, perm], P.tensor(b2.sigma_h), rtol=1e-12, atol=1e-15)
    c1, c2 = P.core_values(s1, ch, 2.0), P.core_values(s2, ch2, 2.0)
    assert c1.gamma_dot == pytest.approx(c2.gamma_dot, rel=1e-12)
    xy1, xy2 = P.component(0, 1), P.component(1, 2)
    assert c1.sigma_h[xy1] == pytest.approx(c2.sigma_h[xy2], rel=1e-12)


def test_time_averaged_profiles():
    ch = P.Channel.centred((4, 6, 4))
    ux = np.random.default_rng(0).normal(2.0, 1.0, 16)
    snaps = []
    for k in range(16):                   # one sphere, its velocity random; the stresslet constant
        snaps.append(snap([0.4], [1.0], velocities=[[ux[k], 0, 0]], stresslet_h=[[0, 1, 0, 0, 0, 0]], time=0.5 * k))
    avg = P.average_profiles(snaps, ch, start_time=1.0)
    assert avg.n_snapshots == 14 and avg.start_time == 1.0
    one = P.profiles_in_bins(snaps[0], ch)
    assert np.allclose(avg.phi, one.phi, rtol=1e-14)
    assert np.allclose(avg.phi_error, 0, atol=1e-15)
    assert np.allclose(avg.sigma_h, one.sigma_h, rtol=1e-14) and np.allclose(avg.sigma_h_error, 0, atol=1e-15)
    filled = avg.phi > 0
    assert np.allclose(avg.u_p[filled, 0], ux[2:].mean()) and np.all(np.isnan(avg.u_p[~filled, 0]))
    assert np.allclose(avg.u_p_error[filled, 0], T.block_average(ux[2:]).error)
    fine = P.average_profiles(snaps, ch, y=ch.planes(0.1), errors=False)
    assert fine.phi_error is None and fine.edges is None
    assert np.allclose(fine.phi, P.profiles_on_planes(snaps[0], ch, ch.planes(0.1)).phi, rtol=1e-14)


# ---- time series -------------------------------------------------------------------------------

def ar1(n, rho, rng, sigma=1.0):
    """AR(1) x_t = rho x_t-1 + e_t with stationary variance sigma^2 (burn-in dropped)."""
    e = rng.standard_normal(n + 1000) * sigma * math.sqrt(1 - rho ** 2)
    return lfilter([1.0], [1.0, -rho], e)[1000:]


def ar1_error(n, rho, sigma=1.0):
    """Exact standard error of the mean of n stationary AR(1) samples."""
    k = np.arange(1, n)
    return sigma * math.sqrt((1 + 2 * np.sum((1 - k / n) * rho ** k)) / n)


def test_block_average_error_of_ar1_series():
    for rho, n in ((0.9, 2 ** 15), (0.5, 5000), (0.0, 2000)):
        for seed in range(8):
            x = ar1(n, rho, np.random.default_rng(seed))
            avg = T.block_average(x)
            assert avg.error == pytest.approx(ar1_error(n, rho), rel=0.2)
            assert avg.plateau
            g = (1 + rho) / (1 - rho)                       # statistical inefficiency
            assert avg.n_eff == pytest.approx(n / g, rel=0.4)
    # columns are independent series
    rng = np.random.default_rng(1)
    X = np.column_stack([ar1(3000, 0.8, rng) for _ in range(3)])
    avg = T.block_average(X)
    assert np.allclose(avg.error, [T.block_average(X[:, i]).error for i in range(3)])
    assert avg.level_errors.shape == (len(avg.block_sizes), 3)
    # a constant series has no error
    c = T.block_average(np.full(100, 2.5))
    assert c.mean == 2.5 and c.error == 0.0


def test_ratio_of_means_error():
    rng = np.random.default_rng(2)
    a = 3.0 + ar1(4000, 0.7, rng)
    r = T.ratio_of_means(a, np.full(4000, 2.0))            # constant denominator: plain error / 2
    assert r.mean == pytest.approx(a.mean() / 2, rel=1e-14)
    assert r.error == pytest.approx(T.block_average(a).error / 2, rel=1e-9)
    # correlated numerator and denominator: the ratio's scatter over seeds
    ratios, errors = [], []
    for seed in range(60):
        g = np.random.default_rng(100 + seed)
        b = 2.0 + 0.3 * ar1(2000, 0.8, g)
        num = 1.5 * b + 0.2 * ar1(2000, 0.8, g)
        r = T.ratio_of_means(num, b)
        ratios.append(r.mean)
        errors.append(r.error)
    assert np.mean(errors) == pytest.approx(np.std(ratios), rel=0.25)


def test_transient_rule_on_relaxation_plus_ar1_noise():
    """MSER-m: exponential relaxation (time constant tau = 40 samples, amplitude 5 sigma) on AR(1)
    noise (rho = 0.8, statistical inefficiency 9) with known mean, 2000 samples: in >= 90 % of
    200 seeds the start is after the relaxation (the transient left after it biases the mean by
    less than half its true standard error) and the mean is within 2 error bars of the truth."""
    n, tau, amp, rho, sigma, mu = 2000, 40.0, 0.5, 0.8, 0.1, 2.0
    t = np.arange(n) * 0.05                                 # strain
    transient = amp * np.exp(-np.arange(n) / tau)
    good, starts = 0, []
    for seed in range(200):
        x = mu + transient + ar1(n, rho, np.random.default_rng(seed), sigma)
        avg, tr = T.steady_average(x, t)
        d = tr.start
        assert tr.start_time == t[d]
        starts.append(d)
        bias_ok = abs(transient[d:].mean()) < 0.5 * ar1_error(n - d, rho, sigma)
        good += bias_ok and abs(avg.mean - mu) <= 2 * avg.error
    assert good >= 180
    starts = np.array(starts)
    assert starts.min() >= tau                              # never within the first e-folding
    assert np.median(starts) >= tau * math.log(amp / sigma)  # typically after the decay into the noise
    # no transient: little is dropped, the error bars still cover the truth
    covered, starts = 0, []
    for seed in range(200):
        x = mu + ar1(n, rho, np.random.default_rng(1000 + seed), sigma)
        avg, tr = T.steady_average(x, t)
        starts.append(tr.start)
        covered += abs(avg.mean - mu) <= 2 * avg.error
    assert covered >= 180
    assert np.median(starts) == 0


def test_transient_of_several_series_is_the_latest():
    rng = np.random.default_rng(4)
    n = 1000
    fast = 1 + 3 * np.exp(-np.arange(n) / 10) + 0.1 * ar1(n, 0.5, rng)
    slow = 1 + 3 * np.exp(-np.arange(n) / 60) + 0.1 * ar1(n, 0.5, rng)
    both = T.detect_transient(np.column_stack([fast, slow]))
    assert both.start == max(T.detect_transient(fast).start, T.detect_transient(slow).start)
    assert both.start == T.detect_transient(slow).start > T.detect_transient(fast).start
    with pytest.raises(ValueError):
        T.detect_transient(np.ones(10))
    with pytest.raises(ValueError):
        T.detect_transient(np.r_[np.ones(100), np.nan])
    # a drift over the whole run: no steady part
    drift = np.linspace(0, 1, 1000) + 0.05 * ar1(1000, 0.5, rng)
    assert not T.detect_transient(drift).steady
    assert T.detect_transient(slow).steady


# ---- rheology ----------------------------------------------------------------------------------

def test_shear_rheology_of_constant_series():
    ch = P.Channel.centred((20, 20, 20))
    n = 64
    sh = np.tile([0.3, 1.2, 0.0, -0.5, 0.0, 0.1], (n, 1))
    sc = np.tile([-0.4, 0.4, 0.0, -0.9, 0.0, -0.6], (n, 1))
    series = P.CoreSeries(times=np.arange(n) * 0.1, phi=np.full(n, 0.45), gamma_dot=np.full(n, 0.8),
                          sigma_h=sh, sigma_c=sc, n_particles=np.full(n, 300), channel=ch, h_layer=5.0)
    r = R.shear_rheology(series, eta=1.0)
    s12 = 0.8 + 1.6
    assert r.start_time == 0.0 and r.steady and r.n_samples == n
    assert r.eta_s.value == pytest.approx(3.0, rel=1e-14) and r.eta_s.error == pytest.approx(0, abs=1e-14)
    assert r.sigma_12.value == pytest.approx(s12, rel=1e-14)
    assert r.n1_hat.value == pytest.approx((-0.1 - (-1.4)) / s12, rel=1e-13)
    assert r.n2_hat.value == pytest.approx((-1.4 - (-0.5)) / s12, rel=1e-13)
    assert [e.value for e in r.sigma_c_hat] == pytest.approx([-0.4 / s12, -0.9 / s12, -0.6 / s12], rel=1e-13)
    assert R.shear_rheology(series, eta=2.0, start_time=3.0).eta_s.value == pytest.approx(2.0, rel=1e-14)
    assert R.shear_rheology(series, start_time=3.0).n_samples == n - 30


def test_shear_rheology_from_snapshots():
    """Snapshots -> core series -> eta_s: particles on U_x = gamma_dot y with constant stresslets."""
    rng = np.random.default_rng(8)
    ch = P.Channel.centred((20, 20, 20))
    n = 200
    a = rng.choice([1.0, 1.4], n)
    S = np.zeros((n, 6))
    S[:, 1] = 2.0 * (4 / 3 * np.pi * a ** 3)               # S_xy / V_p = 2 in every particle
    snaps = []
    for k in range(32):
        pos = rng.uniform(-10, 10, (n, 3))
        pos[:, 1] = rng.uniform(-10 + a, 10 - a)
        U = np.zeros((n, 3))
        U[:, 0] = 0.75 * pos[:, 1]
        snaps.append(P.Snapshot(pos, a, velocities=U, stresslet_h=S, time=0.1 * k))
    series = P.core_series(snaps, ch)
    assert series.h_layer == 5.0
    assert np.allclose(series.gamma_dot, 0.75, rtol=1e-12)
    assert np.allclose(series.sigma_h[:, 1], 2.0 * series.phi, rtol=1e-12)
    r = R.shear_rheology(series, start_time=0.0)
    assert r.eta_s.value == pytest.approx(1 + 2.0 * series.phi.mean() / 0.75, rel=1e-12)
    assert r.phi_core.value == pytest.approx(series.phi.mean(), rel=1e-14)


TABLE8_PHI_CORE = np.array([0.303, 0.359, 0.405, 0.458, 0.493, 0.543, 0.570])


def test_maron_pierce_fit():
    alpha, phi_m = 0.803, 0.59
    eta = R.maron_pierce(TABLE8_PHI_CORE, alpha, phi_m)
    fit = R.fit_maron_pierce(TABLE8_PHI_CORE, eta, 0.03 * eta)
    assert fit.alpha == pytest.approx(alpha, rel=1e-6) and fit.phi_m == pytest.approx(phi_m, rel=1e-7)
    assert fit.covariance.shape == (2, 2) and fit.chi2 < 1e-10 and fit.dof == 5
    assert fit(0.5) == pytest.approx(R.maron_pierce(0.5, alpha, phi_m), rel=1e-6)
    # noisy data (5 % error bars): the errors describe the scatter of the estimates
    fits = []
    for seed in range(200):
        rng = np.random.default_rng(seed)
        err = 0.05 * eta
        fits.append(R.fit_maron_pierce(TABLE8_PHI_CORE, eta + err * rng.standard_normal(eta.size), err))
    a = np.array([f.alpha for f in fits])
    pm = np.array([f.phi_m for f in fits])
    ea = np.array([f.alpha_error for f in fits])
    ep = np.array([f.phi_m_error for f in fits])
    assert np.mean(np.abs(a - alpha) <= 2 * ea) >= 0.9
    assert np.mean(np.abs(pm - phi_m) <= 2 * ep) >= 0.9
    assert np.std(pm) == pytest.approx(np.median(ep), rel=0.25)
    assert np.std(a) == pytest.approx(np.median(ea), rel=0.25)
    assert np.mean([f.chi2 for f in fits]) == pytest.approx(5, rel=0.25)
    corr = np.mean([f.covariance[0, 1] / (f.alpha_error * f.phi_m_error) for f in fits])
    assert corr == pytest.approx(np.corrcoef(a, pm)[0, 1], abs=0.1)


def test_plots_are_written(tmp_path):
    ch = P.Channel.centred((6, 8, 6))
    rng = np.random.default_rng(6)
    snaps = []
    for k in range(16):
        n = 30
        a = rng.choice([1.0, 1.4], n)
        pos = rng.uniform(-3, 3, (n, 3))
        pos[:, 1] = rng.uniform(-4 + a, 4 - a)
        U = np.zeros((n, 3))
        U[:, 0] = 0.9 * pos[:, 1]
        snaps.append(P.Snapshot(pos, a, velocities=U, stresslet_h=rng.normal(size=(n, 6)), time=k))
    coarse = P.average_profiles(snaps, ch)
    fine = P.average_profiles(snaps, ch, y=ch.planes(0.05), errors=False)
    path = P.plot_profiles(str(tmp_path / "profiles.png"), ch, coarse, fine, title="test")
    eta = R.maron_pierce(TABLE8_PHI_CORE, 0.803, 0.59)
    fit = R.fit_maron_pierce(TABLE8_PHI_CORE, eta, 0.05 * eta)
    path2 = R.plot_viscosity(str(tmp_path / "eta.png"), TABLE8_PHI_CORE, eta, 0.05 * eta, fit)
    for p in (path, path2):
        with open(p, "rb") as f:
            assert f.read(8) == b"\x89PNG\r\n\x1a\n"


def test_bad_input():
    with pytest.raises(ValueError):
        P.Channel((0, 0, 0), (1, -1, 1))
    with pytest.raises(ValueError):
        P.Channel((0, 0, 0), (1, 1, 1), wall_axis=1, flow_axis=1)
    with pytest.raises(ValueError):
        P.Snapshot(np.zeros((2, 3)), [1.0])
    with pytest.raises(ValueError):
        P.Snapshot(np.zeros((1, 3)), [1.0], stresslet_h=np.zeros((1, 5)))
    with pytest.raises(ValueError):
        P.Channel.centred((4, 4, 4)).core_bounds(2.0)
    with pytest.raises(ValueError):
        R.fit_maron_pierce([0.1, 0.2], [1, 2], [0.1, 0.1])


# ---- the momentum balance (fdmsubgrid.rheology.stress_balance, fdmsubgrid.output.read_wall_loads) ----------------

def _write_wall_records(run, steps, dt, fluid_forces, subgrid, contact, area=(40.0, 40.0)):
    """fdmFoam's walls.dat and fix fdm/couple's walls file by hand: forces (T, 2, 3) on yLow/ylo and
    yHigh/yhi; the fluid pressure force is (0, 7, 0) on every wall (not in the shear stress)."""
    import os
    os.makedirs(run / "fluid" / "postProcessing" / "fdm")
    os.makedirs(run / "dem")
    with open(run / "fluid" / "postProcessing" / "fdm" / "walls.dat", "w") as f:
        f.write("# fdmFoam: force of the fluid on each wall patch [N]; areas [m2]: yLow %g yHigh %g\n" % area)
        f.write("# step time " + " ".join("%s:%s%s" % (w, p, c) for w in ("yLow", "yHigh")
                                          for p in ("viscous", "pressure") for c in "XYZ") + "\n")
        for k, st in enumerate(steps):
            f.write("%d %.17g %s\n" % (st, st * dt, " ".join("%.17g %.17g %.17g 0 7 0" % tuple(fluid_forces[k, w]) for w in (0, 1))))
    with open(run / "dem" / "walls.dat", "w") as f:
        f.write("# fix fdm/couple walls: force of the particles on each wall [N]: sub-grid lubrication (Eq. D.6) "
                "and contact; timestep %r\n# step" % dt)
        f.write("".join(" %s:%s%s" % (w, p, c) for w in ("ylo", "yhi") for p in ("subgrid", "contact") for c in "XYZ"))
        f.write("\n")
        for k, st in enumerate(steps):
            f.write("%d %s\n" % (st, " ".join("%.17g %.17g %.17g %.17g %.17g %.17g" % (*subgrid[k, w], *contact[k, w]) for w in (0, 1))))


def test_wall_stress_signs_parts_and_balance(tmp_path):
    # Walls y = 0 (low) and y = 8 (high) of area 40; the suspension drags the high wall back (-x) and
    # the low one forward (+x): tau_lo = F_lo,x / A, tau_hi = -F_hi,x / A (n out of the suspension).
    from fdmsubgrid import output as O
    rng = np.random.default_rng(5)
    n = 64
    steps = np.arange(1, n + 1)
    fluid = np.zeros((n, 2, 3))
    sub = np.zeros((n, 2, 3))
    con = np.zeros((n, 2, 3))
    fluid[:, 0, 0], fluid[:, 1, 0] = 80.0, -84.0           # 2.0 and 2.1
    sub[:, 0, 0], sub[:, 1, 0] = 20.0, -16.0               # 0.5 and 0.4
    con[:, 0, 0], con[:, 1, 0] = 4.0 + rng.normal(0, 0.4, n), -4.0  # 0.1 (+ noise) and 0.1
    con[:, :, 1] = 50.0                                     # normal loads: not shear stress
    _write_wall_records(tmp_path, steps, 0.05, fluid, sub, con)
    loads = O.read_wall_loads(str(tmp_path))
    assert loads.faces == ("ylo", "yhi") and np.allclose(loads.areas, 40.0) and loads.particles
    assert np.array_equal(loads.steps, steps) and np.allclose(loads.times, 0.05 * steps)
    assert np.allclose(loads.fluid_pressure[:, :, 1], 7.0)
    channel = P.Channel((0, 0, 0), (10, 8, 4))
    tau = R.wall_shear_stresses(loads, channel)
    assert np.allclose(tau["fluid"], [2.0, 2.1]) and np.allclose(tau["subgrid"], [0.5, 0.4])
    assert np.allclose(tau["contact"][:, 1], 0.1) and np.allclose(tau["contact"][:, 0], con[:, 0, 0] / 40)
    assert np.allclose(tau["total"], tau["fluid"] + tau["subgrid"] + tau["contact"])
    # a core stress of 2.5 = eta gamma_core + Sigma^p_12 with gamma_core = 1, eta = 1, Sigma^p_12 = 1.5
    t = np.arange(20) * 0.5
    sigma = np.zeros((20, 6))
    sigma[:, P.component(0, 1)] = 1.5
    series = P.CoreSeries(times=t, phi=np.full(20, 0.3), gamma_dot=np.ones(20), sigma_h=sigma,
                          sigma_c=np.zeros((20, 6)), n_particles=np.full(20, 10), channel=channel, h_layer=1.0)
    rh = R.shear_rheology(series, eta=1.0, start_time=1.0)
    b = R.stress_balance(rh, loads, channel, strain_rate=1.0)
    sel = loads.times >= 1.0
    wall = np.mean(tau["total"][sel].mean(axis=1))
    assert b.n_steps == int(np.sum(sel)) and b.start_time == 1.0
    assert b.core.value == pytest.approx(2.5) and b.wall.value == pytest.approx(wall, rel=1e-12)
    assert b.rel_error == pytest.approx(abs(2.5 - wall) / wall, rel=1e-12)
    assert b.wall_fluid.value == pytest.approx(2.05) and b.wall_subgrid.value == pytest.approx(0.45)
    assert b.wall_lo.value == pytest.approx(np.mean(tau["total"][sel, 0]))
    assert b.wall_asymmetry == pytest.approx(abs(b.wall_lo.value - b.wall_hi.value) / wall)
    assert 0 < b.wall.error < 0.1 and b.core.error == 0.0
    assert b.rel_error_err == pytest.approx(b.wall.error / wall)
    d = b.as_dict()
    assert d["stress_balance_rel_error"] == b.rel_error and d["stress_wall_contact"] == b.wall_contact.value
    # too few steps in the window, and unknown walls, are errors that say so
    with pytest.raises(ValueError, match="steps with wall loads"):
        R.stress_balance(rh, loads, channel, start_time=3.0 - 1e-12 + 0.05 * 60)
    with pytest.raises(KeyError, match="no wall 'zlo'"):
        R.wall_shear_stresses(loads, P.Channel((0, 0, 0), (10, 8, 4), wall_axis=2))


def test_gap_shear_stress_is_the_box_average():
    # eta (U_hi - U_lo)/L_y + sum_p (S^H + S^c)_12 / V: two spheres with given stresslets
    channel = P.Channel((0, 0, 0), (10, 8, 5))
    sh = np.zeros((2, 6))
    sc = np.zeros((2, 6))
    sh[:, P.component(0, 1)] = [30.0, 10.0]
    sc[0, P.component(0, 1)] = -4.0
    sh[:, 0] = 99.0                               # a normal component: not in the shear stress
    s = P.Snapshot([[2, 4, 2], [7, 3, 3]], [1.0, 1.4], stresslet_h=sh, stresslet_c=sc)
    assert R.gap_shear_stress(s, channel, eta=2.0, wall_shear_rate=0.5) == pytest.approx(1.0 + 36.0 / 400.0)
    assert R.relative_difference(1.1, 1.0) == pytest.approx(0.1) and math.isnan(R.relative_difference(1.0, 0.0))


def test_normal_stress_figure_needs_one_value_of_each_per_row(tmp_path):
    """Fig. 22's plot writes its PNG, and refuses columns of different lengths by saying which."""
    path = R.plot_normal_stresses(str(tmp_path / "n.png"), [0.3, 0.4], [-0.05, -0.06], [0.01, 0.01],
                                  [-0.1, -0.2], [0.01, 0.01], [[-0.2, -0.25, -0.1], [-0.5, -0.55, -0.3]],
                                  [[0.01] * 3] * 2)
    with open(path, "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(ValueError, match="2 phi_core, 2 N1, 1 N2 and 2 contact rows"):
        R.plot_normal_stresses(str(tmp_path / "m.png"), [0.3, 0.4], [-0.05, -0.06], [0.01, 0.01], [-0.1], [0.01],
                               [[-0.2, -0.25, -0.1], [-0.5, -0.55, -0.3]], [[0.01] * 3] * 2)
    # a row listed but not fitted is drawn hollow: one flag per row
    R.plot_normal_stresses(str(tmp_path / "h.png"), [0.3, 0.4], [-0.05, -0.06], [0.01, 0.01], [-0.1, -0.2],
                           [0.01, 0.01], [[-0.2, -0.25, -0.1], [-0.5, -0.55, -0.3]], [[0.01] * 3] * 2,
                           not_fitted=[True, False])
    with pytest.raises(ValueError, match="1 flags for 2 points"):
        R.plot_viscosity(str(tmp_path / "v.png"), [0.3, 0.4], [3.0, 6.0], [0.1, 0.2], not_fitted=[True])
