"""fdmsubgrid.contactstability: the stability theory of the contact springs and the resistances they act
against (docs/contact.md, sections 2b and 3), without a solver: the growth factors per step and the
time-step limits (3c, Eq. C4), the steady gap (3a), the spring recipe, the gap history stepped as fix
fdm/couple does, the measurement of a limit, and the resistances of fdmResistance at the values the
tables of docs/contact.md give (a = 1 m, eta = 1 Pa s, Delta = 0.2 m, cut-offs 0.65 and 0.75 cells).
A second or two (a few dozen fdmResistance calls)."""
import math

import numpy as np
import pytest

from fdmsubgrid import contactstability as cs
from fdmsubgrid import suspension, theory

PI = math.pi


# ---------------------------------------------------------------------------------------------
# the springs' theory
# ---------------------------------------------------------------------------------------------

def test_steady_gap_and_the_recipe():
    # h_ss = h_r - F/k_n (3a): h_r/2 at k_n = 2 F/h_r (recipe step 2), an overlap beyond F = k_n h_r
    assert cs.steady_gap(0.01, 10.0, 2000.0) == pytest.approx(0.005, rel=1e-15)
    assert cs.steady_gap(0.01, 10.0, 2000.0 / 3.0) == pytest.approx(-0.005, rel=1e-12)
    kn = cs.normal_stiffness(10.0, 0.01)
    assert kn == 2000.0 and cs.steady_gap(0.01, 10.0, kn) == pytest.approx(0.005, rel=1e-15)
    assert cs.steady_gap(0.01, 10.0, cs.normal_stiffness(10.0, 0.01, ratio=4.0)) == pytest.approx(0.0075, rel=1e-14)
    # the design load: the Stokes drag scale 6 pi a^2 tau
    assert cs.design_load(1.4, 2.0) == pytest.approx(6 * PI * 1.96 * 2.0, rel=1e-15)


def test_the_suspension_springs_follow_the_recipe():
    # suspension.choose_springs (the Couette and Poiseuille cases) through the same functions: the design
    # load of the large sphere, k_n = 2 F_max/h_r, the explicit ab2 limits zeta/k
    s = suspension.choose_springs(stress=1.5, dt=0.01, delta=1.0 / 3.0)
    assert s.design_load == cs.design_load(suspension.A2, 1.5)
    assert s.kn == cs.normal_stiffness(s.design_load, suspension.ROUGHNESS) and s.kt == s.kn
    assert s.dt_limit_normal == cs.explicit_time_step_limit(s.zeta_n, s.kn, "ab2")
    assert s.dt_limit_tangential == cs.explicit_time_step_limit(s.zeta_t, s.kt, "ab2")


def test_the_suspension_springs_report_the_scenes_model_and_the_mid_gap_lever_arm():
    # zeta_n, zeta_t of the a1-a1 pair at h_r/2 come from the sub-grid model the scene runs with (calibrated
    # unless asked) and the contact points in the middle of the gap (docs/contact.md 2); the springs
    # themselves do not depend on either. At a1/Delta = 3: zeta_t 17.16 N s/m (calibrated) against 19.40
    # (cut-off model) and 19.42 with the lever arm a1 (fdmResistance matrix, 12 x 12 solve)
    delta = 1.0 / 3.0
    calibrated = suspension.choose_springs(stress=1.5, dt=0.01, delta=delta)
    cutoff = suspension.choose_springs(stress=1.5, dt=0.01, delta=delta, model="cutoff")
    gap = 0.5 * suspension.ROUGHNESS
    assert (calibrated.zeta_n, calibrated.zeta_t) == theory.pair_mode_resistances(
        suspension.A1, suspension.A1, gap, delta, suspension.ETA, model="calibrated", contact_in_mid_gap=True)
    assert calibrated.zeta_t == pytest.approx(17.16, abs=0.01)
    assert cutoff.zeta_t == pytest.approx(19.40, abs=0.01)
    lever_a = theory.pair_mode_resistances(suspension.A1, suspension.A1, gap, delta, suspension.ETA)[1]
    assert lever_a == pytest.approx(19.42, abs=0.01)
    assert (calibrated.kn, calibrated.kt, calibrated.design_load) == (cutoff.kn, cutoff.kt, cutoff.design_load)
    with pytest.raises(ValueError, match="model"):
        theory.pair_mode_resistances(1.0, 1.0, gap, delta, model="exact")


def test_limit_ratio_and_the_time_step_limits_of_docs_contact_md():
    assert cs.limit_ratio("ab2") == 1.0 and cs.limit_ratio("euler") == 2.0
    with pytest.raises(ValueError, match="integrator"):
        cs.limit_ratio("rk4")
    # docs/contact.md 3c: the pair with lubrication at h_r/2 (zeta 929.4 N s/m, k_n 2000 N/m)
    assert cs.explicit_time_step_limit(929.4, 2000.0, "ab2") == pytest.approx(0.4647)
    assert cs.explicit_time_step_limit(929.4, 2000.0, "euler") == pytest.approx(0.9294)
    # a sphere between two walls: two tangential springs in series, 2 k_t
    assert cs.explicit_time_step_limit(83.25, 2 * 2000.0) == pytest.approx(0.0208125)


@pytest.mark.parametrize("integrator", cs.INTEGRATORS)
def test_explicit_growth_factor_is_one_at_the_limit(integrator):
    limit = cs.limit_ratio(integrator)
    assert cs.explicit_growth_factor(limit, integrator) == pytest.approx(1.0, abs=1e-12)
    for r in np.linspace(0.01, 0.99, 50) * limit:
        assert cs.explicit_growth_factor(r, integrator) < 1.0
    for r in np.linspace(1.01, 5.0, 50) * limit:
        assert cs.explicit_growth_factor(r, integrator) > 1.0
    # first order in r for a small step: the exact decay exp(-r) to O(r^2)
    r = 1e-4
    assert cs.explicit_growth_factor(r, integrator) == pytest.approx(math.exp(-r), abs=1e-7)


def test_explicit_growth_factors_of_the_table_of_docs_contact_md():
    # the theory column of the growth-factor table (3c) and the tangential kick (1.135 at r = 1.1, ab2)
    ab2 = {0.1: 0.905, 0.25: 0.784, 0.5: 0.640, 0.75: 0.678, 0.9: 0.868, 1.1: 1.135, 1.5: 1.693, 1.9: 2.269,
           2.1: 2.560, 3.0: 3.886, 6.0: 8.359}
    for r, factor in ab2.items():
        assert cs.explicit_growth_factor(r, "ab2") == pytest.approx(factor, abs=6e-4), r
        assert cs.explicit_growth_factor(r, "euler") == pytest.approx(abs(1 - r), abs=1e-15), r
    assert cs.explicit_growth_factor(1.1, "ab2") == pytest.approx(1.1347, abs=1e-4)


@pytest.mark.parametrize("integrator", cs.INTEGRATORS)
def test_implicit_growth_factor_below_one_at_every_step(integrator):
    # Eq. (C4): no time-step limit, no oscillation; 1/3 (ab2) and 0 (euler) as r grows
    r = np.geomspace(1e-6, 1e6, 200)
    factors = np.array([cs.implicit_growth_factor(x, integrator) for x in r])
    assert np.all(factors > 0) and np.all(factors < 1) and np.all(np.diff(factors) < 0)
    assert factors[-1] == pytest.approx(1 / 3 if integrator == "ab2" else 0.0, abs=1e-6)
    assert cs.implicit_growth_factor(1e-4, integrator) == pytest.approx(math.exp(-1e-4), abs=1e-7)


def test_implicit_growth_factors_of_docs_contact_md_3d():
    for r, factor in ((10, 0.375), (100, 0.33775), (1000, 0.33378)):
        assert cs.implicit_growth_factor(r, "ab2") == pytest.approx(factor, abs=1e-5)
    assert cs.implicit_growth_factor(1.0, "euler") == 0.5


# ---------------------------------------------------------------------------------------------
# the gap history and the measurement of stability
# ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize("integrator, r", [("euler", 0.5), ("euler", 1.5), ("ab2", 0.5), ("ab2", 0.9),
                                           ("ab2", 1.1)])
def test_gap_history_grows_by_the_linear_theory(integrator, r):
    # a steady contact (constant zeta: no lubrication) perturbed by 1 % of F/k_n: the error is multiplied
    # each step by the growth factor of the linear theory (the envelope, the ab2 error alternating)
    kn, load, h_r, zeta = 2000.0, 10.0, 0.01, 9.42
    g_ss = cs.steady_gap(h_r, load, kn)
    gap = cs.step_gap_history(g_ss + 0.01 * load / kn, load, kn, h_r, r * zeta / kn, 60, lambda h: zeta, integrator)
    c = cs.classify_perturbation(gap - g_ss, load / kn)
    assert c["factor_measured"] == pytest.approx(cs.explicit_growth_factor(r, integrator), rel=0.01)
    assert c["stable"] == (r < cs.limit_ratio(integrator))


def test_gap_history_settles_at_the_steady_gap():
    # from far: the approach at F/zeta per step, the contact, the steady gap, stopped once settled
    kn, load, h_r, zeta, dt = 2000.0, 10.0, 0.01, 9.42, 0.001
    gap = cs.step_gap_history(0.05, load, kn, h_r, dt, 100000, lambda h: zeta, "ab2", settle=(0.005, 1e-12))
    assert len(gap) < 100000 and gap[-1] == pytest.approx(0.005, abs=1e-12)
    assert gap[1] - gap[2] == pytest.approx(dt * load / zeta, rel=1e-12)      # Euler's first steps
    i = cs.settle_index(gap, 0.005, 0.01 * load / kn)
    assert i is not None and 0 < i < len(gap) - 20
    assert cs.settle_index([1.0, 1.0], 0.0, 0.5) is None and cs.settle_index([0.1, 0.0], 0.0, 0.5) == 0


def test_classify_labels():
    e = 1e-3 * 0.5 ** np.arange(100)
    c = cs.classify_perturbation(e, 1.0)
    assert c["stable"] and c["label"] == "converged" and c["factor_measured"] == pytest.approx(0.5)
    slow = 1e-3 * (-0.999) ** np.arange(100)
    assert cs.classify_perturbation(slow, 1.0)["label"] == "decaying"
    grow = 1e-3 * (-1.1) ** np.arange(100)
    c = cs.classify_perturbation(grow, 1.0)
    assert not c["stable"] and c["label"] == "growing" and c["factor_measured"] == pytest.approx(1.1)
    # a normal contact beyond the limit: lost and made again
    h_r, g_ss = 0.01, 0.005
    gap = g_ss + np.concatenate([1e-5 * (-1.5) ** np.arange(20), 0.006 * (-1.0) ** np.arange(80)])
    assert cs.classify_perturbation(gap - g_ss, 0.005, h_r, gap, g_ss)["label"].startswith("chatter")


@pytest.mark.parametrize("estimate", [0.37, 0.1, 1.0])
def test_bisection_finds_the_limit(estimate):
    limit = 0.37
    lo, hi, runs = cs.bisect_stability_limit(lambda dt: dict(stable=dt < limit, dt=dt), estimate, rel_tol=1e-3)
    assert lo < limit <= hi and hi / lo - 1 <= 1e-3
    assert all(r["stable"] == (r["dt"] < limit) for r in runs)


# ---------------------------------------------------------------------------------------------
# the resistances (fdmResistance), against the values of docs/contact.md
# ---------------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def res(env):
    return cs.ContactResistances(1.0, 1.0, 0.2)


def test_resistances_of_docs_contact_md(res):
    assert (res.cutoff, res.wall_cutoff) == theory.pair_style_cutoffs()
    h = 0.005                                                     # h_r/2 at the scenes' h_r = 0.01 a
    assert res.pair_normal(h) == pytest.approx(929.35, abs=0.01)
    assert res.pair_normal(h, lubrication=False) == pytest.approx(3 * PI)
    assert res.wall_normal(h) == pytest.approx(3675, rel=1e-3)
    assert res.wall_normal(h, lubrication=False) == pytest.approx(6 * PI)
    assert res.between_walls_tangential(h) == pytest.approx(83.25, abs=0.01)
    assert res.pair_slip(h) == pytest.approx(15.61, abs=0.01)
    # Stokes drag only: the contact points in the middle of the gap (lever arms l = a + h/2, the contact
    # law's), 1/zeta_t = 2 (1/(6 pi eta a) + l^2/(8 pi eta a^3)); 12/7 pi eta a at contact (h = 0)
    lever = 1.0 + h / 2
    assert res.pair_slip(h, lubrication=False) == pytest.approx(1 / (2 * (1 / (6 * PI) + lever ** 2 / (8 * PI))),
                                                                rel=1e-12)
    assert res.pair_slip(0.0, lubrication=False) == pytest.approx(12.0 / 7.0 * PI, rel=1e-12)
    # section 3a: the functions frozen at h = 1e-5 a: an overlap has zeta(1e-5 a)
    assert res.pair_normal(-0.005) == res.pair_normal(cs.MIN_GAP) == pytest.approx(4.7e5, rel=0.01)
    assert res.wall_normal(-0.005) == pytest.approx(1.9e6, rel=0.03)
    # nothing beyond the cut-off: the Stokes drag alone
    assert res.pair_normal(0.65 * 0.2) == 3 * PI and res.wall_normal(0.75 * 0.2) == 6 * PI


@pytest.mark.parametrize("gap", [1e-4, 0.0025, 0.005, 0.05])
def test_pair_normal_is_the_free_pairs_closing_resistance(res, gap):
    # 3 pi eta a + X^A_SG (the squeeze entry) against the closing resistance of the full 12 x 12 system
    # (Stokes diagonal + the sub-grid pair block, theory.pair_mode_resistances): the same to the round-off of
    # that solve (its condition number grows as 1/gap)
    zeta_n, _ = theory.pair_mode_resistances(1.0, 1.0, gap, 0.2, 1.0, res.cutoff, contact_in_mid_gap=True)
    assert res.pair_normal(gap) == pytest.approx(zeta_n, rel=1e-10)


def test_gap_table_interpolates_the_resistance(res):
    f = res.gap_table("pair", True)
    assert res.gap_table("pair", True) is f
    for gap in (3e-5, 0.0025, 0.007, 0.1):
        assert f(gap) == pytest.approx(res.pair_normal(gap), rel=1e-3), gap
    assert f(1.0) == 3 * PI and f(-0.01) == res.pair_normal(cs.MIN_GAP)
    assert res.gap_table("wall", False)(0.003) == 6 * PI
    with pytest.raises(ValueError):
        res.gap_table("sphere", True)


def test_stokes_limits_of_rolling_and_sliding():
    # a sphere on a wall, Stokes drag only: the contact point's slip resistance and the fraction of a pull at
    # the centre its stuck contact carries (6 pi eta a U = F - f, 8 pi eta a^2 Omega = f, U = a Omega)
    a, eta = 1.3, 0.7
    zeta = cs.wall_slip_resistance_stokes(a, eta)
    assert 1 / zeta == pytest.approx(1 / (6 * PI * eta * a) + a ** 2 / (8 * PI * eta * a ** 3), rel=1e-14)
    carried = 8 * PI * eta * a / (6 * PI * eta * a + 8 * PI * eta * a)      # f/F from the three equations
    assert cs.ROLLING_CONTACT_FRACTION == pytest.approx(carried, rel=1e-14)
    # sliding between two walls: each contact carries mu_s F_n, the rest moves the sphere
    assert cs.sliding_speed_between_walls(7.5, 10.0, 0.5, 83.25) == pytest.approx(2 * 2.5 / 83.25)
