"""Squeeze corrections outside the measured table (scripts/fdmsubgrid/subgridinterp.py): the interpolation's
error against direct calibrations held back from it, from the stored measurements (no run), the table it
writes as the resistance library reads it, and which species pairs of a scene are calibrated, interpolated
or refused (docs/resistance.md, "Sizes and resolutions outside the table")."""
import dataclasses
import json
import math
import os
import subprocess

import numpy as np
import pytest

from conftest import PROJECT
from fdmsubgrid import calibration, subgridinterp


@pytest.fixture(scope="module")
def blocks():
    return subgridinterp.load_blocks(os.path.join(PROJECT, subgridinterp.SHIPPED_JSON))


@pytest.fixture(scope="module")
def loo(blocks):
    return {(t.kind, t.a_over_delta, t.ratio): t for t in subgridinterp.leave_one_out(blocks)}


def test_collapse_reproduces_the_measured_correction(blocks):
    """Phi of every block through (1) gives back the block's own correction at its measured gaps (the
    variables change, nothing is lost), and Phi -> 1 at the smallest gap (the leading lubrication)."""
    for b in blocks:
        x = b.gaps * b.cells()
        back = b.scale() * b.phi(x) / x
        assert np.allclose(back, b.summary["correction"], rtol=1e-6, atol=1e-9), (b.kind, b.a_over_delta, b.ratio)
        assert b.phi(np.array([x.min()]))[0] == pytest.approx(1.0, abs=2e-3)


def test_each_shipped_block_from_the_others(loo):
    """Leave one out: each shipped block interpolated from the other blocks of its kind, judged at its own
    4 measured positions in the cell. The interpolation's error (position-averaged closing velocity with the
    interpolated correction minus with the block's own) at every gap 1e-4 ... 1: pairs within 3.1 % (measured
    3.0 %, a1/Delta 3, a2/a1 1.4 at xi 0.3), walls within 0.9 % (measured 0.8 %, a/Delta 3, extrapolated
    below its sources; with a/Delta 5.6 in the table a/Delta 5 is inside, 0.4 %); against the theory the
    interpolated correction is within 3.8 % (the direct calibrations' own reach 1.8 %) and, near contact
    (xi <= 1e-3), where the correction carries the resistance, within 0.2 %."""
    assert len(loo) == 11
    for key, t in loo.items():
        bound = 0.031 if t.kind == "pair" else 0.009
        assert t.worst() < bound, (key, t.added())
        assert np.max(np.abs(t.interpolated)) < 0.038, key
        for g, e in zip(t.gaps, t.interpolated):
            if g <= 1e-3:
                assert abs(e) < 2e-3, (key, g, e)
    # the end blocks of the table were extrapolated (below and above their sources)
    assert loo[("pair", 3.0, 1.0)].distance()[0] > 0 and loo[("wall", 5.6, 1.0)].distance()[1] > 0


def fixed_xi_leave_one_out(target, blocks):
    """The target's correction from the other pairs at its own reduced gaps xi, a straight line in a1/Delta
    and a2/a1 (least squares), as the resistance library interpolates inside its grid."""
    others = [b for b in blocks if b.kind == "pair" and b is not target]
    design = np.array([[1.0, b.a_over_delta, b.ratio] for b in others])
    rows = []
    for g in target.gaps:
        s = [b.scale() * b.phi(np.array([g * b.cells()]))[0] / (g * b.cells()) for b in others]
        c = np.linalg.lstsq(design, np.array(s), rcond=None)[0]
        rows.append(c @ [1.0, target.a_over_delta, target.ratio])
    err = subgridinterp.position_errors(target, np.array(rows)).mean(axis=0)
    own = subgridinterp.position_errors(target, np.array(target.summary["correction"])).mean(axis=0)
    return float(np.max(np.abs(err - own)))


def test_the_collapse_is_what_makes_it_work(blocks, loo):
    """The same leave-one-out at a fixed reduced gap xi, linear in a1/Delta and a2/a1: worse at the worst
    pair (measured 4.6 % against 3.0 %) and at the end of the table (a1/Delta 3: 2.4 % and 4.6 % against
    1.5 % and 3.0 %)."""
    pairs = [b for b in blocks if b.kind == "pair"]
    fixed = {(b.a_over_delta, b.ratio): fixed_xi_leave_one_out(b, blocks) for b in pairs}
    collapsed = {(b.a_over_delta, b.ratio): loo[("pair", b.a_over_delta, b.ratio)].worst() for b in pairs}
    assert max(fixed.values()) > max(collapsed.values()) + 0.008
    for key in ((3.0, 1.0), (3.0, 1.4)):
        assert fixed[key] > 0.024 and collapsed[key] < fixed[key] - 0.008, key


def held_back(blocks, index):
    """The held-back calibration HELD_BACK_JSON[index]: its summary (one block), its interpolation from the
    table (subgridinterp.held_back_measurements) and the core-seconds its direct calibration took."""
    path = os.path.join(PROJECT, subgridinterp.HELD_BACK_JSON[index])
    with open(path) as f:
        data = json.load(f)
    [summary] = data["calibrations"]
    [test] = subgridinterp.held_back_measurements(blocks, [path])
    return summary, test, data["core_seconds"]


def test_held_back_direct_calibration(blocks):
    """a2/a1 = 2 at a1/Delta 3, calibrated directly (boxes 12 and 16 a1, 4 positions) and kept out of the
    table, against its interpolation from the 6 shipped pair blocks, gap by gap (docs/data): the
    interpolation's error within 1.6 % at every gap (measured 1.5 %), near contact within 0.2 % of the theory;
    and the direct calibration's cost as the cost model estimates it, within a factor 1.6."""
    s, t, core_seconds = held_back(blocks, 0)
    assert (s["kind"], s["a_over_delta"], s["ratio"]) == ("pair", 3.0, 2.0)
    assert len(s["velocities"]["12"]) == 4 and len(s["gaps"]) == 15
    assert t.u == pytest.approx(2.0)     # a*/Delta inside the shipped pairs' 1.5 ... 2.92, a2/a1 beyond their 1.4
    assert t.worst() < HELD_BACK_BOUND, t.added()
    for g, e in zip(t.gaps, t.interpolated):
        if g <= 1e-3:
            assert abs(e) < 2e-3, (g, e)
    model = subgridinterp.cost_model([b.summary for b in blocks])
    estimate = subgridinterp.estimated_core_seconds("pair", 3.0, 2.0, model)
    assert subgridinterp.calibration_boxes(2.0) == tuple(float(L) for L in s["boxes"])
    assert 1 / 1.6 < estimate / core_seconds < 1.6


# measured 1.5 % (at xi 0.07; docs/resistance.md, "Sizes and resolutions outside the table")
HELD_BACK_BOUND = 0.016


def test_held_back_equal_pair_at_a1_over_delta_6(blocks):
    """The equal pair at a1/Delta 6 (boxes 8 and 12 a1, 48 and 72 cells, 4 positions), calibrated directly and
    kept out of the table: a*/Delta 3, just above the shipped pairs (0.03 in ln u), interpolated from them within
    0.8 % of its own correction at every gap (measured 0.7 %, at xi 0.02), within 2 % of the theory averaged
    over the positions (measured 1.8 %, as its direct calibration), near contact within 0.2 %."""
    s, t, _ = held_back(blocks, 1)
    assert (s["kind"], s["a_over_delta"], s["ratio"]) == ("pair", 6.0, 1.0) and s["boxes"] == [8.0, 12.0]
    assert all(len(v) == 4 for v in s["velocities"].values()) and len(s["gaps"]) == 15
    assert t.u == pytest.approx(3.0) and t.distance()[1] == pytest.approx(math.log(3.0 / 2.92), abs=0.01)
    assert t.worst() < 0.008, t.added()
    assert np.max(np.abs(t.interpolated)) < 0.02 and np.max(np.abs(t.direct)) < 0.02
    for g, e in zip(t.gaps, t.interpolated):
        if g <= 1e-3:
            assert abs(e) < 2e-3, (g, e)
    # every held-back measurement is what the scene writers' bounds see
    assert len(subgridinterp.held_back_measurements(blocks)) == 5


def test_held_back_ratio_2_at_a1_over_delta_4(blocks):
    """a2/a1 2 at a1/Delta 4 (boxes 12 and 16 a1, 48 and 64 cells, 4 positions), calibrated directly and kept out
    of the table: a*/Delta 2.67 inside the shipped pairs, a2/a1 beyond their 1.4 as the ratio-2 pair at a1/Delta
    3. The interpolation adds at most 1.3 % to its own calibration (measured 1.2 %, at xi 0.5), which is within
    2 % of the theory (1.8 %); interpolated it is within 2.6 % (measured 2.55 %, at xi 0.1: above the 2 %, as the
    scene writers' 3.0 % bound for pairs outside the table says), near contact within 0.2 %."""
    s, t, _ = held_back(blocks, 2)
    assert (s["kind"], s["a_over_delta"], s["ratio"]) == ("pair", 4.0, 2.0) and s["boxes"] == [12.0, 16.0]
    assert t.u == pytest.approx(8.0 / 3.0) and t.distance() == pytest.approx((0, 0, math.log(2 / 1.4)))
    assert t.worst() < 0.013, t.added()
    assert np.max(np.abs(t.direct)) < 0.02 and np.max(np.abs(t.interpolated)) < 0.026
    for g, e in zip(t.gaps, t.interpolated):
        if g <= 1e-3:
            assert abs(e) < 2e-3, (g, e)
    # as far beyond the table's ratios as the ratio-2 pair at a1/Delta 3: the bound there stays the worst
    # held-back pair inside the table
    tests = subgridinterp.leave_one_out(blocks) + subgridinterp.held_back_measurements(blocks)
    inside = max(h.worst() for h in tests if h.kind == "pair" and not any(h.distance()))
    assert subgridinterp.error_bound("pair", t.distance(), tests) == pytest.approx(inside)


def test_held_back_ratio_3_at_a1_over_delta_3(blocks):
    """a2/a1 3 at a1/Delta 3 (boxes 18 and 24 a1, 54 and 72 cells, 4 positions), calibrated directly and kept out
    of the table: a*/Delta 2.25 inside the shipped pairs, a2/a1 0.76 beyond their 1.4 in ln ratio. Its own
    correction is within 2.1 % of the theory averaged over the positions (measured 2.03 %: the logistic form fits
    this ratio less well); interpolated from the table it is 6.9 % off (5.6 % added, at xi 0.05). It bounds the
    pairs between a2/a1 2 and 3, not those up to 2, for which the nearer ratio-2 tests hold."""
    s, t, _ = held_back(blocks, 3)
    assert (s["kind"], s["a_over_delta"], s["ratio"]) == ("pair", 3.0, 3.0) and s["boxes"] == [18.0, 24.0]
    assert t.u == pytest.approx(2.25) and t.distance() == pytest.approx((0, 0, math.log(3 / 1.4)))
    assert np.max(np.abs(t.direct)) < 0.021
    assert 0.05 < t.worst() < 0.06 and 0.06 < np.max(np.abs(t.interpolated)) < 0.075
    tests = subgridinterp.leave_one_out(blocks) + subgridinterp.held_back_measurements(blocks)
    inside = max(h.worst() for h in tests if h.kind == "pair" and not any(h.distance()))
    ratio2 = [h.worst() for h in tests if h.kind == "pair" and h.ratio == 2.0]
    assert subgridinterp.error_bound("pair", (0, 0, math.log(2 / 1.4)), tests) == pytest.approx(
        max([inside] + ratio2))
    assert subgridinterp.error_bound("pair", (0, 0, math.log(2.5 / 1.4)), tests) == pytest.approx(t.worst())
    assert subgridinterp.error_bound("pair", (0, 0, math.log(3.5 / 1.4)), tests) is None


def test_held_back_ratio_3_at_a1_over_delta_4(blocks):
    """a2/a1 3 at a1/Delta 4 (boxes 18 and 24 a1, 72 and 96 cells, 4 positions; 6243 core-seconds), calibrated
    directly and kept out of the table: a*/Delta 3, 0.03 above the shipped pairs, a2/a1 0.76 beyond their 1.4. Its
    own correction is within 2 % of the theory averaged over the positions (measured 1.8 %), as the table's blocks
    are; interpolated it is 3.0 % off (1.2 % added, at xi 0.07): measured on demand, not interpolated. Farther out
    than the ratio-3 pair at a1/Delta 3 (above the table's a*/Delta too), it does not bound the pairs that one does."""
    s, t, _ = held_back(blocks, 4)
    assert (s["kind"], s["a_over_delta"], s["ratio"]) == ("pair", 4.0, 3.0) and s["boxes"] == [18.0, 24.0]
    assert t.u == pytest.approx(3.0) and t.distance()[2] == pytest.approx(math.log(3 / 1.4))
    assert t.distance()[1] == pytest.approx(math.log(3.0 / 2.92), abs=0.01)
    assert np.max(np.abs(t.direct)) < 0.0185
    assert 0.01 < t.worst() < 0.014 and 0.025 < np.max(np.abs(t.interpolated)) < 0.032
    tests = subgridinterp.leave_one_out(blocks) + subgridinterp.held_back_measurements(blocks)
    inside = max(h.worst() for h in tests if h.kind == "pair" and not any(h.distance()))
    assert subgridinterp.error_bound("pair", t.distance(), tests) == pytest.approx(max(inside, t.worst()))
    ratio3 = [h for h in tests if h.kind == "pair" and h.ratio == 3.0 and h.a_over_delta == 3.0]
    assert subgridinterp.error_bound("pair", (0, 0, math.log(2.5 / 1.4)), tests) == pytest.approx(ratio3[0].worst())


def test_interpolated_table_is_read_by_the_resistance_library(tmp_path, env):
    """`--interpolate` writes the shipped table plus the blocks it lacks within --max-error; fdmResistance (the library the pair
    style uses) reads it unchanged: the ratio-2 pair and the a/Delta 6 wall are covered, and its X21A is
    -6 pi a1 s_hat of the written rows; near contact xi s_hat is the leading lubrication coefficient
    2 lambda^2/(1 + lambda)^3."""
    data = tmp_path / "dem" / "resistance" / "data"
    data.mkdir(parents=True)
    out = data / "subgrid_calibration.dat"
    done = calibration.main(["--interpolate", "--a-over-delta", "3", "6", "--ratios", "2", "--max-error", "0.031",
                             "--out", str(out)])
    assert {(d["kind"], d["a_over_delta"], d["status"]) for d in done} == {
        ("pair", 3.0, "interpolated"), ("pair", 6.0, "left out"), ("wall", 3.0, "in the table"),
        ("wall", 6.0, "interpolated")}
    # by default (2 %) the pair, measured at 3.0 %, is left out with the command that measures it
    default = calibration.main(["--interpolate", "--a-over-delta", "3", "--ratios", "2", "--no-wall",
                                "--out", str(tmp_path / "default.dat")])
    assert default[0]["status"] == "left out" and default[0]["command"].startswith("python3 -m fdmsubgrid.calibration")
    table = calibration.read_table(str(out))
    shipped = calibration.read_table(os.path.join(PROJECT, "dem", "resistance", "data", "subgrid_calibration.dat"))
    assert set(shipped) < set(table)
    head, rows = table[("pair", 3.0, 2.0)]
    assert head == [] and rows[-1, 1] == 0.0 and np.all(rows[:-1, 1] > 0)
    assert rows[0, 1] == pytest.approx(2 * 4 / 27, rel=1e-3)
    with open(out) as f:
        assert sum(1 for line in f if line.startswith("# interpolated")) == 2

    def resistance(*args):
        environment = dict(env, FDM_ROOT=str(tmp_path))
        done = subprocess.run(["fdmResistance"] + [str(a) for a in args], env=environment, check=True,
                              capture_output=True, text=True)
        return json.loads(done.stdout)
    covered = resistance("coverage", "--a1", 1, "--a2", 2, "--delta", 1 / 3, "--wall")
    assert covered["pair"] and covered["wall"] and not covered["pair_tangential"]
    assert resistance("coverage", "--a1", 2, "--delta", 1 / 3, "--wall")["wall"]
    xi = 0.05
    k = np.searchsorted(rows[:, 0], xi)
    w = (math.log(xi) - math.log(rows[k - 1, 0])) / (math.log(rows[k, 0]) - math.log(rows[k - 1, 0]))
    s_hat = ((1 - w) * rows[k - 1, 1] + w * rows[k, 1]) / xi
    pair = resistance("pair", "--a1", 1, "--a2", 2, "--xi", xi, "--subgrid", "--calibrated", "--delta", 1 / 3)
    assert pair["base"]["X21A"] == pytest.approx(-6 * math.pi * s_hat, rel=1e-6)


def test_coverage_of_scenes(blocks, loo):
    """coverage(): the shipped suspension (radii 1 and 1.4 at a1/Delta 3, walls) is calibrated throughout;
    outside the table each species pair gets the interpolation's measured error for its situation and is
    interpolated only within 2 %; what no held-back test reaches is refused, with the command that measures
    it and its cost."""
    shipped = calibration.coverage([1.0, 1.4, 1.0], 3.0, walls=True)
    assert [(c.pair, c.kind, c.status) for c in shipped] == [
        ((1.0, 1.0), "pair", "calibrated"), ((1.0, 1.4), "pair", "calibrated"), ((1.4, 1.4), "pair", "calibrated"),
        ((1.0, math.inf), "wall", "calibrated"), ((1.4, math.inf), "wall", "calibrated")]
    assert all(c.error is None for c in shipped)
    scene = {(c.pair, c.kind): c for c in calibration.coverage([1.0, 2.0, 4.0], 3.0, walls=True)}
    one_two = scene[((1.0, 2.0), "pair")]
    assert (one_two.a_over_delta, one_two.ratio) == (3.0, 2.0)
    # a2/a1 2 lies beyond the shipped ratios (ln(2/1.4) = 0.36 outside): only the held-back ratio-2
    # calibration measured that far, and the pairs inside their sources bound it from below
    ratio2 = held_back(blocks, 0)[1]
    assert ratio2.distance() == pytest.approx((0, 0, math.log(2 / 1.4)))
    inside = max(t.worst() for t in loo.values() if t.kind == "pair" and not any(t.distance()))
    assert one_two.error == pytest.approx(max(inside, ratio2.worst()))
    assert one_two.status == ("interpolated" if one_two.error <= subgridinterp.TOLERANCE else "refused")
    # a2/a1 3 and 2.5 are bounded by the held-back ratio-3 pair (5.6 %), a2/a1 4 lies farther beyond the
    # ratios than any test: refused whatever the errors measured
    ratio3 = calibration.coverage([1.0, 3.0], 3.0)[1]
    assert ratio3.status == "refused" and 0.05 < ratio3.error < 0.06
    assert calibration.coverage([1.0, 2.5], 3.0)[1].error == pytest.approx(ratio3.error)
    assert calibration.coverage([1.0, 4.0], 3.0)[1].error is None
    # the wall at a/Delta 6 (radius 2) lies 0.18 above the walls' 3 ... 5 in ln u: the wall a/Delta 5 from
    # 3 and 4 lay 0.22 above its sources and was within 1.3 %; a/Delta 6.7 lies farther above than any test
    wall = scene[((2.0, math.inf), "wall")]
    assert wall.status == "interpolated" and wall.error < 0.013
    assert calibration.coverage([1.0], 6.7, walls=True)[1].status == "refused"
    # the pair 1-1.4 at a1/Delta 6 (a*/Delta 3.5) lies 0.18 above the pairs' a*/Delta, farther than the
    # pair tests above their sources (0.15): refused, though the ratio-2 test lies 0.36 outside in ratio
    assert calibration.coverage([1.0, 1.4], 6.0)[1].error is None
    # radius 4 against a wall (a/Delta 12) and the pair (4, 4) at a1/Delta 12: farther than any test
    for key in (((4.0, math.inf), "wall"), ((4.0, 4.0), "pair")):
        c = scene[key]
        assert c.status == "refused" and c.error is None, key
        assert c.command.startswith("python3 -m fdmsubgrid.calibration --a-over-delta 12")
        line = subgridinterp.refusal(c)
        assert c.command in line and "core-seconds" in line and "\n" not in line
    # the cost grows with the calibration's cells: a1/Delta 12 costs more than 3
    assert scene[((4.0, 4.0), "pair")].core_seconds > 50 * scene[((1.0, 1.0), "pair")].core_seconds
    with pytest.raises(ValueError, match="radii must be positive"):
        calibration.coverage([0.0, 1.0], 3.0)


def test_cost_model_against_the_measured_calibrations(blocks):
    """The estimated cost of a direct calibration (a power of its cells through the shipped calibrations'
    measured seconds) is within a factor 1.6 of each of them."""
    model = subgridinterp.cost_model([b.summary for b in blocks])
    for b in blocks:
        estimate = subgridinterp.estimated_core_seconds(b.kind, b.a_over_delta, b.ratio, model)
        assert 1 / 1.6 < estimate / b.summary["wall_seconds"] < 1.6, (b.kind, b.a_over_delta, b.ratio)


def test_scene_table(tmp_path, env):
    """write_scene_table: radii 1 and 2 at a1/Delta 3 between walls: the wall of the larger sphere (a/Delta 6,
    measured 0.6 %) is added and read by the resistance library; the pairs 1-2 and 2-2 (3.0 %) are not."""
    data = tmp_path / "dem" / "resistance" / "data"
    data.mkdir(parents=True)
    out = data / "subgrid_calibration.dat"
    entries = subgridinterp.write_scene_table(str(out), [1.0, 2.0], 3.0, walls=True)
    assert [c.status for c in entries] == ["calibrated", "refused", "refused", "calibrated", "interpolated"]
    added = set(calibration.read_table(str(out))) - set(
        calibration.read_table(os.path.join(PROJECT, "dem", "resistance", "data", "subgrid_calibration.dat")))
    assert added == {("wall", 6.0, 1.0)}
    done = subprocess.run(["fdmResistance"] + [str(a) for a in ("coverage", "--a1", 2, "--a2", 2, "--delta", 1 / 3,
                                                                "--wall")],
                          env=dict(env, FDM_ROOT=str(tmp_path)), check=True, capture_output=True, text=True)
    covered = json.loads(done.stdout)
    assert covered["wall"] and not covered["pair"]


def test_the_measure_command_meshes_its_boxes_in_whole_cells():
    # a refused pair of a scene at a1/Delta 4 with radius 1.4 is at a/Delta 5.6: the default 8 and 12 a1 boxes
    # would be 44.8 and 67.2 cells (foamcase refuses them); the command's boxes are the next sizes of an even
    # number of cells (the gap's centre, at L/2 plus its offset, at the same place in the mesh in both boxes)
    from fdmsubgrid import foamcase
    for kind, a_over_delta, ratio in (("pair", 5.6, 1.0), ("wall", 5.6, 1.0), ("pair", 4.2, 1.4), ("pair", 3.0, 2.0)):
        words = subgridinterp.measure_command(kind, a_over_delta, ratio).split()
        boxes = [float(w) for w in words[words.index("--boxes") + 1:][:2]] if "--boxes" in words else [8.0, 12.0]
        depth = 1.25 if kind == "wall" else 1.0
        for L, default in zip(boxes, subgridinterp.calibration_boxes(ratio) if kind == "pair" else (8.0, 12.0)):
            # at most two cells more (a wall's 1.25 L: at most 3 more, its cell count a multiple of 4)
            assert default <= L < default + (4 if kind == "wall" else 2) / a_over_delta, (kind, a_over_delta, L)
            assert round(L * a_over_delta) % 2 == 0, (kind, a_over_delta, L)
            foamcase.Box((0, 0, 0), (L, depth * L, L), 1.0 / a_over_delta)   # raises if not whole cells
    assert "--boxes 12 16" in subgridinterp.measure_command("pair", 3.0, 2.0)
    assert "--boxes 8.214285714 12.14285714" in subgridinterp.measure_command("pair", 5.6, 1.0)   # 46, 68 cells
    # the tangential wall calibration's three boxes (L x 1.25 L x L) likewise: the shipped ones unchanged
    from fdmsubgrid import wallcalibration
    for a_over_delta in (3.0, 4.0, 5.0):
        assert wallcalibration.box_sizes(a_over_delta) == list(wallcalibration.BOXES)
    cells = [L * 5.6 for L in wallcalibration.box_sizes(5.6)]
    assert cells == pytest.approx([48, 68, 92])
    for L in wallcalibration.box_sizes(5.6):
        foamcase.Box((0, 0, 0), (L, wallcalibration.H_OVER_L * L, L), 1.0 / 5.6)


def test_the_equal_pair_at_a_over_delta_5_6(blocks, loo):
    """The equal pair at a/Delta 5.6 (the spheres of radius 1.4 of a scene at a1/Delta 4), measured in boxes of
    46 and 68 cells: its own position-averaged error within 2 % at every gap (measured 1.4 %), and from the 6
    pairs at a1/Delta 3-5 (u 2.8 inside their 1.5 ... 2.92) the interpolation within 1 % of it (measured 0.9 %);
    the bound the scene writers use for a pair outside the table stays the worst held-back pair inside the
    table (3.0 %, a1/Delta 3, a2/a1 1.4)."""
    [block] = [b for b in blocks if (b.kind, b.a_over_delta, b.ratio) == ("pair", 5.6, 1.0)]
    assert [round(L * 5.6) for L in block.summary["boxes"]] == [46, 68]
    t = loo[("pair", 5.6, 1.0)]
    assert not any(t.distance()) and t.u == pytest.approx(2.8)
    assert t.worst() < 0.01, t.added()
    assert np.max(np.abs(t.direct)) < 0.02
    tests = list(loo.values()) + subgridinterp.held_back_measurements(blocks)
    assert subgridinterp.error_bound("pair", (0.0, 0.0, 0.0), tests) == pytest.approx(loo[("pair", 3.0, 1.4)].worst())


def test_the_table_names_the_commands_that_measure_it_again():
    """The shipped table's header names one command per part it was measured in (a1/Delta 3-5 with walls and
    the tangential functions; the equal pair at 5.6 in boxes of 46 and 68 cells; the wall at 5.6 with its
    tangential functions in boxes of 48 and 68), each meshable as written; a wall at a further a/Delta in the
    pair's boxes would join the first part."""
    shipped = [b.calibration() for b in subgridinterp.load_blocks()]
    out = "dem/resistance/data/subgrid_calibration.dat"
    keys = calibration.read_table(os.path.join(PROJECT, out))
    tangential = sorted({k[1] for k in keys if k[0] == "wall_YA"})
    pairs = sorted({k[1:] for k in keys if k[0] == "pair_K11"})
    commands = calibration.regenerate_commands(shipped, out, tangential, pairs)
    assert commands == [
        "python3 -m fdmsubgrid.calibration --a-over-delta 3 4 5 --ratios 1 1.4 --boxes 8 12 --offsets 4 --tangential "
        "--pair-tangential --out " + out,
        "python3 -m fdmsubgrid.calibration --a-over-delta 5.6 --ratios 1 --no-wall --boxes 8.214285714 12.14285714 "
        "--offsets 4 --pair-tangential --out " + out,
        "python3 -m fdmsubgrid.calibration --a-over-delta 5.6 --no-pairs --boxes 8.571428571 12.14285714 --offsets 4 "
        "--tangential --out " + out]
    with open(os.path.join(PROJECT, out)) as f:
        header = [line for line in f if line.startswith("# Regenerate: ") or line.startswith("#   and: ")]
    assert header == ["# Regenerate: %s\n" % commands[0]] + ["#   and: %s\n" % c for c in commands[1:]]
    # without the wall at 5.6 the table was measured in two parts
    assert calibration.regenerate_commands([c for c in shipped if (c.kind, c.a_over_delta) != ("wall", 5.6)], out,
                                           [t for t in tangential if t != 5.6], pairs) == commands[:2]
