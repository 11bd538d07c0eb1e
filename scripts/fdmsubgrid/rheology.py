"""Rheology of a suspension in simple shear from the core values of a run (paper 6.1, Eqs. 51-57),
and the Maron-Pierce fit of the viscosity over several runs (Eq. 55).

    from fdmsubgrid import profiles, rheology
    series = profiles.core_series(snapshots, channel)             # one row per snapshot
    r = rheology.shear_rheology(series, eta=1.0)                  # steady part found by MSER-m
    r.eta_s.value, r.eta_s.error, r.n1_hat, r.sigma_c_hat[1], r.start_time
    fit = rheology.fit_maron_pierce(phi_core, eta_s, eta_s_error) # alpha, phi_m and their errors
    rheology.plot_viscosity("eta.png", phi_core, eta_s, eta_s_error, fit)

What is computed. Axes: 1 = flow (channel.flow_axis), 2 = wall-normal (channel.wall_axis),
3 = vorticity. Per snapshot (fdmsubgrid.profiles.core_values): gamma_dot_core and the core particle
stresses Sigma^{h,core}, Sigma^{c,core} (Eq. 53 averaged over the core). With <.> the time
average over the steady part, Sigma^p = Sigma^h + Sigma^c, eta the fluid viscosity:

    Sigma_12 = eta <gamma_dot_core> + <Sigma^p_12>                 (Eq. 51, shear component)
    eta_s    = Sigma_12 / (eta <gamma_dot_core>) = 1 + <Sigma^p_12> / (eta <gamma_dot_core>)   (Eq. 54)
    N1_hat   = <Sigma^p_11 - Sigma^p_22> / Sigma_12                  (Eq. 56)
    N2_hat   = <Sigma^p_22 - Sigma^p_33> / Sigma_12
    Sigma^c_ii_hat = <Sigma^c_ii> / Sigma_12,   i = 1, 2, 3          (Eq. 57)

The normal stress differences take the particle stresses only: the -P delta of Eq. 51 cancels in
a difference, and the fluid's Newtonian stress eta gamma_dot (e1 e2 + e2 e1) of Eq. 51 has no
normal components (the particles' disturbance of the fluid is in their stresslets). The
isotropic parts s^h delta/3 of S^H (Eq. 52) are kept in Sigma^h (they cancel in N1, N2, not in
the Sigma^c_ii_hat, which are contact stresses only). Every quantity is a ratio of time averages;
its error is the delta-method error of a ratio of means (fdmsubgrid.timeseries.ratio_of_means), by block
averaging over the snapshots. The steady part starts at the latest start found by MSER-m
(fdmsubgrid.timeseries.detect_transient) on the series that enter these averages (phi_core,
gamma_dot_core, Sigma^p_12, Sigma^p_11 - Sigma^p_22, Sigma^p_22 - Sigma^p_33, Sigma^c_11,
Sigma^c_22, Sigma^c_33), unless start_time is given.

The momentum balance (the built-in check of a Couette run, docs/profiles.md "Stress balance"). In
steady simple shear without inertia the time-averaged shear stress is uniform across the gap, so
the core stress Sigma_12 of Eq. 51 equals the shear stress the suspension exerts on each wall:

    tau_w = -F_w,1 (n_w . e2) / A_w,   F_w = fluid traction + sub-grid lubrication + contact

with F_w the force on wall w per step (fdmsubgrid.output.read_wall_loads: fdmFoam's viscous force on the
patch, and the particles' sub-grid wall force (Eq. D.6) and wall contacts from fix fdm/couple
walls), n_w the wall's normal out of the suspension (-e2 at the low wall, +e2 at the high one), A_w
its area. stress_balance time-averages tau_lo, tau_hi, their mean and its parts over the steady part
(block averaging over the steps) and reports |Sigma_12 - tau|/tau. Instantaneously and exactly (the
divergence theorem over the whole gap, Stokes flow, force-free particles): the mean of the two walls
equals the gap-averaged stress eta (U_hi - U_lo)/L_y + sum_p (S^H_p + S^c_p)_12 / V
(gap_shear_stress), the check of the records themselves.

Maron-Pierce (Eq. 55): eta_s = alpha / (1 - phi/phi_m)^2 fitted by weighted least squares
(scipy.optimize.curve_fit with sigma = the error bars of eta_s, absolute_sigma=True: the
parameter covariance is that of the given error bars, not rescaled by chi^2/dof); the starting
point from the straight line eta_s^(-1/2) = alpha^(-1/2) (1 - phi/phi_m); phi_m is bounded below
by the largest phi of the data.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import curve_fit

from . import timeseries
from .profiles import Channel, CoreSeries, Snapshot, component


@dataclass(frozen=True)
class Estimate:
    """A time average: value, standard error, effective number of independent samples."""

    value: float
    error: float
    n_eff: float

    @classmethod
    def from_average(cls, avg: timeseries.Average, offset: float = 0.0) -> "Estimate":
        return cls(float(avg.mean) + offset, float(avg.error), float(avg.n_eff))


@dataclass(frozen=True)
class ShearRheology:
    """Steady simple-shear rheology of one run (module docstring): phi_core, gamma_dot_core,
    sigma_12 (Sigma_12, stress), eta_s (Eq. 54, relative viscosity), n1_hat, n2_hat (Eq. 56),
    sigma_c_hat (Eq. 57: 11, 22, 33); sigma_h, sigma_c (6,) the mean core particle stresses
    (COMPONENTS order of the box axes); start_time of the steady part, steady (False if the
    transient may last longer than half the run), n_samples averaged."""

    phi_core: Estimate
    gamma_dot_core: Estimate
    sigma_12: Estimate
    eta_s: Estimate
    n1_hat: Estimate
    n2_hat: Estimate
    sigma_c_hat: tuple[Estimate, Estimate, Estimate]
    sigma_h: NDArray
    sigma_c: NDArray
    start_time: float
    steady: bool
    n_samples: int


def shear_rheology(series: CoreSeries, eta: float = 1.0, start_time: float | None = None) -> ShearRheology:
    """Eqs. 54, 56, 57 from the core values of a run (equally spaced snapshots), time-averaged over
    the steady part: from start_time if given, else from the start detected by MSER-m."""
    ch = series.channel
    i1, i2, i3 = ch.flow_axis, ch.wall_axis, ch.vorticity_axis
    c11, c22, c33, c12 = component(i1, i1), component(i2, i2), component(i3, i3), component(i1, i2)
    sp = series.sigma_h + series.sigma_c
    shear = eta * series.gamma_dot
    total12 = shear + sp[:, c12]
    columns = np.column_stack([series.phi, series.gamma_dot, sp[:, c12], sp[:, c11] - sp[:, c22],
                               sp[:, c22] - sp[:, c33], series.sigma_c[:, c11], series.sigma_c[:, c22],
                               series.sigma_c[:, c33]])
    t = series.times
    if start_time is None:
        tr = timeseries.detect_transient(columns, t)
        start, steady = tr.start, tr.steady
    else:
        after = np.nonzero(t >= start_time)[0]
        if len(after) == 0:
            raise ValueError("no snapshot at or after start_time = %g" % start_time)
        start, steady = int(after[0]), True
    sl = slice(start, None)

    def ratio(num: NDArray, den: NDArray, offset: float = 0.0) -> Estimate:
        return Estimate.from_average(timeseries.ratio_of_means(num[sl], den[sl]), offset)

    def mean(x: NDArray) -> Estimate:
        return Estimate.from_average(timeseries.block_average(x[sl]))

    return ShearRheology(
        phi_core=mean(series.phi), gamma_dot_core=mean(series.gamma_dot), sigma_12=mean(total12),
        eta_s=ratio(sp[:, c12], shear, offset=1.0),
        n1_hat=ratio(sp[:, c11] - sp[:, c22], total12), n2_hat=ratio(sp[:, c22] - sp[:, c33], total12),
        sigma_c_hat=(ratio(series.sigma_c[:, c11], total12), ratio(series.sigma_c[:, c22], total12),
                     ratio(series.sigma_c[:, c33], total12)),
        sigma_h=series.sigma_h[sl].mean(axis=0), sigma_c=series.sigma_c[sl].mean(axis=0),
        start_time=float(t[start]), steady=bool(steady), n_samples=len(t) - start)


# ---- the momentum balance: core stress against the walls' --------------------------------------

def wall_shear_stresses(loads, channel: Channel) -> dict[str, NDArray]:
    """Per step the shear stress the suspension exerts on the low and the high wall of the channel,
    tau_w = -F_w,1 (n_w . e2)/A_w (module docstring), and its parts: a dict of (T, 2) arrays
    (column 0 the low wall, 1 the high one) "total", "fluid", "subgrid", "contact". loads: an
    fdmsubgrid.output.WallLoads (forces on the walls per step, faces named like "ylo", "yhi")."""
    axis = "xyz"[channel.wall_axis]
    lo, hi = loads.wall(axis + "lo"), loads.wall(axis + "hi")
    f1 = channel.flow_axis
    # n_w . e2: -1 at the low wall (the suspension lies above it), +1 at the high one
    sign = np.array([1.0, -1.0])
    areas = np.array([loads.areas[lo], loads.areas[hi]])
    if np.any(areas <= 0):
        raise ValueError("wall areas must be positive, got %s" % areas)

    def tau(force: NDArray) -> NDArray:
        return sign * force[:, [lo, hi], f1] / areas

    parts = dict(fluid=tau(loads.fluid_viscous), subgrid=tau(loads.subgrid), contact=tau(loads.contact))
    parts["total"] = parts["fluid"] + parts["subgrid"] + parts["contact"]
    return parts


def gap_shear_stress(snapshot: Snapshot, channel: Channel, eta: float, wall_shear_rate: float) -> float:
    """The shear stress averaged over the whole gap at one instant: eta (U_hi - U_lo)/L_y (the fluid's
    mean strain rate, exact with no-slip walls) + sum_p (S^H_p + S^c_p)_12 / V (Eqs. 51-53 over the
    box). wall_shear_rate = (U_hi - U_lo)/L_y of the walls' flow components."""
    c = component(channel.flow_axis, channel.wall_axis)
    total = float(np.sum(snapshot.stresslet_h[:, c]) + np.sum(snapshot.stresslet_c[:, c]))
    return eta * wall_shear_rate + total / channel.volume


@dataclass(frozen=True)
class StressBalance:
    """The momentum balance of one run (module docstring). core: Sigma_12 of Eq. 51 (the
    ShearRheology's sigma_12); wall: the mean of tau_lo and tau_hi; wall_lo, wall_hi; parts (mean of
    both walls): wall_fluid, wall_subgrid, wall_contact. rel_error = |core - wall|/|wall| and its
    error (core and wall errors combined as independent: the core is sampled at the snapshots, the
    walls every step); wall_asymmetry = |tau_lo - tau_hi|/|wall| (the net force on the walls: zero
    at convergence); n_steps averaged from start_time (strain)."""

    core: Estimate
    wall: Estimate
    wall_lo: Estimate
    wall_hi: Estimate
    wall_fluid: Estimate
    wall_subgrid: Estimate
    wall_contact: Estimate
    rel_error: float
    rel_error_err: float
    wall_asymmetry: float
    start_time: float
    n_steps: int

    def as_dict(self) -> dict:
        """The numbers for results.json: stress_balance_rel_error and its parts (stresses in the
        units of eta gamma_dot)."""
        out = dict(stress_balance_rel_error=self.rel_error, stress_balance_rel_error_err=self.rel_error_err,
                   stress_core=self.core.value, stress_core_err=self.core.error,
                   stress_wall=self.wall.value, stress_wall_err=self.wall.error,
                   stress_wall_asymmetry=self.wall_asymmetry, stress_balance_steps=self.n_steps,
                   stress_balance_from_strain=self.start_time)
        for name in ("wall_lo", "wall_hi", "wall_fluid", "wall_subgrid", "wall_contact"):
            e = getattr(self, name)
            out["stress_" + name] = e.value
            out["stress_" + name + "_err"] = e.error
        return out


def relative_difference(core: float, wall: float) -> float:
    """|core - wall| / |wall| (nan if wall = 0)."""
    return abs(core - wall) / abs(wall) if wall != 0 else float("nan")


def stress_balance(rheology: ShearRheology, loads, channel: Channel, strain_rate: float = 1.0,
                   start_time: float | None = None) -> StressBalance:
    """Core stress against the walls' shear stress, both time-averaged over the steady part: from
    start_time (strain; default the rheology's start) on, the wall loads of every step with
    time x strain_rate >= start_time (block-averaged: the steps are correlated)."""
    start = rheology.start_time if start_time is None else start_time
    tau = wall_shear_stresses(loads, channel)
    strain = np.asarray(loads.times, dtype=float) * strain_rate
    sl = strain >= start - 1e-9 * max(1.0, abs(start))
    n = int(np.sum(sl))
    if n < 2 * timeseries.MIN_BLOCKS:
        raise ValueError("stress balance: %d steps with wall loads from strain %g on; %d at least"
                         % (n, start, 2 * timeseries.MIN_BLOCKS))

    def mean(x: NDArray) -> Estimate:
        return Estimate.from_average(timeseries.block_average(x[sl]))

    wall = mean(tau["total"].mean(axis=1))
    core = rheology.sigma_12
    rel = relative_difference(core.value, wall.value)
    rel_err = float(np.hypot(core.error, wall.error) / abs(wall.value)) if wall.value != 0 else float("nan")
    lo, hi = mean(tau["total"][:, 0]), mean(tau["total"][:, 1])
    return StressBalance(core=core, wall=wall, wall_lo=lo, wall_hi=hi,
                         wall_fluid=mean(tau["fluid"].mean(axis=1)), wall_subgrid=mean(tau["subgrid"].mean(axis=1)),
                         wall_contact=mean(tau["contact"].mean(axis=1)), rel_error=rel, rel_error_err=rel_err,
                         wall_asymmetry=abs(lo.value - hi.value) / abs(wall.value) if wall.value != 0 else float("nan"),
                         start_time=float(start), n_steps=n)


# ---- Maron-Pierce ------------------------------------------------------------------------------

PAPER_MARON_PIERCE = (0.803, 0.59)
"""alpha, phi_m of the paper's fit of Eq. 55 (section 6.1, Fig. 21)."""


def maron_pierce(phi: ArrayLike, alpha: float, phi_m: float) -> NDArray:
    """Eq. 55: alpha / (1 - phi/phi_m)^2."""
    return alpha / (1.0 - np.asarray(phi, dtype=float) / phi_m) ** 2


@dataclass(frozen=True)
class MaronPierceFit:
    """alpha, phi_m, their standard errors and (2, 2) covariance (order alpha, phi_m); chi2 of the
    fit and dof = points - 2. Call it on phi to evaluate the fitted Eq. 55."""

    alpha: float
    phi_m: float
    alpha_error: float
    phi_m_error: float
    covariance: NDArray
    chi2: float
    dof: int

    def __call__(self, phi: ArrayLike) -> NDArray:
        return maron_pierce(phi, self.alpha, self.phi_m)


def fit_maron_pierce(phi: ArrayLike, eta_s: ArrayLike, eta_s_error: ArrayLike,
                     p0: tuple[float, float] | None = None) -> MaronPierceFit:
    """Fit Eq. 55 to eta_s (n,) at phi (n,) (n >= 3) with standard errors eta_s_error (n,) (module
    docstring). p0: starting (alpha, phi_m), default from the linearised fit."""
    x = np.asarray(phi, dtype=float).reshape(-1)
    y = np.asarray(eta_s, dtype=float).reshape(-1)
    s = np.asarray(eta_s_error, dtype=float).reshape(-1)
    if not (x.shape == y.shape == s.shape) or x.size < 3:
        raise ValueError("phi, eta_s, eta_s_error must be three arrays of the same length >= 3")
    if np.any(s <= 0) or np.any(y <= 0):
        raise ValueError("eta_s and its errors must be positive")
    floor = float(x.max()) * (1.0 + 1e-9)
    if p0 is None:
        # eta^(-1/2) = c0 + c1 phi, c0 = alpha^(-1/2), c1 = -c0/phi_m; weights from the error bars
        v = y ** -0.5
        sv = 0.5 * s * y ** -1.5
        c1, c0 = np.polyfit(x, v, 1, w=1.0 / sv)
        alpha0 = 1.0 / c0 ** 2 if c0 > 0 else 1.0
        phim0 = -c0 / c1 if c1 < 0 and c0 > 0 else floor * 1.1
        p0 = (alpha0, max(phim0, floor * 1.01))
    popt, pcov = curve_fit(maron_pierce, x, y, p0=p0, sigma=s, absolute_sigma=True,
                           bounds=([0.0, floor], [np.inf, np.inf]))
    chi2 = float(np.sum(((y - maron_pierce(x, *popt)) / s) ** 2))
    return MaronPierceFit(alpha=float(popt[0]), phi_m=float(popt[1]), alpha_error=float(np.sqrt(pcov[0, 0])),
                          phi_m_error=float(np.sqrt(pcov[1, 1])), covariance=pcov, chi2=chi2, dof=x.size - 2)


def plot_viscosity(path: str, phi_core: ArrayLike, eta_s: ArrayLike, eta_s_error: ArrayLike | None = None,
                   fit: MaronPierceFit | None = None, phi_core_error: ArrayLike | None = None,
                   label: str = "simulations", title: str | None = None,
                   reference: tuple[float, float] | None = None, reference_label: str = "paper",
                   not_fitted: ArrayLike | None = None) -> str:
    """PNG of eta_s against phi_core with error bars and, if given, the Maron-Pierce curve of `fit`
    and a reference curve Eq. 55 with reference = (alpha, phi_m), e.g. PAPER_MARON_PIERCE (Fig. 21).
    not_fitted (booleans, one per point): points drawn hollow, "listed, not fitted". Returns path."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(5.5, 4.2))
    ax = fig.subplots()
    _errorbars(ax, phi_core, eta_s, eta_s_error, phi_core_error, "o", label, not_fitted,
               "listed, not fitted (a step too large, or a short window)")
    eta_data = np.asarray(eta_s, dtype=float)
    if fit is not None:
        grid = np.linspace(0.0, 0.998 * fit.phi_m, 400)
        ax.plot(grid, fit(grid), "--", label=r"Maron-Pierce $\alpha$ = %.3f $\pm$ %.3f, $\phi_m$ = %.3f $\pm$ %.3f"
                % (fit.alpha, fit.alpha_error, fit.phi_m, fit.phi_m_error))
    if reference is not None:
        alpha, phi_m = reference
        grid = np.linspace(0.0, 0.998 * phi_m, 400)
        ax.plot(grid, maron_pierce(grid, alpha, phi_m), ":", color="k",
                label=r"%s: $\alpha$ = %.3f, $\phi_m$ = %.3f" % (reference_label, alpha, phi_m))
    ax.set_yscale("log")
    low = min(eta_data.min(), fit.alpha if fit is not None else eta_data.min())
    ax.set_ylim(0.7 * low, 3.0 * eta_data.max())
    ax.set_xlabel(r"$\phi_{core}$")
    ax.set_ylabel(r"$\eta_s$")
    # upper left: the curve rises steeply to the upper right, and a long label at the lower right ran off the axes
    ax.legend(fontsize=8, loc="upper left")
    if title:
        ax.set_title(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return path


def _errorbars(ax, x: ArrayLike, y: ArrayLike, yerr: ArrayLike | None, xerr: ArrayLike | None, marker: str,
               label: str, not_fitted: ArrayLike | None, hollow_label: str | None = None) -> None:
    """Points with error bars; those flagged in not_fitted hollow, in the same colour, labelled hollow_label
    (default: label + ": not fitted")."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    hollow = np.zeros(x.size, bool) if not_fitted is None else np.asarray(not_fitted, dtype=bool)
    if hollow.size != x.size:
        raise ValueError("not_fitted: %d flags for %d points" % (hollow.size, x.size))

    def pick(err: ArrayLike | None, keep: np.ndarray):
        return None if err is None else np.asarray(err, dtype=float)[keep]

    full = ax.errorbar(x[~hollow], y[~hollow], yerr=pick(yerr, ~hollow), xerr=pick(xerr, ~hollow), fmt=marker,
                       ms=5, capsize=3, label=label)
    if hollow.any():
        ax.errorbar(x[hollow], y[hollow], yerr=pick(yerr, hollow), xerr=pick(xerr, hollow), fmt=marker, ms=5,
                    capsize=3, mfc="none", color=full[0].get_color(),
                    label=hollow_label if hollow_label is not None else label + ": not fitted")


def plot_normal_stresses(path: str, phi_core: ArrayLike, n1: ArrayLike, n1_error: ArrayLike, n2: ArrayLike,
                         n2_error: ArrayLike, sigma_c: ArrayLike, sigma_c_error: ArrayLike,
                         label: str = "simulations", title: str | None = None,
                         not_fitted: ArrayLike | None = None) -> str:
    """PNG of the normalised normal stresses against phi_core with their error bars, laid out as the paper's
    Fig. 22: top N_hat_1 and N_hat_2 (Eq. 56), bottom the contact parts Sigma_hat^c_11, _22, _33 (Eq. 57;
    sigma_c and its error are (rows, 3)); the rows flagged in not_fitted hollow. Returns path."""
    from matplotlib.figure import Figure

    phi = np.asarray(phi_core, dtype=float)
    contact = np.asarray(sigma_c, dtype=float).reshape(-1, 3)
    contact_error = np.asarray(sigma_c_error, dtype=float).reshape(-1, 3)
    if not (phi.size == np.size(n1) == np.size(n2) == contact.shape[0]):
        raise ValueError("plot_normal_stresses: %d phi_core, %d N1, %d N2 and %d contact rows: need one of each "
                         "per row" % (phi.size, np.size(n1), np.size(n2), contact.shape[0]))
    fig = Figure(figsize=(5.5, 7.0))
    top, bottom = fig.subplots(2, 1, sharex=True)
    _errorbars(top, phi, n1, n1_error, None, "o", r"$\hat N_1$", not_fitted, r"$\hat N_1$ (row not in Fig. 21's fit)")
    _errorbars(top, phi, n2, n2_error, None, "s", r"$\hat N_2$", not_fitted, r"$\hat N_2$ (row not in Fig. 21's fit)")
    top.axhline(0.0, color="0.6", lw=0.8)
    top.set_ylabel(r"$\hat N_1$, $\hat N_2$ (Eq. 56)")
    top.legend(fontsize=8, title=label, title_fontsize=8)
    for k, (marker, name) in enumerate(zip("o^s", ("11", "22", "33"))):
        _errorbars(bottom, phi, contact[:, k], contact_error[:, k], None, marker, r"$\hat\Sigma^c_{%s}$" % name,
                   not_fitted, r"$\hat\Sigma^c_{%s}$ (row not in Fig. 21's fit)" % name)
    bottom.axhline(0.0, color="0.6", lw=0.8)
    bottom.set_xlabel(r"$\phi_{core}$")
    bottom.set_ylabel(r"contact part $\hat\Sigma^c$ (Eq. 57)")
    bottom.legend(fontsize=8)
    if title:
        top.set_title(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return path
