"""Calibration of the solver's own squeeze resistance (paper section 2.2 and Appendix B):
R^SG = R^th - R^FDM measured, instead of the cut-off model's guess of what the mesh resolves.

What is measured. Two spheres pushed together by equal and opposite forces +-F along their line of
centres (and a sphere pushed toward a wall by F), with the sub-grid lubrication switched off
(`pair_style fdm/subgrid lubrication no`): the closing velocity V_FDM(xi) of the fictitious-domain
solver alone. For a pair the squeeze block of the sub-grid matrix (Appendix C.2: X11 = X22 = -X21,
X12 = X21) acts on the relative velocity only, s e e^T with e = (1, -1) and s = -X21A^SG; by the
Sherman-Morrison formula the closing velocity under the loads F e of the solver plus that block is
exactly 1/(1/V_FDM + s/F): the squeeze resistances F/V add. So the correction that makes the coupled
solver give the theory is

    s(xi) = F/V_th(xi) - F/V_FDM(xi)          (pair: X21A^SG = -s;  wall: X^A_SG = s)

with V_th the full-range theory (Jeffrey & Onishi; Brenner for the wall). In units of 6 pi eta a1
(a1 the smaller sphere): s_hat = 1/V_hat_th - 1/V_hat_FDM.

Box effect. The loads +-F are a force dipole: in a periodic box of side L its images change V by
O(L^-3) (measured here: 19 % at xi = 1 for L = 8 a1, 4.6 % at 12 a1, a1/Delta = 3). The wall runs
(net force on the sphere, taken by the walls) converge the same way. Two box sizes L1 < L2 are run
and V is extrapolated as V_inf = V2 + (V2 - V1) L1^3/(L2^3 - L1^3); a third size checks it.

Position in the mesh. V_FDM steps as the sphere surfaces cross cell centres; every gap is measured
at several positions of the gap centre inside its cell (`offsets`) and averaged; the spread is the
calibration's own scatter, reported.

Fit. The averaged, extrapolated resistance r_FDM(xi) = 1/V_hat_FDM is fitted by a logistic curve in
ln xi, r_FDM = r_inf + (r_0 - r_inf)/(1 + (xi/xi_1)^p): the plateau r_0 where the solver no longer
sees the gap (below about a tenth of a cell), a rise around xi_1 (least squares in log r). The
calibration is judged by the closing velocity it gives averaged over the positions in the cell (exact
from the measurements: the resistances add); where the curve leaves that more than FIT_VELOCITY_BOUND
off the theory at a gap, the nearest curve that holds every gap within it is taken (SqueezeCalibration.fit).

Positivity and range. The correction s_hat = r_th - r_FDM,fit is kept where positive (where the
solver already resists more than the theory, no correction); it ends at the first gap where it
changes sign, and is tapered to zero between TAPER_START and TAPER_END.

Output: a text table (`write_table`) the resistance library reads (CalibratedSubgridModel,
docs/resistance.md): for every (kind, a/Delta, ratio) the columns xi and xi * s_hat(xi) on a
logarithmic grid from 1e-5 to xi_max (xi * s_hat is smooth at both ends: it tends to the leading
lubrication coefficient as xi -> 0 and to 0 at xi_max; linear interpolation in ln xi). The table also
holds the tangential wall functions (kinds wall_YA, wall_YB, wall_YC, wall_XC) that
wallcalibration.py measures: `--tangential` runs them, `--tangential-from-raw` takes them from an
earlier run; and the pair's other internal modes (kinds pair_K11, pair_K12, pair_K22, pair_Ktw: sliding,
sliding-rolling coupling, rolling, twist) that pairtangential.py measures: `--pair-tangential` runs them,
`--pair-tangential-from-raw` takes them from earlier runs. Beside the table: its squeeze measurements
(squeeze_calibration.json), the tangential ones (wall_tangential_calibration.json,
pair_tangential_calibration.json) and a figure of each (.png).

    python3 -m fdmsubgrid.calibration --a-over-delta 3 4 5 --tangential --pair-tangential --out dem/resistance/data/subgrid_calibration.dat

What it leaves at each position in the cell (no run: the resistances add, so the model's error at every
measured position follows from the measurement; beside it the floor no correction of the gap alone can pass):

    python3 -m fdmsubgrid.calibration --position-errors dem/resistance/data/squeeze_calibration.json
"""
from __future__ import annotations

import argparse
import functools
import json
import math
import os
import sys
import time
from dataclasses import dataclass, field
from typing import Callable, Dict, List, Sequence

import numpy as np

from . import files, pairtangential, squeeze, theory, wallcalibration

GAPS = [1.0, 0.7, 0.5, 0.3, 0.2, 0.15, 0.1, 0.07, 0.05, 0.03, 0.02, 0.01, 3e-3, 1e-3, 1e-4]
# positions of the gap centre inside its mesh cell (fractions of Delta)
OFFSETS = [(0.1, 0.2, 0.3), (0.35, 0.45, 0.55), (0.6, 0.7, 0.8), (0.85, 0.95, 0.05)]
BOXES = (8.0, 12.0)           # L/a1 of the two box sizes extrapolated
TABLE_MIN_GAP = 1e-5          # the resistance library's smallest gap (minimumGap)
TABLE_POINTS_PER_DECADE = 20
# The correction is tapered to zero between TAPER_START and TAPER_END (linearly in ln xi): beyond a
# gap of about one radius what the solver misses is its far-field discretisation error (1.5 % of the
# squeeze resistance at xi = 1, a1/Delta = 3), not lubrication, and a longer range would cost
# neighbour searches for nothing.
TAPER_START, TAPER_END = 0.5, 1.0
# The calibrated model's closing velocity, averaged over the measured positions in the cell, is held within
# this of the theory at every measured gap (SqueezeCalibration.fit): the 2 % the squeeze validation asks
# (docs/validation.md, "Squeeze flows"), less a margin for the table's interpolation between its rows.
FIT_VELOCITY_BOUND = 0.018


@functools.lru_cache(maxsize=None)
def theory_velocity(kind: str, ratio: float, gap: float) -> float:
    """V_hat_th: the closing velocity (pair) or the velocity toward the wall, in F/(6 pi eta a1)."""
    if kind == "wall":
        return theory.wall_squeeze_velocity(1.0, gap)
    return theory.pair_squeeze_velocity(1.0, ratio, gap)


@dataclass
class SqueezeCalibration:
    """One (kind, a/Delta, ratio): measurements, their fit and the correction."""
    kind: str                      # "pair" or "wall"
    a_over_delta: float            # a1/Delta, a1 the smaller sphere (wall: the sphere)
    ratio: float                   # a2/a1 >= 1 (wall: 1)
    gaps: List[float]
    boxes: List[float]
    velocities: Dict[str, List[List[float]]] = field(default_factory=dict)   # "L" -> [offset][gap]
    wall_seconds: float = 0.0

    def velocity_by_position(self) -> np.ndarray:
        """V_hat_FDM at every position (rows) and gap (columns), each box-extrapolated."""
        L1, L2 = self.boxes[0], self.boxes[1]
        return squeeze.extrapolate_box(np.array(self.velocities["%g" % L1]), np.array(self.velocities["%g" % L2]),
                                       L1, L2)

    def velocity_inf(self) -> np.ndarray:
        """Box-extrapolated, offset-averaged V_hat_FDM (the extrapolation is linear: the mean of each
        position's equals the extrapolation of the means)."""
        return self.velocity_by_position().mean(axis=0)

    def spread(self) -> np.ndarray:
        """Relative spread (max - min over the offsets, over the mean) at the largest box."""
        v = np.array(self.velocities["%g" % self.boxes[1]])
        return (v.max(axis=0) - v.min(axis=0)) / v.mean(axis=0)

    def theory(self) -> np.ndarray:
        return np.array([theory_velocity(self.kind, self.ratio, g) for g in self.gaps])

    def corrected_errors(self, fit: Dict[str, float]) -> np.ndarray:
        """The calibrated model's error of the closing velocity at every measured position (rows) and
        gap (columns): 1/(r_FDM,i + s) against the theory, s the correction the table holds (the fit's,
        kept where positive, tapered). Exact for the squeeze (the resistances add, module docstring),
        so it needs no further run."""
        s = np.array([max(self.correction(g, fit), 0.0) * taper(g) for g in self.gaps])
        return self.theory() ** -1 / (1 / self.velocity_by_position() + s) - 1

    def position_floor(self) -> np.ndarray:
        """Per gap, the smallest worst-position error of the closing velocity that any correction
        depending on the gap alone can reach at the calibration's own positions in the cell.

        A correction of the gap alone adds the same s to the solver's resistance r_i = 1/V_FDM,i
        (box-extrapolated) at every position i; the velocity is then 1/(r_i + s) exactly (the squeeze
        resistances add, module docstring). The best s makes the fastest and the slowest position
        equally wrong, r_th/(r_min + s) - 1 = 1 - r_th/(r_max + s): the floor is that common error."""
        r = 1 / self.velocity_by_position()          # the solver's resistance at each position
        r_th = 1 / self.theory()
        spread = r.max(axis=0) - r.min(axis=0)
        # A = r_min + s solves 2 A^2 + 2 A (D - r_th) - r_th D = 0 (D the spread), its positive root
        b = 2 * (spread - r_th)
        a_min = (-b + np.sqrt(b ** 2 + 8 * r_th * spread)) / 4
        return r_th / a_min - 1

    def fit(self) -> Dict[str, float]:
        """r_FDM(xi) = r_inf + (r_0 - r_inf)/(1 + (xi/xi_1)^p) through r_FDM = 1/V_inf (least squares in log r):
        a plateau r_0 where the solver no longer sees the gap, a rise around xi_1. Where that curve leaves
        the calibrated model's closing velocity, averaged over the measured positions in the cell
        (`corrected_errors`), more than FIT_VELOCITY_BOUND off the theory at a gap the correction reaches
        (below TAPER_END), the curve is the one nearest it (least squares in log r again, scipy SLSQP in ln of
        the parameters) that holds each of those gaps within FIT_VELOCITY_BOUND; if the optimizer does not get
        closer to that than the plain curve, the plain curve is kept. rms_rel, max_rel: the curve's deviation
        from r_FDM; velocity_rms, velocity_max: the position-averaged velocity error it leaves."""
        from scipy.optimize import least_squares, minimize
        gaps = np.array(self.gaps)
        r_fdm = 1 / self.velocity_inf()

        def log_residual(q: np.ndarray) -> np.ndarray:
            return np.log(fitted_resistance(gaps, *q) / r_fdm)

        def velocity_error(q: np.ndarray) -> np.ndarray:
            return self.corrected_errors(dict(r_0=q[0], r_inf=q[1], xi_1=q[2], p=q[3])).mean(axis=0)

        def reached_error(q: np.ndarray) -> np.ndarray:      # where the correction acts
            return velocity_error(q)[gaps < TAPER_END]

        x0 = [r_fdm.max(), r_fdm.min() * 0.5, 0.2, 1.5]
        q = least_squares(log_residual, x0=x0, bounds=([0, 0, 1e-3, 0.3], [np.inf, np.inf, 10, 6])).x
        worst = float(np.max(np.abs(reached_error(q))))
        if worst > FIT_VELOCITY_BOUND:
            # in percent, so that the constraints and the objective are of order 1
            held = [{"type": "ineq", "fun": lambda z: 100 * (FIT_VELOCITY_BOUND - reached_error(np.exp(z)))},
                    {"type": "ineq", "fun": lambda z: 100 * (FIT_VELOCITY_BOUND + reached_error(np.exp(z)))}]
            sol = minimize(lambda z: 1e4 * np.mean(log_residual(np.exp(z)) ** 2), np.log(q), method="SLSQP",
                           constraints=held, options=dict(maxiter=500, ftol=1e-12))
            if np.all(np.isfinite(sol.x)) and float(np.max(np.abs(reached_error(np.exp(sol.x))))) < worst:
                q = np.exp(sol.x)
        rel = np.exp(log_residual(q)) - 1
        err = velocity_error(q)
        r_0, r_inf, xi_1, power = (float(v) for v in q)
        return dict(r_0=r_0, r_inf=r_inf, xi_1=xi_1, p=power, rms_rel=float(np.sqrt(np.mean(rel ** 2))),
                    max_rel=float(np.max(np.abs(rel))), velocity_rms=float(np.sqrt(np.mean(err ** 2))),
                    velocity_max=float(np.max(np.abs(err))))

    def correction(self, gap: float, fit: Dict[str, float]) -> float:
        """s_hat(xi) = r_th(xi) - r_FDM,fit(xi) (units 6 pi eta a1), not clipped."""
        r_th = 1 / theory_velocity(self.kind, self.ratio, round_gap(gap))
        return r_th - float(fitted_curve(np.array(gap), fit))

    def table(self, fit: Dict[str, float]) -> List[tuple]:
        """(xi, xi * s_hat * taper) from TABLE_MIN_GAP to the first sign change of s_hat or TAPER_END
        (the last row is 0): `correction_rows` of the fit's correction."""
        return correction_rows(lambda xi: self.correction(xi, fit))


def correction_rows(correction: Callable[[float], float]) -> List[tuple]:
    """The rows (xi, xi * s_hat(xi) * taper(xi)) of a table block, s_hat = `correction` (units 6 pi eta a1,
    not clipped): 20 per decade from TABLE_MIN_GAP to the first sign change of s_hat or TAPER_END, the zero
    crossing interpolated in ln xi (the last row is 0)."""
    rows = []
    n = int(round(TABLE_POINTS_PER_DECADE * math.log10(TAPER_END / TABLE_MIN_GAP)))
    for k in range(n + 1):
        xi = TABLE_MIN_GAP * 10 ** (k / TABLE_POINTS_PER_DECADE)
        s = correction(xi) * taper(xi)
        if s <= 0:
            if rows:  # interpolate the zero crossing
                xp, sp = rows[-1][0], rows[-1][1] / rows[-1][0]
                t = sp / (sp - s)
                x0 = math.exp(math.log(xp) + t * (math.log(xi) - math.log(xp)))
                rows.append((x0, 0.0))
            break
        rows.append((xi, xi * s))
    return rows


def taper(xi: float) -> float:
    """1 below TAPER_START, 0 from TAPER_END, linear in ln xi between."""
    if xi <= TAPER_START:
        return 1.0
    if xi >= TAPER_END:
        return 0.0
    return math.log(TAPER_END / xi) / math.log(TAPER_END / TAPER_START)


def fitted_resistance(xi: np.ndarray, r_0: float, r_inf: float, xi_1: float, p: float) -> np.ndarray:
    """The fit of the solver's squeeze resistance (units 6 pi eta a1)."""
    return r_inf + (r_0 - r_inf) / (1 + (xi / xi_1) ** p)


def fitted_curve(xi: np.ndarray, fit: Dict[str, float]) -> np.ndarray:
    """fitted_resistance with the parameters of a fit (SqueezeCalibration.fit's dict)."""
    return fitted_resistance(xi, fit["r_0"], fit["r_inf"], fit["xi_1"], fit["p"])


def round_gap(g: float) -> float:
    """Gaps passed to fdmResistance (and cached) to 6 significant digits."""
    return float("%.6g" % g)


def measure(kind: str, a_over_delta: float, ratio: float, workdir: str, gaps: Sequence[float] = GAPS,
            boxes: Sequence[float] = BOXES, offsets: Sequence[Sequence[float]] = OFFSETS,
            tol_lambda: float = 1e-5, np_fluid: int = 1) -> SqueezeCalibration:
    """Run the squeeze scenes with the sub-grid lubrication off at every box size and offset."""
    cal = SqueezeCalibration(kind, a_over_delta, ratio if kind == "pair" else 1.0, list(gaps), list(boxes))
    t0 = time.time()
    for L in boxes:
        rows = []
        for off in offsets:
            if kind == "pair":
                r = squeeze.run_pair(workdir, ratio, gaps, False, a_over_delta, L, tol_lambda, np_fluid=np_fluid,
                                     offset=off)
            else:
                r = squeeze.run_wall(workdir, gaps, False, a_over_delta, L, 1.25 * L, tol_lambda, np_fluid=np_fluid,
                                     offset=off)
            if not r["converged"]:
                raise RuntimeError("calibration: %s a/Delta %g ratio %g L %g offset %s: a step did not converge"
                                   % (kind, a_over_delta, ratio, L, off))
            rows.append(r["velocity"])
        cal.velocities["%g" % L] = rows
    cal.wall_seconds = time.time() - t0
    return cal


def project_relative(path: str) -> str:
    """path relative to the project's root if it lies inside it."""
    from .environment import project_dir
    root, full = project_dir(), os.path.realpath(path)
    if root is None:
        return full
    root = os.path.realpath(root)
    return os.path.relpath(full, root) if full.startswith(root + os.sep) else full


def regenerate_command(calibrations: Sequence[SqueezeCalibration], out: str, tangential: bool = False,
                       pair_tangential: bool = False) -> str:
    """The one command that measures and analyses these calibrations again (one set of boxes and positions;
    regenerate_commands splits a table measured in parts)."""
    ads = sorted({c.a_over_delta for c in calibrations})
    ratios = sorted({c.ratio for c in calibrations if c.kind == "pair"})
    c0 = calibrations[0]
    n_offsets = len(next(iter(c0.velocities.values())))
    words = ["python3 -m fdmsubgrid.calibration", "--a-over-delta"] + ["%g" % a for a in ads]
    words += (["--ratios"] + ["%g" % r for r in ratios]) if ratios else ["--no-pairs"]
    if not any(c.kind == "wall" for c in calibrations):
        words.append("--no-wall")
    words += ["--boxes"] + ["%.10g" % L for L in c0.boxes] + ["--offsets", str(n_offsets)]
    if tangential:
        words.append("--tangential")
    if pair_tangential:
        words.append("--pair-tangential")
    return " ".join(words + ["--out", out])


def regenerate_commands(calibrations: Sequence[SqueezeCalibration], out: str, tangential: Sequence[float] = (),
                        pair_tangential: Sequence[tuple] = ()) -> List[str]:
    """The commands that measure these calibrations again: one per part measured alike (one a1/Delta, one set of
    boxes and positions: at a1/Delta 5.6 the pair's boxes of 46 and 68 cells and the wall's of 48 and 68 are two
    parts), the parts of equal content at several a1/Delta merged (a table measured in parts: e.g. a1/Delta 3-5
    with walls and a later equal pair and wall at 5.6). tangential: the a/Delta of the wall tangential blocks
    (measured with the wall's part); pair_tangential: the (a1/Delta, ratio) of the pair tangential ones."""
    def n_offsets(c):
        return len(next(iter(c.velocities.values())))

    parts: Dict[tuple, List[SqueezeCalibration]] = {}
    for c in sorted(calibrations, key=lambda c: (c.a_over_delta, c.kind != "pair", c.ratio)):
        parts.setdefault((c.a_over_delta, tuple(c.boxes), n_offsets(c)), []).append(c)
    groups: List[tuple] = []
    for (ad, boxes, offsets), part in parts.items():
        pairs = tuple(sorted({c.ratio for c in part if c.kind == "pair"}))
        wall = any(c.kind == "wall" for c in part)
        key = (pairs, wall, boxes, offsets, wall and ad in tangential,
               bool(pairs) and all((ad, r) in pair_tangential for r in pairs))
        for g in groups:
            if g[0] == key:
                g[1].extend(part)
                break
        else:
            groups.append((key, list(part)))
    return [regenerate_command(part, out, key[4], key[5]) for key, part in groups]


def write_table(path: str, calibrations: Sequence[SqueezeCalibration], fits: Sequence[Dict],
                tables: Sequence[List[tuple]], command: str, tangential: Sequence[Dict] = (),
                pair_tangential: Sequence[Dict] = ()) -> None:
    """The text table CalibratedSubgridModel reads (dem/resistance/src/subgrid_calibration.cpp): per
    calibration its fit and its rows (SqueezeCalibration.fit, .table), then the tangential wall blocks
    of the wallcalibration summaries `tangential` and the pair blocks of the pairtangential summaries
    `pair_tangential` (with their fits and rows: pairtangential.add_fits)."""
    with open(path, "w") as f:
        f.write("# Sub-grid calibration of the fictitious-domain solver (paper Appendix B; docs/resistance.md)\n")
        f.write("# pair, wall: s_hat(xi) = 1/V_th - 1/V_FDM, the squeeze resistance the sub-grid block adds, in units\n")
        f.write("# of 6 pi eta a1 (a1 the smaller sphere). pair: X21A^SG = -6 pi a1 s_hat; wall: X^A_SG = 6 pi a s_hat.\n")
        f.write("# Block header: kind a1/Delta a2/a1 rows r_0 r_inf xi_1 p fit_rms; then rows: xi  xi*s_hat\n")
        f.write("# wall_YA, wall_YB, wall_YC, wall_XC (scripts/fdmsubgrid/wallcalibration.py): s_hat the sub-grid\n")
        f.write("# function in Kim-Karrila units (6 pi a, 4 pi a^2, 8 pi a^3, 8 pi a^3; d into the wall);\n")
        f.write("# header: kind a/Delta 1 rows f_0 eps_c p fit_rms; rows: eps  eps*s_hat\n")
        f.write("# pair_K11, pair_K12, pair_K22, pair_Ktw (scripts/fdmsubgrid/pairtangential.py): K on the pair's\n")
        f.write("# internal modes (sliding q1, rolling q2, twist) in units of eta a1, eta a1^2, eta a1^3, eta a1^3, for\n")
        f.write("# sphere 1 the smaller one; header: kind a1/Delta a2/a1 rows xi_c p fit_rms; rows: xi  xi*K\n")
        commands = regenerate_commands(calibrations, project_relative(path), [t["a_over_delta"] for t in tangential],
                                       [(t["a_over_delta"], t["ratio"]) for t in pair_tangential])
        for k, line in enumerate(commands):
            f.write("# Regenerate: %s\n" % line if k == 0 else "#   and: %s\n" % line)
        if len(commands) > 1:
            f.write("# (measured in parts: their measurements analysed together with --from-raw, "
                    "--tangential-from-raw, --pair-tangential-from-raw)\n")
        elif "from-raw" in command:
            f.write("# (this file was analysed from the measurements kept by earlier calls: --from-raw, "
                    "--tangential-from-raw, --pair-tangential-from-raw)\n")
        for c, fit, rows in zip(calibrations, fits, tables):
            write_block(f, c, fit, rows)
        for t in tangential:
            blocks = wallcalibration.table_blocks(t["a_over_delta"], t["fits"])
            for name in wallcalibration.FUNCTIONS:
                fit = t["fits"][name]
                f.write("wall_%s %.6g 1 %d %.6g %.6g %.6g %.4g\n" % (name, t["a_over_delta"], len(blocks[name]),
                                                                   fit["f_0"], fit["eps_c"], fit["p"], fit["rms"]))
                for eps, v in blocks[name]:
                    f.write("%.8e %.8e\n" % (eps, v))
        for t in pair_tangential:
            for fit in t["fits"]:
                rows = t["table"][fit["element"]]
                f.write("pair_%s %.6g %.6g %d %.6g %.6g %.4g\n" % (fit["element"], t["a_over_delta"], t["ratio"],
                                                                len(rows), fit["xi_c"], fit["p"], fit["rms"]))
                for xi, v in rows:
                    f.write("%.8e %.8e\n" % (xi, v))


def table_blocks(path: str) -> Dict[tuple, List[str]]:
    """The blocks of a calibration table (write_table's format) as their lines, header first, keyed by (kind,
    a/Delta, ratio); comments and blank lines left out."""
    with open(path) as f:
        lines = [ln for ln in f if ln.strip() and not ln.startswith("#")]
    blocks: Dict[tuple, List[str]] = {}
    k = 0
    while k < len(lines):
        head = lines[k].split()
        try:
            n = int(head[3])
            key = (head[0], float(head[1]), float(head[2]))
        except (IndexError, ValueError):
            raise ValueError("%s: '%s' is not a block header (kind a/Delta ratio rows ...)" % (path, lines[k].strip()))
        blocks[key] = lines[k:k + 1 + n]
        k += 1 + n
    return blocks


def read_table(path: str) -> Dict[tuple, tuple]:
    """The blocks of a calibration table (write_table's format): {(kind, a/Delta, ratio): (header floats
    after the row count, rows as an (n, 2) array of xi and xi * s_hat)}. An interpolated block's header
    (subgridinterp.py) has the word `interpolated` instead of the fit's numbers: its header floats are []."""
    blocks = {}
    for key, lines in table_blocks(path).items():
        head = lines[0].split()
        rows = np.array([[float(x) for x in ln.split()] for ln in lines[1:]])
        blocks[key] = ([] if INTERPOLATED in head[4:] else [float(x) for x in head[4:]], rows)
    return blocks


# the word an interpolated block's header line carries after its row count (the resistance library reads
# the first four words of a header only)
INTERPOLATED = "interpolated"


def write_block(f, c: SqueezeCalibration, fit: Dict[str, float], rows: List[tuple]) -> None:
    f.write("%s %.6g %.6g %d %.6g %.6g %.6g %.6g %.4g\n" % (c.kind, c.a_over_delta, c.ratio, len(rows), fit["r_0"],
                                                        fit["r_inf"], fit["xi_1"], fit["p"], fit["rms_rel"]))
    for xi, v in rows:
        f.write("%.8e %.8e\n" % (xi, v))


def summary(c: SqueezeCalibration, fit: Dict[str, float], table: List[tuple]) -> Dict:
    """What the .json beside the table keeps of one calibration."""
    v_inf = c.velocity_inf()
    v_th = c.theory()
    return dict(kind=c.kind, a_over_delta=c.a_over_delta, ratio=c.ratio, gaps=c.gaps, boxes=c.boxes,
                velocities=c.velocities, velocity_inf=v_inf.tolist(), velocity_theory=v_th.tolist(),
                spread=c.spread().tolist(), fit=fit,
                correction=[c.correction(g, fit) for g in c.gaps], xi_max=table[-1][0],
                wall_seconds=c.wall_seconds)


def plot(path: str, summaries: Sequence[Dict]) -> None:
    """Figs. B.24-B.25 for the squeeze: theory, measured FDM resistance (each box, extrapolated) and fit."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    # one row per a1/Delta, one column per (kind, ratio)
    rows = sorted({s["a_over_delta"] for s in summaries})
    cols = sorted({(s["kind"], s["ratio"]) for s in summaries}, key=lambda kr: (kr[0] == "wall", kr[1]))
    fig, axes = plt.subplots(len(rows), len(cols), figsize=(4.2 * len(cols), 3.6 * len(rows)), squeeze=False)
    used = {(rows.index(s["a_over_delta"]), cols.index((s["kind"], s["ratio"]))) for s in summaries}
    for i, j in np.ndindex(axes.shape):
        if (i, j) not in used:
            axes[i][j].axis("off")      # a table measured in parts: no block of this kind at this a1/Delta
    for s in summaries:
        ax = axes[rows.index(s["a_over_delta"])][cols.index((s["kind"], s["ratio"]))]
        gaps = np.array(s["gaps"])
        fine = np.logspace(-4, 0, 60)
        ax.loglog(fine, [1 / theory_velocity(s["kind"], s["ratio"], round_gap(g)) for g in fine], "k-", label="theory")
        for L in s["boxes"]:
            v = np.array(s["velocities"]["%g" % L])
            ax.errorbar(gaps, 1 / v.mean(axis=0), yerr=[1 / v.min(axis=0) - 1 / v.mean(axis=0),
                                                        1 / v.mean(axis=0) - 1 / v.max(axis=0)][::-1],
                        fmt="x", ms=4, label="FDM, L = %g a1" % L)
        ax.loglog(gaps, 1 / np.array(s["velocity_inf"]), "^", label="FDM, L → ∞")
        f = s["fit"]
        ax.loglog(fine, fitted_curve(fine, f), "-", color="C3", label="fit")
        ax.set_xlabel(r"$\xi$" if s["kind"] == "pair" else r"$\varepsilon$")
        ax.set_ylabel(r"squeeze resistance / $6\pi\eta a_1$")
        ax.set_title("%s, a1/Δ = %g%s" % (s["kind"], s["a_over_delta"],
                                          ", a2/a1 = %g" % s["ratio"] if s["kind"] == "pair" else ""), fontsize=9)
        ax.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def position_errors(path: str) -> List[Dict]:
    """For each calibration in the .json beside a table: per gap the theory's velocity (units F/(6 pi eta a1)),
    the calibrated model's error of it averaged over the measured positions, its standard deviation and the
    worst position's (`corrected_errors`), and the floor (`position_floor`)."""
    with open(path) as f:
        summaries = json.load(f)
    out = []
    for s in summaries:
        cal = SqueezeCalibration(s["kind"], s["a_over_delta"], s["ratio"], s["gaps"], s["boxes"], s["velocities"])
        err = cal.corrected_errors(s["fit"])
        worst = err[np.abs(err).argmax(axis=0), np.arange(len(cal.gaps))]
        out.append(dict(kind=cal.kind, a_over_delta=cal.a_over_delta, ratio=cal.ratio, gaps=cal.gaps,
                        positions=len(err), theory=cal.theory().tolist(), mean=err.mean(axis=0).tolist(),
                        std=err.std(axis=0).tolist(), worst=worst.tolist(), floor=cal.position_floor().tolist()))
    return out


def print_position_errors(path: str) -> None:
    """`position_errors` as a text table, in %."""
    for e in position_errors(path):
        print("%s a1/Delta %g a2/a1 %g (%d positions), error in %%" % (e["kind"], e["a_over_delta"], e["ratio"],
                                                                      e["positions"]))
        print("  gap            " + " ".join("%6.3g" % g for g in e["gaps"]))
        for name in ("mean", "worst", "floor"):
            print("  %-14s " % name + " ".join("%+6.1f" % (100 * v) if name != "floor" else "%6.1f" % (100 * v)
                                               for v in e[name]))


def coverage(radii: Sequence[float], a_over_delta: float, walls: bool = False) -> list:
    """For each species pair of a scene of these radii at a1/Delta = a_over_delta (a1 the smallest radius;
    with walls also each radius against a wall): `calibrated` (in the table), `interpolated` (within 2 %
    as measured on held-back blocks) or `refused`, with the interpolation's measured error, the command
    that would measure the pair directly and its estimated core-seconds (subgridinterp.coverage,
    subgridinterp.PairCoverage)."""
    from . import subgridinterp
    return subgridinterp.coverage(radii, a_over_delta, walls)


def main(argv: Sequence[str] | None = None) -> List[Dict]:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--a-over-delta", type=float, nargs="+", default=[3.0, 4.0, 5.0])
    p.add_argument("--ratios", type=float, nargs="+", default=[1.0, 1.4], help="a2/a1 of the pairs (>= 1)")
    p.add_argument("--no-wall", action="store_true", help="measure the pairs only")
    p.add_argument("--no-pairs", action="store_true", help="measure the wall only")
    p.add_argument("--boxes", type=float, nargs=2, default=list(BOXES), help="the two box sizes L/a1")
    p.add_argument("--offsets", type=int, default=len(OFFSETS), help="positions in the cell averaged (1-4)")
    p.add_argument("--workdir", default="calibration_runs")
    p.add_argument("--out", help="the table (text); its .json beside it holds every measurement")
    p.add_argument("--cache", action="store_true", help="instead of --out: the table in a folder of its own under "
                   "the calibrations measured on demand (FDM_CALIBRATIONS, default calibrations/ in the project), "
                   "where every later scene finds it (subgridinterp.measured_blocks)")
    p.add_argument("--position-errors", metavar="JSON", help="no run: from the measurements beside a table "
                   "(squeeze_calibration.json), per gap the calibrated model's error averaged over the measured "
                   "positions in the cell and at the worst one, and the floor no correction of the gap alone "
                   "can pass there")
    p.add_argument("--from-raw", metavar="RAW_JSON", nargs="+", help="analyse the measurements earlier calls "
                   "kept (<workdir>/measurements.json, or the .json beside a table) instead of running")
    p.add_argument("--tangential", action="store_true", help="also measure the tangential wall functions "
                   "(wallcalibration.py) at every --a-over-delta")
    p.add_argument("--tangential-from-raw", metavar="JSON", nargs="+", help="the tangential wall measurements of "
                   "earlier runs (wall_tangential_calibration.json beside a table, or wallcalibration --out)")
    p.add_argument("--pair-tangential", action="store_true", help="also measure the pairs' sliding, rolling and "
                   "twist (pairtangential.py) at every --a-over-delta and --ratios")
    p.add_argument("--pair-tangential-from-raw", metavar="JSON", nargs="+", help="the tangential pair measurements "
                   "of earlier runs (pair_tangential_calibration.json beside a table, or pairtangential --out)")
    p.add_argument("--interpolate", action="store_true", help="no run: the shipped table with the blocks it lacks "
                   "for --a-over-delta x --ratios (and the walls at each a/Delta unless --no-wall; with "
                   "--no-pairs the walls only) interpolated from the measured ones (subgridinterp.py), in --out")
    p.add_argument("--max-error", type=float, default=0.02, help="with --interpolate: write only the blocks whose "
                   "interpolation error, measured on held-back blocks in the same situation, is within this "
                   "(default 0.02; inf also writes those no held-back test reaches)")
    p.add_argument("--interpolation-errors", action="store_true", help="no run: the interpolation's error on "
                   "every held-back block (each shipped block from the others, and the direct calibrations kept "
                   "out of the table), per gap, averaged over the positions in the cell")
    args = p.parse_args(argv)
    if args.interpolation_errors:
        from . import subgridinterp
        subgridinterp.print_errors()
        return []
    if args.interpolate:
        if not args.out:
            p.error("--interpolate needs --out")
        from . import subgridinterp
        targets = (([] if args.no_pairs else [("pair", ad, r) for ad in args.a_over_delta for r in args.ratios])
                   + ([] if args.no_wall else [("wall", ad, 1.0) for ad in args.a_over_delta]))
        done = subgridinterp.write_interpolated(args.out, targets, max_error=args.max_error)
        for d in done:
            print("%s a1/Delta %g a2/a1 %g: %s%s%s" % (
                d["kind"], d["a_over_delta"], d["ratio"], d["status"],
                "" if "error" not in d else ", held-back error %s" % (
                    "not measured this far outside" if d["error"] is None else "%.1f %%" % (100 * d["error"])),
                "" if "command" not in d else " (beyond --max-error %g; measure it: %s)" % (args.max_error, d["command"])))
        return done
    if args.position_errors:
        print_position_errors(args.position_errors)
        return []
    # what a measuring call measures, in order: (kind, a1/Delta, a2/a1)
    jobs = [(kind, ad, ratio) for ad in args.a_over_delta
            for kind, ratio in (([] if args.no_pairs else [("pair", r) for r in args.ratios])
                                + ([] if args.no_wall else [("wall", 1.0)]))]
    if args.cache:
        if args.out or args.from_raw:
            p.error("--cache measures and keeps its own table: not with --out or --from-raw")
        from . import subgridinterp
        folder = os.path.join(subgridinterp.measured_folder(), subgridinterp.measured_name(jobs))
        args.out = os.path.join(folder, subgridinterp.MEASURED_TABLE)
        if os.path.exists(args.out):
            p.error("--cache: %s holds this measurement already (remove its folder to measure it again)" % args.out)
        os.makedirs(folder, exist_ok=True)
        print("calibration: the table goes to %s, where later scenes find it" % args.out, flush=True)
    if not args.out:
        p.error("--out is required (or --position-errors, --cache)")
    if any(r < 1 for r in args.ratios):
        p.error("--ratios: a2/a1 must be >= 1 (a pair 1/1.4 is the pair 1.4 seen from the other sphere)")
    os.makedirs(args.workdir, exist_ok=True)
    raw_path = os.path.join(args.workdir, "measurements.json")
    cals: List[SqueezeCalibration] = []
    if args.from_raw:
        keys = SqueezeCalibration.__dataclass_fields__.keys()
        for path in args.from_raw:
            with open(path) as f:
                cals += [SqueezeCalibration(**{k: v for k, v in d.items() if k in keys}) for d in json.load(f)]
    else:
        from . import subgridinterp
        model = subgridinterp.cost_model([b.summary for b in subgridinterp.load_blocks()])
        for kind, ad, ratio in jobs:
            print("calibration: %s a1/Delta %g%s: about %.0f core-seconds (the squeeze; estimated from the shipped "
                  "calibrations' run times)" % (kind, ad, " a2/a1 %g" % ratio if kind == "pair" else "",
                                                subgridinterp.estimated_core_seconds(kind, ad, ratio, model)),
                  flush=True)
        for kind, ad, ratio in jobs:
            cals.append(measure(kind, ad, ratio, args.workdir, boxes=args.boxes, offsets=OFFSETS[:args.offsets]))
            files.write_json(raw_path, [c.__dict__ for c in cals], indent=None)   # kept before any analysis
    fits = [c.fit() for c in cals]
    tables = [c.table(fit) for c, fit in zip(cals, fits)]
    summaries = [summary(c, fit, table) for c, fit, table in zip(cals, fits, tables)]
    for c, s in zip(cals, summaries):
        fit = s["fit"]
        print("%s a1/Delta %g a2/a1 %g: %.0f s, fit r_0 %.4f xi_1 %.4f p %.3f (rms %.2f %%, max %.2f %%), "
              "correction up to xi %.3g" % (c.kind, c.a_over_delta, c.ratio, c.wall_seconds, fit["r_0"], fit["xi_1"],
                                            fit["p"], 100 * fit["rms_rel"], 100 * fit["max_rel"], s["xi_max"]),
              flush=True)
    tangential: List[Dict] = []
    if args.tangential_from_raw:
        for path in args.tangential_from_raw:
            with open(path) as f:
                tangential += [wallcalibration.summary(wallcalibration.from_summary(d)) for d in json.load(f)]
    elif args.tangential:
        for ad in args.a_over_delta:
            tangential.append(wallcalibration.summary(wallcalibration.measure(
                ad, args.workdir, offsets=wallcalibration.OFFSETS[:args.offsets])))
            files.write_json(os.path.join(args.workdir, "wall_tangential.json"), tangential,
                             indent=None)   # kept before the table
    pair_tangential: List[Dict] = []
    if args.pair_tangential_from_raw:
        for path in args.pair_tangential_from_raw:
            with open(path) as f:
                pair_tangential += [pairtangential.summarize(s["ratio"], s["a_over_delta"], s["gaps"], s["boxes"],
                                                             s["offsets"], s["raw"], s["wall_seconds"])
                                    for s in json.load(f)]
    elif args.pair_tangential:
        for ad in args.a_over_delta:
            for ratio in args.ratios:
                pair_tangential.append(pairtangential.measure(ratio, ad, args.workdir,
                                                              offsets=pairtangential.OFFSETS[:args.offsets]))
                files.write_json(os.path.join(args.workdir, "pair_tangential.json"), pair_tangential,
                                 indent=None)   # kept before the table
    pair_tangential = [pairtangential.add_fits(s) for s in pair_tangential]
    command = "python3 -m fdmsubgrid.calibration " + " ".join(argv if argv is not None else sys.argv[1:])
    write_table(args.out, cals, fits, tables, command, tangential, pair_tangential)
    if pair_tangential:
        p_path = os.path.join(os.path.dirname(os.path.abspath(args.out)), "pair_tangential_calibration.json")
        with open(p_path, "w") as f:
            json.dump(pair_tangential, f, indent=1)
        pairtangential.plot(os.path.splitext(p_path)[0] + ".png", pair_tangential)
    if tangential:
        t_path = os.path.join(os.path.dirname(os.path.abspath(args.out)), "wall_tangential_calibration.json")
        with open(t_path, "w") as f:
            json.dump(tangential, f, indent=1)
        wallcalibration.plot(os.path.splitext(t_path)[0] + ".png", tangential)
    json_path = os.path.join(os.path.dirname(os.path.abspath(args.out)), "squeeze_calibration.json")
    with open(json_path, "w") as f:
        json.dump(summaries, f, indent=1)
    plot(os.path.splitext(json_path)[0] + ".png", summaries)
    return summaries


if __name__ == "__main__":
    main()
