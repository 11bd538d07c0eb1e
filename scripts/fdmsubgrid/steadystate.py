"""The steady state of a run found from its data: the approach of a series to its plateau fitted (an
exponential with its time constant, the migration time of a channel), the trend of a series over a window
with an error bar that accounts for the samples' correlation, and the window they give (from
STEADY_AFTER_TAUS time constants on, the series checked to have stopped rising: MSER alone was fooled at
L_y 16 by a stall before a rise). Used by the channel's analysis (fdmsubgrid.poiseuille); nothing in it is
particular to a channel."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import timeseries

STEADY_AFTER_TAUS = 3.0   # the window starts 3 time constants after the first sample: e^-3 = 5 % of the rise left
MIN_SNAPSHOTS = 8         # the fewest samples a fit or a window takes
SLOPE_SIGMAS = 2.0        # a series has stopped rising when its slope over the window is below 2 error bars
STEADY_WINDOW_TAUS = 1.0  # and the window spans one time constant (at its upper error bar) at least: a shorter
                          # one cannot tell a slow rise from the centre's swings (L_y 12 a1: 73 time units at 3 tau)


def _inefficiency(residuals: NDArray) -> float:
    """Samples per independent sample of a correlated series (>= 1): n/n_eff of its block average."""
    r = np.asarray(residuals, dtype=float)
    if len(r) < 2 * timeseries.MIN_BLOCKS:
        return 1.0
    return max(1.0, len(r) / float(timeseries.block_average(r).n_eff))


@dataclass(frozen=True)
class Approach:
    """x(t) = plateau - (plateau - initial) exp(-(t - t0)/tau) fitted to a series (t0 its first time);
    the standard errors from the fit's covariance scaled by the residuals' statistical inefficiency (the
    samples are correlated in time: the plain least-squares errors would be too small by sqrt(g)).
    ok False (and nan values) when the fit fails or the series does not approach a plateau."""

    tau: float
    tau_err: float
    plateau: float
    plateau_err: float
    initial: float
    t0: float
    inefficiency: float
    ok: bool

    def __call__(self, t: ArrayLike) -> NDArray:
        return self.plateau - (self.plateau - self.initial) * np.exp(-(np.asarray(t, dtype=float) - self.t0) / self.tau)


def fit_approach(times: ArrayLike, x: ArrayLike, plateau_min: float = -math.inf) -> Approach:
    """The exponential approach of a series to its plateau (Approach: plateau, initial value and time
    constant tau fitted, scipy's curve_fit), rising or falling; the plateau held >= plateau_min (e.g. 0
    for an rms). tau is bounded by 10 times the series' duration: a longer one is no approach (ok False)."""
    from scipy.optimize import curve_fit
    t = np.asarray(times, dtype=float)
    y = np.asarray(x, dtype=float)
    nan = Approach(math.nan, math.nan, math.nan, math.nan, math.nan, float(t[0]) if len(t) else math.nan, math.nan, False)
    if len(t) < MIN_SNAPSHOTS or not np.all(np.isfinite(y)):
        return nan
    span = float(t[-1] - t[0])
    tail = float(y[-max(2, len(y) // 4):].mean())
    t0 = float(t[0])

    def model(tt: NDArray, plateau: float, initial: float, tau: float) -> NDArray:
        return plateau - (plateau - initial) * np.exp(-(tt - t0) / tau)

    try:
        p, cov = curve_fit(model, t, y, p0=(max(tail, plateau_min + 1e-9 * abs(tail)), float(y[:max(2, len(y) // 20)].mean()),
                                            0.25 * span),
                           bounds=([plateau_min, -np.inf, 1e-6 * span], [np.inf, np.inf, 10 * span]))
    except (RuntimeError, ValueError):
        return nan
    g = _inefficiency(y - model(t, *p))
    err = np.sqrt(np.diag(cov) * g)
    if not (np.all(np.isfinite(err)) and p[2] < 10 * span * (1 - 1e-6)):
        return nan
    return Approach(tau=float(p[2]), tau_err=float(err[2]), plateau=float(p[0]), plateau_err=float(err[0]),
                    initial=float(p[1]), t0=t0, inefficiency=g, ok=True)


def profile_change(profiles_phi: ArrayLike, final_fraction: float = 0.25) -> tuple[NDArray, NDArray]:
    """(rms change of each profile against the final profile (T,), the final profile (n,)) of a series of
    phi profiles (T, n) (e.g. bins of a1 of every snapshot): the final profile the mean of the last
    final_fraction of the series. Its approach to its noise floor measures the migration of the whole
    profile, not of the centre alone."""
    p = np.asarray(profiles_phi, dtype=float)
    if p.ndim != 2 or len(p) < 2:
        raise ValueError("profile_change needs (T, n) profiles with T >= 2, got shape %s" % (p.shape,))
    final = p[-max(1, int(round(final_fraction * len(p)))):].mean(axis=0)
    return np.sqrt(np.mean((p - final) ** 2, axis=1)), final


@dataclass(frozen=True)
class Trend:
    """The least-squares slope of a series over a window, its standard error (the plain one times the
    square root of the residuals' statistical inefficiency), and the change slope x duration."""

    slope: float
    slope_err: float
    change: float
    change_err: float
    n: int


def trend(times: ArrayLike, x: ArrayLike) -> Trend:
    """The linear trend of x(t) (at least 3 samples)."""
    t = np.asarray(times, dtype=float)
    y = np.asarray(x, dtype=float)
    if len(t) < 3:
        raise ValueError("a trend needs at least 3 samples, got %d" % len(t))
    tc = t - t.mean()
    sxx = float(np.sum(tc * tc))
    slope = float(np.sum(tc * (y - y.mean())) / sxx)
    res = y - y.mean() - slope * tc
    err = math.sqrt(float(np.sum(res * res)) / (len(t) - 2) / sxx * _inefficiency(res))
    span = float(t[-1] - t[0])
    return Trend(slope=slope, slope_err=err, change=slope * span, change_err=err * span, n=len(t))


@dataclass(frozen=True)
class SteadyWindow:
    """The steady window of a channel run found from its data (steady_window): start index and time, its end,
    the approaches fitted to phi_center(t) and to the profile's rms change, the trend of phi_center over the
    window; steady True when both fits succeeded, the window holds MIN_SNAPSHOTS, spans STEADY_WINDOW_TAUS
    time constants (tau + its error bar) and phi_center's slope there is within SLOPE_SIGMAS error bars of zero.
    reason: why not, else ''."""

    start: int
    start_time: float
    end_time: float
    center: Approach
    profile: Approach
    trend: Trend
    mser_start_time: float
    steady: bool
    reason: str


def steady_window(times: ArrayLike, phi_center: ArrayLike, rms_change: ArrayLike,
                  after_taus: float = STEADY_AFTER_TAUS) -> SteadyWindow:
    """The steady window: from after_taus migration times (tau of phi_center's approach, fit_approach)
    after the first snapshot to the end, checked by phi_center's trend over it (not rising, nor falling,
    beyond SLOPE_SIGMAS error bars). The approach of the profile's rms change to its floor (>= 0) is
    fitted too and reported. MSER's start (on phi_center) is reported beside it: it can stop at a stall
    before a further rise. Not steady (reason given) when the fit fails, when the run ends before
    after_taus migration times with MIN_SNAPSHOTS to spare (the window is then the later of MSER's start and
    the run's second half: averages of the latest part), when the window from after_taus on spans less than
    STEADY_WINDOW_TAUS migration times (tau + tau_err), or when the trend is significant."""
    t = np.asarray(times, dtype=float)
    pc = np.asarray(phi_center, dtype=float)
    center, prof = fit_approach(t, pc), fit_approach(t, rms_change, plateau_min=0.0)
    mser = (timeseries.detect_transient(pc, t).start_time if len(pc) >= 4 * timeseries.MIN_BLOCKS else math.nan)
    fallback = max(len(t) // 2, int(np.searchsorted(t, mser - 1e-9)) if math.isfinite(mser) else 0)
    reason = ""
    if not center.ok:
        start = fallback
        reason = "no exponential approach fitted to phi_center(t)"
    else:
        start = int(np.searchsorted(t, t[0] + after_taus * center.tau - 1e-9))
        if start > len(t) - MIN_SNAPSHOTS:
            reason = ("the run ends %.4g after its first snapshot, before %g migration times (%.4g +- %.2g): run longer"
                      % (t[-1] - t[0], after_taus, after_taus * center.tau, after_taus * center.tau_err))
            start = fallback
        elif t[-1] - t[start] < STEADY_WINDOW_TAUS * (center.tau + center.tau_err):
            reason = ("the window from %g migration times holds %.4g time units, less than %g migration time%s "
                      "(%.4g + %.2g): run longer" % (after_taus, t[-1] - t[start], STEADY_WINDOW_TAUS,
                                                   "" if STEADY_WINDOW_TAUS == 1 else "s", center.tau, center.tau_err))
    start = min(start, max(0, len(t) - MIN_SNAPSHOTS))
    tr = trend(t[start:], pc[start:])
    if not reason and abs(tr.slope) > SLOPE_SIGMAS * tr.slope_err:
        reason = ("phi_center %s over the window (slope %.3g +- %.3g per time unit, a change of %.3g): not steady"
                  % ("still rises" if tr.slope > 0 else "falls", tr.slope, tr.slope_err, tr.change))
    return SteadyWindow(start=start, start_time=float(t[start]), end_time=float(t[-1]), center=center, profile=prof,
                        trend=tr, mser_start_time=float(mser), steady=not reason, reason=reason)
