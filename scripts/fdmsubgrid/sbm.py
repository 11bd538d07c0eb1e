"""The Suspension Balance Model of a pressure-driven channel flow (paper section 6.2, Eqs. 62a, 62b, 63).

In a plane channel -1/2 < y* < 1/2 (y* = y/L_y) driven by the uniform pressure gradient of Eq. (58), the
steady particle flux vanishes where the particle normal stress is uniform across the channel. With the
contact stress Sigma^c_22 = Sigma_hat_22(phi) Sigma_xy as that stress and Sigma_xy proportional to y*
(the momentum balance), the volume fraction obeys

    d phi_r/dy* = -Sigma_hat_22(phi_r) / (y* Sigma_hat_22'(phi_r))                       (62b)

(phi_r = phi/phi_m), whose first integral is Sigma_hat_22(phi_r(y*)) |y*| = constant, and the particle
velocity u* = u_p/(2 U_c) follows from

    du*/dy* = -4 y* / eta_s(phi_r)                                                         (62a)

with the particle volume conserved,

    mean of phi_r over the channel = phi_bulk/phi_m.                                       (63)

As the paper does, the particle flux is taken to vanish once phi reaches phi_m: a jammed zone
|y*| < y_j holds phi = phi_m and moves as a plug (eta_s is infinite there). And the model is solved
outside the layering region, |y*| < y_edge = 1/2 - 2.5 a1/L_y, with the mean volume fraction of that
region in Eq. (63) and the particle velocity at its edge given (wall slip): `solve(material,
phi_mean, y_edge, u_edge)`.

The solution: Eq. (62b) in t = ln(y_edge/y*) is autonomous, dphi_r/dt = Sigma_hat/Sigma_hat', integrated
inward from the edge value phi_r(y_edge) with scipy's solve_ivp (stopped where phi_r reaches 1), the
edge value found with brentq so that Eq. (63) holds; Eq. (62a) is then integrated outward-in on a fine
grid. Material functions: `MaterialFunctions` from the Maron-Pierce viscosity (Eq. 55) and a power law
of the contact normal stress, given as numbers or fitted from Couette runs' results files
(`from_couette_results`). The command: `python3 -m fdmsubgrid.sbm --help`.
"""
from __future__ import annotations

import argparse
import json
import math
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.integrate import cumulative_trapezoid, solve_ivp
from scipy.optimize import brentq, curve_fit

from . import results, rheology

# The paper's material functions (section 6): Maron-Pierce fit of Fig. 21 (Eq. 55) with the jamming
# fraction of section 6.2 (phi_m = 0.592, where section 6.1's fit rounds to 0.59)
PAPER_ALPHA = rheology.PAPER_MARON_PIERCE[0]
PAPER_PHI_M = 0.592
# The contact normal stress Sigma_hat^c_22 = -K phi_r^n: n = 2 and K = 0.8 give Morris & Boulay's (1999)
# normal-to-shear viscosity ratio lambda_2 = 0.8 at phi_m with their phi_r^2 growth, and -0.218 at
# phi_core 0.309, where this project's Table 8 phi_bulk 0.27 run measured -0.216 +- 0.006
# (docs/data/validation_table8_phi0.27.json)
DEFAULT_CONTACT_K = 0.8
DEFAULT_CONTACT_N = 2.0
LAYER_OVER_A1 = 2.5          # the layering region left out of the model (paper section 6.2)


class SBMError(ValueError):
    """Input the model cannot solve: the message says which value and why."""


@dataclass(frozen=True)
class MaterialFunctions:
    """eta_s(phi_r) (relative viscosity) and Sigma_hat_22(phi_r) = Sigma^c_22/Sigma_xy (negative:
    compressive) of a homogeneous suspension, phi_r = phi/phi_m; dsigma22 its derivative in phi_r.
    `describe` says where they come from."""

    phi_m: float
    eta_s: Callable[[NDArray], NDArray]
    sigma22: Callable[[NDArray], NDArray]
    dsigma22: Callable[[NDArray], NDArray]
    describe: dict = field(default_factory=dict)

    @classmethod
    def maron_pierce_power_law(cls, alpha: float = PAPER_ALPHA, phi_m: float = PAPER_PHI_M,
                               contact_k: float = DEFAULT_CONTACT_K, contact_n: float = DEFAULT_CONTACT_N
                               ) -> "MaterialFunctions":
        """eta_s = alpha/(1 - phi_r)^2 (Eq. 55) and Sigma_hat_22 = -K phi_r^n."""
        if not (alpha > 0 and 0 < phi_m < 1):
            raise SBMError("Maron-Pierce parameters alpha = %g, phi_m = %g: need alpha > 0 and 0 < phi_m < 1"
                           % (alpha, phi_m))
        if not (contact_k > 0 and contact_n > 0):
            raise SBMError("contact normal stress -K phi_r^n with K = %g, n = %g: Eq. (62b) needs K > 0 and n > 0 "
                           "(Sigma_hat_22 growing more compressive with phi; otherwise its derivative vanishes "
                           "or changes sign and Eq. (62b) is singular)" % (contact_k, contact_n))

        def eta_s(r: NDArray) -> NDArray:
            r = np.asarray(r, dtype=float)
            with np.errstate(divide="ignore"):
                return np.where(r < 1.0, rheology.maron_pierce(np.minimum(r, 1.0) * phi_m, alpha, phi_m), np.inf)

        return cls(phi_m=phi_m, eta_s=eta_s,
                   sigma22=lambda r: -contact_k * np.power(np.asarray(r, dtype=float), contact_n),
                   dsigma22=lambda r: -contact_k * contact_n * np.power(np.asarray(r, dtype=float), contact_n - 1),
                   describe=dict(eta_s="maron_pierce", alpha=alpha, phi_m=phi_m, sigma22="power_law",
                                 contact_k=contact_k, contact_n=contact_n))


def check_singular(material: MaterialFunctions, r_lo: float, r_hi: float = 1.0, samples: int = 2001) -> None:
    """Raise SBMError if Eq. (62b) is singular or ill-posed on [r_lo, r_hi]: Sigma_hat_22 must be
    negative and strictly decreasing (dSigma_hat_22/dphi_r < 0) there."""
    r = np.linspace(r_lo, r_hi, samples)
    s = np.asarray(material.sigma22(r), dtype=float)
    ds = np.asarray(material.dsigma22(r), dtype=float)
    bad = ~(np.isfinite(s) & np.isfinite(ds) & (s < 0) & (ds < 0))
    if np.any(bad):
        k = int(np.argmax(bad))
        raise SBMError("material functions: at phi = %.4g (phi_r = %.4g) Sigma_hat_22 = %.4g, dSigma_hat_22/dphi_r "
                       "= %.4g: Eq. (62b) needs Sigma_hat_22 < 0 and a negative derivative over phi_r in [%.3g, %.3g] "
                       "(a vanishing derivative makes it singular)"
                       % (r[k] * material.phi_m, r[k], s[k], ds[k], r_lo, r_hi))


@dataclass(frozen=True)
class SBMProfile:
    """The steady profiles on y (ascending, -y_edge..y_edge, units of L_y): phi_r, phi = phi_r phi_m,
    u* = u_p/(2 U_c); the jammed half-width y_jammed (0 if none), the first integral
    constant C = -Sigma_hat_22(phi_r) |y*| outside it, and the edge values."""

    y: NDArray
    phi_r: NDArray
    phi: NDArray
    u: NDArray
    y_edge: float
    y_jammed: float
    invariant: float
    phi_edge: float
    phi_mean: float
    u_edge: float

    def at(self, y: ArrayLike) -> tuple[NDArray, NDArray]:
        """(phi, u*) interpolated at y (units of L_y; NaN outside |y| <= y_edge)."""
        y = np.asarray(y, dtype=float)
        inside = np.abs(y) <= self.y_edge * (1 + 1e-12)
        phi = np.where(inside, np.interp(y, self.y, self.phi), np.nan)
        u = np.where(inside, np.interp(y, self.y, self.u), np.nan)
        return phi, u


def _inward(material: MaterialFunctions, r_edge: float, y_edge: float, y_min: float):
    """Eq. (62b) in t = ln(y_edge/y) from phi_r(y_edge) = r_edge inward, with the integral of phi_r dy
    carried along; stops where phi_r reaches 1. Returns (solution, t_jammed or None)."""

    def rhs(t: float, z: NDArray) -> list[float]:
        r = min(z[0], 1.0)
        return [float(material.sigma22(r) / material.dsigma22(r)), float(z[0] * y_edge * math.exp(-t))]

    def jammed(t: float, z: NDArray) -> float:
        return z[0] - 1.0

    jammed.terminal = True
    jammed.direction = 1
    t_max = math.log(y_edge / y_min)
    sol = solve_ivp(rhs, (0.0, t_max), [r_edge, 0.0], method="LSODA", events=jammed, dense_output=True,
                    rtol=1e-10, atol=1e-12)
    if sol.status < 0:
        raise SBMError("Eq. (62b) could not be integrated from phi_r = %g at the edge: %s" % (r_edge, sol.message))
    t_jam = float(sol.t_events[0][0]) if len(sol.t_events[0]) else None
    return sol, t_jam


def _half_mean(material: MaterialFunctions, r_edge: float, y_edge: float, y_min: float) -> float:
    """Mean of phi_r over 0 < y < y_edge for the edge value r_edge."""
    if r_edge >= 1.0:
        return 1.0    # jammed from the edge inward
    sol, t_jam = _inward(material, r_edge, y_edge, y_min)
    integral = float(sol.y[1, -1])
    rest = y_edge * math.exp(-t_jam) if t_jam is not None else y_min * min(sol.y[0, -1], 1.0)
    return (integral + rest) / y_edge


def solve(material: MaterialFunctions, phi_mean: float, y_edge: float = 0.5, u_edge: float = 0.0,
          points: int = 2001) -> SBMProfile:
    """The steady phi and u* profiles (module docstring) over |y*| < y_edge, with mean volume fraction
    phi_mean there (Eq. 63) and u* = u_edge at y* = +-y_edge."""
    if not (0 < y_edge <= 0.5):
        raise SBMError("y_edge = %g: the region solved must be 0 < y_edge <= 1/2 (units of L_y)" % y_edge)
    if not (0 < phi_mean < material.phi_m):
        raise SBMError("mean volume fraction %g of the region solved: the model needs 0 < phi < phi_m = %g"
                       % (phi_mean, material.phi_m))
    target = phi_mean / material.phi_m
    y_min = 1e-10 * y_edge
    r_lo = 1e-6 * target
    check_singular(material, r_lo)
    mean_lo = _half_mean(material, r_lo, y_edge, y_min)
    if mean_lo > target:
        raise SBMError("mean phi_r %g reached with phi_r -> 0 at the edge already: the material functions make the "
                       "profile too steep (Sigma_hat_22 grows too slowly with phi)" % mean_lo)
    r_edge = brentq(lambda r: _half_mean(material, r, y_edge, y_min) - target, r_lo, 1.0, xtol=1e-13, rtol=1e-13)
    sol, t_jam = _inward(material, r_edge, y_edge, y_min)
    y_jam = y_edge * math.exp(-t_jam) if t_jam is not None else 0.0

    # the half channel on a grid fine near the centre (phi_r varies as a power of y there)
    half = np.unique(np.concatenate([np.geomspace(max(y_jam, y_min), y_edge, points),
                                     np.linspace(0.0, y_edge, points), [y_jam]]))
    t = np.log(y_edge / np.maximum(half, y_min))
    r = np.where(half <= y_jam, 1.0, np.minimum(sol.sol(np.minimum(t, sol.t[-1]))[0], 1.0))
    # Eq. (62a) from the edge inward: u*(y) = u_edge + int_y^{y_edge} 4 s/eta_s(phi_r(s)) ds
    slope = 4.0 * half / np.asarray(material.eta_s(r), dtype=float)
    rise = cumulative_trapezoid(slope[::-1], -half[::-1], initial=0.0)[::-1]
    u = u_edge + rise
    invariant = float(-material.sigma22(r_edge) * y_edge)
    y = np.concatenate([-half[::-1], half[1:]]) if half[0] == 0.0 else np.concatenate([-half[::-1], half])
    full_r = np.concatenate([r[::-1], r[1:]]) if half[0] == 0.0 else np.concatenate([r[::-1], r])
    full_u = np.concatenate([u[::-1], u[1:]]) if half[0] == 0.0 else np.concatenate([u[::-1], u])
    return SBMProfile(y=y, phi_r=full_r, phi=full_r * material.phi_m, u=full_u, y_edge=y_edge, y_jammed=y_jam,
                      invariant=invariant, phi_edge=float(r_edge * material.phi_m), phi_mean=phi_mean, u_edge=u_edge)


def fit_contact_power_law(phi: ArrayLike, sigma22: ArrayLike, sigma22_err: ArrayLike, phi_m: float,
                          n: float | None = None) -> tuple[float, float]:
    """(K, n) of Sigma_hat_22 = -K (phi/phi_m)^n fitted to measured (phi_core, Sigma_hat^c_22 +- err);
    n is fitted with two or more rows, else held at the given n (default DEFAULT_CONTACT_N)."""
    x = np.asarray(phi, dtype=float) / phi_m
    y = -np.asarray(sigma22, dtype=float)
    s = np.asarray(sigma22_err, dtype=float)
    if x.size == 0 or np.any(y <= 0) or np.any(s <= 0):
        raise SBMError("contact normal stress fit: need rows with Sigma_hat^c_22 < 0 and positive errors, got %s +- %s"
                       % (list(-y), list(s)))
    if n is None and x.size >= 2 and np.ptp(x) > 0:
        (k, n_fit), _ = curve_fit(lambda r, k, nn: k * r ** nn, x, y, p0=(DEFAULT_CONTACT_K, DEFAULT_CONTACT_N),
                                  sigma=s, absolute_sigma=True, bounds=([0, 0], [np.inf, 20]))
        return float(k), float(n_fit)
    n = DEFAULT_CONTACT_N if n is None else n
    w = x ** n / s
    return float(np.sum(w * y / s) / np.sum(w * w)), float(n)


def couette_rows(path: str) -> list[dict]:
    """The Couette rows of one results file: a row's own file (cases/couette results.json, fdmProfiles'
    profiles.json, docs/data/validation_table8_*_phi*.json: phi_core, eta_s, Sigma_c_hat [xx, yy, zz] with
    their errors, at top level or under "mser_window") is one row; a Table 8 summary (table8.py's, e.g.
    docs/data/validation_table8_fluidEvery.json: a "rows" list of them) is all its rows."""
    data = results.read_data(path)   # a case's results file (either shape) or fdmProfiles' summary
    rows = data["rows"] if isinstance(data.get("rows"), list) and "phi_core" not in data else [data]
    out = []
    for k, row in enumerate(rows):
        row = row.get("mser_window", row) if isinstance(row, dict) else row
        where = path if len(rows) == 1 else "%s, row %d" % (path, k)
        try:
            out.append(dict(phi_core=float(row["phi_core"]), eta_s=float(row["eta_s"]),
                            eta_s_err=float(row["eta_s_err"]), sigma22=float(row["Sigma_c_hat"][1]),
                            sigma22_err=float(row["Sigma_c_hat_err"][1]), source=where))
        except (KeyError, IndexError, TypeError, AttributeError) as e:
            raise SBMError("%s: not a Couette results file or row (needs phi_core, eta_s, eta_s_err, Sigma_c_hat, "
                           "Sigma_c_hat_err): missing %s" % (where, e)) from None
    return out


def from_couette_results(paths: Sequence[str], phi_m: float | None = None) -> MaterialFunctions:
    """The material functions fitted from Couette results files (couette_rows: a row's own file or a
    Table 8 summary holding all its rows). eta_s: the Maron-Pierce fit (Eq. 55) with three rows or more,
    phi_m included (its fitted value and error in `describe`), else alpha fitted with phi_m held (phi_m,
    default the paper's 0.592); Sigma_hat_22 = Sigma^c_22/Sigma_xy, the contact normal stress along the
    gradient that Eq. (62b) uses: the power law (fit_contact_power_law)."""
    rows = [row for path in paths for row in couette_rows(path)]
    if not rows:
        raise SBMError("no Couette results files given")
    phi, eta, eta_err, s22, s22_err = (np.array([r[k] for r in rows]) for k in
                                       ("phi_core", "eta_s", "eta_s_err", "sigma22", "sigma22_err"))
    extra = {}
    if len(rows) >= 3 and phi_m is None:
        fit = rheology.fit_maron_pierce(phi, eta, eta_err)
        alpha, phi_m = fit.alpha, fit.phi_m
        extra = dict(alpha_err=fit.alpha_error, phi_m_err=fit.phi_m_error, maron_pierce_chi2=fit.chi2,
                     maron_pierce_dof=fit.dof)
    else:
        phi_m = PAPER_PHI_M if phi_m is None else phi_m
        if np.any(phi >= phi_m):
            raise SBMError("Couette rows at phi_core %s reach phi_m = %g" % (list(phi), phi_m))
        g = 1.0 / (1.0 - phi / phi_m) ** 2
        alpha = float(np.sum(g * eta / eta_err ** 2) / np.sum(g * g / eta_err ** 2))
    k, n = fit_contact_power_law(phi, s22, s22_err, phi_m)
    material = MaterialFunctions.maron_pierce_power_law(alpha, phi_m, k, n)
    material.describe.update(fitted_from=list(paths), rows_phi_core=[float(v) for v in phi],
                             phi_core_max=float(phi.max()), **extra)
    return material


def main(argv: list[str] | None = None) -> SBMProfile:
    p = argparse.ArgumentParser(prog="python3 -m fdmsubgrid.sbm", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--phi-mean", type=float, default=0.45, help="mean phi of the region solved (Eq. 63)")
    p.add_argument("--channel", type=float, default=None, metavar="LY_OVER_A1",
                   help="L_y/a1: solve outside the layering region, |y| < L_y/2 - 2.5 a1 (default: the whole channel)")
    p.add_argument("--u-edge", type=float, default=0.0, help="u* at the edge of the region solved")
    p.add_argument("--couette", nargs="+", default=None, metavar="RESULTS_JSON",
                   help="fit the material functions from these Couette results files")
    p.add_argument("--alpha", type=float, default=PAPER_ALPHA)
    p.add_argument("--phi-m", type=float, default=PAPER_PHI_M)
    p.add_argument("--contact-k", type=float, default=DEFAULT_CONTACT_K)
    p.add_argument("--contact-n", type=float, default=DEFAULT_CONTACT_N)
    p.add_argument("--out", default=None, help="write the profiles as JSON here")
    args = p.parse_args(argv)
    if args.couette:
        material = from_couette_results(args.couette)
    else:
        material = MaterialFunctions.maron_pierce_power_law(args.alpha, args.phi_m, args.contact_k, args.contact_n)
    y_edge = 0.5 if args.channel is None else 0.5 - LAYER_OVER_A1 / args.channel
    try:
        prof = solve(material, args.phi_mean, y_edge, args.u_edge)
    except SBMError as e:
        raise SystemExit("sbm: %s" % e)
    print("material functions:", material.describe)
    print("region |y*| < %.4g: phi at the edge %.4f, jammed zone |y*| < %.4g, u* at the centre %.4f"
          % (y_edge, prof.phi_edge, prof.y_jammed, float(prof.at(0.0)[1])))
    if args.out:
        with open(args.out, "w") as f:
            json.dump(dict(material=material.describe, y=prof.y.tolist(), phi=prof.phi.tolist(), u=prof.u.tolist(),
                           y_jammed=prof.y_jammed, phi_edge=prof.phi_edge), f)
    return prof


if __name__ == "__main__":
    main()
