"""The frictional contact of pair_style fdm/subgrid in DEM-only scenes (fdmDEM, fix fdm/couple
transport none; cases/contactTuning, docs/contact.md): the steady gap under a load, the Coulomb
sliding threshold, equal and opposite contact forces, and the stability limit of the time step
against dt k_n / zeta. Units SI at the 1 m scale (a = 1 m, eta = 1 Pa s, Delta = 0.2 m,
h_r = 0.01 m, mu_s = 0.5, loads of 10 N). About 10 s."""
import math

import pytest

from conftest import load_case_module


@pytest.fixture(scope="module")
def ct():
    return load_case_module("contactTuning")


@pytest.fixture(scope="module")
def res(ct, tmp_path_factory):
    cutoff, wall_cutoff = ct.probe_cutoffs(str(tmp_path_factory.mktemp("probe")))
    p = ct.BASE
    return ct.Resistance(p["a"], p["eta"], p["delta"], cutoff, wall_cutoff)


@pytest.mark.parametrize("geometry, kn, lubrication", [
    ("pair", 2000.0, True),             # gap h_r/2 with lubrication
    ("pair", 2000.0 / 3.0, False),      # F/k_n = 1.5 h_r: an overlap of h_r/2 (no lubrication: it gets there)
    ("wall", 2000.0, True),             # a sphere pressed on a wall
])
def test_steady_gap_under_a_load(tmp_path, env, ct, res, geometry, kn, lubrication):
    # steady gap = h_r - F/k_n within 1 % of F/k_n; the contact force equals the load; on a pair the
    # contact forces are equal and opposite at every step
    r = ct.normal_run(res, str(tmp_path), geometry, kn, ct.LOAD, ct.BASE["hr"], lubrication=lubrication,
                      steps=1500 if lubrication else 400)
    assert r["ok"], r.get("log")
    assert abs(r["gap_error"]) < 0.01, r
    assert abs(r["gap_end"] - (ct.BASE["hr"] - ct.LOAD / kn)) < 0.01 * ct.LOAD / kn
    assert abs(r["normal_force_error"]) < 0.01, r
    if geometry == "pair":
        assert r["force_balance"] < 1e-9, r     # |F1 + F2| / F, every step
    if not lubrication:
        assert r["gap_end"] < 0                 # an overlap, as F > k_n h_r asks


def test_sticks_below_mu_s_fn(tmp_path, env, ct, res):
    # Ft = 0.5 mu_s Fn per contact: the sphere stops, each contact carries exactly Ft, no rotation
    for integrator in ("ab2", "euler"):
        r = ct.sliding_run(res, str(tmp_path), 0.5, integrator)
        assert r["ok"], r.get("log")
        assert r["stuck"], r
        assert abs(r["ft_over_Ft"] - 1) < 1e-6, r
        assert r["omega_max"] == 0.0 and r["normal_force_sum_max"] < 1e-9, r
    # the sphere's displacement is the spring's elongation Ft/k_t (position update euler, which
    # the contact history uses too)
    assert abs(r["displacement_over_spring"] - 1) < 0.01, r


def test_stuck_displacement_equals_spring_with_ab2(tmp_path, env, ct, res):
    r = ct.sliding_run(res, str(tmp_path), 0.5, "ab2")
    assert r["ok"] and r["stuck"], r
    assert abs(r["displacement_over_spring"] - 1) < 0.01, r


def test_slides_above_mu_s_fn(tmp_path, env, ct, res):
    # Ft = 1.5 mu_s Fn per contact: steady sliding, the tangential force of each contact is mu_s Fn
    # (within 1 %), the speed 2 (Ft - mu_s Fn) / zeta_t with the wall lubrication (within 1 %)
    r = ct.sliding_run(res, str(tmp_path), 1.5)
    assert r["ok"], r.get("log")
    assert not r["stuck"] and r["steady"], r
    assert abs(r["ft_over_muFn"] - 1) < 0.01, r
    assert abs(r["sliding_speed_error"]) < 0.01, r
    # just below the threshold it still sticks, just above it slides
    below, above = (ct.sliding_run(res, str(tmp_path), q) for q in (0.98, 1.02))
    assert below["stuck"] and not above["stuck"], (below, above)


def test_rolling_on_one_wall(tmp_path, env, ct, res):
    # a sphere pulled at its centre on one wall rolls; without lubrication the stuck contact carries
    # 4/7 of the load (6 pi eta a U = Ft - f, 8 pi eta a^2 Omega = f, U = a Omega)
    out = ct.rolling_runs(res, str(tmp_path), 1, "ab2")
    r = [x for x in out if not x["lubrication"]][0]
    assert r["ok"], r.get("log")
    assert abs(r["ft_over_Ft"] - 4.0 / 7.0) < 1e-3, r
    assert abs(r["slip_over_U"]) < 1e-6, r


@pytest.mark.parametrize("integrator", ["ab2", "euler"])
def test_stability_limit_of_the_time_step(tmp_path, env, ct, res, integrator):
    # two spheres with lubrication at their steady gap (h_r/2), perturbed by 1 % of F/k_n: the gap
    # error is multiplied each step by 1 - r (euler) or the largest root of l^2 - (1 - 3r/2) l - r/2
    # (ab2), r = dt k_n / zeta, zeta = 3 pi eta a + X^A_SG(gap) (fdmResistance): stable below
    # r = 2 (euler) or 1 (ab2)
    c = ct.StabilityConfig(res, "pair, lubrication", "pair", True, integrator)
    assert abs(c.zeta / (3 * math.pi + res.pair_XA(c.g_ss)) - 1) < 1e-12
    well_below = c.run(str(tmp_path), 0.5 * c.dt_estimate)
    assert well_below["ok"] and well_below["stable"] and well_below["label"] == "converged", well_below
    # the measured growth factor per step is the linear theory's
    assert abs(well_below["factor_measured"] - well_below["factor_theory"]) < 0.01, well_below
    # the fix's outputs give the same zeta: -(F^SG + F^FDM) / closing speed at the first step
    assert abs(well_below["zeta_from_outputs"] / c.zeta_at_start - 1) < 1e-6, well_below
    near_below, near_above = (c.run(str(tmp_path), f * c.dt_estimate) for f in (0.95, 1.05))
    assert near_below["stable"] and not near_above["stable"], (near_below, near_above)
    well_above = c.run(str(tmp_path), 2.0 * c.dt_estimate)
    assert well_above["ok"] and not well_above["stable"], well_above
    assert well_above["max_error_over_initial"] > 10, well_above


def test_stability_limit_of_the_tangential_spring(tmp_path, env, ct, res):
    # the same pair with a one-step tangential kick: the tangential spring relaxes through the slip
    # of the contact points (translation and rotation of both spheres), resistance zeta_t (sub-grid
    # block + Stokes, here about 15.6 N s/m against 929 for the normal mode); the history adds the
    # displacement of the step, so its limit is the integrator's: r = dt k_t / zeta_t = 1 with ab2
    c = ct.StabilityConfig(res, "pair tangential, lubrication", "pair_tangential", True, "ab2")
    assert abs(c.zeta / ct.StabilityConfig(res, "pair", "pair", True, "ab2").zeta) < 0.1   # the stiffer limit
    below, above = (c.run(str(tmp_path), f * c.dt_estimate) for f in (0.9, 1.1))
    assert below["ok"] and below["stable"], below
    assert above["ok"] and not above["stable"], above
    assert abs(above["factor_measured"] - above["factor_theory"]) < 0.02, above
