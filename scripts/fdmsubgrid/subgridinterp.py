"""Squeeze corrections for sizes and resolutions outside the measured table (calibration.py): interpolation
of the measured blocks in the variables the solver's missing resistance depends on, its error measured
against direct calibrations held back from it, and which species pairs of a scene it covers.

Collapse. Near contact the squeeze force of two spheres depends on their radii through the reduced radius
a* = a1 a2/(a1 + a2) alone (the gap between them is h + rho^2/(2 a*) at a distance rho from the axis); the
wall is the limit a2 -> infinity, a* = a. The mesh sees that gap region in cells: the gap x = h/Delta
(pair h = xi (a1 + a2)/2, wall h = eps a) and the reduced radius u = a*/Delta. Scaled by the leading
lubrication resistance, a*^2/(a1 h) in units of 6 pi eta a1, the correction the table holds becomes the
fraction of that leading term the solver misses,

    Phi(x, u) = s_hat(xi) * x / ((a*/a1)^2 * a1/Delta),                                  (1)

which tends to 1 as x -> 0 (the solver resolves a finite resistance, the theory's diverges) and to 0
beyond a few cells. Across the measured pair blocks (a1/Delta 3-5, a2/a1 1 and 1.4: u 1.5-2.92) Phi at a
fixed x varies by a few hundredths and linearly with u (docs/resistance.md, "Sizes and resolutions outside
the table"); at a fixed xi, linear in a1/Delta and a2/a1 as the resistance library interpolates inside its
grid, the blocks collapse less well (held back one at a time, the pairs' worst error is 4.5 % against
3.0 %, and 2.6-4.5 % against 1.5-3.0 % at the end of the table, a1/Delta 3). Pairs and walls differ beyond
the lubrication region (their far fields do): each kind is interpolated from its own blocks.

Interpolation. At every x the measured blocks' Phi (each from its fit, calibration.SqueezeCalibration.fit,
and the theory at its measured gaps: `CollapsedBlock`) is fitted by a straight line in u (least squares)
and read at the target's u; s_hat follows from (1), and the block's rows are made as a measured block's
(calibration.correction_rows: kept where positive, tapered between xi 0.5 and 1). No run and no theory
call: the target's correction needs only the blocks' Phi.

    python3 -m fdmsubgrid.calibration --interpolate --a-over-delta 3 --ratios 2 --out my_calibration.dat

writes the shipped table with the interpolated blocks added whose measured error (`error_bound`) is within
--max-error (default TOLERANCE), each header marked `interpolated`; the pair style reads it with
`pair_style fdm/subgrid calibration my_calibration.dat`.

Measured on demand. A pair or wall the interpolation does not reach within TOLERANCE is refused with the one
command that measures it (`measure_command`, `calibration --cache`): its table goes into a folder of its own
under `measured_folder()` (FDM_CALIBRATIONS, default calibrations/ in the project), where `coverage` finds it
for every later scene (status `measured`) and `interpolated_table` adds its blocks to the scene's table.
"""
from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass
from typing import Dict, List, NamedTuple, Sequence, Tuple

import numpy as np

from . import calibration, foamcase

# The shipped measurements the interpolation starts from (beside the shipped table), and the direct
# calibrations held back from it to measure its error.
SHIPPED_JSON = os.path.join("dem", "resistance", "data", "squeeze_calibration.json")
HELD_BACK_JSON = (os.path.join("docs", "data", "validation_calibrationInterpolation_ratio2_ad3.json"),
                  os.path.join("docs", "data", "validation_calibrationInterpolation_ratio1_ad6.json"),
                  os.path.join("docs", "data", "validation_calibrationInterpolation_ratio2_ad4.json"),
                  os.path.join("docs", "data", "validation_calibrationInterpolation_ratio3_ad3.json"),
                  os.path.join("docs", "data", "validation_calibrationInterpolation_ratio3_ad4.json"))
# A species pair is used without refusal when the interpolation's error, measured on held-back blocks in
# the same situation (`error_bound`), is within this (position-averaged, every gap 1e-4 ... 1).
TOLERANCE = 0.02


def _project_file(relative: str) -> str:
    from .environment import project_dir
    root = project_dir()
    if root is None:
        raise RuntimeError("subgridinterp: the project's folder is not found (set FDM_ROOT) for %s" % relative)
    return os.path.join(root, relative)


def reduced_radius(kind: str, ratio: float) -> float:
    """a*/a1: a2/(a1 + a2) of a pair (a1 the smaller sphere, ratio = a2/a1 >= 1), 1 for a wall."""
    return ratio / (1 + ratio) if kind == "pair" else 1.0


def cells_per_gap(kind: str, a_over_delta: float, ratio: float) -> float:
    """x/xi: the gap in cells per unit reduced gap, (a1 + a2)/(2 Delta) (pair) or a/Delta (wall)."""
    return a_over_delta * (1 + ratio) / 2 if kind == "pair" else a_over_delta


@dataclass
class CollapsedBlock:
    """One measured calibration (an entry of squeeze_calibration.json) in the variables of (1)."""
    kind: str
    a_over_delta: float
    ratio: float
    summary: Dict

    def __post_init__(self) -> None:
        from scipy.interpolate import PchipInterpolator
        gaps = np.array(self.summary["gaps"], dtype=float)
        order = np.argsort(gaps)
        self.gaps = gaps
        self.r_theory = 1 / np.array(self.summary["velocity_theory"], dtype=float)
        # xi * r_th is smooth in ln xi (to the leading lubrication coefficient as xi -> 0): the theory
        # between the measured gaps without a call of fdmResistance
        self._xi_r = PchipInterpolator(np.log(gaps[order]), (gaps * self.r_theory)[order])
        self.x_range = (float(gaps.min() * self.cells()), float(gaps.max() * self.cells()))

    @classmethod
    def from_summary(cls, s: Dict) -> "CollapsedBlock":
        return cls(s["kind"], float(s["a_over_delta"]), float(s["ratio"]), s)

    def u(self) -> float:
        """a*/Delta."""
        return reduced_radius(self.kind, self.ratio) * self.a_over_delta

    def cells(self) -> float:
        return cells_per_gap(self.kind, self.a_over_delta, self.ratio)

    def scale(self) -> float:
        """(a*/a1)^2 a1/Delta: s_hat = scale * Phi / x."""
        return reduced_radius(self.kind, self.ratio) ** 2 * self.a_over_delta

    def calibration(self) -> calibration.SqueezeCalibration:
        s = self.summary
        return calibration.SqueezeCalibration(s["kind"], s["a_over_delta"], s["ratio"], s["gaps"], s["boxes"],
                                              s["velocities"])

    def phi(self, x: np.ndarray) -> np.ndarray:
        """Phi of (1) from the block's fit at gaps x in cells: held at its smallest measured gap below it
        (where Phi is within 1e-3 of 1), 0 beyond its largest (a cell-scale correction has ended there)."""
        x = np.atleast_1d(np.asarray(x, dtype=float))
        xi = np.clip(x, *self.x_range) / self.cells()
        r_th = self._xi_r(np.log(xi)) / xi
        out = (x.clip(min=self.x_range[0])) * (r_th - calibration.fitted_curve(xi, self.summary["fit"])) / self.scale()
        return np.where(x > self.x_range[1] * (1 + 1e-9), 0.0, out)


def load_blocks(path: str | None = None) -> List[CollapsedBlock]:
    """The measured squeeze blocks (default: the shipped squeeze_calibration.json)."""
    with open(path or _project_file(SHIPPED_JSON)) as f:
        return [CollapsedBlock.from_summary(s) for s in json.load(f)]


def predict_phi(blocks: Sequence[CollapsedBlock], u: float, x: np.ndarray) -> np.ndarray:
    """Phi at gaps x (cells) and reduced radius u (cells): at every x the straight line in u through the
    blocks' Phi (least squares)."""
    if len(blocks) < 2:
        raise ValueError("subgridinterp: the interpolation needs two measured blocks of a kind, got %d" % len(blocks))
    x = np.atleast_1d(np.asarray(x, dtype=float))
    us = np.array([b.u() for b in blocks])
    phis = np.array([b.phi(x) for b in blocks])                 # (blocks, x)
    design = np.vstack([np.ones_like(us), us - u]).T
    coefficients = np.linalg.lstsq(design, phis, rcond=None)[0]
    return coefficients[0]


def predict_correction(blocks: Sequence[CollapsedBlock], kind: str, a_over_delta: float, ratio: float,
                       gaps: np.ndarray) -> np.ndarray:
    """s_hat (units 6 pi eta a1, not clipped, not tapered) at reduced gaps `gaps` of a (kind, a1/Delta,
    a2/a1) from the measured blocks of that kind."""
    same = [b for b in blocks if b.kind == kind]
    cells = cells_per_gap(kind, a_over_delta, ratio)
    x = np.asarray(gaps, dtype=float) * cells
    scale = reduced_radius(kind, ratio) ** 2 * a_over_delta
    return scale * predict_phi(same, reduced_radius(kind, ratio) * a_over_delta, x) / x


def interpolated_rows(blocks: Sequence[CollapsedBlock], kind: str, a_over_delta: float,
                      ratio: float) -> List[tuple]:
    """The table rows (xi, xi * s_hat) of an interpolated block, made as a measured block's."""
    return calibration.correction_rows(
        lambda xi: float(predict_correction(blocks, kind, a_over_delta, ratio, np.array([xi]))[0]))


# ---------------------------------------------------------------------------------------------------
# The interpolation's error, measured against direct calibrations it was not made from


@dataclass
class HeldBack:
    """The interpolation of one measured block from others, judged at the block's own measured positions:
    per gap the closing velocity's error against the theory averaged over the positions in the cell (the
    interpolated correction's and the block's own fit's) and the spread over the positions."""
    kind: str
    a_over_delta: float
    ratio: float
    u: float
    sources_u: List[float]
    sources_ratio: List[float]
    gaps: List[float]
    interpolated: List[float]         # position-averaged error, interpolated correction
    interpolated_std: List[float]     # its standard deviation over the positions
    direct: List[float]               # position-averaged error, the block's own calibration
    positions: int

    def distance(self) -> Tuple[float, float, float]:
        """How far outside its sources the block lies (`outside`); (0, 0, 0) inside."""
        return outside(self.u, self.ratio, self.sources_u, self.sources_ratio)

    def added(self) -> np.ndarray:
        """Per gap the interpolation's error: interpolated minus direct, position-averaged."""
        return np.array(self.interpolated) - np.array(self.direct)

    def worst(self) -> float:
        return float(np.max(np.abs(self.added())))

    def as_dict(self) -> Dict:
        d = dict(self.__dict__)
        d.update(distance=list(self.distance()), added=self.added().tolist(), worst=self.worst())
        return d


def position_errors(block: CollapsedBlock, correction: np.ndarray) -> np.ndarray:
    """The closing velocity's error against the theory at each of the block's measured positions (rows) and
    gaps (columns) with the correction s_hat (the block's gaps; clipped at 0 and tapered as the table is):
    the squeeze resistances add (calibration.py)."""
    s = np.array([max(v, 0.0) * calibration.taper(g) for v, g in zip(correction, block.gaps)])
    r = 1 / block.calibration().velocity_by_position()
    return block.r_theory / (r + s) - 1


def hold_back(target: CollapsedBlock, sources: Sequence[CollapsedBlock]) -> HeldBack:
    """The target interpolated from `sources` (those of its kind) against its own measurement."""
    same = [b for b in sources if b.kind == target.kind and b is not target]
    predicted = predict_correction(same, target.kind, target.a_over_delta, target.ratio, target.gaps)
    err = position_errors(target, predicted)
    own = position_errors(target, np.array(target.summary["correction"]))
    return HeldBack(target.kind, target.a_over_delta, target.ratio, target.u(), [b.u() for b in same],
                    [b.ratio for b in same],
                    target.gaps.tolist(), err.mean(axis=0).tolist(), err.std(axis=0).tolist(),
                    own.mean(axis=0).tolist(), len(err))


def leave_one_out(blocks: Sequence[CollapsedBlock] | None = None) -> List[HeldBack]:
    """Every shipped block interpolated from the other blocks of its kind (no run)."""
    blocks = load_blocks() if blocks is None else blocks
    return [hold_back(b, [o for o in blocks if o is not b]) for b in blocks]


def held_back_measurements(blocks: Sequence[CollapsedBlock] | None = None,
                           paths: Sequence[str] | None = None) -> List[HeldBack]:
    """The direct calibrations kept out of the table (HELD_BACK_JSON, calibration.py's summaries),
    each interpolated from every shipped block of its kind."""
    blocks = load_blocks() if blocks is None else blocks
    out = []
    for path in paths if paths is not None else [_project_file(p) for p in HELD_BACK_JSON]:
        if not os.path.isfile(path):
            continue
        with open(path) as f:
            data = json.load(f)
        for s in data["calibrations"]:
            out.append(hold_back(CollapsedBlock.from_summary(s), blocks))
    return out


def outside(u: float, ratio: float, sources_u: Sequence[float],
            sources_ratio: Sequence[float]) -> Tuple[float, float, float]:
    """How far a block (a*/Delta u, a2/a1 ratio) lies outside the measured blocks it is interpolated from,
    in three directions: ln u below their smallest u, ln u above their largest, ln ratio beyond their largest
    ratio (the collapse puts the ratio into u; how far that holds is measured, not assumed); 0 where inside."""
    return (max(0.0, math.log(min(sources_u) / u)), max(0.0, math.log(u / max(sources_u))),
            max(0.0, math.log(ratio / max(sources_ratio))))


def error_bound(kind: str, distance: Sequence[float], tests: Sequence[HeldBack]) -> float | None:
    """The interpolation's error to expect for a block of `kind` lying `distance` (`outside`) outside the
    measured blocks: the worst of the held-back tests of that kind inside their sources and, for a block
    outside, of the nearest tests at least as far outside in each direction (an extrapolation is never trusted
    more than an interpolation; a test farther out than another such test does not bound it, as the ratio-3 pair
    does not bound a ratio-2 one); None when no test lies that far outside (an extrapolation farther than any
    measured)."""
    same = [t for t in tests if t.kind == kind]
    inside = [t.worst() for t in same if not any(t.distance())]
    if not any(d > 0 for d in distance):
        return max(inside, default=None)

    def at_least(a: Sequence[float], b: Sequence[float]) -> bool:
        return all(x >= y - 1e-9 for x, y in zip(a, b))
    farther = [t for t in same if at_least(t.distance(), distance)]
    # those no other such test lies nearer to (at most as far in every direction, nearer in one)
    nearest = [t.worst() for t in farther
               if not any(at_least(t.distance(), f.distance()) and not at_least(f.distance(), t.distance())
                          for f in farther)]
    if not nearest:
        return None
    return max(inside + nearest)


# ---------------------------------------------------------------------------------------------------
# Which species pairs of a scene the table covers, interpolates or refuses


class PairCoverage(NamedTuple):
    """One species pair of a scene (radii; (a, inf) for a sphere against a wall)."""
    pair: Tuple[float, float]
    status: str                   # "calibrated", "measured" (on demand), "interpolated" or "refused"
    error: float | None           # the interpolation's measured error (position-averaged, worst gap); None if
    #                               calibrated or measured
    kind: str                     # "pair" or "wall"
    a_over_delta: float           # a1/Delta, a1 the smaller sphere (wall: a/Delta)
    ratio: float                  # a2/a1 (wall: 1)
    command: str                  # the one command that measures it directly
    core_seconds: float           # that command's estimated cost


def calibration_boxes(ratio: float) -> Tuple[float, float]:
    """The two box sizes L/a1 of a direct calibration: calibration.BOXES up to a2/a1 1.4, beyond it
    growing with the larger sphere (6 and 8 a2: ratio 2 at 12 and 16 a1, as the held-back measurement)."""
    if ratio <= 1.4 + 1e-9:
        return tuple(calibration.BOXES)
    return (6.0 * ratio, 8.0 * ratio)


def _depth(kind: str) -> float:
    return 1.0 if kind == "pair" else 1.25        # the wall's channel is L x 1.25 L x L


def measure_command(kind: str, a_over_delta: float, ratio: float) -> str:
    """The one command that calibrates (kind, a1/Delta, a2/a1) directly (its boxes in whole cells)."""
    words = ["python3 -m fdmsubgrid.calibration", "--a-over-delta", "%g" % a_over_delta]
    boxes = calibration_boxes(ratio) if kind == "pair" else calibration.BOXES
    sizes = [foamcase.whole_cell_box(L, a_over_delta, _depth(kind)) for L in boxes]
    if kind == "wall":
        words += ["--no-pairs"]
    else:
        words += ["--ratios", "%g" % ratio, "--no-wall"]
    if kind == "pair" or sizes != list(boxes):
        words += ["--boxes"] + ["%.10g" % L for L in sizes]
    return " ".join(words + ["--cache"])


def calibration_cells(kind: str, a_over_delta: float, ratio: float) -> float:
    """Mesh cells of one direct calibration, summed over its two boxes (the wall's channel is L x 1.25 L x L)."""
    boxes = calibration_boxes(ratio) if kind == "pair" else calibration.BOXES
    return sum(_depth(kind) * (foamcase.whole_cell_box(L, a_over_delta, _depth(kind)) * a_over_delta) ** 3
               for L in boxes)


def cost_model(summaries: Sequence[Dict]) -> Tuple[float, float]:
    """ln(seconds) = c + q ln(cells) through the measured calibrations' wall seconds (each serial: the
    fluid and the particle code alternate on one core). Returns (c, q)."""
    cells = np.array([calibration_cells(s["kind"], s["a_over_delta"], s["ratio"]) for s in summaries
                      if s.get("wall_seconds")])
    seconds = np.array([s["wall_seconds"] for s in summaries if s.get("wall_seconds")])
    q, c = np.polyfit(np.log(cells), np.log(seconds), 1)
    return float(c), float(q)


def estimated_core_seconds(kind: str, a_over_delta: float, ratio: float, model: Tuple[float, float]) -> float:
    c, q = model
    return float(math.exp(c + q * math.log(calibration_cells(kind, a_over_delta, ratio))))


def _grid_corners(table, kind: str, a_over_delta: float, ratio: float) -> List[tuple] | None:
    """The blocks the resistance library reads for (kind, a/Delta, ratio) (subgrid_calibration.cpp, `stencil`):
    the value itself or the two tabulated values around it, in a/Delta and in ratio; None if a corner is
    missing or the value lies outside the table. table: any mapping keyed by (kind, a/Delta, ratio)."""
    keys = [k for k in table if k[0] == kind]

    def bracket(values, v):
        values = sorted(set(values))
        for w in values:
            if abs(w - v) <= 1e-6 * w:
                return (w, w)
        for lo, hi in zip(values, values[1:]):
            if lo < v < hi:
                return (lo, hi)
        return None

    a = bracket([k[1] for k in keys], a_over_delta)
    r = bracket([k[2] for k in keys], ratio)
    if a is None or r is None:
        return None
    corners = sorted({(kind, ai, ri) for ai in a for ri in r})
    return corners if all(c in table for c in corners) else None


def _table_grid(table, kind: str, a_over_delta: float, ratio: float) -> bool:
    """Whether the table covers (kind, a/Delta, ratio) as the resistance library does (_grid_corners)."""
    return _grid_corners(table, kind, a_over_delta, ratio) is not None


# ---------------------------------------------------------------------------------------------------
# Calibrations measured on demand

# The folder of the calibrations a user measured (`calibration --cache`): one sub-folder per command, its
# subgrid_calibration.dat (with the measurements beside it) found by every later scene.
MEASURED_ENV = "FDM_CALIBRATIONS"
MEASURED_TABLE = "subgrid_calibration.dat"
# the blocks that go with a squeeze block of the same (a/Delta, ratio) when it is added to a scene's table
_COMPANIONS = {"pair": ("pair_K11", "pair_K12", "pair_K22", "pair_Ktw"),
               "wall": ("wall_YA", "wall_YB", "wall_YC", "wall_XC")}


def measured_folder() -> str:
    """FDM_CALIBRATIONS, or calibrations/ in the project's folder."""
    folder = os.environ.get(MEASURED_ENV)
    return folder if folder else _project_file("calibrations")


def measured_name(jobs: Sequence[Tuple[str, float, float]]) -> str:
    """The sub-folder of one `calibration --cache` command: its (kind, a1/Delta, a2/a1) in words."""
    return "_".join("%s_ad%g%s" % (kind, ad, "_ratio%g" % ratio if kind == "pair" else "") for kind, ad, ratio in jobs)


def measured_blocks(folder: str | None = None) -> Dict[tuple, Tuple[str, str]]:
    """The blocks of every table measured on demand (FOLDER/*/subgrid_calibration.dat): {(kind, a/Delta,
    ratio): (the table's path, the block's text)}. The same block measured twice with different values is
    refused, naming both files (a scene never runs with one of two measurements silently)."""
    folder = measured_folder() if folder is None else folder
    out: Dict[tuple, Tuple[str, str]] = {}
    if not os.path.isdir(folder):
        return out
    for name in sorted(os.listdir(folder)):
        path = os.path.join(folder, name, MEASURED_TABLE)
        if not os.path.isfile(path):
            continue
        for key, lines in calibration.table_blocks(path).items():
            text = "".join(lines)
            if key in out and out[key][1] != text:
                raise ValueError("calibrations measured on demand: %s a/Delta %g ratio %g is in %s and, with other "
                                 "values, in %s: remove one of them" % (key + (out[key][0], path)))
            out.setdefault(key, (path, text))
    return out


def _with_measured(table: Dict[tuple, tuple], measured: Dict[tuple, tuple]) -> Dict[tuple, tuple | None]:
    """The keys of a table's blocks and of those measured on demand it lacks (for _grid_corners)."""
    return {**table, **{k: None for k in measured if k not in table}}


def coverage(radii: Sequence[float], a_over_delta: float, walls: bool = False, table: str | None = None,
             tests: Sequence[HeldBack] | None = None) -> List[PairCoverage]:
    """For each species pair of a scene (every two distinct radii and each radius with itself; with walls
    each radius against a wall): whether the calibration table covers it (`calibrated`), the table with the
    calibrations measured on demand does (`measured`: measured_blocks), the interpolation does within TOLERANCE
    as measured on held-back blocks in the same situation (`interpolated`), or neither (`refused`), with the
    command that would measure it directly and that command's estimated cost. radii: the species' radii (any
    order, repeats ignored); a_over_delta: the smallest radius over the mesh size; table: default the shipped
    table."""
    sizes = sorted({float(r) for r in radii})
    if not sizes or sizes[0] <= 0:
        raise ValueError("coverage: radii must be positive, got %s" % list(radii))
    if not a_over_delta > 0:
        raise ValueError("coverage: a_over_delta must be positive, got %r" % a_over_delta)
    delta = sizes[0] / a_over_delta
    shipped = calibration.read_table(table or _project_file(os.path.join("dem", "resistance", "data",
                                                                         "subgrid_calibration.dat")))
    with_measured = _with_measured(shipped, measured_blocks())
    blocks = load_blocks()
    tests = list(leave_one_out(blocks)) + held_back_measurements(blocks) if tests is None else tests
    model = cost_model([b.summary for b in blocks])
    wanted = [("pair", (a, b)) for i, a in enumerate(sizes) for b in sizes[i:]]
    if walls:
        wanted += [("wall", (a, math.inf)) for a in sizes]
    out = []
    for kind, (a, b) in wanted:
        ad = a / delta
        ratio = b / a if kind == "pair" else 1.0
        key_ad, key_ratio = float("%.6g" % ad), float("%.6g" % ratio)
        command = measure_command(kind, key_ad, key_ratio)
        cost = estimated_core_seconds(kind, ad, ratio, model)
        if _table_grid(shipped, kind, ad, ratio):
            out.append(PairCoverage((a, b), "calibrated", None, kind, key_ad, key_ratio, command, cost))
            continue
        if _table_grid(with_measured, kind, ad, ratio):
            out.append(PairCoverage((a, b), "measured", None, kind, key_ad, key_ratio, command, cost))
            continue
        same = [x for x in blocks if x.kind == kind]
        distance = outside(reduced_radius(kind, ratio) * ad, ratio, [x.u() for x in same], [x.ratio for x in same])
        bound = error_bound(kind, distance, tests)
        status = "interpolated" if bound is not None and bound <= TOLERANCE else "refused"
        out.append(PairCoverage((a, b), status, bound, kind, key_ad, key_ratio, command, cost))
    return out


def refusal(entry: PairCoverage) -> str:
    """One line for a refused species pair: what, why, the command that measures it and its cost."""
    what = ("the pair of radii %g and %g at a1/Delta %g (a2/a1 %g)" % (entry.pair + (entry.a_over_delta, entry.ratio))
            if entry.kind == "pair" else "radius %g against a wall at a/Delta %g" % (entry.pair[0], entry.a_over_delta))
    why = ("no held-back test of the interpolation this far outside the table" if entry.error is None
           else "interpolation error %.1f %% > %g %%" % (100 * entry.error, 100 * TOLERANCE))
    return "%s: not calibrated, %s; measure it (about %.0f core-seconds): %s" % (what, why, entry.core_seconds,
                                                                                entry.command)


# ---------------------------------------------------------------------------------------------------
# Writing a table with interpolated blocks


def write_interpolated(out: str, targets: Sequence[Tuple[str, float, float]], table: str | None = None,
                       max_error: float = TOLERANCE) -> List[Dict]:
    """Copy the calibration table (default: the shipped one) to `out` with an interpolated block for each
    (kind, a1/Delta, a2/a1) of `targets` it lacks whose measured error (`error_bound`) is within max_error
    (math.inf: also those no held-back test reaches), each preceded by a comment line and its header marked
    `interpolated`. Returns per target what was done (status "in the table", "interpolated" or "left out",
    with the measured error and, left out, the command that measures it)."""
    from .files import write_atomically
    text, done = interpolated_table(targets, table, max_error)
    write_atomically(out, text)
    return done


def interpolated_table(targets: Sequence[Tuple[str, float, float]], table: str | None = None,
                       max_error: float = TOLERANCE) -> Tuple[str, List[Dict]]:
    """The text `write_interpolated` writes and its per-target record. A target the calibrations measured on
    demand cover (measured_blocks, with the table's blocks as the resistance library reads them) gets their
    blocks (squeeze and, where measured, the tangential ones of the same a/Delta and ratio), status
    "measured"."""
    table = table or _project_file(os.path.join("dem", "resistance", "data", "subgrid_calibration.dat"))
    present = calibration.read_table(table)
    blocks = load_blocks()
    tests = list(leave_one_out(blocks)) + held_back_measurements(blocks)
    with open(table) as f:
        text = f.read()
    done = []
    added = []
    measured = measured_blocks()
    with_measured = _with_measured(present, measured)
    for kind, ad, ratio in targets:
        key = (kind, float("%.6g" % ad), float("%.6g" % ratio))
        if key in present:
            done.append(dict(kind=kind, a_over_delta=ad, ratio=ratio, status="in the table"))
            continue
        corners = _grid_corners(with_measured, kind, ad, ratio)
        if corners is not None:
            new = [c for c in corners if c not in present and c not in {k for _, k, _ in added}]
            for c in new:
                path = calibration.project_relative(measured[c][0])
                companions = [measured[(name,) + c[1:]][1] for name in _COMPANIONS[kind]
                              if (name,) + c[1:] in measured]
                added.append(("# measured on demand: %s a1/Delta %g a2/a1 %g from %s\n" % (c + (path,)),
                              c, measured[c][1] + "".join(companions)))
            done.append(dict(kind=kind, a_over_delta=ad, ratio=ratio, status="measured",
                             tables=sorted({calibration.project_relative(measured[c][0]) for c in corners
                                            if c in measured})))
            continue
        rows = interpolated_rows(blocks, kind, ad, ratio)
        same = [b for b in blocks if b.kind == kind]
        us = sorted(b.u() for b in same)
        u = reduced_radius(kind, ratio) * ad
        distance = outside(u, ratio, us, [b.ratio for b in same])
        bound = error_bound(kind, distance, tests)
        if not ((bound if bound is not None else math.inf) <= max_error):
            done.append(dict(kind=kind, a_over_delta=ad, ratio=ratio, status="left out", error=bound,
                             command=measure_command(kind, ad, ratio)))
            continue
        note = ("# interpolated (fdmsubgrid.subgridinterp): %s a1/Delta %g a2/a1 %g, a*/Delta %.4g from the %s "
                "blocks at a*/Delta %s; held-back error in this situation %s\n"
                % (kind, ad, ratio, u, kind, " ".join("%.4g" % v for v in us),
                   "not measured" if bound is None else "%.1f %%" % (100 * bound)))
        block = "%s %.6g %.6g %d %s\n" % (kind, ad, ratio, len(rows), calibration.INTERPOLATED)
        block += "".join("%.8e %.8e\n" % (xi, v) for xi, v in rows)
        added.append((note, key, block))
        done.append(dict(kind=kind, a_over_delta=ad, ratio=ratio, status="interpolated", error=bound, rows=len(rows)))
    return text + "".join(note + block for note, _, block in added), done


def print_errors(tests: Sequence[HeldBack] | None = None) -> None:
    """Every held-back test (each shipped block from the others, and the direct calibrations kept out of the
    table) as a text table in %: per gap the interpolated correction's closing-velocity error against the
    theory averaged over the positions in the cell, ± its standard deviation over them, the block's own
    calibration's, and the interpolation's error (their difference)."""
    if tests is None:
        blocks = load_blocks()
        tests = list(leave_one_out(blocks)) + held_back_measurements(blocks)
    for t in tests:
        print("%s a1/Delta %g a2/a1 %g (a*/Delta %.3g, %s, %d positions): interpolation error %.1f %%"
              % (t.kind, t.a_over_delta, t.ratio, t.u, "inside its sources" if not any(t.distance())
                 else "outside its sources by %.2f below, %.2f above in ln a*/Delta, %.2f beyond in ln a2/a1"
                 % t.distance(), t.positions, 100 * t.worst()))
        print("  gap               " + " ".join("%6.3g" % g for g in t.gaps))
        for name, values in (("interpolated", t.interpolated), ("  +- positions", t.interpolated_std),
                             ("direct", t.direct), ("difference", t.added())):
            form = "%6.2f" if name.startswith(" ") else "%+6.2f"
            print("  %-16s " % name + " ".join(form % (100 * v) for v in values))


def write_scene_table(out: str, radii: Sequence[float], a_over_delta: float, walls: bool = False,
                      max_error: float = TOLERANCE) -> List[PairCoverage]:
    """For a scene (as `coverage`): the shipped table with an interpolated block for each species pair and
    wall it lacks whose measured error is within max_error, in `out` (for `pair_style fdm/subgrid calibration
    out`). Returns the scene's coverage; the pairs still `refused` are not in the file (the pair style
    refuses them at its start, as `fdmResistance coverage` does beforehand)."""
    entries = coverage(radii, a_over_delta, walls)
    targets = [(c.kind, c.a_over_delta, c.ratio) for c in entries if c.status != "calibrated"]
    write_interpolated(out, targets, max_error=max_error)
    return entries
