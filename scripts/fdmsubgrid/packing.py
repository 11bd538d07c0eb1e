"""Random dense packings of spheres in a periodic box (numpy, scipy's KD-tree), written as LIGGGHTS data files.

    from fdmsubgrid import packing
    p = packing.random_packing(1000, 0.45, bidisperse=True, seed=1)   # the paper's a1 = 1, a2 = 1.4
    p.min_gap, p.phi, p.box                                           # measured, not assumed
    packing.write_data("spheres.data", p)                            # atom_style sphere, type 1 / 2
    case.write_dem_input(dem_dir, box, p.spheres(), ...)             # or as (x, y, z, a) tuples
    demonly.Scene(p, ...)                                            # fdmDEM scenes (fdm/demonly.py)

Command line (prints a summary, writes the data file):

    python3 -m fdmsubgrid.packing N PHI [--bidisperse | --radii A... [--volume-fractions F...]] [--seed S]
                                 [--min-gap G] [--box-multiple D] [--shake SWEEPS] [--walls y] -o FILE

    p = packing.channel_packing((10, 12, 8), phi=0.3, seed=1)        # any box, walls at y = 0 and L_y
                                                                     # (the Couette and Poiseuille cells)
    sizes = packing.SizeDistribution.of([1, 1.2, 1.4], [0.4, 0.3, 0.3])   # any size distribution
    p = packing.channel_packing((10, 12, 8), phi=0.3, sizes=sizes)   # species k is atom type k + 1

Boxes are periodic, or wall-bounded along some axes (walls=(1,): planar walls at y = 0 and
y = L, every sphere at least min_gap from them; LIGGGHTS boundary 'p f p'), for Couette cells.

Method. Radii: all a1 (monodisperse), the paper's bidisperse suspension (section 6: a1 = 1,
a2 = 1.4 a1, the two populations occupying equal volumes, i.e. n1 a1^3 = n2 a2^3), or any
SizeDistribution (radii with their shares of the particle volume, one atom type each). The cubic box
side follows from the target volume fraction phi (optionally rounded to a multiple of a mesh size,
so that the same box can be meshed by blockMesh; phi is then recomputed). Centres are placed
uniformly at random at their full size (overlapping), then the overlaps are removed by iterative
pairwise displacement ("overlap relaxation"): every pair whose surface gap is below a target gap
g_t = (1 + margin) min_gap is pushed apart along its line of centres, each sphere by 0.55 of the
deficit (a slight over-relaxation; minimum image in the periodic directions; a sphere closer than
g_t to a wall is put back at g_t), all pairs at once, until the smallest surface gap in the box is
>= min_gap: 100-350 sweeps at phi = 0.45-0.5. The result is a stiff, worst case for lubrication:
the relaxation leaves the pairs it separated at about g_t, ~1.4 pairs per sphere below 1e-3 a1 at
phi = 0.45 and ~1.7 at phi = 0.5 (min_gap 1e-4). Optionally, hard-sphere Monte Carlo sweeps (moves
rejected if any gap would drop below min_gap) then loosen them: after 100 sweeps ~0.07 pairs per
sphere below 1e-3 a1 at phi = 0.45 (1000 spheres: 5 s). Neighbours come from a periodic cell list
(Verlet list with a skin, rebuilt when a sphere has moved half the skin) found by scipy's periodic
KD-tree (cKDTree with boxsize; 2-3 times faster than the former numpy cell list, same pairs):
1000 spheres at phi = 0.5 take under a second without Monte Carlo.

The minimum gap is measured at the end over every pair (minimum image, O(N) with the cell list)
and returned in Packing.min_gap; generation fails (RuntimeError) if it is below min_gap.
Lengths are in units of a1 (scale them with `scale`)."""
import argparse
import math
import sys
from dataclasses import dataclass
from typing import Sequence

import numpy as np

A2_OVER_A1 = 1.4


class SizeDistributionError(ValueError):
    """Radii and volume fractions that do not make a suspension; the message names the value."""


@dataclass(frozen=True)
class SizeDistribution:
    """The species of a suspension: radii (units of a1, strictly increasing; species k is LIGGGHTS atom type
    k + 1) and the share of the particle volume each occupies (volume_fractions, each in (0, 1], summing to 1
    within FRACTION_SUM_TOLERANCE). The paper's suspension is PAPER_SUSPENSION: radii 1 and 1.4, equal volumes.

        SizeDistribution.of([1, 1.4, 2], [0.4, 0.3, 0.3])      # checked; SizeDistributionError otherwise
        SizeDistribution.lognormal(1.2, 0.2, 3)                # a log-normal distribution in 3 species
    """

    radii: tuple
    volume_fractions: tuple

    FRACTION_SUM_TOLERANCE = 1e-6

    @classmethod
    def of(cls, radii: Sequence[float], volume_fractions: Sequence[float] | None = None) -> "SizeDistribution":
        """The distribution of these radii and volume fractions (default: equal volumes), checked: the same
        number of each, radii positive and distinct (sorted ascending with their fractions), fractions positive
        and summing to 1. SizeDistributionError naming the offending value otherwise."""
        radii = [float(r) for r in radii]
        if not radii:
            raise SizeDistributionError("size distribution: no radius given")
        if volume_fractions is None:
            volume_fractions = [1.0 / len(radii)] * len(radii)
        fractions = [float(f) for f in volume_fractions]
        if len(fractions) != len(radii):
            raise SizeDistributionError("size distribution: %d radii (%s) but %d volume fractions (%s): one fraction "
                                        "per radius" % (len(radii), " ".join("%g" % r for r in radii), len(fractions),
                                                        " ".join("%g" % f for f in fractions)))
        for r in radii:
            if not (math.isfinite(r) and r > 0):
                raise SizeDistributionError("size distribution: radius %g is not a positive length (units of a1)" % r)
        for f in fractions:
            if not (math.isfinite(f) and 0 < f <= 1):
                raise SizeDistributionError("size distribution: volume fraction %g is not in (0, 1]" % f)
        if len(set(radii)) != len(radii):
            raise SizeDistributionError("size distribution: radius %g is given twice; give each radius once with the "
                                        "sum of its volume fractions" % next(r for r in radii if radii.count(r) > 1))
        total = math.fsum(fractions)
        if abs(total - 1.0) > cls.FRACTION_SUM_TOLERANCE:
            raise SizeDistributionError("size distribution: the volume fractions %s sum to %.9g, not 1: each is the "
                                        "share of the particle volume (phi_k / phi_bulk)"
                                        % (" ".join("%g" % f for f in fractions), total))
        order = sorted(range(len(radii)), key=lambda k: radii[k])
        return cls(tuple(radii[k] for k in order), tuple(fractions[k] for k in order))

    @classmethod
    def lognormal(cls, median: float, sigma: float, n_species: int, width: float = 2.0) -> "SizeDistribution":
        """A log-normal number distribution of radii (median `median` a1, standard deviation `sigma` of ln a)
        discretised into n_species: ln a from ln median - width sigma to ln median + width sigma cut into
        n_species equal intervals, each species the geometric centre of its interval, holding the particle
        volume of its interval (its probability times a^3, normalised). n_species 1: the median alone."""
        if not (median > 0 and sigma >= 0 and int(n_species) == n_species and n_species >= 1):
            raise SizeDistributionError("size distribution: lognormal needs MEDIAN > 0, SIGMA >= 0 and N >= 1 species, "
                                        "got %g %g %g" % (median, sigma, n_species))
        n_species = int(n_species)
        if n_species == 1 or sigma == 0:
            return cls.of([median], [1.0])
        from scipy.stats import norm
        edges = np.linspace(-width, width, n_species + 1)
        probability = np.diff(norm.cdf(edges))
        radii = median * np.exp(sigma * 0.5 * (edges[1:] + edges[:-1]))
        volume = probability * radii ** 3
        return cls.of([float(r) for r in radii], [float(v) for v in volume / volume.sum()])

    @property
    def n_species(self) -> int:
        return len(self.radii)

    @property
    def smallest(self) -> float:
        return self.radii[0]

    @property
    def largest(self) -> float:
        return self.radii[-1]

    def describe(self) -> str:
        return ", ".join("radius %g (%.4g of the volume)" % (r, f) for r, f in zip(self.radii, self.volume_fractions))

    def counts_for_volume(self, volume: float, phi: float, a1: float = 1.0) -> list[int]:
        """The sphere count of each species filling the fraction phi of `volume`: n_k = round(f_k phi volume /
        (4/3 pi (a1 r_k)^3)) (each species' volume within half a sphere of its share)."""
        return [int(round(f * phi * volume / (4.0 / 3.0 * math.pi * (a1 * r) ** 3)))
                for r, f in zip(self.radii, self.volume_fractions)]

    def counts_for_number(self, n: int) -> list[int]:
        """n spheres split so that the species' volumes follow the fractions: n_k = round(n w_k / sum w), w_k =
        f_k / r_k^3, for every species but the first, which takes the rest."""
        if self == PAPER_SUSPENSION:
            return list(counts(n, True))
        w = np.array(self.volume_fractions) / np.array(self.radii) ** 3
        rest = [int(round(n * wk / w.sum())) for wk in w[1:]]
        return [n - sum(rest)] + rest

    def volume_tolerance(self, volume: float, phi: float, a1: float = 1.0) -> list[float]:
        """How far each species' share of the particle volume may be from its fraction after rounding the
        counts (counts_for_volume): half a sphere of that species over the particle volume phi volume."""
        return [0.5 * 4.0 / 3.0 * math.pi * (a1 * r) ** 3 / (phi * volume) for r in self.radii]


PAPER_SUSPENSION = SizeDistribution((1.0, A2_OVER_A1), (0.5, 0.5))
"""The paper's suspension (section 6): radii a1 = 1 and a2 = 1.4 a1 in equal volumes."""


class Packing:
    """N spheres in the box [0, L)^3, periodic except along the axes in walls (planar walls at 0 and
    L there): positions (N, 3), radii (N,), types (N,) (1 for a1, 2 for a2; species k + 1 of a
    SizeDistribution), box (L, L, L), phi
    (actual volume fraction), min_gap (smallest surface gap, pairs and walls, measured),
    min_wall_gap, and the generator's statistics in info."""

    def __init__(self, positions, radii, types, box, info=None, walls=()):
        self.positions = np.asarray(positions, dtype=float)
        self.radii = np.asarray(radii, dtype=float)
        self.types = np.asarray(types, dtype=int)
        self.box = np.asarray(box, dtype=float)
        self.walls = tuple(walls)
        self.info = dict(info or {})
        self.min_gap = minimum_gap(self.positions, self.radii, self.box, self.walls)
        w = wall_gaps(self.positions, self.radii, self.box, self.walls)
        self.min_wall_gap = float(w.min()) if w.size else math.inf

    @property
    def boundary(self):
        """LIGGGHTS boundary command arguments, e.g. 'p f p' for walls=(1,)."""
        return " ".join("f" if d in self.walls else "p" for d in range(3))

    @property
    def n(self):
        return len(self.radii)

    @property
    def phi(self):
        return float(np.sum(4.0 / 3.0 * math.pi * self.radii ** 3) / np.prod(self.box))

    def species(self):
        """[(type, radius, count, share of the particle volume), ...] by type: what the packing holds of each
        species (a type holds one radius)."""
        volumes = 4.0 / 3.0 * math.pi * self.radii ** 3
        total = float(np.sum(volumes))
        out = []
        for t in np.unique(self.types):
            mask = self.types == t
            out.append((int(t), float(self.radii[mask][0]), int(np.sum(mask)), float(np.sum(volumes[mask])) / total))
        return out

    def spheres(self):
        """[(x, y, z, a), ...] as fdmsubgrid.deminput.write_dem_input takes them."""
        return [(float(x[0]), float(x[1]), float(x[2]), float(a)) for x, a in zip(self.positions, self.radii)]

    def gaps(self, cutoff):
        """Surface gaps of every pair closer than `cutoff` (surface to surface), sorted."""
        i, j, d = neighbour_pairs(self.positions, self.box, 2 * self.radii.max() + cutoff, self.walls)
        g = d - self.radii[i] - self.radii[j]
        return np.sort(g[g < cutoff])

    def summary(self):
        gaps = self.gaps(0.1 * self.radii.min())
        a = self.radii.min()
        return ("%d spheres (%s), box %s (boundary %s), phi %.4f, min surface gap %.3g a1%s; pairs with gap "
                "< 1e-3 a1: %d, < 1e-2 a1: %d, < 0.1 a1: %d; %s"
                % (self.n, ", ".join("%d of radius %g" % (np.sum(self.radii == r), r) for r in np.unique(self.radii)),
                   " x ".join("%g" % b for b in self.box), self.boundary, self.phi, self.min_gap / a,
                   "" if not self.walls else " (walls: %.3g a1)" % (self.min_wall_gap / a),
                   np.sum(gaps < 1e-3 * a), np.sum(gaps < 1e-2 * a), len(gaps),
                   ", ".join("%s %s" % (k, v) for k, v in self.info.items())))


def counts(n, bidisperse):
    """(n1, n2): sphere counts of radius a1 and a2 = 1.4 a1 with equal volumes (n1 a1^3 = n2 a2^3)."""
    if not bidisperse:
        return n, 0
    n2 = int(round(n / (1.0 + A2_OVER_A1 ** 3)))
    return n - n2, n2


def box_side(radii, phi, multiple=None):
    """Side of the cube holding spheres of these radii at volume fraction phi (rounded to the
    nearest multiple of `multiple`, e.g. the mesh size, if given)."""
    side = (np.sum(4.0 / 3.0 * math.pi * np.asarray(radii) ** 3) / phi) ** (1.0 / 3.0)
    if multiple:
        side = max(1, round(side / multiple)) * multiple
    return float(side)


# ------------------------------------------------------------------------------------------------
# neighbour search: scipy's periodic KD-tree (and the former cell list)
# ------------------------------------------------------------------------------------------------

def _periodic_mask(walls):
    mask = np.ones(3, dtype=bool)
    for axis in walls:
        mask[axis] = False
    return mask


def _minimum_image(dx, box, periodic=(True, True, True)):
    return dx - np.where(periodic, box, 0.0) * np.round(dx / box)


def _wrap(x, box, periodic):
    return x - np.where(periodic, box, 0.0) * np.floor(x / box)


def neighbour_pairs(x, box, cutoff, walls=()):
    """Every pair i < j with centre distance < cutoff (minimum image in the periodic directions,
    i.e. all but the axes listed in walls); returns (i, j, distance). Needs cutoff < box/2.
    scipy's periodic KD-tree (neighbour_pairs_kdtree): the same pairs as the cell list
    (neighbour_pairs_cells) and 2-3 times faster (measured on a shared 2-core machine, bidisperse, walls in y, cut-off 3.1 a1:
    350 spheres 0.36 against 0.98 ms, 1000 spheres 1.7 against 4.4 ms, 4000 spheres 7.6 against 16 ms)."""
    return neighbour_pairs_kdtree(x, box, cutoff, walls)


def neighbour_pairs_cells(x, box, cutoff, walls=()):
    """neighbour_pairs by the periodic cell list (vectorised numpy; the generator's search before
    scipy's KD-tree replaced it, kept as the reference of tests/test_couette.py)."""
    x = np.asarray(x, dtype=float)
    box = np.asarray(box, dtype=float)
    periodic = _periodic_mask(walls)
    n = len(x)
    if np.any(cutoff >= box / 2):
        raise ValueError("neighbour cut-off %g is not below half the box %s" % (cutoff, box))
    ncell = np.maximum(np.floor(box / cutoff).astype(int), 1)
    if np.any(ncell < 3) or n < 64:
        # small box or few spheres: all pairs
        i, j = np.triu_indices(n, 1)
    else:
        # cells wrap in every direction; in a wall-bounded one the true distance removes the far pairs
        xw = np.clip(_wrap(x, box, periodic), 0.0, box * (1 - 1e-15))
        c = np.minimum((xw / (box / ncell)).astype(int), ncell - 1)
        cell = (c[:, 0] * ncell[1] + c[:, 1]) * ncell[2] + c[:, 2]
        order = np.argsort(cell, kind="stable")
        ncells = int(np.prod(ncell))
        occupancy = np.bincount(cell, minlength=ncells)
        start = np.concatenate(([0], np.cumsum(occupancy)[:-1]))
        width = int(occupancy.max())
        members = -np.ones((ncells, width), dtype=int)
        rank = np.arange(n) - start[cell[order]]
        members[cell[order], rank] = order
        ii, jj = [], []
        for o in np.array(np.meshgrid([-1, 0, 1], [-1, 0, 1], [-1, 0, 1], indexing="ij")).reshape(3, -1).T:
            cn = (c + o) % ncell
            other = members[(cn[:, 0] * ncell[1] + cn[:, 1]) * ncell[2] + cn[:, 2]]  # (n, width)
            i_ = np.repeat(np.arange(n), width)
            j_ = other.ravel()
            keep = (j_ > i_)
            ii.append(i_[keep])
            jj.append(j_[keep])
        i = np.concatenate(ii)
        j = np.concatenate(jj)
        # a pair can be seen through two offsets only if ncell < 3 (excluded above): no duplicates
    d = np.linalg.norm(_minimum_image(x[i] - x[j], box, periodic), axis=1)
    keep = d < cutoff
    return i[keep], j[keep], d[keep]


def neighbour_pairs_kdtree(x, box, cutoff, walls=()):
    """The same pairs as neighbour_pairs (i < j, centre distance < cutoff, minimum image in the
    periodic directions), from scipy.spatial.cKDTree with a toroidal `boxsize`. A wall-bounded axis
    gets a period longer than the spread of the centres plus cutoff, so that no pair is found
through its wrap. Needs cutoff <
    box/2 along the periodic axes (one image per pair)."""
    from scipy.spatial import cKDTree
    x = np.asarray(x, dtype=float)
    box = np.asarray(box, dtype=float)
    periodic = _periodic_mask(walls)
    if np.any(cutoff >= box[periodic] / 2):
        raise ValueError("neighbour cut-off %g is not below half the box %s" % (cutoff, box))
    xw = _wrap(x, box, periodic)
    xw = np.where(periodic, np.minimum(xw, np.nextafter(box, 0)), xw)   # [0, L): the tree refuses L itself
    low = np.where(periodic, 0.0, xw.min(axis=0) if len(xw) else 0.0)  # a wall axis: shifted to start at 0
    xw = xw - low
    span = xw.max(axis=0) if len(xw) else np.zeros(3)
    period = np.where(periodic, box, span + cutoff + 1.0)
    tree = cKDTree(xw, boxsize=period)
    ij = tree.query_pairs(cutoff, output_type="ndarray")
    if len(ij) == 0:
        return np.zeros(0, dtype=int), np.zeros(0, dtype=int), np.zeros(0)
    i, j = ij[:, 0], ij[:, 1]
    d = np.linalg.norm(_minimum_image(x[i] - x[j], box, periodic), axis=1)
    keep = d < cutoff
    return i[keep], j[keep], d[keep]


def wall_gaps(x, radii, box, walls=()):
    """Surface gaps to the walls (the faces 0 and L of each axis in walls), shape (N, 2 len(walls))."""
    cols = []
    for axis in walls:
        cols.append(x[:, axis] - radii)
        cols.append(box[axis] - x[:, axis] - radii)
    return np.array(cols).T if cols else np.zeros((len(radii), 0))


def minimum_gap(x, radii, box, walls=()):
    """Smallest surface gap over every pair (minimum image in the periodic directions) and, with
    walls, every sphere-wall gap; +inf for a single sphere without walls."""
    g = math.inf
    w = wall_gaps(x, radii, box, walls)
    if w.size:
        g = float(w.min())
    if len(radii) < 2:
        return g
    rmax = float(np.max(radii))
    cutoff = min(2 * rmax * 1.5, 0.499 * float(np.min(box)))
    i, j, d = neighbour_pairs(x, box, cutoff, walls)
    if len(i) == 0:
        return min(g, math.inf if cutoff >= 2 * rmax else float(cutoff - 2 * rmax))
    return min(g, float(np.min(d - radii[i] - radii[j])))


# ------------------------------------------------------------------------------------------------
# generation
# ------------------------------------------------------------------------------------------------

class PackingError(RuntimeError):
    """The packing could not be made (volume fraction too high for the box, or sweeps exhausted)."""


def relax_overlaps(x, radii, box, min_gap, margin=0.5, max_iterations=20000, skin=None, step=0.55, walls=(),
                   wall_gap=None):
    """Pushes apart every pair (and pushes off the walls every sphere) with a surface gap below
    (1 + margin) min_gap until the smallest gap is >= min_gap (and every wall gap >= wall_gap,
    default min_gap). x is modified in place; returns the number of sweeps; raises PackingError
    after max_iterations sweeps."""
    periodic = _periodic_mask(walls)
    target = (1.0 + margin) * min_gap
    wall_gap = min_gap if wall_gap is None else float(wall_gap)
    wall_target = (1.0 + margin) * wall_gap
    skin = 0.3 * float(np.min(radii)) if skin is None else skin
    cutoff = 2 * float(np.max(radii)) + target + skin
    reference = x.copy()
    i, j, _ = neighbour_pairs(x, box, cutoff, walls)
    contact = radii[i] + radii[j] + target
    for sweep in range(1, max_iterations + 1):
        if np.max(np.linalg.norm(_minimum_image(x - reference, box, periodic), axis=1)) > 0.5 * skin:
            reference = x.copy()
            i, j, _ = neighbour_pairs(x, box, cutoff, walls)
            contact = radii[i] + radii[j] + target
        dx = _minimum_image(x[i] - x[j], box, periodic)
        d = np.linalg.norm(dx, axis=1)
        deficit = contact - d
        bad = deficit > 0
        wall_gaps_now = wall_gaps(x, radii, box, walls)
        pair_ok = not np.any(bad) or np.min(d - radii[i] - radii[j]) >= min_gap
        if pair_ok and (wall_gaps_now.size == 0 or wall_gaps_now.min() >= wall_gap):
            return sweep
        for k, axis in enumerate(walls):  # off the walls, to the target gap
            lo = np.maximum(wall_target - wall_gaps_now[:, 2 * k], 0.0)
            hi = np.maximum(wall_target - wall_gaps_now[:, 2 * k + 1], 0.0)
            x[:, axis] += lo - hi
        b = np.nonzero(bad)[0]
        dd = np.where(d[b] > 0, d[b], 1e-12)
        n = dx[b] / dd[:, None]
        n[d[b] == 0] = np.array([1.0, 0.0, 0.0])
        push = (step * deficit[b])[:, None] * n
        move = np.zeros_like(x)
        np.add.at(move, i[b], push)
        np.add.at(move, j[b], -push)
        x += move
        x[:] = _wrap(x, box, periodic)
    raise PackingError("overlap relaxation did not reach a minimum gap of %g in %d sweeps (phi too high?)"
                       % (min_gap, max_iterations))


def shake(x, radii, box, min_gap, sweeps, rng, max_step=None, walls=()):
    """Hard-sphere Monte Carlo: each sweep tries one random displacement per sphere (uniform in a
    cube of half-side max_step, adapted towards 40 % acceptance, at least 0.02 a1), rejected if any surface gap would
    drop below min_gap (pairs and walls). x is modified in place; returns the acceptance ratio."""
    periodic = _periodic_mask(walls)
    n = len(radii)
    step = 0.1 * float(np.min(radii)) if max_step is None else max_step
    min_step = 0.02 * float(np.min(radii))  # a floor: gaps of 1e-4 must not freeze the moves
    skin = 0.5 * float(np.min(radii))
    cutoff = 2 * float(np.max(radii)) + min_gap + skin
    accepted = tried = 0
    for _ in range(sweeps):
        i, j, _ = neighbour_pairs(x, box, cutoff, walls)
        neighbours = [[] for _ in range(n)]
        for a, b in zip(i.tolist(), j.tolist()):
            neighbours[a].append(b)
            neighbours[b].append(a)
        neighbours = [np.array(v, dtype=int) for v in neighbours]
        start = x.copy()
        step = min(step, 0.2 * skin)  # a move plus the sweep's drift stays within the skin
        acc_sweep = 0
        for p in rng.permutation(n):
            trial = x[p] + rng.uniform(-step, step, 3)
            if np.linalg.norm(_minimum_image(trial - start[p], box, periodic)) > 0.45 * skin:
                continue
            if any(trial[a] - radii[p] < min_gap or box[a] - trial[a] - radii[p] < min_gap for a in walls):
                tried += 1
                continue
            nb = neighbours[p]
            if len(nb):
                d = np.linalg.norm(_minimum_image(x[nb] - trial, box, periodic), axis=1)
                if np.any(d - radii[nb] - radii[p] < min_gap):
                    tried += 1
                    continue
            x[p] = _wrap(trial, box, periodic)
            accepted += 1
            acc_sweep += 1
            tried += 1
        ratio = acc_sweep / n
        step = max(step * (1.2 if ratio > 0.4 else 0.8), min_step)
    return accepted / tried if tried else 0.0


def random_packing(n, phi, bidisperse=False, seed=0, min_gap=1e-4, box_multiple=None, shake_sweeps=0,
                   margin=0.5, a1=1.0, walls=(), sizes=None):
    """A random packing of n spheres at volume fraction phi in a cube (see the module's docstring),
    periodic except along the axes in walls (e.g. walls=(1,): planar walls at y = 0 and y = L, for
    a Couette cell; every sphere at least min_gap from them too). min_gap: smallest surface gap
    required (units of length, a1 = 1 by default); box_multiple: round the box side to a multiple
    of this (a mesh size; phi changes slightly); shake_sweeps: hard-sphere Monte Carlo sweeps after
    the relaxation; sizes: a SizeDistribution (n split by its volume fractions, species k of radius
    a1 sizes.radii[k] as type k + 1) in place of bidisperse. Deterministic for a seed."""
    rng = np.random.default_rng(seed)
    if sizes is not None:
        numbers = sizes.counts_for_number(n)
        radii = np.concatenate([np.full(k, a1 * r) for k, r in zip(numbers, sizes.radii)])
        types = np.concatenate([np.full(k, t + 1, dtype=int) for t, k in enumerate(numbers)])
    else:
        n1, n2 = counts(n, bidisperse)
        radii = np.concatenate([np.full(n1, a1), np.full(n2, A2_OVER_A1 * a1)])
        types = np.concatenate([np.ones(n1, dtype=int), 2 * np.ones(n2, dtype=int)])
    perm = rng.permutation(n)  # mix the two sizes in tag order
    radii, types = radii[perm], types[perm]
    side = box_side(radii, phi, box_multiple)
    box = np.full(3, side)
    if 2 * radii.max() + 2 * min_gap >= side / 2:
        raise ValueError("box side %g is too small for spheres of radius %g" % (side, radii.max()))
    x = rng.uniform(0.0, 1.0, (n, 3)) * box
    for axis in walls:  # centres where the sphere fits between the walls
        x[:, axis] = radii + 2 * min_gap + rng.uniform(0.0, 1.0, n) * (side - 2 * radii - 4 * min_gap)
    sweeps = relax_overlaps(x, radii, box, min_gap, margin=margin, walls=walls)
    acceptance = shake(x, radii, box, min_gap, shake_sweeps, rng, walls=walls) if shake_sweeps else None
    info = dict(seed=seed, relaxation_sweeps=sweeps)
    if shake_sweeps:
        info.update(mc_sweeps=shake_sweeps, mc_acceptance=round(acceptance, 3))
    p = Packing(x, radii, types, box, info, walls)
    if not (p.min_gap >= min_gap):
        raise RuntimeError("packing has a minimum gap %g below the requested %g" % (p.min_gap, min_gap))
    return p


RANDOM_CLOSE_PACKING = 0.64
"""Above this volume fraction no random packing exists (a bidisperse mixture packs a little denser,
but not at random from an overlap relaxation): refused at once."""


def bidisperse_counts_for_volume(volume, phi, a1=1.0):
    """(n1, n2) for the paper's suspension (section 6: a2 = 1.4 a1, equal volumes of both sizes)
    filling the fraction phi of `volume`: n_k = round(phi volume / 2 / (4/3 pi a_k^3))."""
    n1, n2 = PAPER_SUSPENSION.counts_for_volume(volume, phi, a1)
    return n1, n2


def centres_along(profile, length, low, high, rng):
    """Centres along an axis of the given length drawn with a density proportional to profile(y) >= 0 (a
    callable on [0, length]), each inside its own [low, high] (arrays: where the sphere fits)."""
    grid = np.linspace(0.0, length, 4001)
    weight = np.asarray(profile(grid), dtype=float)
    if weight.shape != grid.shape or not np.all(np.isfinite(weight)) or np.any(weight < 0) or weight.max() <= 0:
        raise ValueError("packing: the profile must be finite and >= 0 across the channel, and positive somewhere")
    weight = weight + 1e-9 * weight.max()          # a strictly rising cumulative, to invert
    cdf = np.concatenate([[0.0], np.cumsum(0.5 * (weight[1:] + weight[:-1]) * np.diff(grid))])
    cdf /= cdf[-1]
    c_lo, c_hi = np.interp(low, grid, cdf), np.interp(high, grid, cdf)
    return np.interp(c_lo + rng.uniform(0.0, 1.0, len(low)) * (c_hi - c_lo), cdf, grid)


def channel_packing(box, phi=None, n=None, seed=0, min_gap=0.01, wall_gap=None, wall_axis=1, a1=1.0,
                    attempts=3, max_sweeps=3000, margin=0.5, sizes=None, profile=None):
    """A random packing of the size distribution `sizes` (a SizeDistribution; default PAPER_SUSPENSION, the
    paper's a2 = 1.4 a1 in equal volumes) in the box [0, L_x] x [0, L_y] x [0, L_z] of any shape, periodic
    except along wall_axis (planar walls at 0 and L there), for Couette and Poiseuille cells. Species k (radius
    a1 sizes.radii[k]) is atom type k + 1.

    box: (L_x, L_y, L_z); phi: the target volume fraction (the counts from sizes.counts_for_volume, each
    species' volume within half of one of its spheres of its share; the actual phi is Packing.phi) or n: the
    total count (split by sizes.counts_for_number, e.g. the N_P of Table 8). min_gap: smallest surface gap
    between spheres, wall_gap: between a sphere and a wall (default min_gap). Tries `attempts` seeds (seed,
    seed + 1, ...) of at most max_sweeps relaxation sweeps each. profile: None (uniform), or a callable giving the
    relative density of the centres across the walls (y from 0 to L along wall_axis), e.g. a steady profile to
    start a channel near its steady state (the relaxation of the overlaps then smooths it a little).

    Raises ValueError for a box side smaller than a particle (the largest diameter plus the wall gaps
    across the walls) or too small for the minimum image (a periodic side below 2 (2 a_max + gaps)),
    for phi >= RANDOM_CLOSE_PACKING and for a species that gets no sphere in this box; PackingError naming
    phi, the box and the attempts when the relaxation fails at every seed."""
    sizes = PAPER_SUSPENSION if sizes is None else sizes
    box = np.asarray(box, dtype=float)
    if box.shape != (3,) or np.any(box <= 0):
        raise ValueError("packing: the box must be three positive lengths, got %s" % (box,))
    wall_gap = min_gap if wall_gap is None else float(wall_gap)
    a_max = sizes.largest * a1
    a_min = sizes.smallest * a1
    text = " x ".join("%g" % b for b in box)
    if box[wall_axis] < 2 * a_max + 2 * wall_gap or np.any(box < 2 * a_max):
        raise ValueError("packing: the box %s a1 is smaller than a particle: the largest spheres have a diameter of "
                         "%g a1 (and need %g a1 between the walls)" % (text, 2 * a_max, 2 * a_max + 2 * wall_gap))
    periodic_sides = np.delete(box, wall_axis)
    needed = 2 * (2 * a_max + (1 + margin) * min_gap + 0.3 * a_min)
    if np.any(periodic_sides <= needed):
        raise ValueError("packing: the periodic sides of the box %s a1 must exceed %.3g a1 (twice the neighbour "
                         "cut-off of the largest spheres) for the minimum image to be unique" % (text, needed))
    if (phi is None) == (n is None):
        raise ValueError("packing: give either phi or n")
    if n is None:
        if not 0 < phi < RANDOM_CLOSE_PACKING:
            raise ValueError("packing: phi = %g is not in (0, %g): no random packing of spheres reaches it"
                             % (phi, RANDOM_CLOSE_PACKING))
        numbers = sizes.counts_for_volume(float(np.prod(box)), phi, a1)
    else:
        numbers = sizes.counts_for_number(int(n))
    radii = np.concatenate([np.full(k, a1 * r) for k, r in zip(numbers, sizes.radii)])
    types = np.concatenate([np.full(k, t + 1, dtype=int) for t, k in enumerate(numbers)])
    total = int(sum(numbers))
    if total == 0:
        raise ValueError("packing: phi = %g in the box %s a1 makes no sphere" % (phi, text))
    empty = [r for r, k in zip(sizes.radii, numbers) if k == 0]
    if empty:
        raise ValueError("packing: the species of radius %s a1 gets no sphere in the box %s a1 (its volume share "
                         "is below half a sphere): enlarge the box, raise phi or its volume fraction, or leave it out"
                         % (", ".join("%g" % r for r in empty), text))
    phi_actual = float(np.sum(4.0 / 3.0 * math.pi * radii ** 3) / np.prod(box))
    if phi_actual >= RANDOM_CLOSE_PACKING:
        raise ValueError("packing: %d spheres in the box %s a1 make phi = %.4g, not below %g: no random packing "
                         "reaches it" % (total, text, phi_actual, RANDOM_CLOSE_PACKING))
    failures = []
    for attempt in range(attempts):
        rng = np.random.default_rng(seed + attempt)
        perm = rng.permutation(total)  # mix the sizes in tag order
        r, t = radii[perm], types[perm]
        x = rng.uniform(0.0, 1.0, (total, 3)) * box
        # centres where the sphere fits between the walls
        low, high = r + 2 * wall_gap, box[wall_axis] - r - 2 * wall_gap
        x[:, wall_axis] = (low + rng.uniform(0.0, 1.0, total) * (high - low) if profile is None
                           else centres_along(profile, box[wall_axis], low, high, rng))
        try:
            sweeps = relax_overlaps(x, r, box, min_gap, margin=margin, max_iterations=max_sweeps,
                                    walls=(wall_axis,), wall_gap=wall_gap)
        except PackingError as e:
            failures.append("seed %d: %s" % (seed + attempt, e))
            continue
        p = Packing(x, r, t, box, dict(seed=seed + attempt, relaxation_sweeps=sweeps, attempts=attempt + 1),
                    walls=(wall_axis,))
        if p.min_gap >= min(min_gap, wall_gap) and p.min_wall_gap >= wall_gap:
            return p
        failures.append("seed %d: minimum gap %g, wall gap %g" % (seed + attempt, p.min_gap, p.min_wall_gap))
    raise PackingError("packing: phi = %.4g (%s spheres) could not be packed in the box %s a1 with walls on "
                       "axis %s: %d attempts of %d relaxation sweeps failed (%s); lower phi or enlarge the box"
                       % (phi_actual, " + ".join("%d" % k for k in numbers), text, "xyz"[wall_axis], attempts,
                          max_sweeps, "; ".join(failures)))


def slab_volume_fractions(p, edges, axis=1):
    """The packing's volume fraction in the slabs between consecutive planes `edges` across `axis` (each
    sphere's exact volume in each slab)."""
    edges = np.asarray(edges, dtype=float)
    r = p.radii[:, None]
    c = p.positions[:, axis][:, None]
    a = np.clip(edges[None, :-1] - c, -r, r)
    b = np.clip(edges[None, 1:] - c, -r, r)
    volume = np.pi * (r ** 2 * (b - a) - (b ** 3 - a ** 3) / 3)
    area = float(np.prod(np.delete(p.box, axis)))
    return volume.sum(axis=0) / (area * np.diff(edges))


def profiled_channel_packing(box, target, phi, iterations=3, wall_axis=1, **options):
    """channel_packing whose volume fraction across the walls follows target(y) (a callable, y from 0 to L along
    wall_axis; its level is set by phi, only its shape matters), not only its centres: the centres are drawn
    with a density corrected `iterations` times by the ratio of the target to the packed phi in slabs of a1
    (the spheres' width and the relaxation of overlaps smooth the drawn density; the slabs within 2 a1 of a
    wall left as drawn), the packing nearest the target kept. Its info gains profile_rms (the rms difference
    in the slabs) and profile_iterations."""
    length = float(box[wall_axis])
    edges = np.linspace(0.0, length, max(2, int(round(length))) + 1)
    centres = 0.5 * (edges[1:] + edges[:-1])
    wanted = np.asarray(target(centres), dtype=float)
    correction = np.ones_like(centres)
    # the slabs within 2 a1 of a wall are left as drawn: no sphere's centre comes nearer the wall than its
    # radius, so no density of centres makes them follow a continuum profile
    inner = (centres > 2.0) & (centres < length - 2.0)
    best = None
    for k in range(iterations + 1):
        factor = correction.copy()
        p = channel_packing(box, phi=phi, wall_axis=wall_axis,
                            profile=lambda y, f=factor: np.asarray(target(y), dtype=float)
                            * np.interp(y, centres, f), **options)
        packed = slab_volume_fractions(p, edges, wall_axis)
        aim = wanted * packed.mean() / wanted.mean()
        rms = float(np.sqrt(np.mean((packed - aim)[inner] ** 2)))
        if best is None or rms < best[1]:
            best = (p, rms, k)
        correction[inner] *= np.clip(aim / np.maximum(packed, 1e-3), 0.5, 2.0)[inner]
    p, rms, k = best
    p.info.update(profile_rms=rms, profile_iterations=k)
    return p


def write_data(path, p, density=1000.0, scale=1.0, title=None):
    """LIGGGHTS data file (read_data; atom_style sphere: id type diameter density x y z), box
    [0, L)^3, one atom type per radius (1: a1, 2: a2; species k + 1 of a SizeDistribution). scale
    multiplies every length."""
    ntypes = int(p.types.max())
    with open(path, "w") as f:
        if title is None:  # LIGGGHTS reads a short first line only
            title = "fdmsubgrid.packing: %d spheres, box %s (%s), phi %.5f, min surface gap %.4g" % (
                p.n, " ".join("%.10g" % b for b in p.box), p.boundary, p.phi, p.min_gap)
        f.write("%s\n\n%d atoms\n%d atom types\n\n" % (title[:200], p.n, ntypes))
        for d, axis in enumerate("xyz"):
            f.write("0 %.17g %slo %shi\n" % (scale * p.box[d], axis, axis))
        f.write("\nAtoms\n\n")
        for k in range(p.n):
            x = scale * p.positions[k]
            f.write("%d %d %.17g %.17g %.17g %.17g %.17g\n"
                    % (k + 1, p.types[k], 2 * scale * p.radii[k], density, x[0], x[1], x[2]))
    return path


def read_data(path, walls=()):
    """Reads a data file written by write_data (or any atom_style sphere data file with a box
    starting at 0) back into a Packing (walls: the wall-bounded axes, not in the file)."""
    box = np.zeros(3)
    atoms = []
    with open(path) as f:
        lines = f.read().splitlines()
    section = None
    for line in lines[1:]:
        words = line.split("#")[0].split()
        if not words:
            continue
        if len(words) == 4 and words[2].endswith("lo") and words[3].endswith("hi"):
            box["xyz".index(words[2][0])] = float(words[1]) - float(words[0])
        elif words[0] == "Atoms":
            section = "atoms"
        elif section == "atoms" and len(words) >= 7:
            atoms.append([float(w) for w in words[:7]])
    a = np.array(sorted(atoms))
    return Packing(a[:, 4:7], a[:, 2] / 2, a[:, 1].astype(int), box, walls=walls)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("n", type=int, help="number of spheres")
    ap.add_argument("phi", type=float, help="target volume fraction")
    ap.add_argument("--bidisperse", action="store_true", help="a1 = 1, a2 = 1.4, equal volumes (paper section 6)")
    ap.add_argument("--radii", type=float, nargs="+", default=None, help="any size distribution: the radii [a1] "
                    "(with --volume-fractions, equal volumes if left out), one atom type each")
    ap.add_argument("--volume-fractions", type=float, nargs="+", default=None,
                    help="with --radii: each species' share of the particle volume, summing to 1")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--min-gap", type=float, default=1e-4, help="smallest surface gap [a1] (default 1e-4)")
    ap.add_argument("--box-multiple", type=float, default=None, help="round the box side to a multiple of this")
    ap.add_argument("--shake", type=int, default=0, help="hard-sphere Monte Carlo sweeps after the relaxation")
    ap.add_argument("--walls", default="", help="wall-bounded axes, e.g. y (walls at y = 0 and y = L)")
    ap.add_argument("--density", type=float, default=1000.0)
    ap.add_argument("-o", "--output", default=None, help="LIGGGHTS data file to write")
    args = ap.parse_args(argv)
    sizes = None
    if args.radii is not None or args.volume_fractions is not None:
        if args.radii is None or args.bidisperse:
            ap.error("--volume-fractions goes with --radii, and --radii replaces --bidisperse")
        try:
            sizes = SizeDistribution.of(args.radii, args.volume_fractions)
        except SizeDistributionError as e:
            ap.error(str(e))
    p = random_packing(args.n, args.phi, args.bidisperse, args.seed, args.min_gap, args.box_multiple, args.shake,
                       walls=tuple("xyz".index(c) for c in args.walls), sizes=sizes)
    print(p.summary())
    if args.output:
        write_data(args.output, p, args.density)
        print("wrote", args.output)


if __name__ == "__main__":
    sys.exit(main())
