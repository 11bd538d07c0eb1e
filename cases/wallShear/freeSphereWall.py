#!/usr/bin/env python3
"""The reference of cases/wallShear: a free sphere near ONE plane wall in simple shear (paper 5.2.1).

A sphere of radius a, centre at height d = (1 + eps) a above the wall y = 0 at rest, in the shear
flow u = gamma_dot y e_x (unbounded above), force- and torque-free. It translates at U_x and
rotates at Omega_z. Sign convention (the case's frame: x the flow, y the wall normal, z = x cross y):
the vorticity of the flow is -gamma_dot e_z, so far from the wall U_x -> gamma_dot d and
Omega_z -> -gamma_dot/2. This module returns

  Ux_norm = U_x / (gamma_dot d)        -> +1 far from the wall, -> 0 (as 1/ln(1/eps)) at contact
  Wz_norm = Omega_z / (gamma_dot / 2)  -> -1 far from the wall, -> 0 (as 1/ln(1/eps)) at contact
  S_star  = S_xy / ((10/3) pi eta a^3 gamma_dot), Sangani et al. (2011) fit, paper Eq. (46)

How U and Omega are computed (Goldman, Cox & Brenner 1967, "GCB"). In GCB's frame (wall normal z',
rotation about y' = -z; Omega' = -Omega_z > 0 for this flow) the force and torque on the sphere are

  F_x  = -6 pi eta a Ft U + 6 pi eta a^2 Fr Omega' + 6 pi eta a d gamma_dot Fs                 (R1)
  T_y' =  8 pi eta a^2 Tt U - 8 pi eta a^3 Tr Omega' + 4 pi eta a^3 gamma_dot Ts              (R2)

(translation: drag Ft and a torque Tt > 0 that turns the sphere as if rolling on the wall;
rotation: torque Tr and a force Fr > 0 along the rolling direction's opposite; the symmetry of the
resistance matrix gives 6 Fr = 8 Tt; shear: the force Fs and torque Ts on the sphere held fixed).
In the case's frame, with Omega_z = -Omega', these read F_x = -6 pi eta a (Ft U + a Fr Omega_z)
+ 6 pi eta a d gamma_dot Fs and T_z = -(8 pi eta a^2 Tt U + 8 pi eta a^3 Tr Omega_z
+ 4 pi eta a^3 gamma_dot Ts). F_x = T_y' = 0 with u = U/(gamma_dot d), w = Omega'/(gamma_dot/2):

  Ft u - (a / 2d) Fr w = Fs,   Tr w = Ts + (2d/a) Tt u
  u = (Fs + (a/2d) Fr Ts / Tr) / (Ft - Fr Tt / Tr),   w = (Ts + (2d/a) Tt u) / Tr              (R3)

Far from the wall Ft = Fs = Tr = Ts = 1, Fr = Tt = 0: u = w = 1. The factors, by gap:
  * Ft, Tt, Fr, Tr for 1e-3 <= eps <= 3: the exact bipolar-coordinate table (Brenner 1961, Dean &
    O'Neill 1963, O'Neill 1964; 129 of its 3000 rows in wallSphereData.json, a cubic spline of
    ln(value) in ln(eps), within 2e-6 of every row of the full table);
  * the same below eps = 1e-3: the small-gap forms of Chaoui & Feuillebois (2003, Tables 11, 13),
    whose j = 0 terms are the lubrication asymptotes (they equal the table to 1e-7 at eps = 1e-3);
  * Fs, Ts (sphere held fixed in the shear): GCB's 9 tabulated gaps h/a = 1 ... 10.07, a cubic
    spline in x = a/d through them and the far-field point x = 0 (Fs = Ts = 1), its slope there
    the far-field one (dFs/dx = 9/16, as Ft; dTs/dx = 0: Ts = 1 - O(x^3)). Leaving each
    interior point out and interpolating it from the others misses it by at most 3.8e-4 (Fs,
    eps = 0.045) and 2.2e-4 (Ts, eps = 2.76): an upper bound of the interpolation error (the
    spacing doubles when a point is left out; a cubic's error then grows about 16 times);
  * eps > 3 (beyond the table): GCB's method of reflections, u = w = 1 - (5/16) (a/d)^3; against
    (R3) with the exact table it is within 1.5e-4 at eps = 3 (6e-4 at eps = 2).
Accuracy (measured by `freeSphereWall.py --check`, asserted by tests/test_wall_shear.py): the
translation and rotation factors of two independent sources agree at GCB's gaps (u, w within
1e-4 for eps >= 0.005; GCB's reduced table 1e-3 off at eps = 0.0032) and with Chaoui & Feuillebois
to 3e-8 for eps <= 1; the Fs, Ts interpolation moves u and w by at most 4e-4. The reference is
good to about 1e-3 in u and w over 1e-4 <= eps <= 10.

The stresslet has no second source here: Eq. (46) as the paper prints it, with Y = 1 + eps (its two
branches differ by 3 % at 1/Y = 0.85, where they join: the fit's own uncertainty there).

  freeSphereWall.py                  the reference at the case's default gaps
  freeSphereWall.py --eps 1e-3 0.1 1 any gaps
  freeSphereWall.py --check          the two sources compared, the interpolation error, the limits
"""
from __future__ import annotations

import argparse
import functools
import json
import math
import os
from typing import Sequence

import numpy as np
from scipy.interpolate import CubicSpline

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(HERE, "wallSphereData.json")
EPS_TABLE = (1e-3, 3.0)          # the exact table's range of eps (h/a = 1.001 ... 4)
EPS_MIN = 1e-6                   # below this the small-gap forms are not checked against anything
FS_SLOPE_FAR, TS_SLOPE_FAR = 9.0 / 16.0, 0.0   # dFs/dx, dTs/dx at x = a/d = 0 (far field)
EQ46_SWITCH = 0.85               # Eq. (46): first branch for 1/Y <= 0.85
FS_TS_LOO_BOUND = (3.8e-4, 2.2e-4)   # measured by fs_ts_leave_one_out() (module docstring)


@functools.lru_cache(maxsize=None)
def data() -> dict:
    """wallSphereData.json (the tables, with their sources)."""
    with open(DATA) as f:
        return json.load(f)


@functools.lru_cache(maxsize=None)
def _exact_splines() -> tuple:
    """Cubic splines of ln(Fxt), ln(Fxr), ln(Tyr) in ln(eps) through the table's rows."""
    rows = np.array(data()["exact_bipolar"]["rows"])
    log_eps = np.log(rows[:, 0] - 1.0)
    return tuple(CubicSpline(log_eps, np.log(rows[:, c])) for c in (1, 2, 3))


def small_gap_factors(eps: float) -> tuple[float, float, float, float]:
    """(Ft, Tt, Fr, Tr) from Chaoui & Feuillebois' small-gap forms X = sum_j (A_j ln eps + B_j) eps^j
    (f_xx^t = Ft, c_yx^t = Tt, c_yy^r = Tr; Fr = (4/3) Tt by the symmetry of the resistance matrix).
    Good for eps <= 1 (to 1e-7 against the exact table)."""
    rows = data()["chaoui_feuillebois_2003_small_gap"]["rows"]
    log_eps = math.log(eps)
    values = []
    for column in (1, 3, 5):
        values.append(sum((r[column] * log_eps + r[column + 1]) * eps ** r[0] for r in rows))
    ft, tt, tr = values
    return ft, tt, 4.0 / 3.0 * tt, tr


def lubrication_factors(eps: float) -> tuple[float, float, float, float]:
    """(Ft, Tt, Fr, Tr) to leading order at contact: the j = 0 terms of the small-gap forms (the
    lubrication asymptotes: Ft = (8/15) ln(1/eps) + 0.954, Tt = (1/10) ln(1/eps) - 0.193,
    Tr = (2/5) ln(1/eps) + 0.371)."""
    r = data()["chaoui_feuillebois_2003_small_gap"]["rows"][0]
    log_eps = math.log(eps)
    ft, tt, tr = (r[c] * log_eps + r[c + 1] for c in (1, 3, 5))
    return ft, tt, 4.0 / 3.0 * tt, tr


def exact_factors(eps: float) -> tuple[float, float, float, float]:
    """(Ft, Tt, Fr, Tr) in GCB's normalisation (module docstring) from the exact table for
    1e-3 <= eps <= 3, the small-gap forms below 1e-3. Raises ValueError beyond 3."""
    if eps < EPS_TABLE[0]:
        return small_gap_factors(eps)
    if eps > EPS_TABLE[1] * (1 + 1e-12):
        raise ValueError("freeSphereWall: eps = %g is beyond the exact table (eps <= %g)" % (eps, EPS_TABLE[1]))
    fxt, fxr, tyr = (math.exp(float(s(math.log(eps)))) for s in _exact_splines())
    # the table is divided by 6 pi eta: T/(8 pi eta ...) = (6/8) T/(6 pi eta ...)
    return fxt, 0.75 * fxr, fxr, 0.75 * tyr


@functools.lru_cache(maxsize=None)
def _shear_splines(leave_out: int | None = None) -> tuple[CubicSpline, CubicSpline]:
    """Fs(x), Ts(x), x = a/d: cubic splines through GCB's points and x = 0 (Fs = Ts = 1), clamped to
    the far-field slopes at x = 0 (module docstring); leave_out drops GCB's row of that index."""
    rows = [r for k, r in enumerate(data()["gcb1967_fixed_sphere_in_shear"]["rows"]) if k != leave_out]
    rows = sorted(rows, key=lambda r: -r[0])            # increasing x = 1/h
    x = np.array([0.0] + [1.0 / r[0] for r in rows])
    fs = np.array([1.0] + [r[1] for r in rows])
    ts = np.array([1.0] + [r[2] for r in rows])
    return (CubicSpline(x, fs, bc_type=((1, FS_SLOPE_FAR), "not-a-knot")),
            CubicSpline(x, ts, bc_type=((1, TS_SLOPE_FAR), "not-a-knot")))


def shear_factors(eps: float, leave_out: int | None = None) -> tuple[float, float]:
    """(Fs, Ts) of the sphere held fixed in the shear at eps (GCB, interpolated in x = a/d)."""
    fs, ts = _shear_splines(leave_out)
    x = 1.0 / (1.0 + eps)
    return float(fs(x)), float(ts(x))


def fs_ts_leave_one_out() -> list[dict]:
    """Each interior GCB gap interpolated from the others (and the far-field point): the misses in
    Fs and Ts, an upper bound of the interpolation error (module docstring)."""
    rows = data()["gcb1967_fixed_sphere_in_shear"]["rows"]
    out = []
    for k, r in enumerate(rows):
        if r[0] == 1.0:                 # the contact limit: the end of the range, not interpolated
            continue
        fs, ts = shear_factors(r[0] - 1.0, leave_out=k)
        out.append(dict(eps=r[0] - 1.0, Fs_miss=fs - r[1], Ts_miss=ts - r[2]))
    return out


def free_sphere(eps: float, ft: float, tt: float, fr: float, tr: float, fs: float, ts: float) -> tuple[float, float]:
    """(u, w) = (U/(gamma_dot d), Omega'/(gamma_dot/2)) of the force- and torque-free sphere, Eq. (R3)
    of the module docstring (w > 0: GCB's sense, i.e. Omega_z = -w gamma_dot/2 in the case's frame)."""
    d = 1.0 + eps                                   # d/a
    u = (fs + fr * ts / (2.0 * d * tr)) / (ft - fr * tt / tr)
    w = (ts + 2.0 * d * tt * u) / tr
    return u, w


def far_field(eps: float) -> tuple[float, float]:
    """GCB's method of reflections: u = w = 1 - (5/16) (a/d)^3."""
    x = 1.0 / (1.0 + eps)
    return 1.0 - 5.0 / 16.0 * x ** 3, 1.0 - 5.0 / 16.0 * x ** 3


def lubrication_limit(eps: float) -> tuple[float, float]:
    """(u, w) with the leading-order factors at contact (lubrication_factors and GCB's contact
    values Fs(0) = 1.7005, Ts(0) = 0.94399): u ln(1/eps) -> 2 (Fs0 + Ts0/6) = 3.716 and
    w ln(1/eps) -> (5/2) (Ts0 + 2 * 0.1 * 3.716) = 4.218 as eps -> 0. GCB's printed small-gap form
    U/(gamma_dot d) = 0.7431/(0.6376 - 0.2 ln eps) has the same leading term (0.7431/0.2 = 3.7155) but
    is 7.3 % below this reference at eps = 1e-3: its constant is off (as the reference data's README warns)."""
    fs0, ts0 = data()["gcb1967_fixed_sphere_in_shear"]["rows"][0][1:3]
    return free_sphere(eps, *lubrication_factors(eps), fs0, ts0)


def stresslet_eq46(eps: float) -> float:
    """S* of a free sphere in shear near a wall, Sangani, Acrivos & Peyla (2011) fit, paper Eq. (46)
    exactly as printed, Y = 1 + eps: [1 - 15/(16 Y^3) + 1/Y^5 - 0.65/Y^7]^-1 for 1/Y <= 0.85, else
    (0.847 ln(1/eps) - 0.41 + 1.44 eps ln(1/eps) - 0.3 eps) / ((1/5) ln(1/eps) + 0.6376)."""
    if not eps > 0:
        raise ValueError("freeSphereWall: eps must be positive, got %g" % eps)
    y = 1.0 + eps
    if 1.0 / y <= EQ46_SWITCH:
        return 1.0 / (1.0 - 15.0 / (16.0 * y ** 3) + 1.0 / y ** 5 - 0.65 / y ** 7)
    log_inv = math.log(1.0 / eps)
    return (0.847 * log_inv - 0.41 + 1.44 * eps * log_inv - 0.3 * eps) / (0.2 * log_inv + 0.6376)


def stresslet_eq46_branches(eps: float) -> tuple[float, float]:
    """Both branches of Eq. (46) at eps (wherever defined), to see how well they meet."""
    y = 1.0 + eps
    far = 1.0 / (1.0 - 15.0 / (16.0 * y ** 3) + 1.0 / y ** 5 - 0.65 / y ** 7)
    log_inv = math.log(1.0 / eps)
    near = (0.847 * log_inv - 0.41 + 1.44 * eps * log_inv - 0.3 * eps) / (0.2 * log_inv + 0.6376)
    return far, near


def velocities(eps: float) -> tuple[float, float, str]:
    """(u, w, source) of the free sphere at eps: Eq. (R3) with the best factors (module docstring)."""
    if not eps >= EPS_MIN:
        raise ValueError("freeSphereWall: eps = %g is below %g (the small-gap forms are not checked there)"
                         % (eps, EPS_MIN))
    if eps > EPS_TABLE[1] * (1 + 1e-12):
        u, w = far_field(eps)
        return u, w, "GCB method of reflections 1 - (5/16)(a/d)^3"
    fs, ts = shear_factors(eps)
    source = ("exact bipolar table" if eps >= EPS_TABLE[0] else "Chaoui-Feuillebois small-gap forms") + \
        " + GCB Fs, Ts (spline in a/d)"
    u, w = free_sphere(eps, *exact_factors(eps), fs, ts)
    return u, w, source


def uncertainty(eps: float) -> tuple[float, float]:
    """Upper bounds of the reference's errors in (u, w): the change when Fs and Ts move by their
    leave-one-out bounds (the largest source of error), plus 1e-4 for the translation and rotation
    factors (the two sources' agreement); the far-field form's 1.5e-4 beyond the table."""
    if eps > EPS_TABLE[1] * (1 + 1e-12):
        return 1.5e-4, 1.5e-4
    factors = exact_factors(eps)
    fs, ts = shear_factors(eps)
    u0, w0 = free_sphere(eps, *factors, fs, ts)
    du = dw = 0.0
    for dfs, dts in ((FS_TS_LOO_BOUND[0], 0.0), (0.0, FS_TS_LOO_BOUND[1])):
        u1, w1 = free_sphere(eps, *factors, fs + dfs, ts + dts)
        du, dw = du + abs(u1 - u0), dw + abs(w1 - w0)
    return du + 1e-4, dw + 1e-4


def reference(eps: float) -> dict:
    """The case's reference at eps: Ux_norm = U_x/(gamma_dot d), Wz_norm = Omega_z/(gamma_dot/2)
    (negative: the case's frame), S_star (Eq. 46), their sources and uncertainty bounds."""
    u, w, source = velocities(eps)
    du, dw = uncertainty(eps)
    return dict(eps=eps, Ux_norm=u, Wz_norm=-w, S_star=stresslet_eq46(eps), velocity_source=source,
                stresslet_source="Sangani et al. (2011) fit, paper Eq. (46)",
                Ux_norm_uncertainty=du, Wz_norm_uncertainty=dw)


def compare_sources() -> dict:
    """The checks of the module docstring: (1) at GCB's gaps, u and w from the exact table against
    those from GCB's own translation and rotation factors (both with GCB's Fs, Ts there: no
    interpolation); (2) the exact table against Chaoui & Feuillebois' small-gap forms; (3) the Fs, Ts
    leave-one-out misses; (4) the far-field form against (R3) at the table's end."""
    out = dict(gcb_gaps=[], small_gap=[], leave_one_out=fs_ts_leave_one_out(), far_field=[])
    for r in data()["gcb1967_all_factors"]["rows"]:
        h, ft, tt, fr, tr, fs, ts = r
        eps = h - 1.0
        ug, wg = free_sphere(eps, ft, tt, fr, tr, fs, ts)
        entry = dict(eps=eps, u_gcb=ug, w_gcb=wg)
        if EPS_TABLE[0] <= eps <= EPS_TABLE[1]:
            ue, we = free_sphere(eps, *exact_factors(eps), fs, ts)
            entry.update(u_exact=ue, w_exact=we, u_diff=ue - ug, w_diff=we - wg)
        else:
            uf, wf = far_field(eps)
            entry.update(u_far=uf, w_far=wf, u_diff=uf - ug, w_diff=wf - wg)
        out["gcb_gaps"].append(entry)
    for eps in (1e-3, 3e-3, 1e-2, 3e-2, 0.1, 0.3, 1.0):
        fs, ts = shear_factors(eps)
        ue, we = free_sphere(eps, *exact_factors(eps), fs, ts)
        uc, wc = free_sphere(eps, *small_gap_factors(eps), fs, ts)
        out["small_gap"].append(dict(eps=eps, u_exact=ue, u_cf=uc, w_exact=we, w_cf=wc, u_diff=uc - ue,
                                     w_diff=wc - we))
    for eps in (1.0, 2.0, 3.0):
        u, w = free_sphere(eps, *exact_factors(eps), *shear_factors(eps))
        uf, wf = far_field(eps)
        out["far_field"].append(dict(eps=eps, u=u, w=w, u_far=uf, w_far=wf))
    return out


def main(argv: Sequence[str] | None = None) -> dict:
    """Print the reference at --eps, or the checks (--check)."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--eps", type=float, nargs="+", default=[1e-3, 3e-3, 1e-2, 3e-2, 0.1, 0.3, 1.0, 3.0],
                   help="reduced gaps eps = d/a - 1")
    p.add_argument("--check", action="store_true", help="compare the sources (module docstring)")
    args = p.parse_args(argv)
    if args.check:
        c = compare_sources()
        print("u = U/(gamma d), w = -Omega_z/(gamma/2) from two sources of Ft, Tt, Fr, Tr at GCB's gaps:")
        for e in c["gcb_gaps"]:
            print("  eps %-9.5g GCB u %.5f w %.5f   %s u %.5f w %.5f   diff %+.1e %+.1e" % (
                e["eps"], e["u_gcb"], e["w_gcb"], "exact" if "u_exact" in e else "far  ",
                e.get("u_exact", e.get("u_far")), e.get("w_exact", e.get("w_far")), e["u_diff"], e["w_diff"]))
        print("exact table against Chaoui & Feuillebois' small-gap forms:")
        for e in c["small_gap"]:
            print("  eps %-7g u %.6f / %.6f  w %.6f / %.6f" % (e["eps"], e["u_exact"], e["u_cf"], e["w_exact"],
                                                                e["w_cf"]))
        print("GCB Fs, Ts: each point interpolated from the others:")
        for e in c["leave_one_out"]:
            print("  eps %-8.4g Fs %+.1e  Ts %+.1e" % (e["eps"], e["Fs_miss"], e["Ts_miss"]))
        print("far field 1 - (5/16)(a/d)^3 against Eq. (R3):")
        for e in c["far_field"]:
            print("  eps %g: u %.5f w %.5f far %.5f" % (e["eps"], e["u"], e["w"], e["u_far"]))
        return c
    rows = []
    try:
        for eps in args.eps:
            rows.append(reference(eps))
    except ValueError as e:
        p.error(str(e))
    print("%-8s %-9s %-9s %-8s %-9s  %s" % ("eps", "Ux_norm", "Wz_norm", "S*", "+-u,w", "source"))
    for r in rows:
        print("%-8g %-9.5f %-9.5f %-8.4f %.0e,%.0e  %s" % (r["eps"], r["Ux_norm"], r["Wz_norm"], r["S_star"],
                                                          r["Ux_norm_uncertainty"], r["Wz_norm_uncertainty"],
                                                          r["velocity_source"]))
    return dict(rows=rows)


if __name__ == "__main__":
    main()
