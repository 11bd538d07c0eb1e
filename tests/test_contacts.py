"""fdmsubgrid.contacts: contacts across periodic faces, their statistics and the chord term that
breaks them at a large time step (docs/benchmarks.md, "The time step at φ 0.37"), on hand-made
records. Pure Python, no solver; under a second."""
import math

import numpy as np
import pytest

from fdmsubgrid import contacts as C
from fdmsubgrid.output import ParticleRecords

H_R = 5e-3


def records(frames, radii, box=(10.0, 10.0, 10.0), periodic=(1, 0, 1), dt=1.0):
    """Records of fix fdm/output in memory: one block per frame (positions (N, 3)), every step."""
    n = len(radii)
    particle = np.dtype([("x", "<f8", (3,)), ("radius", "<f8")])
    dtype = np.dtype([("step", "<i8"), ("time", "<f8"), ("particles", particle, (n,)), ("end", "<i8")])
    blocks = np.zeros(len(frames), dtype=dtype)
    for k, x in enumerate(frames):
        blocks[k]["step"], blocks[k]["time"], blocks[k]["end"] = k, k * dt, ~k
        blocks[k]["particles"]["x"] = np.asarray(x, dtype=float)
        blocks[k]["particles"]["radius"] = radii
    header = dict(box_lo=[0, 0, 0], box_hi=list(box), periodic=list(periodic), particles=n, every=1, dt=dt)
    return ParticleRecords("test.records", header, blocks, 0)


def test_a_contact_across_a_periodic_face():
    # unit spheres near the two x faces of a 10-wide box: 2.002 apart through the face, 8 directly
    x = np.array([[0.999, 5.0, 5.0], [10.0 - 1.003, 5.0, 5.0]])
    radii = np.ones(2)
    pairs, gaps = C.close_pairs(x, radii, np.array([10.0, 0, 10.0]), H_R)
    assert pairs.tolist() == [[0, 1]]
    assert gaps[0] == pytest.approx(0.002, abs=1e-12)
    assert C.contact_set(x, radii, np.zeros(3), H_R) == set()   # not periodic: no contact


def test_the_chord_term_of_a_sliding_pair():
    # two unit spheres in contact (gap 0.004 along x); the second slides by t along y in one straight
    # step: the gap opens by sqrt(2.004^2 + t^2) - 2.004, the chord term, while the normal
    # displacement is zero. t = 0.2 breaks the contact by the chord alone, t = 0.02 does not
    for t, breaks in ((0.2, 1), (0.02, 0)):
        a = [[3.0, 5.0, 5.0], [5.004, 5.0, 5.0]]
        b = [[3.0, 5.0, 5.0], [5.004, 5.0 + t, 5.0]]
        out = C.contact_breaks(records([a, b], np.ones(2)), H_R)
        chord = math.hypot(2.004, t) - 2.004
        assert out.contact_steps == 1
        assert out.broken == breaks and out.broken_by_chord == breaks
        assert out.chord_median == pytest.approx(chord, rel=1e-9)
        assert out.margin_median == pytest.approx(H_R - 0.004, rel=1e-9)


def test_a_contact_that_separates_is_not_a_chord_break():
    # the same pair pulled apart along its normal: broken, by the normal displacement
    a = [[3.0, 5.0, 5.0], [5.004, 5.0, 5.0]]
    b = [[3.0, 5.0, 5.0], [5.010, 5.0, 5.0]]
    out = C.contact_breaks(records([a, b], np.ones(2)), H_R)
    assert out.broken == 1 and out.broken_by_chord == 0
    assert out.chord_median == pytest.approx(0.0, abs=1e-12)


def test_statistics_of_a_contact_that_lives_two_samples():
    # three spheres; pair (0, 1) in contact at samples 0 and 1, apart at 2; pair (1, 2) forms at 2
    frames = [[[1.0, 5, 5], [3.003, 5, 5], [6.0, 5, 5]],
              [[1.0, 5, 5], [3.003, 5, 5], [6.0, 5, 5]],
              [[1.0, 5, 5], [3.5, 5, 5], [5.502, 5, 5]]]
    s = C.contact_statistics(records(frames, np.ones(3), periodic=(0, 0, 0)), H_R)
    assert s.samples == 3 and s.spacing == 1.0
    assert s.per_particle == pytest.approx(2 * 1 / 3)            # one contact in each sample
    assert s.formed_per_time == pytest.approx(0.5 / 3)            # 0, then 1 formed
    assert s.broken_per_time == pytest.approx(0.5 / 3)            # 0, then 1 broken
    assert s.persistence == pytest.approx(0.5)                    # kept 1 of 1, then 0 of 1
    assert s.mean_lifetime == pytest.approx(2.0)


def test_too_few_records_is_a_clear_error():
    with pytest.raises(ValueError, match="fewer than two records"):
        C.contact_statistics(records([[[1.0, 5, 5]]], np.ones(1)), H_R)
