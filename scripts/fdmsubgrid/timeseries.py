"""Time averages of correlated samples: error bars by block averaging, and the end of the transient.

    from fdmsubgrid import timeseries
    avg = timeseries.block_average(x)              # x: (n,) or (n, ...) samples, equally spaced
    avg.mean, avg.error, avg.n_eff                 # mean, standard error, independent samples
    tr = timeseries.detect_transient(x, times)     # MSER-m: where the steady part starts
    avg, tr = timeseries.steady_average(x, times)  # both: the mean of the steady part
    r = timeseries.ratio_of_means(a, b)            # <a>/<b> with its error (delta method)

Block averaging (Flyvbjerg & Petersen, J. Chem. Phys. 91, 461 (1989)). The series is blocked
repeatedly: x'_i = (x_2i + x_2i+1)/2 (a trailing odd sample is dropped), level k holding
n_k = n/2^k means of blocks of 2^k samples. At each level, with s_k^2 the variance of the block
means (1/n_k normalisation) and g_k their lag-1 autocovariance (1/n_k), s_k^2/(n_k - 1) is the
naive squared standard error of the mean; it grows with the block size and reaches a plateau,
the true squared error, once the blocks are longer than the correlation time. The plateau level
is chosen by the automated test of Jonsson (Phys. Rev. E 98, 043304 (2018)): the first level j at
which M_j = sum_{k >= j} n_k (g_k/s_k^2)^2 falls below the 0.99 quantile of chi^2 with as many
degrees of freedom as levels summed, i.e. the block means of that level and all coarser ones show
no lag-1 correlation. Levels with fewer than MIN_BLOCKS blocks are not used. At the chosen level
the squared error is

    error^2 = (s_k^2 + 2 g_k) / (n_k - 1)      (the factor 1 + 2 g_k/s_k^2 is kept >= 1/2)

i.e. the lag-1 covariance of adjacent block means, which the plateau test lets through at the
level of its noise, is included: it removes the O(tau/block) bias of the plain estimate (on AR(1)
series with rho = 0.9 and 2^14 samples the plain plateau value is 9 % low on average, this one
within 1 %). The effective number of independent samples is n_eff = var(x)/error^2 (var with
n - 1), the statistical inefficiency g = n/n_eff. If no level passes the test (series shorter than
a few correlation times), the coarsest usable level is taken and `plateau` is False: the error is
then a lower bound.

End of the transient: MSER-m (White, Simulation 69, 323 (1997); White, Cobb & Spratt, Proc.
Winter Simulation Conference 2000, 755): the series is cut into batches of m samples, z_j their
means (nb batches, a trailing partial batch dropped), and the truncation d (in batches) minimises

    MSER(d) = sum_{j >= d} (z_j - mean_{j >= d} z)^2 / (nb - d)^2,     0 <= d <= nb/2;

the start of the steady part is d m. MSER(d) is the squared standard error of the mean of the
retained batch means (treated as independent); discarding the transient lowers it while the
transient stands out of the batch noise, then the shrinking sample raises it. MSER-5 (m = 5) was
designed for weakly correlated output; for correlated samples the batch must outlast the
correlation time, so here m = ceil(factor g) with g the statistical inefficiency of the second half
of the series (from the block averaging above, the second half taken as steady), factor = 8 by
default, kept between n/50 and n/20 (20 to 50 batches). The batch means then fluctuate by at
most sigma_x sqrt(g/m) = 0.35 sigma_x (sigma_x the sample standard deviation), and the start is
where the transient has decayed to about that level. If the minimum sits at the last allowed truncation
(nb/2), the transient may last longer than half the run: `steady` is False. The samples must be
equally spaced in time (or strain). Measured on exponential relaxations plus AR(1) noise
(tests/test_profiles.py, docs/profiles.md): the remaining transient biases the mean by less than
half its standard error and the mean lies within two error bars of the truth in >= 90 % of the
seeds.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.stats import chi2

MIN_BLOCKS = 4
"""Blocking levels with fewer block means than this are not used."""

MSER_FACTOR = 8.0
"""Batch size of MSER-m in units of the statistical inefficiency g."""

MSER_MIN_BATCHES = 20
MSER_MAX_BATCHES = 50
"""The MSER batch size is kept between n / MSER_MAX_BATCHES and n / MSER_MIN_BATCHES."""


def _out(a: NDArray) -> float | NDArray:
    """A 0-d array as a float, others unchanged."""
    return float(a) if np.ndim(a) == 0 else a


@dataclass(frozen=True)
class Average:
    """Time average of a series of samples, each of shape `shape` (() for a scalar series).

    mean, error, n_eff: float for a scalar series, else arrays of shape `shape`. error is the
    standard error of the mean; n_eff the effective number of independent samples
    (var(x)/error^2); block_size the number of samples per block at the chosen level; plateau
    False where no blocking level passed the plateau test (error is then a lower bound).
    block_sizes (L,), level_errors (L, *shape), level_error_errors (L, *shape): the naive
    error s_k/sqrt(n_k - 1) at every level and its own uncertainty s_k/sqrt(2 (n_k - 1)^2 / ...)
    (Flyvbjerg-Petersen: relative uncertainty 1/sqrt(2 (n_k - 1))), for plotting the plateau."""

    mean: float | NDArray
    error: float | NDArray
    n_eff: float | NDArray
    block_size: int | NDArray
    plateau: bool | NDArray
    n_samples: int
    block_sizes: NDArray
    level_errors: NDArray
    level_error_errors: NDArray


def block_average(x: ArrayLike, axis: int = 0) -> Average:
    """Mean and standard error of correlated, equally spaced samples by block averaging
    (Flyvbjerg-Petersen blocking, plateau by Jonsson's test, lag-1 corrected; module docstring).

    x: samples along `axis` (n >= 2 MIN_BLOCKS), any further axes are independent series, e.g.
    (n_times, n_bins) for a profile. Returns an Average whose arrays have x's shape without
    `axis`."""
    data = np.moveaxis(np.asarray(x, dtype=float), axis, 0)
    n = data.shape[0]
    if n < 2 * MIN_BLOCKS:
        raise ValueError("block_average needs at least %d samples, got %d" % (2 * MIN_BLOCKS, n))
    shape = data.shape[1:]
    flat = data.reshape(n, -1)
    mean = flat.mean(axis=0)
    var0 = flat.var(axis=0, ddof=1)

    sizes, counts, s2s, g1s = [], [], [], []
    level = flat
    size = 1
    while level.shape[0] >= MIN_BLOCKS:
        nk = level.shape[0]
        dev = level - level.mean(axis=0)
        sizes.append(size)
        counts.append(nk)
        s2s.append(np.mean(dev * dev, axis=0))
        g1s.append(np.sum(dev[:-1] * dev[1:], axis=0) / nk)
        half = nk // 2
        level = 0.5 * (level[0:2 * half:2] + level[1:2 * half:2])
        size *= 2
    counts_a = np.array(counts, dtype=float)
    s2 = np.array(s2s)                      # (L, m)
    g1 = np.array(g1s)
    positive = s2 > 0
    r = np.where(positive, g1 / np.where(positive, s2, 1.0), 0.0)
    n_levels = len(sizes)
    stat = counts_a[:, None] * r ** 2
    m_stat = np.cumsum(stat[::-1], axis=0)[::-1]          # M_j = sum_{k >= j}
    quantile = chi2.ppf(0.99, np.arange(n_levels, 0, -1))[:, None]
    passed = m_stat < quantile
    plateau = passed.any(axis=0)
    chosen = np.where(plateau, np.argmax(passed, axis=0), n_levels - 1)
    cols = np.arange(flat.shape[1])
    n_chosen = counts_a[chosen]
    factor = np.maximum(1.0 + 2.0 * r[chosen, cols], 0.5)
    err2 = s2[chosen, cols] * factor / (n_chosen - 1.0)
    error = np.sqrt(err2)
    with np.errstate(divide="ignore", invalid="ignore"):
        n_eff = np.where(err2 > 0, var0 / np.where(err2 > 0, err2, 1.0), float(n))
    level_errors = np.sqrt(s2 / (counts_a[:, None] - 1.0))
    level_error_errors = level_errors / np.sqrt(2.0 * (counts_a[:, None] - 1.0))
    block = np.array(sizes)[chosen]

    def shaped(a: NDArray) -> float | NDArray:
        return _out(a.reshape(shape)) if shape else _out(a[0])

    return Average(mean=shaped(mean), error=shaped(error), n_eff=shaped(n_eff),
                   block_size=int(block[0]) if not shape else block.reshape(shape),
                   plateau=bool(plateau[0]) if not shape else plateau.reshape(shape),
                   n_samples=n, block_sizes=np.array(sizes),
                   level_errors=level_errors.reshape((n_levels,) + shape),
                   level_error_errors=level_error_errors.reshape((n_levels,) + shape))


def ratio_of_means(numerator: ArrayLike, denominator: ArrayLike, axis: int = 0) -> Average:
    """R = <a>/<b> of two series sampled together (e.g. Eq. 54: <Sigma_xy^p>/<eta gamma_dot>), with
    the standard error of R by the delta method: R's error is the standard error of the mean of
    z_t = (a_t - R b_t)/<b>, found by block averaging z (so the correlation between a and b and in
    time is accounted for). Shapes as block_average; `mean` of the result is R (nan where
    <b> = 0)."""
    a = np.moveaxis(np.asarray(numerator, dtype=float), axis, 0)
    b = np.moveaxis(np.asarray(denominator, dtype=float), axis, 0)
    a, b = np.broadcast_arrays(a, b)
    mb = b.mean(axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = a.mean(axis=0) / mb
        z = (a - ratio * b) / mb
    z = np.where(np.isfinite(z), z, 0.0)
    avg = block_average(z, axis=0)
    nan = ~np.isfinite(ratio)
    error = np.where(nan, np.nan, avg.error)
    return Average(mean=_out(ratio), error=_out(error), n_eff=avg.n_eff, block_size=avg.block_size,
                   plateau=avg.plateau, n_samples=avg.n_samples, block_sizes=avg.block_sizes,
                   level_errors=avg.level_errors, level_error_errors=avg.level_error_errors)


@dataclass(frozen=True)
class Transient:
    """Where the steady part of a series starts (MSER-m, module docstring).

    start: index of the first steady sample; start_time: its time (or strain); batch: m, samples
    per batch; inefficiency: g of the second half (samples per independent sample); steady:
    False if the MSER minimum is at the last allowed truncation (half the run): the transient may
    last longer, run longer. For several series (columns), start is the latest of their starts,
    steady is True only if all are; batch and inefficiency are those of the series that set the
    start."""

    start: int
    start_time: float
    batch: int
    inefficiency: float
    steady: bool


def _mser_start(x: NDArray, factor: float, min_batches: int, max_batches: int) -> tuple[int, int, float, bool]:
    n = len(x)
    second = x[n // 2:]
    g = max(1.0, len(second) / float(block_average(second).n_eff))
    batch = max(1, min(max(int(math.ceil(factor * g)), n // max_batches), n // min_batches))
    nb = n // batch
    z = x[:nb * batch].reshape(nb, batch).mean(axis=1)
    z = z - z.mean()
    s1 = np.cumsum(z[::-1])[::-1]                 # sum_{j >= d} z_j
    s2 = np.cumsum((z * z)[::-1])[::-1]
    m = nb - np.arange(nb, dtype=float)
    mser = (s2 - s1 ** 2 / m) / m ** 2
    last = nb // 2
    d = int(np.argmin(mser[:last + 1]))
    return d * batch, batch, g, (d < last or last == 0)


def detect_transient(x: ArrayLike, times: ArrayLike | None = None, factor: float = MSER_FACTOR,
                     min_batches: int = MSER_MIN_BATCHES, max_batches: int = MSER_MAX_BATCHES) -> Transient:
    """Start of the steady part of an equally spaced series by MSER-m (module docstring).

    x: (n,) samples, or (n, k) for k series sampled together (the latest start is returned);
    times: (n,) their times or strains (default: the index); factor: batch size in units of the
    statistical inefficiency g, kept between n/max_batches and n/min_batches samples."""
    data = np.asarray(x, dtype=float)
    if data.ndim == 1:
        data = data[:, None]
    data = data.reshape(data.shape[0], -1)
    n = data.shape[0]
    if n < 4 * MIN_BLOCKS:
        raise ValueError("detect_transient needs at least %d samples, got %d" % (4 * MIN_BLOCKS, n))
    if not np.all(np.isfinite(data)):
        raise ValueError("detect_transient: the series has nan or infinite samples")
    t = np.arange(n, dtype=float) if times is None else np.asarray(times, dtype=float)
    if t.shape != (n,):
        raise ValueError("times has shape %s, expected (%d,)" % (t.shape, n))
    start, batch, g = -1, 1, 1.0
    steady = True
    for col in data.T:
        s, b, gc, ok = _mser_start(col, factor, min_batches, max_batches)
        steady = steady and ok
        if s > start:
            start, batch, g = s, b, gc
    return Transient(start=start, start_time=float(t[start]), batch=batch, inefficiency=g, steady=steady)


def steady_average(x: ArrayLike, times: ArrayLike | None = None, start: int | None = None,
                   factor: float = MSER_FACTOR) -> tuple[Average, Transient]:
    """The block average of the steady part of x (along axis 0) and where it starts: detected by
    detect_transient on x itself, unless start (an index) is given."""
    data = np.asarray(x, dtype=float)
    t = np.arange(len(data), dtype=float) if times is None else np.asarray(times, dtype=float)
    if start is None:
        tr = detect_transient(data, t, factor=factor)
    else:
        tr = Transient(start=int(start), start_time=float(t[start]), batch=1, inefficiency=float("nan"), steady=True)
    return block_average(data[tr.start:], axis=0), tr
