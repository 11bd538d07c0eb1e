"""The solver's own tangential pair resistance (paper section 2.2 and Appendix B): what fdmFoam resolves of
the internal modes of two spheres other than the squeeze, and the sub-grid correction R_SG = R_th - R_FDM
that would make the coupled resistance the theory's. The squeeze is calibrated by calibration.py; the wall
functions by wallcalibration.py. This module measures the pair's other internal modes, fits them and
writes the rows of the table's pair_K11, pair_K12, pair_K22 and pair_Ktw blocks (calibration.py
--pair-tangential puts them in the table CalibratedSubgridModel reads).

The internal modes. With Appendix C.2's relations the pair's sub-grid block is R_SG = P^T K P exactly, K
acting on six internal modes (checked with the resistance library to 1e-15; docs/resistance.md): for the
line of centres d (from sphere 1 to sphere 2, r = |x2 - x1|) and a transverse direction e, n = d x e,

    squeeze  (U1 - U2).d                           twist  (W1 - W2).d
    q1 = (U1 - U2).e + (r/2)(W1 + W2).n            q2 = (W1 - W2).n       (per transverse direction)

A rigid motion of the pair leaves all six at zero. Their conjugate loads are self-equilibrated (no net
force or moment): Q1 is the force pair +-Q e on spheres 1 and 2 with the torque (r/2) Q n on each, Q2 the
torque couple +-Q n, the twist the torque couple +-T d. The responses q to loads Q give the internal
mobility M (2 x 2 per transverse direction, a scalar for the twist), of the solver (measured) and of the
theory (P R_th^-1 P^T with the full-range two-sphere functions), and the correction on these modes is
K = M_th^-1 - M_FDM^-1 (Sherman-Morrison/Woodbury: the coupled solver's internal resistance is its own
plus K).

What is run. Spheres of radii 1 and `ratio` along x in a periodic cube, the sub-grid lubrication off, all
loads at once: Q1 along y (force pair and torques about z), Q2 along z (the torque couple about -y, i.e.
the y case turned by 90 degrees about d: its responses U_z and -W_y stand for U_y and W_z), and the twist
about x. In the continuous problem the three decouple by symmetry. Each gap is one coupled step with the
spheres held (quasi-static), largest gap first; the centre of the gap sits at `offset` inside its cell;
two box sizes are extrapolated as M_inf + c L^-3 (the loads are self-equilibrated: their far field
decays like a force dipole's, as the squeeze's).

    python3 -m fdmsubgrid.pairtangential --a-over-delta 3 --ratio 1 --out runs/pair_tangential.json
"""
from __future__ import annotations

import argparse
import functools
import json
import math
import os
import time
from typing import Dict, List, Sequence

import numpy as np

from . import deminput, files, foamcase, runner, squeeze, theory
from .squeeze import pair_centres
from .wallcalibration import seen_gap

GAPS = [1.0, 0.7, 0.5, 0.3, 0.2, 0.15, 0.1, 0.07, 0.05, 0.03, 0.02, 0.01, 3e-3, 1e-3, 1e-4]
OFFSETS = [(0.1, 0.2, 0.3), (0.35, 0.45, 0.55), (0.6, 0.7, 0.8), (0.85, 0.95, 0.05)]
BOXES = (8.0, 12.0)
FORCE = 6 * math.pi          # eta = a1 = 1
TORQUE = 8 * math.pi


def separation(ratio: float, xi: float) -> float:
    """r = |x2 - x1| at the reduced gap xi = 2r/(a1 + a2) - 2."""
    return (1.0 + ratio) / 2 * (2 + xi)


def loads(r: float) -> Dict[str, np.ndarray]:
    """Force and torque on each sphere (rows: sphere 1, sphere 2; [Fx Fy Fz Tx Ty Tz]) of the three
    loads at once for the separation r: Q1 = FORCE along y, Q2 = TORQUE about -y, twist TORQUE about x."""
    q1, q2, tw = FORCE, TORQUE, TORQUE
    s1 = np.array([0, q1, 0, tw, -q2, 0.5 * r * q1])
    s2 = np.array([0, -q1, 0, -tw, q2, 0.5 * r * q1])
    return dict(sphere1=s1, sphere2=s2)


def _load_lines(r: float) -> List[str]:
    """The LIGGGHTS fixes of the three loads at separation r (groups one, two defined)."""
    load = loads(r)
    lines = []
    for name, group, s in (("1", "one", load["sphere1"]), ("2", "two", load["sphere2"])):
        lines.append("fix             push%s %s addforce %r %r %r" % (name, group, *map(float, s[:3])))
        lines.append("fix             turn%s %s fdm/torque %r %r %r" % (name, group, *map(float, s[3:])))
    return lines


def run_loaded_pair(workdir: str, ratio: float, xis: Sequence[float], a_over_delta: float, L_over_a: float,
                    offset: Sequence[float], tol_lambda: float = 1e-5, np_fluid: int = 1, keep: bool = False,
                    model: str | None = None, stresslets: bool = False) -> dict:
    """The loaded pair at the gaps `xis` (largest first, each one coupled step warm-started from the
    previous) in a periodic cube of side L_over_a a1; returns dict(U1, W1, U2, W2: per gap [x, y, z],
    wall_seconds, inner_iterations, converged). The torques' moment arm r/2 changes with the gap: the
    fixes are redefined before each step. Kept as <run folder>.json: a later call with the same scene and
    gaps reads it (a killed measurement resumes). `model` None: the solver alone (lubrication off, the
    measurement); 'calibrated' or 'cutoff': the coupled solver with that sub-grid model (the validation).
    With `stresslets` (fix fdm/couple ... stresslets yes, the records of fix fdm/output read) also S1, S2:
    per gap each sphere's stresslet S_fluid + S_subgrid (xx xy xz yy yz zz as recorded: Kim-Karrila's S,
    of the particle on the fluid; pairshearstresslet.py)."""
    run_dir = os.path.join(workdir, "lambda%g_ad%g_L%g_off%g_%g_%g" % (ratio, a_over_delta, L_over_a, *offset)
                           + ("" if model is None else "_" + model) + ("_stresslets" if stresslets else ""))
    kept = squeeze.kept_result(run_dir, xis, tol_lambda)
    if kept is not None:
        return kept
    squeeze._fresh_run_dir(workdir, os.path.basename(run_dir))
    delta = 1.0 / a_over_delta
    L = L_over_a
    box = foamcase.Box((0, 0, 0), (L, L, L), delta)
    centre = [L / 2 + o * delta for o in offset]
    foamcase.write_fluid_case(os.path.join(run_dir, "fluid"), box, nu=1.0, rho=1.0, tol_lambda=tol_lambda, n_max=3000,
                          n_particles=2)
    runs: List[str] = []
    for k, xi in enumerate(xis):
        if k > 0:
            runs += ["unfix           push1", "unfix           turn1", "unfix           push2", "unfix           turn2"]
            runs += ["set             atom %d x %r y %r z %r" % (i + 1, *map(float, c))
                     for i, c in enumerate(pair_centres(ratio, xi, centre))]
        runs += _load_lines(separation(ratio, xi))
        runs.append("run             1")
    if stresslets:
        runs = [deminput.RECORD_EVERY_STEP] + runs
    p1, p2 = pair_centres(ratio, xis[0], centre)
    deminput.write_dem_input(os.path.join(run_dir, "dem"), box, [p1 + (1.0,), p2 + (ratio,)], dt=1.0,
                         fix_options="move no stresslets yes" if stresslets else "move no",
                         pair_style="fdm/subgrid " + ("lubrication no" if model is None else "model " + model),
                         before_run="group           one id 1\ngroup           two id 2", runs=runs,
                         name="in.pairTangential")
    wall, parts, steps = runner.run_and_read(run_dir, np_fluid=np_fluid, keep=keep)
    out: Dict[str, object] = {}
    for tag, k in ((1, "1"), (2, "2")):
        sel = parts["tag"] == tag
        out["U" + k] = np.column_stack([parts[c][sel] for c in ("Ux", "Uy", "Uz")]).tolist()
        out["W" + k] = np.column_stack([parts[c][sel] for c in ("Wx", "Wy", "Wz")]).tolist()
    out.update(wall_seconds=wall, inner_iterations=[int(n) for n in steps["innerIterations"]],
               converged=bool(steps["converged"].all()), gaps=[float(x) for x in xis], tol_lambda=tol_lambda)
    if stresslets:
        n = len(xis)
        records, _ = runner.read_held_steps(run_dir, n, "pairtangential.run_loaded_pair")
        total = np.asarray(records["S_fluid"][-n:], dtype=float) + np.asarray(records["S_subgrid"][-n:], dtype=float)
        out.update(S1=total[:, 0].tolist(), S2=total[:, 1].tolist())
    squeeze.keep_result(run_dir, out)
    return out


def internal_mobility(result: dict, ratio: float) -> np.ndarray:
    """Per gap [M11, M12, M21, M22, M_twist] of the measured internal modes (module docstring): column 1
    from the Q1 load along y, column 2 from the Q2 load along z read in the turned frame."""
    U1, W1, U2, W2 = (np.asarray(result[k]) for k in ("U1", "W1", "U2", "W2"))
    r = np.array([separation(ratio, xi) for xi in result["gaps"]])
    # y block: q1 = (U1 - U2)_y + r/2 (W1 + W2)_z, q2 = (W1 - W2)_z
    q1_from_Q1 = (U1[:, 1] - U2[:, 1]) + 0.5 * r * (W1[:, 2] + W2[:, 2])
    q2_from_Q1 = W1[:, 2] - W2[:, 2]
    # z block turned: U_y -> U_z, W_z -> -W_y
    q1_from_Q2 = (U1[:, 2] - U2[:, 2]) - 0.5 * r * (W1[:, 1] + W2[:, 1])
    q2_from_Q2 = -(W1[:, 1] - W2[:, 1])
    twist = W1[:, 0] - W2[:, 0]
    return np.column_stack([q1_from_Q1 / FORCE, q1_from_Q2 / TORQUE, q2_from_Q1 / FORCE, q2_from_Q2 / TORQUE,
                            twist / TORQUE])


def _levi_civita_dot(d: np.ndarray) -> np.ndarray:
    e = np.zeros((3, 3, 3))
    e[0, 1, 2] = e[1, 2, 0] = e[2, 0, 1] = 1
    e[0, 2, 1] = e[2, 1, 0] = e[1, 0, 2] = -1
    return np.einsum("ijk,k->ij", e, d)


def theory_matrix(ratio: float, xi: float) -> np.ndarray:
    """The 12 x 12 two-sphere resistance (eta = 1, a1 = 1, d = e_x; F = -R U, order U1 W1 U2 W2) from the
    full-range functions of `fdmResistance pair --theory --full` (Jeffrey & Onishi; same convention as
    `fdmResistance matrix`, checked to 1e-13 with the near-field forms)."""
    f = theory.pair_full_range(1.0, ratio, xi)
    d = np.array([1.0, 0.0, 0.0])
    dd, eye, ed = np.outer(d, d), np.eye(3), _levi_civita_dot(d)
    R = np.zeros((12, 12))
    for a in range(2):
        for b in range(2):
            s = "%d%d" % (a + 1, b + 1)
            R[6 * a:6 * a + 3, 6 * b:6 * b + 3] = f["XA" + s] * dd + f["YA" + s] * (eye - dd)
            R[6 * a:6 * a + 3, 6 * b + 3:6 * b + 6] = (f["YB%d%d" % (b + 1, a + 1)] * ed).T
            R[6 * a + 3:6 * a + 6, 6 * b:6 * b + 3] = f["YB" + s] * ed
            R[6 * a + 3:6 * a + 6, 6 * b + 3:6 * b + 6] = f["XC" + s] * dd + f["YC" + s] * (eye - dd)
    return R


def theory_mobility(ratio: float, xi: float) -> np.ndarray:
    """[M11, M12, M21, M22, M_twist] of the theory: P R_th^-1 P^T."""
    P = mode_matrix(separation(ratio, xi))[[2, 3, 1]]     # q1, q2 along y and the twist
    M = P @ np.linalg.solve(theory_matrix(ratio, xi), P.T)
    return np.array([M[0, 0], M[0, 1], M[1, 0], M[1, 1], M[2, 2]])


def internal_resistance(m: np.ndarray) -> np.ndarray:
    """Per row of [M11, M12, M21, M22, M_twist] the internal resistance [R11, R12, R22, R_twist]: the
    inverse of the symmetrised 2 x 2 (the solver's operator need not be exactly reciprocal) and 1/M_twist."""
    out = []
    for m_row in np.atleast_2d(m):
        off = 0.5 * (m_row[1] + m_row[2])
        r = np.linalg.inv(np.array([[m_row[0], off], [off, m_row[3]]]))
        out.append([r[0, 0], r[0, 1], r[1, 1], 1 / m_row[4]])
    return np.array(out)


def correction(m_th: np.ndarray, m_fdm: np.ndarray) -> np.ndarray:
    """K = M_th^-1 - M_FDM^-1 on the internal modes: [K11, K12, K22, K_twist] (the 2 x 2 symmetrised)."""
    return internal_resistance(m_th) - internal_resistance(m_fdm)


def mode_matrix(r: float) -> np.ndarray:
    """P (6 x 12) of all six internal modes for d = e_x: squeeze, twist, and (q1, q2) along y and z."""
    P = np.zeros((6, 12))
    P[0, 0], P[0, 6] = 1, -1                                        # squeeze (U1 - U2).d
    P[1, 3], P[1, 9] = 1, -1                                        # twist (W1 - W2).d
    P[2, 1], P[2, 7], P[2, 5], P[2, 11] = 1, -1, r / 2, r / 2      # e = e_y, n = e_z
    P[3, 5], P[3, 11] = 1, -1
    P[4, 2], P[4, 8], P[4, 4], P[4, 10] = 1, -1, -r / 2, -r / 2    # e = e_z, n = -e_y
    P[5, 4], P[5, 10] = -1, 1
    return P


def model_correction(ratio: float, xi: float, delta: float) -> tuple:
    """([K11, K12, K22, K_twist], residual): the internal-mode matrix K of the sub-grid block the pair
    style builds (`fdmResistance matrix --delta`, the cut-off model) at xi, and |R_SG - P^T K P| / |R_SG|,
    which is zero (to rounding) when the block acts on the internal modes only."""
    r = separation(ratio, xi)
    R = np.array(theory.resistance("matrix", "--x1", 0, 0, 0, "--x2", "%.17g" % r, 0, 0, "--a1", 1, "--a2", ratio,
                                   "--delta", "%.17g" % delta)["R"])
    P = mode_matrix(r)
    G = np.linalg.inv(P @ P.T)
    K = G @ P @ R @ P.T @ G
    residual = float(np.linalg.norm(R - P.T @ K @ P) / max(np.linalg.norm(R), 1e-300))
    return np.array([K[2, 2], K[2, 3], K[3, 3], K[1, 1]]), residual


def run_scenes(ratio: float, a_over_delta: float, workdir: str, gaps: Sequence[float], boxes: Sequence[float],
               offsets: Sequence[Sequence[float]], tol_lambda: float, model: str | None = None) -> Dict[str, List[dict]]:
    """Every offset in the first box, the first offset in the second (run_loaded_pair, `model` as there):
    the raw results by box ("%g" % L); a step that did not converge stops it."""
    raw: Dict[str, List[dict]] = {}
    for k, L in enumerate(boxes):
        raw["%g" % L] = []
        for off in (offsets if k == 0 else offsets[:1]):
            res = run_loaded_pair(workdir, ratio, gaps, a_over_delta, L, off, tol_lambda, model=model)
            if not res["converged"]:
                raise RuntimeError("pair tangential: ratio %g a/Delta %g L %g offset %s: a step did not converge"
                                   % (ratio, a_over_delta, L, off))
            raw["%g" % L].append(res)
            print("pair tangential: ratio %g a/Delta %g L %g offset %s%s done (%.0f s)"
                  % (ratio, a_over_delta, L, off, "" if model is None else ", model " + model, res["wall_seconds"]),
                  flush=True)
    return raw


def extrapolated_mobility(raw: Dict[str, List[dict]], ratio: float, boxes: Sequence[float]) -> tuple:
    """(M, mobilities by box): the offset-averaged mobility in the first box plus the box correction
    M_inf - M(L1) of the first offset, M = M_inf + c L^-3."""
    by_box = {L: [internal_mobility(res, ratio) for res in runs] for L, runs in raw.items()}
    L1, L2 = boxes
    first, second = by_box["%g" % L1][0], by_box["%g" % L2][0]
    box_correction = squeeze.extrapolate_box(first, second, L1, L2) - first
    return np.mean(by_box["%g" % L1], axis=0) + box_correction, by_box


def measure(ratio: float, a_over_delta: float, workdir: str, gaps: Sequence[float] = GAPS,
            boxes: Sequence[float] = BOXES, offsets: Sequence[Sequence[float]] = OFFSETS,
            tol_lambda: float = 1e-5) -> Dict:
    """The solver alone (run_scenes); the summary the JSON keeps."""
    t0 = time.time()
    raw = run_scenes(ratio, a_over_delta, workdir, gaps, boxes, offsets, tol_lambda)
    return summarize(ratio, a_over_delta, list(gaps), list(boxes), [list(o) for o in offsets], raw,
                     sum(r["wall_seconds"] for runs in raw.values() for r in runs) or time.time() - t0)


def summarize(ratio: float, a_over_delta: float, gaps: List[float], boxes: List[float], offsets: List[List[float]],
              raw: Dict[str, List[dict]], wall_seconds: float) -> Dict:
    """Mobilities (extrapolated_mobility), the theory's, the scatter over offsets and the correction K."""
    m_fdm, by_box = extrapolated_mobility(raw, ratio, boxes)
    m_th = np.array([theory_mobility(ratio, xi) for xi in gaps])
    cells = np.array(by_box["%g" % boxes[0]])
    spread = np.ptp(cells, axis=0) / np.abs(np.mean(cells, axis=0))
    cutoff = np.array([model_correction(ratio, xi, 1 / a_over_delta)[0] for xi in gaps])
    return dict(ratio=ratio, a_over_delta=a_over_delta, gaps=gaps, boxes=boxes, offsets=offsets,
                mobility_fdm=m_fdm.tolist(), mobility_theory=m_th.tolist(),
                mobility_by_box={k: v[0].tolist() for k, v in by_box.items()}, offset_spread=spread.tolist(),
                correction=correction(m_th, m_fdm).tolist(), cutoff_correction=cutoff.tolist(), raw=raw,
                wall_seconds=wall_seconds)


ELEMENTS = ("K11", "K12", "K22", "Ktw")   # the table's kinds are pair_K11, ...: sliding, coupling, rolling, twist


@functools.lru_cache(maxsize=None)
def _theory_resistance_splines(ratio: float) -> tuple:
    """The theory's [R11, R12, R22, R_twist] as cubic splines in ln xi, xi = 1e-6 ... 3 (36 gaps: one
    `fdmResistance pair --full` call each, about 1.4 s)."""
    from scipy.interpolate import CubicSpline
    xis = np.logspace(-6, math.log10(3.0), 36)
    r = internal_resistance(np.array([theory_mobility(ratio, float("%.6g" % x)) for x in xis]))
    return tuple(CubicSpline(np.log(xis), r[:, j]) for j in range(4))


def theory_resistance(ratio: float, xi) -> np.ndarray:
    """[R11, R12, R22, R_twist] of the theory at xi (1e-6 ... 3; any shape, the elements last)."""
    t = np.log(np.asarray(xi, dtype=float))
    return np.stack([s(t) for s in _theory_resistance_splines(ratio)], axis=-1)


def fit_elements(summary: Dict) -> List[Dict[str, float]]:
    """Per element of the internal resistance (R11, R12, R22, R_twist) the seen-gap fit
    R_FDM(xi) = R_th(seen_gap(xi, xi_c, p)) through the measured (box-extrapolated, offset-averaged) one,
    least squares relative to the theory's scale (|R_th|; sqrt(R11 R22) for R12). The solver's sliding and
    rolling resistance is the theory's at a gap no smaller than about 0.3 cell (docs/resistance.md). For
    equal spheres R12 is zero by symmetry in both: its fit is the theory's (xi_c = 0)."""
    from scipy.optimize import least_squares
    ratio, xi = summary["ratio"], np.asarray(summary["gaps"], dtype=float)
    fdm = internal_resistance(np.array(summary["mobility_fdm"]))
    th = internal_resistance(np.array(summary["mobility_theory"]))
    fits = []
    for j, name in enumerate(ELEMENTS):
        scale = np.sqrt(th[:, 0] * th[:, 2]) if j == 1 else np.abs(th[:, j])
        if j == 1 and ratio == 1:
            fits.append(dict(element=name, xi_c=0.0, p=1.0, rms=0.0, max=0.0, symmetric_zero=True))
            continue

        def residual(q: np.ndarray, j: int = j, scale: np.ndarray = scale) -> np.ndarray:
            return (theory_resistance(ratio, seen_gap(xi, 10 ** q[0], q[1]))[:, j] - fdm[:, j]) / scale

        sol = min((least_squares(residual, x0=[x0, 2.0], bounds=([-4, 0.5], [0.5, 8])) for x0 in (-2, -1, -0.3)),
                  key=lambda r: r.cost)
        fits.append(dict(element=name, xi_c=10 ** float(sol.x[0]), p=float(sol.x[1]),
                         rms=float(np.sqrt(np.mean(sol.fun ** 2))), max=float(np.max(np.abs(sol.fun)))))
    return fits


def dissipative(k: np.ndarray, r_th: np.ndarray) -> tuple:
    """The dissipation rule on one gap's [K11, K12, K22, K_twist]: R_th + K positive semi-definite on the
    internal modes (K11, K22, K_twist at least minus the theory's; |R12_th + K12| at most the geometric
    mean of the diagonals, its sign kept). Returns (K after the rule, whether it changed anything)."""
    out = np.array(k, dtype=float)
    for j in (0, 2, 3):
        out[j] = max(out[j], -r_th[j])
    bound = math.sqrt((r_th[0] + out[0]) * (r_th[2] + out[2]))
    coupling = r_th[1] + out[1]
    out[1] = math.copysign(min(abs(coupling), bound), coupling) - r_th[1]
    return out, bool(np.any(np.abs(out - k) > 1e-12 * (1 + np.abs(k))))


def table_blocks(ratio: float, fits: Sequence[Dict[str, float]], min_gap: float = 1e-5, per_decade: int = 20,
                 taper_start: float = 0.5, taper_end: float = 1.0) -> tuple:
    """({element: rows (xi, xi K)}, clipped rows) from min_gap to taper_end (the last row 0): K = R_th(xi) -
    R_FDM(xi) of the fits, through the dissipation rule, tapered to zero between taper_start and taper_end
    linearly in ln xi (as the squeeze and wall blocks)."""
    n = int(round(per_decade * math.log10(taper_end / min_gap)))
    xis = np.array([min_gap * 10 ** (k / per_decade) for k in range(n + 1)])
    r_th = theory_resistance(ratio, xis)
    r_fdm = np.column_stack([theory_resistance(ratio, seen_gap(xis, f["xi_c"], f["p"]))[:, j]
                             for j, f in enumerate(fits)])
    rows: Dict[str, List[tuple]] = {name: [] for name in ELEMENTS}
    clipped = 0
    for k, xi in enumerate(xis):
        t = 1.0 if xi <= taper_start else max(0.0, math.log(taper_end / xi) / math.log(taper_end / taper_start))
        values, changed = dissipative(r_th[k] - r_fdm[k], r_th[k])
        clipped += changed
        for j, name in enumerate(ELEMENTS):
            rows[name].append((float(xi), 0.0 if k == n else float(xi * values[j] * t)))
    return rows, clipped


def add_fits(summary: Dict) -> Dict:
    """The summary with its fits and table rows (what calibration.py writes as the pair_K.. blocks)."""
    fits = fit_elements(summary)
    rows, clipped = table_blocks(summary["ratio"], fits)
    return dict(summary, fits=fits, table=rows, clipped_rows=clipped)


def validate(ratio: float, a_over_delta: float, workdir: str, model: str, gaps: Sequence[float] = GAPS,
             boxes: Sequence[float] = BOXES, offsets: Sequence[Sequence[float]] = OFFSETS[:1],
             tol_lambda: float = 1e-5) -> Dict:
    """The coupled solver with the sub-grid `model` on, loaded and extrapolated as in the measurement, at
    `offsets`: per gap the internal mobilities [M11, M12, M21, M22, M_twist] and the errors of sliding,
    rolling and twist against the theory, M/M_th - 1."""
    raw = run_scenes(ratio, a_over_delta, workdir, gaps, boxes, offsets, tol_lambda, model=model)
    m, _ = extrapolated_mobility(raw, ratio, boxes)
    th = np.array([theory_mobility(ratio, xi) for xi in gaps])
    errors = m[:, [0, 3, 4]] / th[:, [0, 3, 4]] - 1
    return dict(ratio=ratio, a_over_delta=a_over_delta, model=model, gaps=list(gaps), offsets=[list(o) for o in offsets],
                mobility=m.tolist(), mobility_theory=th.tolist(), errors=errors.tolist())


def plot(path: str, summaries: Sequence[Dict]) -> None:
    """Like the paper's Fig. B.24 for the tangential internal modes: the solver's mobility over the
    theory's (sliding q1, rolling q2, twist) per box and extrapolated, and the correction K the solver
    needs against the one the cut-off model adds."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(len(summaries), 2, figsize=(11, 3.6 * len(summaries)), squeeze=False)
    for (left, right), s in zip(axes, summaries):
        xi = np.array(s["gaps"])
        th, fdm = np.array(s["mobility_theory"]), np.array(s["mobility_fdm"])
        for j, name, c in ((0, "sliding q1", "C0"), (3, "rolling q2", "C1"), (4, "twist", "C2")):
            left.semilogx(xi, fdm[:, j] / th[:, j], "^-", color=c, label=name + ", L → ∞")
            for L, m in s["mobility_by_box"].items():
                left.semilogx(xi, np.array(m)[:, j] / th[:, j], "x", color=c, ms=4)
        left.axhline(1, color="k", lw=0.8)
        left.set_xlabel(r"$\xi$")
        left.set_ylabel("M_FDM / M_theory")
        left.set_title("a2/a1 = %g, a1/Δ = %g (x: boxes %s, first position)" % (s["ratio"], s["a_over_delta"],
                                                                             ", ".join(s["mobility_by_box"])),
                       fontsize=9)
        left.legend(fontsize=7)
        k, cut = np.array(s["correction"]), np.array(s["cutoff_correction"])
        for j, name, c in ((0, "K11 (sliding)", "C0"), (2, "K22 (rolling)", "C1"), (3, "K twist", "C2"),
                           (1, "K12", "C3")):
            right.semilogx(xi, k[:, j], "^-", color=c, label=name + " measured")
            right.semilogx(xi, cut[:, j], "--", color=c, label="cut-off model")
            if "table" in s:
                rows = np.array(s["table"][ELEMENTS[j]])
                right.semilogx(rows[:, 0], rows[:, 1] / rows[:, 0], "-", color=c, lw=0.8, alpha=0.7,
                               label="table (seen-gap fit)")
        right.axhline(0, color="k", lw=0.8)
        right.set_xlabel(r"$\xi$")
        right.set_ylabel("K (η a1, η a1², η a1³)")
        right.legend(fontsize=6, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv: Sequence[str] | None = None) -> List[Dict]:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--a-over-delta", type=float, default=3.0, help="a1/Delta")
    p.add_argument("--ratio", type=float, nargs="+", default=[1.0], help="a2/a1")
    p.add_argument("--boxes", type=float, nargs=2, default=list(BOXES))
    p.add_argument("--offsets", type=int, default=len(OFFSETS), help="positions in the cell averaged (1-4)")
    p.add_argument("--gaps", type=float, nargs="+", default=GAPS, help="xi, largest first")
    p.add_argument("--tol-lambda", type=float, default=1e-5)
    p.add_argument("--workdir", default="pair_tangential_runs")
    p.add_argument("--out", required=True, help="JSON of every measurement and the corrections (a .png beside)")
    p.add_argument("--from-raw", metavar="JSON", nargs="+", help="analyse the measurements earlier calls kept (--out)")
    p.add_argument("--validate", choices=["calibrated", "cutoff"], help="run the coupled solver with this sub-grid "
                   "model instead of measuring, and print its errors against the theory (--out: their JSON)")
    p.add_argument("--offset", type=float, nargs=3, action="append", metavar=("X", "Y", "Z"),
                   help="with --validate: a position of the gap centre in its cell (fractions of Delta; repeat for "
                   "several) instead of the first --offsets of the calibration's")
    args = p.parse_args(argv)
    out = []
    if args.validate:
        os.makedirs(args.workdir, exist_ok=True)
        for ratio in args.ratio:
            out.append(validate(ratio, args.a_over_delta, args.workdir, args.validate, args.gaps, args.boxes,
                                args.offset or OFFSETS[:args.offsets], args.tol_lambda))
            files.write_json(args.out, out)   # each ratio's validation kept whole before the next
        for v in out:
            print("%s model, ratio %g, a1/Delta %g, %d positions: xi, M/M_th - 1 of sliding, rolling, twist"
                  % (v["model"], v["ratio"], v["a_over_delta"], len(v["offsets"])))
            for xi, e in zip(v["gaps"], v["errors"]):
                print("  %8.2g  %+7.2f%% %+7.2f%% %+7.2f%%" % (xi, *(100 * np.array(e))))
        return out
    if args.from_raw:
        for path in args.from_raw:
            with open(path) as f:
                out += [summarize(s["ratio"], s["a_over_delta"], s["gaps"], s["boxes"], s["offsets"], s["raw"],
                                  s["wall_seconds"]) for s in json.load(f)]
    else:
        os.makedirs(args.workdir, exist_ok=True)
        for ratio in args.ratio:
            out.append(measure(ratio, args.a_over_delta, args.workdir, args.gaps, args.boxes, OFFSETS[:args.offsets],
                               args.tol_lambda))
            files.write_json(args.out, out)   # each ratio's hours kept whole before the next
    out = [add_fits(s) for s in out]
    files.write_json(args.out, out)   # the same file as the kept measurements: whole, never half
    plot(os.path.splitext(args.out)[0] + ".png", out)
    for s in out:
        print("ratio %g a1/Delta %g (%.0f s): xi, FDM/theory of M11 M22 M_twist, (M12 - M12_th)/sqrt(M11 M22),"
              " then K11 K12 K22 K_twist measured and [the cut-off model's]" % (s["ratio"], s["a_over_delta"],
                                                                               s["wall_seconds"]))
        for xi, f, t, k, cut in zip(s["gaps"], s["mobility_fdm"], s["mobility_theory"], s["correction"],
                                    s["cutoff_correction"]):
            print("  %8.2g  %7.4f %7.4f %7.4f %+7.4f   %9.4g %9.4g %9.4g %9.4g   [%.4g %.4g %.4g %.4g]"
                  % (xi, f[0] / t[0], f[3] / t[3], f[4] / t[4], (0.5 * (f[1] + f[2]) - t[1]) / np.sqrt(t[0] * t[3]),
                     *k, *cut))
        surface_cells = (1 + s["ratio"]) / 2 * s["a_over_delta"]     # xi_c as a surface gap in mesh cells
        print("  seen-gap fits (xi_c as a surface gap in cells, p, rms, max): " + "; ".join(
            "%s %.2f %.2f %.1f%% %.1f%%" % (f["element"], f["xi_c"] * surface_cells, f["p"], 100 * f["rms"],
                                          100 * f["max"]) for f in s["fits"]) + "; clipped rows %d" % s["clipped_rows"])
    return out


if __name__ == "__main__":
    main()
