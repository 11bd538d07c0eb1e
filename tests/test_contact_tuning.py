"""The frictional contact of pair_style fdm/subgrid in DEM-only scenes (fdmDEM, fix fdm/couple
transport none; cases/contactTuning, docs/contact.md): the steady gap under a load, the Coulomb
sliding threshold, equal and opposite contact forces, the stuck displacement F_t/k_t, and the
stability limits of the time step against dt k_n / zeta_n and dt k_t / zeta_t. Units SI at the 1 m
scale (a = 1 m, eta = 1 Pa s, Delta = 0.2 m, h_r = 0.01 m, mu_s = 0.5, loads of 10 N). About 20 s."""
import math

import pytest




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


@pytest.mark.parametrize("integrator", ["ab2", "euler"])
def test_sticks_below_mu_s_fn(tmp_path, env, ct, res, integrator):
    # Ft = 0.5 mu_s Fn per contact: the sphere stops, each contact carries exactly Ft, no rotation
    r = ct.sliding_run(res, str(tmp_path), 0.5, integrator)
    assert r["ok"], r.get("log")
    assert r["stuck"], r
    assert abs(r["ft_over_Ft"] - 1) < 1e-6, r
    assert r["omega_max"] == 0.0 and r["normal_force_sum_max"] < 1e-9, r
    # the spring history adds the displacement of each step (with ab2 the fix's v holds the step's
    # displacement rate 3/2 U_n - 1/2 U_(n-1) during the force computation), so the sphere's
    # displacement is the spring's elongation Ft/k_t with either integrator
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
    assert abs(c.zeta / (3 * math.pi + res.pair_squeeze(c.g_ss)) - 1) < 1e-12
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


@pytest.mark.parametrize("integrator", ["ab2", "euler"])
def test_stability_limit_of_the_tangential_spring(tmp_path, env, ct, res, integrator):
    # the same pair with a one-step tangential kick: the tangential spring relaxes through the slip
    # of the contact points (translation and rotation of both spheres), resistance zeta_t (sub-grid
    # block + Stokes, here about 15.6 N s/m against 929 for the normal mode). The history adds the
    # displacement of the step, so the spring error is multiplied per step by the integrator's
    # factor with r = dt k_t / zeta_t, and the limit is the normal spring's: r = 1 (ab2), 2 (euler)
    c = ct.StabilityConfig(res, "pair tangential, lubrication", "pair_tangential", True, integrator)
    assert c.limit_r == (1.0 if integrator == "ab2" else 2.0)
    assert abs(c.dt_estimate - c.limit_r * c.zeta / ct.BASE["kt"]) < 1e-12 * c.dt_estimate
    assert c.zeta < 0.1 * ct.StabilityConfig(res, "pair", "pair", True, integrator).zeta   # the stiffer limit
    # beyond the limit the spring grows by 1.135 (ab2) or 1.2 (euler) per step from the kick (0.05 N)
    # to a limit cycle at the Coulomb cap (5 N, ~0.999 of it after 50 steps): the linear growth is
    # judged before it, over 30 (20) steps
    below = c.run(str(tmp_path), 0.9 * c.dt_estimate)
    above = c.run(str(tmp_path), 1.1 * c.dt_estimate, steps=30 if integrator == "ab2" else 20)
    assert below["ok"] and below["stable"], below
    assert above["ok"] and not above["stable"] and not above["sliding_seen"], above
    # the growth factor beyond the limit is the linear theory's: ab2 the largest root of
    # l^2 - (1 - 3r/2) l - r/2 (1.135 at r = 1.1; the former Euler update of the history gave
    # |1 - r| = 0.1, stable), euler |1 - r| (1.2 at r = 2.2). (Below the limit the spring mode decays
    # within a few dozen steps and a slow one is left: the kick turns the line of centres a little
    # and the two loaded spheres roll on each other.)
    assert abs(above["r"] - 1.1 * c.limit_r) < 1e-12
    assert abs(above["factor_measured"] - above["factor_theory"]) < 0.01, above
    assert abs(above["factor_theory"] - (1.1347 if integrator == "ab2" else 1.2)) < 1e-4
