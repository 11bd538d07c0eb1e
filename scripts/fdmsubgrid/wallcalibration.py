"""Calibration of the solver's own tangential sphere-wall resistance (paper section 2.2 and
Appendix B): R^SG = R^th - R^FDM for Y^A, Y^B, Y^C (translation along the wall and rotation about a
wall-parallel axis) and X^C (rotation about the wall normal), measured with fdmFoam itself, instead of
the cut-off model's guess of what the mesh resolves. The squeeze function X^A is calibrated by
calibration.py; this module does the other four.

What is measured. A sphere of radius a at the gap eps = h/a - 1 above the wall y = 0 of a channel
(walls at rest at y = 0 and H, periodic in x and z), the sub-grid lubrication off
(`pair_style fdm/subgrid lubrication no`), loaded at once by a force F along x and torques T along x
and along y (fix addforce, fix fdm/torque). Stokes flow is linear and the three loads excite three
independent responses of the continuous problem:

* F e_x: translation U_x and rotation Omega_z (the tangential 2x2 block, its first column);
* T e_x: rotation Omega_x and translation U_z: the same block's second column seen in a frame turned
  by 90 degrees about the wall normal (T e_z gives U_x e_x + Omega_z e_z; turned, T e_x gives
  -U_x e_z + Omega_z e_x);
* T e_y: rotation Omega_y about the normal (X^C).

In the frame (U_x, Omega_z), d = -e_y the unit normal into the wall, the theory's block is
R_th = eta [[6 pi a Y^A, -4 pi a^2 Y^B], [-4 pi a^2 Y^B, 8 pi a^3 Y^C]] (Kim-Karrila functions,
docs/resistance.md: T = -eta B U with B = Y^B eps.d). The sub-grid block enters Eq. (31) beside the
solver's own resistance, so the coupled solver's resistance is R_FDM + R_SG exactly and the correction
that gives the theory is R_SG = R_th - R_FDM, R_FDM the inverse of the measured mobility M (a 2x2
matrix; its symmetry M_12 = M_21, reciprocity, is reported as a check of the measurement).

Box effect. The force F on the sphere is carried by the walls; its images in the periodic directions
and the far wall change the mobility by O(L^-2) (the far field of a stokeslet parallel to a wall is a
source dipole) with an O(L^-3) part of the same size at these boxes: measured at a/Delta = 3 between
L = 8, 12 and 16 a (H = 1.25 L), the differences of M11 fall as L^-2.8, and 4 % of M11 separate L = 8
from the infinite box. So each scene runs in three boxes and M(L) = M_inf + c2 L^-2 + c3 L^-3 is
solved exactly through them (`extrapolate3`). A fourth box (L = 20 a) checks it: the fit predicts
M(20) within 0.12 % and M_inf from (12, 16, 20) agrees within 0.6 % (docs/resistance.md).

Position in the mesh. The wall lies on a cell face, so the gap fixes where the sphere sits across the
wall; the position along the wall (x, z inside the cell) is averaged over `offsets` in the smallest
box, and the box correction M_inf - M(L1), a far-field effect, is measured at the first offset only.

Fit. Each function the solver resolves is fitted (least squares, residuals over the theory's scale)
as the theory at the gap the solver sees,

    f_FDM(eps) = f_th(eps_seen),   eps_seen = (eps^p + eps_c^p)^(1/p):

the solver follows the theory at gaps it resolves and, below about a fifth of a cell, sees a gap no
smaller than eps_c (its plateau f_th(eps_c)); p sets how sharply it stops resolving. (A smooth
version of the cut-off model, whose eps_c is a guess and p infinite.) The coupling Y^B has one more
term: the solver couples translation and rotation about twice as much as the theory where the
sphere's surface is about 0.3 cell from the wall (measured at a/Delta 3, 4 and 5: the excess peaks
at eps_b a/Delta = 0.30-0.32, -0.19 to -0.23 in Kim-Karrila units), fitted as a bump in ln eps,

    Y^B_FDM(eps) = Y^B_th(eps_seen) + A exp(-(ln(eps/eps_b))^2 / (2 w^2)).

The correction is then s(eps) = f_th(eps) - f_FDM(eps): the theory's singular part below eps_c
(and for Y^B the excess coupling taken away), nothing at large gaps whatever the solver's own
discretisation error there.

Dissipation. The correction may take away at most half of what the solver resolves itself:
R_SG + R_FDM/2 >= 0 with R_FDM = R_th - R_SG, i.e. R_th + R_SG positive semi-definite, in the units of
the block (6 pi a Y^A, 4 pi a^2 Y^B, 8 pi a^3 Y^C; X^C alone). The correction alone may be indefinite
(removing the excess coupling is), the coupled resistance cannot be, even where the solver's own at a
position in the cell falls to half its mean. The sub-grid model applies the same rule after
interpolation (docs/resistance.md).

Output: per (a/Delta) and gap the measured, extrapolated mobilities, R_FDM, R_th, fits and
corrections in Kim-Karrila units (the JSON `--out`), a figure like the paper's Fig. B.25, and the table
blocks `wall_YA`, `wall_YB`, `wall_YC`, `wall_XC` that calibration.py writes into the table the
resistance library reads (dem/resistance/data/subgrid_calibration.dat).

    python3 -m fdmsubgrid.wallcalibration --a-over-delta 3 --out runs/wall_tangential.json
"""
from __future__ import annotations

import argparse
import functools
import json
import math
import os
import time
from dataclasses import dataclass, field
from typing import Dict, List, Sequence

import numpy as np

from . import deminput, foamcase, squeeze, theory

GAPS = [1.0, 0.7, 0.5, 0.3, 0.2, 0.15, 0.1, 0.07, 0.05, 0.03, 0.02, 0.01, 3e-3, 1e-3, 1e-4]
# (x, z) of the sphere's centre inside its mesh cell, fractions of Delta
OFFSETS = [(0.1, 0.3), (0.35, 0.55), (0.6, 0.8), (0.85, 0.05)]
BOXES = (8.0, 12.0, 16.0)  # L/a of the three boxes extrapolated (H = H_OVER_L L)
H_OVER_L = 1.25
FUNCTIONS = ("YA", "YB", "YC", "XC")
# Kim-Karrila normalisation of each function (eta = 1, a = 1): 6 pi a, 4 pi a^2, 8 pi a^3
SCALE = dict(YA=6 * math.pi, YB=4 * math.pi, YC=8 * math.pi, XC=8 * math.pi)


def run_loaded_sphere(workdir: str, epss: Sequence[float], a_over_delta: float, L_over_a: float,
                      H_over_a: float, offset: Sequence[float], tol_lambda: float = 1e-5, np_fluid: int = 1,
                      keep: bool = False) -> dict:
    """One sphere (a = 1, eta = 1) above the wall y = 0 of a channel L x H x L (walls at rest, periodic
    x and z), the lubrication off, loaded by F = 6 pi e_x and T = 8 pi (e_x + e_y), held at each gap of
    `epss` for one coupled step (largest first, each warm-started from the previous). Returns
    dict(U=[[Ux, Uy, Uz] per gap], W=[[Wx, Wy, Wz] per gap], wall_seconds, cells, inner_iterations,
    converged). The result is kept as <run folder>.json: a later call with the same scene and gaps reads it
    instead of running again (a killed calibration resumes where it stopped)."""
    force, torque = 6 * math.pi, 8 * math.pi     # eta = a = 1
    run_dir = os.path.join(workdir, "ad%g_L%g_H%g_off%g_%g" % (a_over_delta, L_over_a, H_over_a, *offset))
    kept = squeeze.kept_result(run_dir, epss, tol_lambda)
    if kept is not None:
        return kept
    pair = deminput.subgrid_pair_style(walls=(("ylo", (0, 0, 0)), ("yhi", (0, 0, 0))), subgrid=False)
    wall, parts, steps, box = squeeze.run_wall_scene(
        run_dir, epss, a_over_delta, L_over_a, H_over_a, offset, tol_lambda, pair,
        "fix             push all addforce %r 0 0\n"
        "fix             turn all fdm/torque %r %r 0" % (force, torque, torque), "in.wallTangential", np_fluid, keep)
    U = np.column_stack([parts["Ux"], parts["Uy"], parts["Uz"]])
    W = np.column_stack([parts["Wx"], parts["Wy"], parts["Wz"]])
    result = dict(U=U.tolist(), W=W.tolist(), wall_seconds=wall, cells=box.n[0] * box.n[1] * box.n[2],
                  inner_iterations=[int(n) for n in steps["innerIterations"]],
                  converged=bool(steps["converged"].all()), gaps=[float(e) for e in epss], tol_lambda=tol_lambda)
    squeeze.keep_result(run_dir, result)
    return result


def mobility(U: np.ndarray, W: np.ndarray) -> np.ndarray:
    """Per gap, the mobilities (a = eta = 1) [M11, M12, M21, M22, MXC] of the tangential block in the
    frame (U_x, Omega_z) and of the rotation about the normal, from the responses to F = 6 pi e_x and
    T = 8 pi (e_x + e_y) (module docstring): M11 = U_x/F, M21 = Omega_z/F, M12 = -U_z/T, M22 = Omega_x/T,
    MXC = Omega_y/T. Shape (gaps, 5)."""
    U, W = np.asarray(U), np.asarray(W)
    force, torque = 6 * math.pi, 8 * math.pi
    return np.column_stack([U[:, 0] / force, -U[:, 2] / torque, W[:, 2] / force, W[:, 0] / torque,
                            W[:, 1] / torque])


def extrapolate3(m: Sequence[np.ndarray], boxes: Sequence[float]) -> np.ndarray:
    """M at an infinite box from three box sizes, M(L) = M_inf + c2 L^-2 + c3 L^-3 through the three."""
    A = np.array([[1.0, L ** -2, L ** -3] for L in boxes])
    weights = np.linalg.inv(A)[0]          # M_inf = sum_k weights[k] M(L_k)
    return sum(w * np.asarray(mk) for w, mk in zip(weights, m))


def resistance_from_mobility(m: np.ndarray) -> np.ndarray:
    """Per gap [R11, R12, R22, RXC] (a = eta = 1): the inverse of the symmetrised 2x2 mobility and 1/MXC."""
    out = []
    for m11, m12, m21, m22, mxc in np.atleast_2d(m):
        off = 0.5 * (m12 + m21)
        r = np.linalg.inv(np.array([[m11, off], [off, m22]]))
        out.append([r[0, 0], r[0, 1], r[1, 1], 1 / mxc])
    return np.array(out)


@functools.lru_cache(maxsize=None)
def theory_functions(eps: float) -> Dict[str, float]:
    """Y^A, Y^B, Y^C, X^C of a sphere and a wall at eps (Kim-Karrila units; fdmResistance wall)."""
    kk = theory.resistance("wall", "--a", 1, "--eps", "%.6g" % eps)["kim_karrila"]
    return {k: float(kk[k]) for k in FUNCTIONS}


def functions_from_resistance(r: np.ndarray) -> np.ndarray:
    """[Y^A, Y^B, Y^C, X^C] (Kim-Karrila) from [R11, R12, R22, RXC] in the frame (U_x, Omega_z) with the
    wall below: R11 = 6 pi Y^A, R12 = -4 pi Y^B, R22 = 8 pi Y^C, RXC = 8 pi X^C."""
    r = np.atleast_2d(r)
    return np.column_stack([r[:, 0] / SCALE["YA"], -r[:, 1] / SCALE["YB"], r[:, 2] / SCALE["YC"],
                            r[:, 3] / SCALE["XC"]])


@dataclass
class WallTangentialCalibration:
    """One a/Delta: the raw responses per box and offset, and what follows from them."""
    a_over_delta: float
    gaps: List[float]
    boxes: List[float]
    offsets: List[List[float]]
    # "L" -> [per offset: dict(U, W)]: every offset in the first box, the first offset in the others
    responses: Dict[str, List[dict]] = field(default_factory=dict)
    wall_seconds: float = 0.0

    def mobilities(self, L: float) -> np.ndarray:
        """(offsets, gaps, 5) mobilities in the box L."""
        return np.array([mobility(r["U"], r["W"]) for r in self.responses["%g" % L]])

    def box_correction(self) -> np.ndarray:
        """M_inf - M(L1) at the first offset (gaps, 5)."""
        first = [self.mobilities(L)[0] for L in self.boxes]
        return extrapolate3(first, self.boxes) - first[0]

    def mobility_inf(self) -> np.ndarray:
        """Offset-averaged mobilities of the first box plus the box correction (gaps, 5)."""
        return self.mobilities(self.boxes[0]).mean(axis=0) + self.box_correction()

    def fdm_functions(self) -> np.ndarray:
        """(gaps, 4): Y^A, Y^B, Y^C, X^C the solver resolves (Kim-Karrila), infinite box."""
        return functions_from_resistance(resistance_from_mobility(self.mobility_inf()))

    def fdm_functions_by_offset(self) -> np.ndarray:
        """(offsets, gaps, 4), infinite box, each offset on its own (the scatter a correction cannot remove)."""
        correction = self.box_correction()
        return np.array([functions_from_resistance(resistance_from_mobility(m + correction))
                         for m in self.mobilities(self.boxes[0])])

    def theory(self) -> np.ndarray:
        return np.array([[theory_functions(g)[k] for k in FUNCTIONS] for g in self.gaps])

    def reciprocity(self) -> np.ndarray:
        """Per gap |M12 - M21| / sqrt(M11 M22), infinite box (the solver spreads forces with I_lambda and
        averages velocities with I_u: its operator need not be symmetric; the fit uses the symmetric part)."""
        m = self.mobility_inf()
        return np.abs(m[:, 1] - m[:, 2]) / np.sqrt(m[:, 0] * m[:, 3])


@functools.lru_cache(maxsize=None)
def _theory_spline(name: str):
    """The theory of `name` as a cubic spline in ln eps, eps = 1e-6 ... 30 (40 points per decade)."""
    from scipy.interpolate import CubicSpline
    eps = np.logspace(-6, math.log10(30.0), 300)
    return CubicSpline(np.log(eps), [theory_functions(float("%.6g" % e))[name] for e in eps])


def theory_at(name: str, eps) -> np.ndarray:
    """f_th(eps) of `name` (Kim-Karrila), eps in 1e-6 ... 30, any shape."""
    return _theory_spline(name)(np.log(np.asarray(eps, dtype=float)))


def seen_gap(eps, eps_c: float, p: float):
    """The gap the solver sees: (eps^p + eps_c^p)^(1/p)."""
    return (np.asarray(eps, dtype=float) ** p + eps_c ** p) ** (1 / p)


def bump(eps, amplitude: float, eps_b: float, width: float):
    """The solver's excess coupling Y^B near eps_b: amplitude exp(-(ln(eps/eps_b))^2 / (2 width^2))."""
    return amplitude * np.exp(-0.5 * (np.log(np.asarray(eps, dtype=float) / eps_b) / width) ** 2)


def fdm_fit(name: str, eps, fit: Dict[str, float]):
    """The fitted FDM function `name` at eps (Kim-Karrila): f_th(seen gap), plus the bump for Y^B."""
    f = theory_at(name, seen_gap(eps, fit["eps_c"], fit["p"]))
    if "bump" in fit:
        f = f + bump(eps, fit["bump"], fit["eps_b"], fit["width"])
    return f


def residual_scale(name: str, eps) -> np.ndarray:
    """The scale a fit's residuals of function `name` are measured on: sqrt(Y^A Y^C) of the theory for
    Y^B (which crosses zero), |f_th| for the others."""
    return (np.sqrt(theory_at("YA", eps) * theory_at("YC", eps)) if name == "YB"
            else np.abs(theory_at(name, eps)))


def fit_function(name: str, gaps: Sequence[float], fdm: np.ndarray) -> Dict[str, float]:
    """(eps_c, p) of f_FDM = f_th(seen_gap(eps)), and for Y^B the bump (amplitude `bump`, centre eps_b,
    width in ln eps), through the measured FDM function `name` (least squares with the residuals over
    the theory's scale: |f_th| for Y^A, Y^C, X^C, sqrt(Y^A Y^C) for Y^B), and the plateau
    f_0 = f_th(eps_c)."""
    from scipy.optimize import least_squares
    gaps = np.asarray(gaps, dtype=float)
    scale = residual_scale(name, gaps)
    with_bump = name == "YB"

    def as_fit(q: np.ndarray) -> Dict[str, float]:
        fit = dict(eps_c=10 ** float(q[0]), p=float(q[1]))
        if with_bump:
            fit.update(bump=float(q[2]), eps_b=10 ** float(q[3]), width=float(q[4]))
        return fit

    def residual(q: np.ndarray) -> np.ndarray:
        return (fdm_fit(name, gaps, as_fit(q)) - fdm) / scale

    if with_bump:   # the bump's centre from three starts (the cost has a local minimum per decade)
        sols = [least_squares(residual, x0=[math.log10(0.05), 2.0, -0.2, c, 0.7],
                              bounds=([-4, 0.5, -2, -3, 0.2], [0, 8, 2, 0, 3])) for c in (-1.5, -1.0, -0.5)]
        sol = min(sols, key=lambda r: r.cost)
    else:
        sol = least_squares(residual, x0=[math.log10(0.05), 2.0], bounds=([-4, 0.5], [0, 8]))
    fit = as_fit(sol.x)
    fit.update(f_0=float(theory_at(name, fit["eps_c"])), rms=float(np.sqrt(np.mean(sol.fun ** 2))),
               max=float(np.max(np.abs(sol.fun))))
    return fit


def correction(name: str, eps: float, fit: Dict[str, float]) -> float:
    """s(eps) = f_th(eps) - f_FDM(eps), f_FDM the fit: the sub-grid function `name` (Kim-Karrila),
    before the dissipation rule."""
    th = theory_functions(float("%.6g" % eps))[name]
    return th - float(fdm_fit(name, eps, fit))


def dissipative(values: Dict[str, float], eps: float) -> Dict[str, float]:
    """The dissipation rule on one gap's corrections (Kim-Karrila): R_th + R_SG positive semi-definite,
    i.e. Y^A, Y^C, X^C at least minus the theory and |Y^B_th + Y^B_SG| at most
    sqrt(6 pi (Y^A_th + Y^A_SG) 8 pi (Y^C_th + Y^C_SG))/(4 pi) (the sign of Y^B_th + Y^B_SG kept)."""
    th = theory_functions(float("%.6g" % eps))
    out = {k: max(values[k], -th[k]) for k in ("YA", "YC", "XC")}
    bound = math.sqrt(SCALE["YA"] * (th["YA"] + out["YA"]) * SCALE["YC"] * (th["YC"] + out["YC"])) / SCALE["YB"]
    coupling = th["YB"] + values["YB"]
    out["YB"] = math.copysign(min(abs(coupling), bound), coupling) - th["YB"]
    return out


def table_blocks(a_over_delta: float, fits: Dict[str, Dict[str, float]], min_gap: float = 1e-5,
                 per_decade: int = 20, taper_start: float = 0.5, taper_end: float = 1.0) -> Dict[str, List[tuple]]:
    """The rows (eps, eps * s_hat) of the four blocks from min_gap to taper_end (the last row 0), s_hat the
    corrections after the dissipation rule, tapered to zero between taper_start and taper_end linearly in
    ln eps (as the squeeze blocks)."""
    n = int(round(per_decade * math.log10(taper_end / min_gap)))
    rows: Dict[str, List[tuple]] = {k: [] for k in FUNCTIONS}
    for k in range(n + 1):
        eps = min_gap * 10 ** (k / per_decade)
        t = 1.0 if eps <= taper_start else max(0.0, math.log(taper_end / eps) / math.log(taper_end / taper_start))
        values = dissipative({name: correction(name, eps, fits[name]) for name in FUNCTIONS}, eps)
        for name in FUNCTIONS:
            rows[name].append((eps, 0.0 if k == n else eps * values[name] * t))
    return rows


def box_sizes(a_over_delta: float) -> List[float]:
    """BOXES at a/Delta, each the next size whose L and H_OVER_L L are whole, even numbers of cells (BOXES
    themselves at a/Delta 3, 4, 5; at 5.6: 48, 68 and 92 cells across)."""
    return [foamcase.whole_cell_box(L, a_over_delta, H_OVER_L) for L in BOXES]


def measure(a_over_delta: float, workdir: str, gaps: Sequence[float] = GAPS, boxes: Sequence[float] | None = None,
            offsets: Sequence[Sequence[float]] = OFFSETS, tol_lambda: float = 1e-5,
            np_fluid: int = 1) -> WallTangentialCalibration:
    """Run the loaded-sphere scenes: every offset in the first box, the first offset in the others. boxes:
    L/a; by default BOXES, each grown to whole, even numbers of cells (box_sizes)."""
    boxes = box_sizes(a_over_delta) if boxes is None else boxes
    if len(boxes) != 3:
        raise ValueError("wall calibration: three box sizes are needed (M_inf + c2 L^-2 + c3 L^-3), got %s" % boxes)
    cal = WallTangentialCalibration(a_over_delta, list(gaps), list(boxes), [list(o) for o in offsets])
    t0 = time.time()
    for k, L in enumerate(boxes):
        rows = []
        for off in (offsets if k == 0 else offsets[:1]):
            r = run_loaded_sphere(workdir, gaps, a_over_delta, L, H_OVER_L * L, off, tol_lambda, np_fluid)
            if not r["converged"]:
                raise RuntimeError("wall calibration: a/Delta %g L %g offset %s: a step did not converge"
                                   % (a_over_delta, L, off))
            rows.append(dict(U=r["U"], W=r["W"], inner_iterations=r["inner_iterations"]))
            print("wall calibration: a/Delta %g L %g offset %s done (%.0f s)" % (a_over_delta, L, off,
                                                                               r["wall_seconds"]), flush=True)
        cal.responses["%g" % L] = rows
    cal.wall_seconds = time.time() - t0
    return cal


def summary(c: WallTangentialCalibration) -> Dict:
    """What the .json keeps of one calibration."""
    fdm = c.fdm_functions()
    th = c.theory()
    by_box = {"%g" % L: functions_from_resistance(resistance_from_mobility(c.mobilities(L)[0])).tolist()
              for L in c.boxes}
    f = c.fdm_functions_by_offset()
    spread = ((f.max(axis=0) - f.min(axis=0)) / np.abs(f.mean(axis=0))).tolist()
    fits = {name: fit_function(name, c.gaps, fdm[:, j]) for j, name in enumerate(FUNCTIONS)}
    corrections = [dissipative({name: correction(name, g, fits[name]) for name in FUNCTIONS}, g) for g in c.gaps]
    return dict(a_over_delta=c.a_over_delta, gaps=c.gaps, boxes=c.boxes, offsets=c.offsets, functions=FUNCTIONS,
                fdm=fdm.tolist(), fdm_by_box=by_box, offset_spread=spread,
                theory=th.tolist(), measured_difference=(th - fdm).tolist(), fits=fits,
                correction=[[cg[name] for name in FUNCTIONS] for cg in corrections],
                reciprocity=c.reciprocity().tolist(), responses=c.responses, wall_seconds=c.wall_seconds)


def from_summary(d: Dict) -> WallTangentialCalibration:
    """The calibration an earlier summary (the JSON `--out`) kept, to analyse again."""
    return WallTangentialCalibration(d["a_over_delta"], d["gaps"], d["boxes"], d["offsets"], d["responses"],
                                     d["wall_seconds"])


def plot(path: str, summaries: Sequence[Dict]) -> None:
    """Like the paper's Fig. B.25 for the tangential functions: theory, the FDM function in each box
    and extrapolated, per a/Delta."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(len(summaries), 4, figsize=(16, 3.6 * len(summaries)), squeeze=False)
    for row, s in zip(axes, summaries):
        gaps = np.array(s["gaps"])
        fine = np.logspace(-4, 0, 40)
        th_fine = np.array([[theory_functions(float("%.6g" % g))[k] for k in FUNCTIONS] for g in fine])
        for j, (ax, name) in enumerate(zip(row, FUNCTIONS)):
            sign = -1 if name == "YB" else 1
            ax.semilogx(fine, sign * th_fine[:, j], "k-", label="theory")
            for L in s["boxes"]:
                ax.semilogx(gaps, sign * np.array(s["fdm_by_box"]["%g" % L])[:, j], "x", ms=4,
                            label="FDM, L = %g a (first position)" % L)
            ax.semilogx(gaps, sign * np.array(s["fdm"])[:, j], "^", label="FDM, L → ∞")
            f = s["fits"][name]
            ax.semilogx(fine, sign * fdm_fit(name, fine, f), "-", color="C3", label="fit")
            ax.set_xlabel(r"$\varepsilon$")
            ax.set_ylabel(("-" if sign < 0 else "") + name + " (Kim–Karrila)")
            ax.set_title("wall %s, a/Δ = %g" % (name, s["a_over_delta"]), fontsize=9)
            ax.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv: Sequence[str] | None = None) -> List[Dict]:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--a-over-delta", type=float, nargs="+", default=[3.0])
    p.add_argument("--boxes", type=float, nargs=3, help="the three box sizes L/a (default %s, in whole, even "
                   "numbers of cells)" % " ".join("%g" % L for L in BOXES))
    p.add_argument("--offsets", type=int, default=len(OFFSETS), help="positions in the cell averaged (1-4)")
    p.add_argument("--gaps", type=float, nargs="+", default=GAPS, help="eps, largest first")
    p.add_argument("--workdir", default="wall_calibration_runs")
    p.add_argument("--out", required=True, help="JSON of every measurement and the corrections")
    p.add_argument("--from-raw", metavar="JSON", help="analyse the measurements an earlier call kept (--out)")
    args = p.parse_args(argv)
    os.makedirs(args.workdir, exist_ok=True)
    cals: List[WallTangentialCalibration] = []
    if args.from_raw:
        with open(args.from_raw) as f:
            cals = [from_summary(d) for d in json.load(f)]
    else:
        for ad in args.a_over_delta:
            cals.append(measure(ad, args.workdir, gaps=args.gaps, boxes=args.boxes, offsets=OFFSETS[:args.offsets]))
            with open(args.out, "w") as f:   # kept after every a/Delta
                json.dump([summary(c) for c in cals], f, indent=1)
    summaries = [summary(c) for c in cals]
    with open(args.out, "w") as f:
        json.dump(summaries, f, indent=1)
    plot(os.path.splitext(args.out)[0] + ".png", summaries)
    for s in summaries:
        print("a/Delta %g (%.0f s): eps, then FDM/theory of %s" % (s["a_over_delta"], s["wall_seconds"],
                                                                   " ".join(FUNCTIONS)))
        for g, f, t in zip(s["gaps"], s["fdm"], s["theory"]):
            print("  %8.2g  " % g + "  ".join("%7.4f" % (fi / ti) for fi, ti in zip(f, t)))
    return summaries


if __name__ == "__main__":
    main()
