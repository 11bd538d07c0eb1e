"""Profiles of a wall-bounded suspension from particle snapshots (paper sections 6.1 and 6.2).

    from fdmsubgrid import profiles
    ch = profiles.Channel(lo=(0, -10, 0), hi=(20, 10, 20))            # walls y = -10, 10
    s = profiles.Snapshot(positions, radii, velocities=U, stresslet_h=SH, stresslet_c=SC, time=t)
    fine = profiles.profiles_on_planes(s, ch, ch.planes(0.02))        # Eqs. 49, 53, 59 on planes
    coarse = profiles.profiles_in_bins(s, ch, ch.bin_edges(1.0))      # Eq. 60: exact bin averages
    core = profiles.core_values(s, ch, h_layer=5.0)                   # Eq. 50, core stresses, shear rate
    avg = profiles.average_profiles(snapshots, ch, edges=ch.bin_edges(1.0), start_time=5.0)

Geometry. The walls are normal to `Channel.wall_axis` (y by default), at lo and hi of that axis; the
two other axes are periodic, of lengths L_x and L_z (their product is `Channel.area`). "y" below
is the wall-normal coordinate whatever the axis; `flow_axis` (x by default) is the direction of
the wall velocity or of the pressure gradient, the third axis the vorticity direction. Any
consistent units (lengths, velocities, stresses).

A snapshot (Snapshot) holds, per particle p: the centre x_p (3), radius a_p, type, velocity U_p
(3), angular velocity Omega_p (3), and the hydrodynamic and contact stresslets S^H_p and S^c_p as
6 components in the order COMPONENTS = xx xy xz yy yz zz of the box axes (not traceless: S^H =
S^h + s^h delta/3, Eq. 52). Particles are spheres, V_p = 4/3 pi a_p^3.

Exact formulas. The plane y cuts sphere p in a disc of area A_p(y) = pi (a_p^2 - (y - y_p)^2) for
|y - y_p| < a_p, 0 otherwise; with periodic x and z the whole disc lies in the plane (images
included), whatever x_p, z_p. So, on a plane (Eqs. 49, 59, 53):

    phi(y)         = sum_p A_p(y) / (L_x L_z)
    phi(y) u_p(y)  = sum_p A_p(y) U_p / (L_x L_z)          (u_p: the particle-volume-weighted velocity)
    Sigma^{h,c}(y) = sum_p A_p(y) S^{H,c}_p / V_p / (L_x L_z)

Between two planes y0 < y1 the integral of A_p is the volume of the slice of the sphere,

    V_p(y0, y1) = F(s1) - F(s0),   F(s) = pi (a_p^2 s - s^3/3),   s_i = clip(y_i - y_p, -a_p, a_p),

and the averages over [y0, y1] (bins of Eq. 60, the core of Eq. 50) are exact:

    phi[y0, y1]         = sum_p V_p(y0, y1) / (L_x L_z (y1 - y0))
    (phi u_p)[y0, y1]   = sum_p V_p(y0, y1) U_p / (L_x L_z (y1 - y0)),   u_p = (phi u_p) / phi
    Sigma[y0, y1]       = sum_p V_p(y0, y1) S_p / V_p / (L_x L_z (y1 - y0)).

The bin value of u_p is the ratio of the bin averages of phi u_p and phi (Eq. 59 averaged as Eq.
60), i.e. the particle-volume-weighted mean velocity of the particle matter in the bin; it is nan
where phi = 0. Over the whole channel, for spheres inside the walls, phi[y_lo, y_hi] =
sum_p V_p / V_box = phi_bulk to round-off.

Core (section 6.1): |y - y_mid| < L_y/2 - H_layer (H_layer = 5 a1 by default, a1 the smallest
radius). phi_core (Eq. 50) and the core stresses Sigma^{h,core}, Sigma^{c,core} (Eq. 53 averaged
over the core) are the exact averages above over the core slab: a sphere cut by a core boundary
contributes the share of its volume inside. The core shear rate gamma_dot_core is the slope of the
ordinary least-squares line U_flow = u0 + gamma_dot y through the particles whose centres lie in
the core (|y_p - y_mid| < L_y/2 - H_layer), each particle one point (weighting="number", the
default) or weighted by its volume (weighting="volume"); section 6.1 says "a linear regression of
the particle velocity distribution of the particles situated inside the core region".
The rheology from a run of snapshots (Eqs. 54-57) is in fdmsubgrid.rheology; time averages and error
bars in fdmsubgrid.timeseries. Method and tests: docs/profiles.md, tests/test_profiles.py.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import timeseries

COMPONENTS = ("xx", "xy", "xz", "yy", "yz", "zz")
"""Order of the 6 components of a symmetric tensor (stresslets, stresses)."""

_SYM = np.array([[0, 1, 2], [1, 3, 4], [2, 4, 5]])

_CHUNK = 4_000_000
"""Largest (planes x particles) block held at once."""

# columns of the per-particle weight matrix
_PHI, _U, _OMEGA, _SH, _SC, _NCOL = 0, slice(1, 4), slice(4, 7), slice(7, 13), slice(13, 19), 19


def component(i: int, j: int) -> int:
    """Index in COMPONENTS of the (i, j) component (axes 0, 1, 2), symmetric: component(1, 0) = 1."""
    return int(_SYM[i, j])


def tensor(six: ArrayLike) -> NDArray:
    """(..., 6) components in COMPONENTS order -> (..., 3, 3) symmetric tensors."""
    s = np.asarray(six, dtype=float)
    return s[..., _SYM]


@dataclass(frozen=True)
class Channel:
    """The box: lo, hi (3,) corners; walls at lo[wall_axis] and hi[wall_axis], periodic along the
    two other axes; flow_axis: direction of the flow (wall velocity, pressure gradient)."""

    lo: tuple[float, float, float]
    hi: tuple[float, float, float]
    wall_axis: int = 1
    flow_axis: int = 0

    def __post_init__(self) -> None:
        lo = tuple(float(v) for v in self.lo)
        hi = tuple(float(v) for v in self.hi)
        if len(lo) != 3 or len(hi) != 3 or any(h <= l for l, h in zip(lo, hi)):
            raise ValueError("Channel needs lo < hi on the three axes, got lo=%s hi=%s" % (lo, hi))
        if self.wall_axis not in (0, 1, 2) or self.flow_axis not in (0, 1, 2) or self.wall_axis == self.flow_axis:
            raise ValueError("wall_axis and flow_axis must be two different axes among 0, 1, 2")
        object.__setattr__(self, "lo", lo)
        object.__setattr__(self, "hi", hi)

    @classmethod
    def centred(cls, lengths: Sequence[float], wall_axis: int = 1, flow_axis: int = 0) -> "Channel":
        """The box [-L/2, L/2] on every axis (the paper's y in [-L_y/2, L_y/2])."""
        hx, hy, hz = (0.5 * float(v) for v in lengths)
        return cls((-hx, -hy, -hz), (hx, hy, hz), wall_axis, flow_axis)

    @property
    def lengths(self) -> NDArray:
        """(3,) box lengths."""
        return np.subtract(self.hi, self.lo)

    @property
    def vorticity_axis(self) -> int:
        return 3 - self.wall_axis - self.flow_axis

    @property
    def width(self) -> float:
        """L_y, the distance between the walls."""
        return float(self.hi[self.wall_axis] - self.lo[self.wall_axis])

    @property
    def area(self) -> float:
        """L_x L_z, the area of a plane parallel to the walls."""
        L = self.lengths
        return float(L[self.flow_axis] * L[self.vorticity_axis])

    @property
    def volume(self) -> float:
        return float(np.prod(self.lengths))

    @property
    def y_lo(self) -> float:
        return float(self.lo[self.wall_axis])

    @property
    def y_hi(self) -> float:
        return float(self.hi[self.wall_axis])

    @property
    def y_mid(self) -> float:
        return 0.5 * (self.y_lo + self.y_hi)

    def core_bounds(self, h_layer: float) -> tuple[float, float]:
        """(y0, y1) of the core, the planes H_layer from the walls (section 6.1)."""
        if not 0 <= h_layer < 0.5 * self.width:
            raise ValueError("H_layer = %g must be in [0, L_y/2 = %g)" % (h_layer, 0.5 * self.width))
        return self.y_lo + h_layer, self.y_hi - h_layer

    def bin_edges(self, width: float) -> NDArray:
        """(M+1,) edges of M equal bins covering the channel, M = round(L_y/width) (at least 1):
        the bin width is L_y/M, i.e. `width` adjusted to fit the channel exactly (Eq. 60 uses
        width a1)."""
        m = max(1, int(round(self.width / float(width))))
        return np.linspace(self.y_lo, self.y_hi, m + 1)

    def planes(self, spacing: float) -> NDArray:
        """(n,) equally spaced planes from wall to wall (both included), spacing adjusted to fit."""
        m = max(1, int(round(self.width / float(spacing))))
        return np.linspace(self.y_lo, self.y_hi, m + 1)


class Snapshot:
    """Particles at one time. positions (N, 3); radii (N,); types (N,) int (default 1);
    velocities U_p (N, 3) and omegas Omega_p (N, 3) (default 0); stresslet_h S^H_p and stresslet_c
    S^c_p (N, 6), COMPONENTS order, force x length (default 0); time (or strain). The arrays are
    copied to float (int for types) and their shapes checked."""

    positions: NDArray
    radii: NDArray
    velocities: NDArray
    omegas: NDArray
    stresslet_h: NDArray
    stresslet_c: NDArray
    types: NDArray
    time: float

    def __init__(self, positions: ArrayLike, radii: ArrayLike, velocities: ArrayLike | None = None,
                 omegas: ArrayLike | None = None, stresslet_h: ArrayLike | None = None,
                 stresslet_c: ArrayLike | None = None, types: ArrayLike | None = None, time: float = 0.0) -> None:
        x = np.array(positions, dtype=float)
        if x.ndim != 2 or x.shape[1] != 3:
            raise ValueError("positions must be (N, 3), got %s" % (x.shape,))
        n = x.shape[0]
        a = np.array(radii, dtype=float).reshape(-1)
        if a.shape != (n,):
            raise ValueError("radii must be (%d,), got %s" % (n, a.shape))
        if np.any(a <= 0):
            raise ValueError("radii must be positive")
        self.positions, self.radii = x, a

        def per_particle(name: str, v: ArrayLike | None, cols: int) -> NDArray:
            arr = np.zeros((n, cols)) if v is None else np.array(v, dtype=float)
            if arr.shape != (n, cols):
                raise ValueError("%s must be (%d, %d), got %s" % (name, n, cols, arr.shape))
            return arr

        self.velocities = per_particle("velocities", velocities, 3)
        self.omegas = per_particle("omegas", omegas, 3)
        self.stresslet_h = per_particle("stresslet_h", stresslet_h, 6)
        self.stresslet_c = per_particle("stresslet_c", stresslet_c, 6)
        t = np.ones(n, dtype=int) if types is None else np.array(types, dtype=int).reshape(-1)
        if t.shape != (n,):
            raise ValueError("types must be (%d,), got %s" % (n, t.shape))
        self.types = t
        self.time = float(time)

    def __repr__(self) -> str:
        return "Snapshot(%d particles, time %g)" % (self.n, self.time)

    def select(self, which: ArrayLike) -> "Snapshot":
        """The particles picked by a boolean mask or index array (N,), e.g. s.select(s.types == 2)
        for the profiles of one species (their phi adds up to the total; give the bins and H_layer
        explicitly, their defaults follow the smallest radius of the selection)."""
        k = np.asarray(which)
        return Snapshot(self.positions[k], self.radii[k], self.velocities[k], self.omegas[k], self.stresslet_h[k],
                        self.stresslet_c[k], self.types[k], self.time)

    @property
    def n(self) -> int:
        return len(self.radii)

    @property
    def volumes(self) -> NDArray:
        """(N,) V_p = 4/3 pi a_p^3."""
        return 4.0 / 3.0 * math.pi * self.radii ** 3

    def weights(self) -> NDArray:
        """(N, 19) per-particle quantities spread over the particle's volume: 1 (for phi), U_p,
        Omega_p, S^H_p/V_p, S^c_p/V_p."""
        w = np.empty((self.n, _NCOL))
        v = self.volumes[:, None]
        w[:, _PHI] = 1.0
        w[:, _U] = self.velocities
        w[:, _OMEGA] = self.omegas
        w[:, _SH] = self.stresslet_h / v
        w[:, _SC] = self.stresslet_c / v
        return w


# ---- exact geometry -----------------------------------------------------------------------------

def cross_section_areas(centres: ArrayLike, radii: ArrayLike, y: ArrayLike) -> NDArray:
    """(M, N) areas A_p(y_k) = pi max(a_p^2 - (y_k - y_p)^2, 0) of the discs cut from the spheres
    (wall-normal centre coordinates `centres` (N,), radii (N,)) by the planes y (M,) (Eq. 49)."""
    c = np.asarray(centres, dtype=float).reshape(-1)
    a = np.asarray(radii, dtype=float).reshape(-1)
    d = np.asarray(y, dtype=float).reshape(-1)[:, None] - c[None, :]
    return math.pi * np.maximum(a[None, :] ** 2 - d * d, 0.0)


def _cap_primitive(s: NDArray, a: NDArray) -> NDArray:
    """F(s) = pi (a^2 s - s^3/3) at s clipped to [-a, a]: volume of the sphere below the plane at
    height s from its centre, minus half its volume."""
    s = np.clip(s, -a, a)
    return math.pi * (a * a * s - s ** 3 / 3.0)


def slab_volumes(centres: ArrayLike, radii: ArrayLike, y0: ArrayLike, y1: ArrayLike) -> NDArray:
    """(N, M) volume of sphere p between the planes y0[k] < y1[k] (M,): F(s1) - F(s0), the
    integral of A_p(y) over [y0, y1] (exact; module docstring)."""
    c = np.asarray(centres, dtype=float).reshape(-1)[:, None]
    a = np.asarray(radii, dtype=float).reshape(-1)[:, None]
    lo = np.asarray(y0, dtype=float).reshape(-1)[None, :]
    hi = np.asarray(y1, dtype=float).reshape(-1)[None, :]
    if np.any(hi < lo):
        raise ValueError("slab_volumes needs y0 <= y1")
    return _cap_primitive(hi - c, a) - _cap_primitive(lo - c, a)


def bin_volumes(centres: ArrayLike, radii: ArrayLike, edges: ArrayLike) -> NDArray:
    """(N, M) volume of sphere p in each of the bins between consecutive edges (M+1,), increasing."""
    e = np.asarray(edges, dtype=float).reshape(-1)
    if e.size < 2 or np.any(np.diff(e) <= 0):
        raise ValueError("bin edges must be at least two increasing values")
    c = np.asarray(centres, dtype=float).reshape(-1)[:, None]
    a = np.asarray(radii, dtype=float).reshape(-1)[:, None]
    return np.diff(_cap_primitive(e[None, :] - c, a), axis=1)


# ---- profiles of one snapshot -------------------------------------------------------------------

@dataclass(frozen=True)
class Profiles:
    """Profiles of one snapshot, on planes (edges None; y the plane positions) or as exact bin
    averages (edges (n+1,); y the bin centres). phi (n,); phi_u = phi u_p (n, 3) (Eq. 59);
    phi_omega (n, 3) the same with Omega_p; sigma_h, sigma_c (n, 6) the particle stresses of Eq. 53
    (COMPONENTS order, stress units)."""

    y: NDArray
    edges: NDArray | None
    phi: NDArray
    phi_u: NDArray
    phi_omega: NDArray
    sigma_h: NDArray
    sigma_c: NDArray

    @property
    def u_p(self) -> NDArray:
        """(n, 3) particle velocity u_p = (phi u_p)/phi (Eq. 59), nan where phi = 0."""
        return _divide(self.phi_u, self.phi[:, None])

    @property
    def omega_p(self) -> NDArray:
        """(n, 3) particle angular velocity, weighted as u_p."""
        return _divide(self.phi_omega, self.phi[:, None])

    @property
    def sigma_p(self) -> NDArray:
        """(n, 6) Sigma^h + Sigma^c."""
        return self.sigma_h + self.sigma_c


def _divide(num: NDArray, den: NDArray) -> NDArray:
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(den != 0, num / np.where(den != 0, den, 1.0), np.nan)


def _profiles(y: NDArray, edges: NDArray | None, sums: NDArray) -> Profiles:
    return Profiles(y=y, edges=edges, phi=sums[:, _PHI], phi_u=sums[:, _U], phi_omega=sums[:, _OMEGA],
                    sigma_h=sums[:, _SH], sigma_c=sums[:, _SC])


def _plane_sums(snapshot: Snapshot, channel: Channel, y: NDArray) -> NDArray:
    """(M, 19): sum_p A_p(y) w_p / (L_x L_z)."""
    c = snapshot.positions[:, channel.wall_axis]
    a = snapshot.radii
    w = snapshot.weights()
    out = np.zeros((len(y), _NCOL))
    step = max(1, _CHUNK // max(1, len(y)))
    for i in range(0, snapshot.n, step):
        out += cross_section_areas(c[i:i + step], a[i:i + step], y) @ w[i:i + step]
    return out / channel.area


def _bin_sums(snapshot: Snapshot, channel: Channel, edges: NDArray) -> NDArray:
    """(M, 19): sum_p V_p(bin) w_p / (L_x L_z width)."""
    c = snapshot.positions[:, channel.wall_axis]
    a = snapshot.radii
    w = snapshot.weights()
    out = np.zeros((len(edges) - 1, _NCOL))
    step = max(1, _CHUNK // max(1, len(edges)))
    for i in range(0, snapshot.n, step):
        out += bin_volumes(c[i:i + step], a[i:i + step], edges).T @ w[i:i + step]
    return out / (channel.area * np.diff(edges))[:, None]


def profiles_on_planes(snapshot: Snapshot, channel: Channel, y: ArrayLike) -> Profiles:
    """Point values of phi (Eq. 49), phi u_p (Eq. 59) and Sigma^h, Sigma^c (Eq. 53) on the planes
    y (n,) (wall-normal coordinates, e.g. channel.planes(0.02 a1)), exact."""
    yy = np.asarray(y, dtype=float).reshape(-1)
    return _profiles(yy, None, _plane_sums(snapshot, channel, yy))


def profiles_in_bins(snapshot: Snapshot, channel: Channel, edges: ArrayLike | None = None) -> Profiles:
    """Exact averages of the profiles of profiles_on_planes over the bins between consecutive
    edges (n+1,) (Eq. 60; default: bins of width a1 = the smallest radius, channel.bin_edges)."""
    e = channel.bin_edges(float(snapshot.radii.min())) if edges is None else np.asarray(edges, dtype=float)
    return _profiles(0.5 * (e[1:] + e[:-1]), e, _bin_sums(snapshot, channel, e))


def volume_fraction(snapshot: Snapshot, channel: Channel, y0: float | None = None, y1: float | None = None) -> float:
    """Exact mean of phi(y) over [y0, y1] (default: wall to wall, i.e. phi_bulk for spheres inside
    the walls; Eqs. 49-50)."""
    lo = channel.y_lo if y0 is None else float(y0)
    hi = channel.y_hi if y1 is None else float(y1)
    return float(profiles_in_bins(snapshot, channel, [lo, hi]).phi[0])


def bulk_volume_fraction(snapshot: Snapshot, channel: Channel) -> float:
    """phi_bulk = sum_p V_p / V_box."""
    return float(snapshot.volumes.sum() / channel.volume)


# ---- core region -------------------------------------------------------------------------------

def _h_layer(snapshot: Snapshot, h_layer: float | None) -> float:
    return 5.0 * float(snapshot.radii.min()) if h_layer is None else float(h_layer)


def core_shear_rate(snapshot: Snapshot, channel: Channel, h_layer: float | None = None,
                    weighting: str = "number") -> float:
    """gamma_dot_core: least-squares slope of U_flow against y over the particles whose centres are
    in the core |y_p - y_mid| < L_y/2 - H_layer (H_layer default 5 a1, a1 the smallest radius);
    weighting "number" (each particle counts once) or "volume" (weights V_p). nan if fewer than
    two particles or no spread in y."""
    if weighting not in ("number", "volume"):
        raise ValueError("weighting must be 'number' or 'volume', got %r" % (weighting,))
    h = _h_layer(snapshot, h_layer)
    y0, y1 = channel.core_bounds(h)
    y = snapshot.positions[:, channel.wall_axis]
    inside = np.abs(y - channel.y_mid) < 0.5 * (y1 - y0)
    if inside.sum() < 2:
        return float("nan")
    u = snapshot.velocities[inside, channel.flow_axis]
    yi = y[inside]
    w = snapshot.volumes[inside] if weighting == "volume" else np.ones(len(yi))
    ym = np.sum(w * yi) / w.sum()
    um = np.sum(w * u) / w.sum()
    syy = np.sum(w * (yi - ym) ** 2)
    if syy <= 0:
        return float("nan")
    return float(np.sum(w * (yi - ym) * (u - um)) / syy)


@dataclass(frozen=True)
class CoreValues:
    """Core averages of one snapshot: phi (Eq. 50), gamma_dot (core_shear_rate), sigma_h and
    sigma_c (6,) (Eq. 53 averaged over the core, COMPONENTS order), n_particles (centres in the
    core), bounds (y0, y1) of the core, h_layer."""

    phi: float
    gamma_dot: float
    sigma_h: NDArray
    sigma_c: NDArray
    n_particles: int
    bounds: tuple[float, float]
    h_layer: float


def core_values(snapshot: Snapshot, channel: Channel, h_layer: float | None = None,
                weighting: str = "number") -> CoreValues:
    """phi_core (Eq. 50), Sigma^{h,core}, Sigma^{c,core} (Eq. 53 averaged over the core, exact: a
    sphere cut by a core boundary counts with the share of its volume inside) and gamma_dot_core
    (core_shear_rate) of one snapshot. H_layer default 5 a1 (a1 the smallest radius)."""
    h = _h_layer(snapshot, h_layer)
    y0, y1 = channel.core_bounds(h)
    s = profiles_in_bins(snapshot, channel, [y0, y1])
    y = snapshot.positions[:, channel.wall_axis]
    n_in = int(np.sum(np.abs(y - channel.y_mid) < 0.5 * (y1 - y0)))
    return CoreValues(phi=float(s.phi[0]), gamma_dot=core_shear_rate(snapshot, channel, h, weighting),
                      sigma_h=s.sigma_h[0].copy(), sigma_c=s.sigma_c[0].copy(), n_particles=n_in,
                      bounds=(y0, y1), h_layer=h)


@dataclass(frozen=True)
class CoreSeries:
    """Core values of a run, one row per snapshot: times (T,), phi (T,), gamma_dot (T,),
    sigma_h, sigma_c (T, 6), n_particles (T,); the channel and H_layer used."""

    times: NDArray
    phi: NDArray
    gamma_dot: NDArray
    sigma_h: NDArray
    sigma_c: NDArray
    n_particles: NDArray
    channel: Channel
    h_layer: float


def core_series(snapshots: Sequence[Snapshot], channel: Channel, h_layer: float | None = None,
                weighting: str = "number") -> CoreSeries:
    """core_values of every snapshot of a run (in time order), for fdmsubgrid.rheology.shear_rheology.
    H_layer default 5 a1 of the first snapshot."""
    if len(snapshots) == 0:
        raise ValueError("core_series needs at least one snapshot")
    h = _h_layer(snapshots[0], h_layer)
    values = [core_values(s, channel, h, weighting) for s in snapshots]
    return CoreSeries(times=np.array([s.time for s in snapshots]), phi=np.array([v.phi for v in values]),
                      gamma_dot=np.array([v.gamma_dot for v in values]),
                      sigma_h=np.array([v.sigma_h for v in values]), sigma_c=np.array([v.sigma_c for v in values]),
                      n_particles=np.array([v.n_particles for v in values]), channel=channel, h_layer=h)


# ---- time averages -----------------------------------------------------------------------------

@dataclass(frozen=True)
class ProfileAverage:
    """Time-averaged profiles over the snapshots with time >= start_time, on planes (edges None)
    or bins (edges (n+1,)); y (n,). Means: phi (n,), u_p (n, 3) = <phi u_p>/<phi>, omega_p (n, 3),
    sigma_h, sigma_c, sigma_p = sigma_h + sigma_c (n, 6). The *_error fields are the standard
    errors by block averaging over the snapshots (fdmsubgrid.timeseries.block_average; for u_p and
    omega_p the ratio of means, timeseries.ratio_of_means); None if not computed (errors=False),
    nan with fewer than 2 timeseries.MIN_BLOCKS snapshots. n_snapshots: snapshots averaged."""

    y: NDArray
    edges: NDArray | None
    phi: NDArray
    u_p: NDArray
    omega_p: NDArray
    sigma_h: NDArray
    sigma_c: NDArray
    sigma_p: NDArray
    phi_error: NDArray | None
    u_p_error: NDArray | None
    omega_p_error: NDArray | None
    sigma_h_error: NDArray | None
    sigma_c_error: NDArray | None
    sigma_p_error: NDArray | None
    n_snapshots: int
    start_time: float


def average_profiles(snapshots: Sequence[Snapshot], channel: Channel, *, y: ArrayLike | None = None,
                     edges: ArrayLike | None = None, start_time: float = -math.inf,
                     errors: bool = True) -> ProfileAverage:
    """Time average of the profiles of the snapshots with time >= start_time: on the planes y
    (profiles_on_planes) or in the bins edges (profiles_in_bins; the default, bins of width a1).
    With errors=False only running sums are kept (memory independent of the number of snapshots,
    for fine plane grids); with errors=True every snapshot's profile is kept for block averaging
    (equally spaced snapshots)."""
    if y is not None and edges is not None:
        raise ValueError("give planes y or bin edges, not both")
    chosen = [s for s in snapshots if s.time >= start_time]
    if not chosen:
        raise ValueError("no snapshot at or after start_time = %g" % start_time)
    if y is not None:
        yy = np.asarray(y, dtype=float).reshape(-1)
        ee = None

        def one(s: Snapshot) -> NDArray:
            return _plane_sums(s, channel, yy)
    else:
        ee = channel.bin_edges(float(chosen[0].radii.min())) if edges is None else np.asarray(edges, dtype=float)
        yy = 0.5 * (ee[1:] + ee[:-1])

        def one(s: Snapshot) -> NDArray:
            return _bin_sums(s, channel, ee)
    n_t = len(chosen)
    if errors:
        rows = np.array([one(s) for s in chosen])               # (T, n, 19)
        mean = rows.mean(axis=0)
    else:
        mean = np.zeros((len(yy), _NCOL))
        for s in chosen:
            mean += one(s)
        mean /= n_t
    phi = mean[:, _PHI]
    sigma_h, sigma_c = mean[:, _SH], mean[:, _SC]
    phi_e: NDArray | None = None
    u_e: NDArray | None = None
    omega_e: NDArray | None = None
    sh_e: NDArray | None = None
    sc_e: NDArray | None = None
    sp_e: NDArray | None = None
    if errors:
        if n_t >= 2 * timeseries.MIN_BLOCKS:
            e = np.asarray(timeseries.block_average(rows, axis=0).error)
            phi_e, sh_e, sc_e = e[:, _PHI], e[:, _SH], e[:, _SC]
            sp_e = np.asarray(timeseries.block_average(rows[:, :, _SH] + rows[:, :, _SC], axis=0).error)
            phi_t = rows[:, :, _PHI][:, :, None]
            u_e = np.asarray(timeseries.ratio_of_means(rows[:, :, _U], phi_t, axis=0).error)
            omega_e = np.asarray(timeseries.ratio_of_means(rows[:, :, _OMEGA], phi_t, axis=0).error)
        else:
            nan = np.full(mean.shape, np.nan)
            phi_e, u_e, omega_e, sh_e, sc_e = nan[:, _PHI], nan[:, _U], nan[:, _OMEGA], nan[:, _SH], nan[:, _SC]
            sp_e = nan[:, _SH].copy()
    return ProfileAverage(y=yy, edges=ee, phi=phi, u_p=_divide(mean[:, _U], phi[:, None]),
                          omega_p=_divide(mean[:, _OMEGA], phi[:, None]), sigma_h=sigma_h, sigma_c=sigma_c,
                          sigma_p=sigma_h + sigma_c, phi_error=phi_e, u_p_error=u_e, omega_p_error=omega_e,
                          sigma_h_error=sh_e, sigma_c_error=sc_e, sigma_p_error=sp_e, n_snapshots=n_t,
                          start_time=float(chosen[0].time))


@dataclass(frozen=True)
class SpeciesProfile:
    """One species (LIGGGHTS atom type) of a run alone: its radius and count, its time-averaged profiles
    (ProfileAverage of its spheres only, on the bins of the whole suspension: the species' phi add up to
    the total, bin by bin) and its volume fraction in the core (Eq. 50 restricted to the species, the core of
    the whole suspension's H_layer), averaged over the same snapshots, with its standard error (None with
    fewer than 2 timeseries.MIN_BLOCKS snapshots)."""

    type: int
    radius: float
    n: int
    average: ProfileAverage
    phi_core: float
    phi_core_error: float | None


def species_profiles(snapshots: Sequence[Snapshot], channel: Channel, *, h_layer: float | None = None,
                     edges: ArrayLike | None = None, start_time: float = -math.inf) -> list[SpeciesProfile]:
    """The profiles of each species of the snapshots with time >= start_time (SpeciesProfile, by type): bins
    `edges` (default: those of average_profiles for the whole suspension, a1 = the smallest radius of all),
    H_layer default 5 a1 likewise. A type holding two radii is an error (one radius per species)."""
    chosen = [s for s in snapshots if s.time >= start_time]
    if not chosen:
        raise ValueError("no snapshot at or after start_time = %g" % start_time)
    first = chosen[0]
    h = _h_layer(first, h_layer)
    ee = channel.bin_edges(float(first.radii.min())) if edges is None else np.asarray(edges, dtype=float)
    out = []
    for t in np.unique(first.types):
        mask = first.types == t
        radii = np.unique(first.radii[mask])
        if len(radii) != 1:
            raise ValueError("atom type %d holds the radii %s: a species is one radius" % (t, radii.tolist()))
        parts = [s.select(s.types == t) for s in chosen]
        average = average_profiles(parts, channel, edges=ee)
        core = np.array([core_values(part, channel, h).phi for part in parts])
        error = (float(timeseries.block_average(core).error) if len(core) >= 2 * timeseries.MIN_BLOCKS else None)
        out.append(SpeciesProfile(type=int(t), radius=float(radii[0]), n=int(np.sum(mask)), average=average,
                                  phi_core=float(core.mean()), phi_core_error=error))
    return out


def species_summary(species: Sequence[SpeciesProfile], volume: float) -> list[dict]:
    """The species of species_profiles as JSON-ready dicts: type, radius, n, phi_bulk (its spheres' volume over
    the box `volume`), phi_core with phi_core_err, and its phi profile (phi_profile, phi_profile_err, on the bins
    of the whole suspension's profile)."""
    def listed(v: NDArray | None) -> list | None:
        return None if v is None else [None if not np.isfinite(x) else float(x) for x in v]
    return [dict(type=sp.type, radius=sp.radius, n=sp.n,
                 phi_bulk=sp.n * 4.0 / 3.0 * math.pi * sp.radius ** 3 / volume,
                 phi_core=sp.phi_core, phi_core_err=sp.phi_core_error,
                 phi_profile=listed(sp.average.phi), phi_profile_err=listed(sp.average.phi_error))
            for sp in species]


# ---- plots -------------------------------------------------------------------------------------

def plot_profiles(path: str, channel: Channel, coarse: ProfileAverage, fine: ProfileAverage | None = None,
                  title: str | None = None, species: Sequence[SpeciesProfile] | None = None) -> str:
    """PNG of phi(y), u_p(y) (flow component) and the particle shear stresses Sigma^h_12,
    Sigma^c_12, Sigma^p_12 (1 = flow, 2 = wall-normal axis): the fine profile as a line, the
    coarse bins as points with error bars (standard errors); with species (species_profiles, more than
    one), each species' phi and u_p in its bins too. Returns path. The fluid's own shear
    stress (eta times the local fluid shear rate) is not included: these are the particle
    contributions of Eq. 51."""
    from matplotlib.figure import Figure

    xy = component(channel.flow_axis, channel.wall_axis)
    f = channel.flow_axis
    axes_name = "xyz"
    y_label = "%s (wall-normal)" % axes_name[channel.wall_axis]
    fig = Figure(figsize=(13, 4.2))
    ax = fig.subplots(1, 3)

    if fine is not None:
        ax[0].plot(fine.y, fine.phi, "-", lw=0.8, color="0.4", label="planes")
        ax[1].plot(fine.y, fine.u_p[:, f], "-", lw=0.8, color="0.4", label="planes")
        ax[2].plot(fine.y, fine.sigma_p[:, xy], "-", lw=0.8, color="0.4", label="planes")
    ax[0].errorbar(coarse.y, coarse.phi, yerr=coarse.phi_error, fmt="o", ms=4, capsize=2, label="bins")
    ax[1].errorbar(coarse.y, coarse.u_p[:, f], yerr=None if coarse.u_p_error is None else coarse.u_p_error[:, f],
                   fmt="o", ms=4, capsize=2, label="bins")
    for data, error, lab, mk in ((coarse.sigma_p, coarse.sigma_p_error, "h + c", "o"),
                                 (coarse.sigma_h, coarse.sigma_h_error, "h", "s"),
                                 (coarse.sigma_c, coarse.sigma_c_error, "c", "^")):
        ax[2].errorbar(coarse.y, data[:, xy], yerr=None if error is None else error[:, xy], fmt=mk, ms=4,
                       capsize=2, label="bins, " + lab)
    if species is not None and len(species) > 1:
        for sp in species:
            label = "type %d (a %g)" % (sp.type, sp.radius)
            ax[0].errorbar(sp.average.y, sp.average.phi, yerr=sp.average.phi_error, fmt="--.", ms=3, lw=0.8,
                           capsize=1, label=label)
            ax[1].plot(sp.average.y, sp.average.u_p[:, f], "--.", ms=3, lw=0.8, label=label)
    names = (r"$\phi$", r"$u_{p,%s}$" % axes_name[f],
             r"$\Sigma_{%s%s}$ (particles)" % (axes_name[f], axes_name[channel.wall_axis]))
    for a, name in zip(ax, names):
        a.set_xlabel(y_label)
        a.set_ylabel(name)
        a.axvline(channel.y_lo, color="k", lw=0.5)
        a.axvline(channel.y_hi, color="k", lw=0.5)
        a.legend(fontsize=8)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return path
