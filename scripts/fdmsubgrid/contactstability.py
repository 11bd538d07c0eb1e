"""The frictional contact of pair_style fdm/subgrid as a stability problem (docs/contact.md, sections 2b
and 3): the resistances the springs act against, the steady gap, the growth factor per step of a
perturbed contact, the time-step limit of the explicit springs, the overdamped gap history as
fix fdm/couple steps it, and the measurement of a stability limit from runs. One implementation for
the contact-tuning scenes (cases/contactTuning), the springs of the suspension cases
(suspension.choose_springs) and the tests.

    from fdmsubgrid import contactstability as cs
    res = cs.ContactResistances(a=1.0, eta=1.0, delta=0.2)       # the pair style's default cut-offs
    zeta = res.pair_normal(cs.steady_gap(0.01, 10.0, 2000.0))     # 929.35 N s/m at h = h_r/2
    cs.explicit_time_step_limit(zeta, 2000.0, "ab2")             # 0.4647 s (docs/contact.md 3c)

The model (docs/contact.md): the particles have no inertia, Eq. (31) gives their velocities from the
forces, implicit in the lubrication; a contact's spring k acts on one mode of the pair (the closing
speed for k_n, the slip of the contact points for k_t) whose resistance zeta is the isolated Stokes
drag plus the sub-grid block of the resistance library (fdmResistance, the code the pair style
calls; DEM only: `fix fdm/couple transport none`). With r = dt k/zeta:

    h_ss = h_r - F/k_n                                   the steady gap under the load F     (3a)
    euler: l = 1 - r;   ab2: l^2 - (1 - 3r/2) l - r/2 = 0   explicit springs, growth per step (3c)
    dt_max = zeta/k (ab2),  2 zeta/k (euler)              their time-step limit               (3c)
    ab2: (1 + r/2)/(1 + 3r/2);   euler: 1/(1 + r)          implicit springs, growth per step (C4)

Units: any consistent set (the scenes use SI at the 1 m scale, a = 1 m, eta = 1 Pa s).
"""
from __future__ import annotations

import concurrent.futures
import math
import threading
from typing import Callable, Dict, List, Optional, Sequence, Tuple

import numpy as np

from . import theory

INTEGRATORS = ("ab2", "euler")        # fix fdm/couple ... integrator (position update; ab2 the default)
# the reduced gap h/a below which the resistance library freezes its functions (docs/resistance.md): an
# overlap has the resistance of this gap
MIN_GAP = 1e-5


def _check_integrator(integrator: str) -> None:
    if integrator not in INTEGRATORS:
        raise ValueError("integrator must be one of %s, got %r" % (", ".join(INTEGRATORS), integrator))


# ---------------------------------------------------------------------------------------------
# the springs: steady state, design rules
# ---------------------------------------------------------------------------------------------

def steady_gap(h_r: float, load: float, kn: float) -> float:
    """h_ss = h_r - F/k_n: the gap of a contact carrying the normal force `load` (docs/contact.md 3a);
    negative: an overlap (F > k_n h_r)."""
    return h_r - load / kn


def design_load(a: float, stress: float) -> float:
    """F_max = 6 pi a^2 tau: the Stokes drag scale of a sphere of radius a under the shear stress tau, the
    largest normal load its contacts are designed for (docs/contact.md, "A recipe", step 1)."""
    return 6 * math.pi * a ** 2 * stress


def normal_stiffness(load: float, h_r: float, ratio: float = 2.0) -> float:
    """k_n = ratio F/h_r: a contact under F sits at h = (1 - 1/ratio) h_r, inside the roughness layer
    (docs/contact.md, "A recipe", step 2: ratio 2 ... 4)."""
    return ratio * load / h_r


# ---------------------------------------------------------------------------------------------
# stability of the springs (docs/contact.md 3c and Eq. C4)
# ---------------------------------------------------------------------------------------------

def limit_ratio(integrator: str) -> float:
    """r = dt k/zeta at the stability limit of an explicit spring: 1 (ab2), 2 (euler) (docs/contact.md 3c)."""
    _check_integrator(integrator)
    return 2.0 if integrator == "euler" else 1.0


def explicit_growth_factor(r: float, integrator: str) -> float:
    """|growth factor per step| of the deviation of an explicit spring from its steady state, r = dt k/zeta
    (docs/contact.md 3c): |1 - r| (euler); ab2 the largest |root| of l^2 - (1 - 3r/2) l - r/2 = 0."""
    _check_integrator(integrator)
    if integrator == "euler":
        return abs(1 - r)
    roots = np.roots([1.0, -(1 - 1.5 * r), -0.5 * r])
    return float(max(abs(roots)))


def implicit_growth_factor(r: float, integrator: str) -> float:
    """Growth factor per step of an implicit spring (docs/contact.md 2b, Eq. C4): (1 + r/2)/(1 + 3r/2)
    (ab2), 1/(1 + r) (euler); below 1 at every r, without oscillation."""
    _check_integrator(integrator)
    return (1 + 0.5 * r) / (1 + 1.5 * r) if integrator == "ab2" else 1.0 / (1 + r)


def explicit_time_step_limit(zeta: float, k: float, integrator: str = "ab2") -> float:
    """dt_max = zeta/k (ab2) or 2 zeta/k (euler): the largest stable time step of an explicit spring k
    acting on a mode of resistance zeta (docs/contact.md 3c; k_t twice for a sphere held by two
    contacts in series)."""
    return limit_ratio(integrator) * zeta / k


def step_gap_history(gap0: float, load: float, kn: float, h_r: float, dt: float, steps: int,
                     zeta: Callable[[float], float], integrator: str = "ab2",
                     settle: Optional[Tuple[float, float]] = None) -> np.ndarray:
    """Gap history of a contact pressed by `load` (pair: zeta of the pair's closing; wall), the spring
    force k_n (h_r - gap) for gap < h_r, stepped as fix fdm/couple does with explicit springs: the
    overdamped equation zeta(h) dh/dt = -(F - k_n max(0, h_r - h)) (docs/contact.md 3a), the velocity
    solved at step n from the positions of step n (initial velocity 0), the position moved at the next
    step with it (euler) or with 3/2 U_n - 1/2 U_(n-1) (ab2, from the third step on). With
    `settle` = (h_ss, tol): stops 20 steps after |gap - h_ss| < tol began to hold."""
    _check_integrator(integrator)
    g = []
    x, current, previous = gap0, 0.0, None
    quiet = 0
    for n in range(steps):
        if integrator == "ab2" and previous is not None:
            x -= dt * (1.5 * current - 0.5 * previous)
        else:
            x -= dt * current
        v = (load - kn * max(0.0, h_r - x)) / zeta(x)
        if n > 0:
            previous = current
        current = v
        g.append(x)
        if settle is not None:
            quiet = quiet + 1 if abs(x - settle[0]) < settle[1] else 0
            if quiet > 20:
                break
    return np.array(g)


# ---------------------------------------------------------------------------------------------
# the resistances the springs act against (Stokes drag + the sub-grid blocks of fdmResistance)
# ---------------------------------------------------------------------------------------------

# a sphere on a wall pulled at its centre, Stokes drag only: the contact point sticks and carries 4/7 of
# the pull (6 pi eta a U = F - f, 8 pi eta a^2 Omega = f, U = a Omega; docs/contact.md 3b)
ROLLING_CONTACT_FRACTION = 4.0 / 7.0


def wall_slip_resistance_stokes(a: float, eta: float) -> float:
    """Slip resistance of the contact point of a free sphere on a wall with Stokes drag only (translation
    and rotation, no lubrication): 1/zeta = 1/(6 pi eta a) + a^2/(8 pi eta a^3), zeta = 24/7 pi eta a; a
    lower bound of the resistance with lubrication."""
    return 24.0 / 7.0 * math.pi * eta * a


def sliding_speed_between_walls(tangential_load: float, normal_load: float, mu_s: float, zeta_t: float) -> float:
    """Speed of a sphere squeezed between two walls (F_n per contact) and pulled along them by 2 F_t, once
    it slides (F_t > mu_s F_n): each contact carries mu_s F_n, so 2 (F_t - mu_s F_n)/zeta_t, zeta_t the
    translational resistance between the walls (ContactResistances.between_walls_tangential)."""
    return 2 * (tangential_load - mu_s * normal_load) / zeta_t


class ContactResistances:
    """Resistances (force per unit speed of the mode a spring acts on) of equal spheres of radius a in a
    fluid of viscosity eta, at mesh size delta, with pair_style fdm/subgrid's cut-off model (`model
    cutoff`) at `cutoff` and `wall_cutoff` mesh cells (None: the pair style's defaults): the isolated
    Stokes drag that fix fdm/couple transport none puts in Eq. (31), plus with lubrication the sub-grid
    blocks of the resistance library (fdmResistance, the code the pair style calls). The sub-grid
    functions are zero beyond the cut-off and frozen below a gap MIN_GAP a (an overlap)."""

    def __init__(self, a: float, eta: float, delta: float, cutoff: Optional[float] = None,
                 wall_cutoff: Optional[float] = None):
        if cutoff is None or wall_cutoff is None:
            pair_default, wall_default = theory.pair_style_cutoffs()
            cutoff = pair_default if cutoff is None else cutoff
            wall_cutoff = wall_default if wall_cutoff is None else wall_cutoff
        self.a, self.eta, self.delta = float(a), float(eta), float(delta)
        self.cutoff, self.wall_cutoff = float(cutoff), float(wall_cutoff)
        self._cache: Dict[tuple, dict] = {}
        self._lock = threading.Lock()
        self._tables: Dict[tuple, Callable[[float], float]] = {}
        self._table_lock = threading.Lock()

    def _call(self, key: tuple, *args: object) -> dict:
        with self._lock:
            if key in self._cache:
                return self._cache[key]
        value = theory.resistance(*args)
        with self._lock:
            self._cache[key] = value
        return value

    def pair_squeeze(self, gap: float) -> float:
        """Sub-grid squeeze resistance X^A_11 (N s/m) of two equal spheres at the surface gap `gap`
        (`fdmResistance pair --subgrid`, docs/contact.md 3a)."""
        xi = gap / self.a
        if xi >= self.cutoff * self.delta / self.a:
            return 0.0
        xi = max(xi, MIN_GAP)
        out = self._call(("pair", round(math.log(xi), 12)), "pair", "--a1", self.a, "--a2", self.a, "--xi",
                         "%.17g" % xi, "--subgrid", "--delta", self.delta, "--cutoff", self.cutoff)
        return self.eta * out["dimensional_over_eta"]["XA11"]

    def wall_functions(self, gap: float) -> Dict[str, float]:
        """Sub-grid wall functions (XA, YA, ... dimensional: N s/m etc.) of a sphere at the surface gap
        `gap` from a wall (`fdmResistance wall --delta`)."""
        eps = gap / self.a
        if eps >= self.wall_cutoff * self.delta / self.a:
            return dict(XA=0.0, YA=0.0)
        eps = max(eps, MIN_GAP)
        out = self._call(("wall", round(math.log(eps), 12)), "wall", "--a", self.a, "--eps", "%.17g" % eps,
                         "--delta", self.delta, "--cutoff", self.wall_cutoff)
        return {k: self.eta * v for k, v in out["subgrid_dimensional_over_eta"].items()}

    def pair_normal(self, gap: float, lubrication: bool = True) -> float:
        """zeta_n of two free equal spheres, F = zeta_n (U_1 - U_2).n under equal and opposite loads F:
        3 pi eta a + X^A_SG(gap) (half of each sphere's Stokes drag plus the squeeze block; equal to
        theory.pair_mode_resistances' zeta_n to round-off)."""
        return 3 * math.pi * self.eta * self.a + (self.pair_squeeze(gap) if lubrication else 0.0)

    def wall_normal(self, gap: float, lubrication: bool = True) -> float:
        """Normal resistance of a sphere and a wall: 6 pi eta a + X^A_SG,wall(gap)."""
        return 6 * math.pi * self.eta * self.a + (self.wall_functions(gap)["XA"] if lubrication else 0.0)

    def between_walls_tangential(self, gap: float, lubrication: bool = True) -> float:
        """A sphere translating between two walls at the same gap (no rotation, by symmetry):
        6 pi eta a + 2 Y^A_SG,wall(gap)."""
        return 6 * math.pi * self.eta * self.a + (2 * self.wall_functions(gap)["YA"] if lubrication else 0.0)

    def pair_slip(self, gap: float, lubrication: bool = True) -> float:
        """Slip resistance zeta_t of the contact of two free equal spheres: equal and opposite tangential
        forces f at the contact points in the middle of the gap (the contact law's lever arms a + h/2,
        docs/contact.md 2), with their torques, make the contact points slip at f/zeta_t; the spheres
        translate and rotate (theory.pair_mode_resistances). 12/7 pi eta a without lubrication."""
        return theory.pair_mode_resistances(self.a, self.a, gap, self.delta, self.eta, self.cutoff,
                                            subgrid=lubrication, contact_in_mid_gap=True)[1]

    def gap_table(self, kind: str, lubrication: bool, points: int = 40,
                  jobs: int = 2) -> Callable[[float], float]:
        """zeta(gap) of the normal mode (`kind` 'pair' or 'wall') as a function cheap to call (for
        step_gap_history): sampled on `points` log-spaced gaps from MIN_GAP a to the cut-off, gap * zeta
        interpolated in log(gap) (quadratic through the three nearest samples; smooth, the lubrication
        is ~1/gap); kept per (kind, lubrication)."""
        if kind not in ("pair", "wall"):
            raise ValueError("kind must be 'pair' or 'wall', got %r" % kind)
        key = (kind, lubrication)
        with self._table_lock:
            if key not in self._tables:
                self._tables[key] = self._make_table(kind, lubrication, points, jobs)
            return self._tables[key]

    def _make_table(self, kind: str, lubrication: bool, points: int, jobs: int) -> Callable[[float], float]:
        if not lubrication:
            z = self.pair_normal(1.0, False) if kind == "pair" else self.wall_normal(1.0, False)
            return lambda gap: z
        cut = (self.cutoff if kind == "pair" else self.wall_cutoff) * self.delta
        gaps = np.geomspace(MIN_GAP * self.a, cut, points)
        zeta = self.pair_normal if kind == "pair" else self.wall_normal
        with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
            values = np.array(list(pool.map(zeta, gaps)))
        far = zeta(2 * cut)
        logs, products = np.log(gaps), gaps * values

        def f(gap: float) -> float:
            if gap >= cut:
                return far
            if gap <= gaps[0]:
                return values[0]
            s = math.log(gap)
            i = min(max(int(np.searchsorted(logs, s)), 1), len(logs) - 2)
            x0, x1, x2 = logs[i - 1], logs[i], logs[i + 1]
            y0, y1, y2 = products[i - 1], products[i], products[i + 1]
            y = (y0 * (s - x1) * (s - x2) / ((x0 - x1) * (x0 - x2)) + y1 * (s - x0) * (s - x2) / ((x1 - x0) * (x1 - x2))
                 + y2 * (s - x0) * (s - x1) / ((x2 - x0) * (x2 - x1)))
            return y / gap
        return f


# ---------------------------------------------------------------------------------------------
# measuring stability from a run
# ---------------------------------------------------------------------------------------------

def settle_index(series: Sequence[float], target: float, tol: float) -> Optional[int]:
    """First index from which |series - target| <= tol holds to the end (None if it does not hold at the end)."""
    bad = np.nonzero(np.abs(np.asarray(series) - target) > tol)[0]
    if len(bad) == 0:
        return 0
    return None if bad[-1] == len(series) - 1 else int(bad[-1] + 1)


def classify_perturbation(error: Sequence[float], scale: float, h_r: Optional[float] = None,
                          gap: Optional[np.ndarray] = None, gap_steady: Optional[float] = None) -> dict:
    """Stability of a perturbed steady state from its error series (gap - h_ss, or the tangential force
    error), error[0] the initial perturbation. Stable: the perturbation never grows beyond 1.5 times its
    initial size (a stable run of either integrator stays below it; an unstable one, even growing by
    0.1 % per step, passes it within a few hundred steps). `label`: converged, decaying, growing, or with
    the gap history (gap, h_r, gap_steady) what an unstable normal contact does: chatter (contact lost
    and made again), deep overlap, bounded oscillation. `factor_measured`: the growth factor per step
    over the linear window (|error| between 1e-9 and 20 times the start), from the envelope of the
    alternating error. scale: the size of the state (round-off: 1e-10 of it counts as converged)."""
    e = np.abs(np.asarray(error, float))
    n = len(e)
    e0 = e[0]
    w = max(5, min(40, n // 8))
    last = e[-w:].max()
    stable = not bool(e[1:].max() > 1.5 * e0)
    if last < 1e-6 * e0 or last < 1e-10 * scale:   # 1e-10: round-off of positions ~ 1e-15 m
        label = "converged"
    elif stable:
        label = "decaying"
    else:
        label = "growing"
        if gap is not None:
            late = gap[-max(w, n // 2):]
            if late.max() >= h_r:
                label = "chatter (contact lost and made again)"
            elif late.min() < 0 and late.min() < gap_steady - (h_r - gap_steady):
                label = "deep overlap"
            else:
                label = "bounded oscillation"
    lo = 3
    hi = lo
    while hi + 1 < n and hi - lo < 60 and 1e-9 * e0 < e[hi + 1] < 20 * e0:
        hi += 1
    factor = None
    if hi - lo >= 4:
        # envelope: the larger of each pair of neighbours (the error alternates in sign)
        a, b = max(e[lo], e[lo + 1]), max(e[hi - 1], e[hi])
        if a > 0 and b > 0:
            factor = float((b / a) ** (1.0 / (hi - 1 - lo)))
    elif n > lo + 1 and e[lo + 1] <= 1e-9 * e0:
        factor = 0.0
    return dict(stable=stable, label=label, factor_measured=factor, max_error_over_initial=float(e.max() / e0),
                late_error_over_initial=float(last / e0))


def bisect_stability_limit(run: Callable[[float], dict], estimate: float, rel_tol: float = 0.01,
                           widen: int = 6) -> Tuple[float, float, List[dict]]:
    """The largest stable time step, by bisection in log(dt) between a stable and an unstable run of
    `run(dt)` (a dict with `stable`), starting from [0.8, 1.25] times `estimate` and widening the bracket
    by 1.5 at most `widen` times each way. Returns (lo, hi, runs): hi/lo - 1 <= rel_tol, the measured
    limit sqrt(lo hi)."""
    lo, hi = 0.8 * estimate, 1.25 * estimate
    r_lo, r_hi = run(lo), run(hi)
    runs = [r_lo, r_hi]
    for _ in range(widen):
        if r_lo["stable"]:
            break
        hi, r_hi = lo, r_lo
        lo /= 1.5
        r_lo = run(lo)
        runs.append(r_lo)
    for _ in range(widen):
        if not r_hi["stable"]:
            break
        lo, r_lo = hi, r_hi
        hi *= 1.5
        r_hi = run(hi)
        runs.append(r_hi)
    while hi / lo - 1 > rel_tol:
        mid = math.sqrt(lo * hi)
        r = run(mid)
        runs.append(r)
        if r["stable"]:
            lo = mid
        else:
            hi = mid
    return lo, hi, runs
