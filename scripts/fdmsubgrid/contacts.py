"""Contact statistics of a suspension run from its particle records (fix fdm/output ... records).

    from fdmsubgrid import contacts, output
    rec = output.read_particle_records("RUN/dem/particles.records")
    stats = contacts.contact_statistics(rec, roughness=5e-3, from_time=3.0)
    stats.per_particle           # mean number of contacts per particle (coordination number Z)
    stats.formed_per_time        # contacts formed per unit time, per particle
    stats.persistence            # fraction of the contacts of a sample still there one spacing later
    breaks = contacts.contact_breaks(rec, roughness=5e-3, from_time=3.0)
    breaks.broken, breaks.broken_by_chord   # breaks between consecutive time steps, and those of them
                                            # that only the chord term caused (docs/benchmarks.md)

A pair (i, j) is in contact when its surface gap h = |x_j - x_i| - a_i - a_j is below the roughness
height h_r (docs/contact.md, section 2), with the minimum image across the periodic faces of the
records' box. Command line:

    python3 -m fdmsubgrid.contacts RUN_DIR [--roughness 5e-3] [--from-time 3] [--spacing 0.16]
"""
from __future__ import annotations

import argparse
import os
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from . import packing
from .output import ParticleRecords, read_particle_records


def minimum_image(d: NDArray, period: NDArray) -> NDArray:
    """Separations d (..., 3) brought to their nearest periodic image (period 0: not periodic; a records
    file's period is ParticleRecords.period)."""
    return packing._minimum_image(np.asarray(d, dtype=float), np.where(period > 0, period, 1.0), period > 0)


def close_pairs(x: NDArray, radii: NDArray, period: NDArray, max_gap: float) -> tuple[NDArray, NDArray]:
    """Index pairs (m, 2) with i < j whose surface gap is below max_gap, and their gaps (m,).

    x: (N, 3) positions, radii (N,), period: box lengths of the periodic directions (0: none).
    The neighbours are those of packing.neighbour_pairs (scipy's periodic KD-tree)."""
    x = np.asarray(x, dtype=float)
    radii = np.asarray(radii, dtype=float)
    if len(x) < 2:
        return np.zeros((0, 2), dtype=int), np.zeros(0)
    walls = tuple(k for k in range(3) if not period[k] > 0)
    i, j, distance = packing.neighbour_pairs(x, np.where(period > 0, period, 1.0),
                                             2 * radii.max() + max_gap, walls)
    gaps = distance - radii[i] - radii[j]
    keep = gaps < max_gap
    return np.stack([i, j], axis=1)[keep], gaps[keep]


def smallest_gaps(records: ParticleRecords | str) -> NDArray:
    """The smallest pair surface gap of each record (T,) (negative: an overlap), e.g. how deep the
    contacts of a run went into each other (the roughness layer is h_r deep)."""
    rec = read_particle_records(records) if isinstance(records, str) else records
    out = np.full(len(rec), np.inf)
    for k in range(len(rec)):
        radii = rec["radius"][k]
        _, gaps = close_pairs(rec["x"][k], radii, rec.period, float(radii.min()))
        if len(gaps):
            out[k] = gaps.min()
    return out


def contact_set(x: NDArray, radii: NDArray, period: NDArray, roughness: float) -> set:
    """The pairs (i, j), i < j, in contact: surface gap below the roughness height."""
    pairs, _ = close_pairs(x, radii, period, roughness)
    return set(map(tuple, pairs.tolist()))


@dataclass
class ContactStatistics:
    """Contacts of the records' samples from `from_time` on, resampled every `spacing` in time."""
    samples: int                 # samples used
    spacing: float               # time between them
    per_particle: float          # mean contacts per particle, 2 <n_contacts>/N (coordination number)
    formed_per_time: float       # contacts formed per unit time, per particle
    broken_per_time: float       # contacts lost per unit time, per particle
    persistence: float           # fraction of a sample's contacts still in contact at the next sample
    mean_lifetime: float         # spacing/(1 - persistence): the mean life of a contact (exponential model)


def contact_statistics(records: ParticleRecords | str, roughness: float, from_time: float = 0.0,
                       spacing: float | None = None) -> ContactStatistics:
    """How many contacts, how fast they form and break (see ContactStatistics).

    spacing: time between the samples compared (default: the records' own spacing); runs written
    at different time steps are compared at one spacing (the nearest record to each multiple of it)."""
    rec = read_particle_records(records) if isinstance(records, str) else records
    times = np.asarray(rec.times, dtype=float)
    use = np.flatnonzero(times >= from_time)
    if len(use) < 2:
        raise ValueError("%s: fewer than two records from time %g on" % (rec.path, from_time))
    if spacing is None:
        spacing = float(np.median(np.diff(times[use])))
    wanted = np.arange(times[use[0]], times[use[-1]] + 0.5 * spacing, spacing)
    index = np.unique([int(use[np.argmin(np.abs(times[use] - t))]) for t in wanted])
    period = rec.period
    sets = [contact_set(rec["x"][k], rec["radius"][k], period, roughness) for k in index]
    n = rec.n_particles
    formed = np.array([len(b - a) for a, b in zip(sets[:-1], sets[1:])], dtype=float)
    broken = np.array([len(a - b) for a, b in zip(sets[:-1], sets[1:])], dtype=float)
    kept = np.array([len(a & b) / len(a) for a, b in zip(sets[:-1], sets[1:]) if a])
    persistence = float(kept.mean()) if len(kept) else float("nan")
    return ContactStatistics(
        samples=len(sets), spacing=float(spacing),
        per_particle=float(2 * np.mean([len(s) for s in sets]) / n),
        formed_per_time=float(formed.mean() / spacing / n), broken_per_time=float(broken.mean() / spacing / n),
        persistence=persistence,
        mean_lifetime=float(spacing / (1 - persistence)) if persistence < 1 else float("inf"))


@dataclass
class ContactBreaks:
    """Contacts of one time step against the next (records written every step)."""
    contact_steps: int           # (contact, step) pairs examined
    broken: int                  # contacts whose gap is at or above h_r one step later
    broken_by_chord: int         # of those, the ones whose gap change along the old normal n_n alone
                                 # would have kept them in contact: broken by the chord term
    chord_median: float          # the chord term h_{n+1} - (h_n + n_n . (displacement)), median
    chord_p90: float             # and its 90th percentile
    margin_median: float         # h_r - h_n of the contacts, median


def contact_breaks(records: ParticleRecords | str, roughness: float, from_time: float = 0.0) -> ContactBreaks:
    """Which contacts break between consecutive records, and why: the gap of a pair moved by
    relative displacements Delta (normal part Delta_n along n_n, tangential part Delta_t) is
    h_{n+1} = h_n + Delta_n + |Delta_t|^2/(2 r) + ..., a straight step opening every sliding or
    rolling pair by the chord term |Delta_t|^2/(2 r), second order in the time step. The records
    must be written every time step (fix fdm/output ... records 1)."""
    rec = read_particle_records(records) if isinstance(records, str) else records
    times = np.asarray(rec.times, dtype=float)
    steps = np.asarray(rec.steps)
    period = rec.period
    total = broken = by_chord = 0
    chords, margins = [], []
    for k in range(len(rec) - 1):
        if times[k] < from_time or steps[k + 1] != steps[k] + 1:
            continue
        x0, x1, radii = rec["x"][k], rec["x"][k + 1], np.asarray(rec["radius"][k], dtype=float)
        pairs, h0 = close_pairs(x0, radii, period, roughness)
        if len(pairs) == 0:
            continue
        d0 = minimum_image(x0[pairs[:, 1]] - x0[pairs[:, 0]], period)
        d1 = minimum_image(x1[pairs[:, 1]] - x1[pairs[:, 0]], period)
        contact = radii[pairs[:, 0]] + radii[pairs[:, 1]]
        h1 = np.linalg.norm(d1, axis=1) - contact
        normal = d0 / np.linalg.norm(d0, axis=1)[:, None]
        linear = np.sum(normal * d1, axis=1) - contact        # h_n + Delta_n
        total += len(pairs)
        broken += int(np.sum(h1 >= roughness))
        by_chord += int(np.sum((h1 >= roughness) & (linear < roughness)))
        chords.append(h1 - linear)
        margins.append(roughness - h0)
    if total == 0:
        raise ValueError("%s: no contact between two consecutive steps from time %g on (records written "
                         "every step?)" % (rec.path, from_time))
    chord = np.concatenate(chords)
    return ContactBreaks(contact_steps=total, broken=broken, broken_by_chord=by_chord,
                         chord_median=float(np.median(chord)), chord_p90=float(np.percentile(chord, 90)),
                         margin_median=float(np.median(np.concatenate(margins))))


def main(argv: list[str] | None = None) -> None:
    p = argparse.ArgumentParser(prog="python3 -m fdmsubgrid.contacts", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("run", help="a run folder (its dem/particles.records) or a records file")
    p.add_argument("--roughness", type=float, default=5e-3, help="contact gap h_r (default 5e-3, the cases')")
    p.add_argument("--from-time", type=float, default=0.0, help="ignore the records before this time")
    p.add_argument("--spacing", type=float, default=None, help="time between the samples compared")
    args = p.parse_args(argv)
    path = args.run
    if os.path.isdir(path):
        path = os.path.join(path, "dem", "particles.records")
    rec = read_particle_records(path)
    s = contact_statistics(rec, args.roughness, args.from_time, args.spacing)
    print("%s: %d samples every %g: %.3f contacts per particle; per particle and unit time %.3f formed, %.3f "
          "broken; persistence %.3f over a spacing, mean lifetime %.3f"
          % (path, s.samples, s.spacing, s.per_particle, s.formed_per_time, s.broken_per_time, s.persistence,
             s.mean_lifetime))
    if int(rec.header.get("every", 0)) == 1:
        b = contact_breaks(rec, args.roughness, args.from_time)
        print("step to step: %d contacts, %d broken, %d of them by the chord term alone (median %.2e, 90th "
              "percentile %.2e; margin h_r - h median %.2e)" % (b.contact_steps, b.broken, b.broken_by_chord,
                                                                b.chord_median, b.chord_p90, b.margin_median))


if __name__ == "__main__":
    main()
