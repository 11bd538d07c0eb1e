"""The shear-mode stresslets of a pair (Y^G, Y^H; paper Eq. 13, Appendix C.2; issue 14): whether the stresslet the
coupled solver gives two spheres moving across their line of centres is the theory's for that motion.

The squeeze stresslet X^G is checked by pairstresslet.py. Here the motion is that of the tangential scene of
pairtangential.py (spheres of radii 1 and `ratio` along x in a periodic cube, the self-equilibrated sliding,
rolling and twist loads at once, held at each gap for one coupled step), run with `stresslets yes`. For the
velocities the solver gives (U1, W1, U2, W2), the theory's stresslet of sphere alpha in the quiescent fluid
is, with d = e_x from sphere 1 to sphere 2 and the library's full-range functions (Kim & Karrila 1991,
ch. 11; Jeffrey 1992), S = G.(U_inf - U) + H.(W_inf - W) with U_inf = W_inf = 0:

    -S^(alpha)_ij = sum_beta  X^G_ab (d_i d_j - delta_ij/3) d.U^(beta)
                            + Y^G_ab (d_i U^(beta)_j + d_j U^(beta)_i - 2 d_i d_j d.U^(beta))
                            + Y^H_ab ((W^(beta) x d)_i d_j + (W^(beta) x d)_j d_i),

Kim-Karrila's S, the stresslet the particle exerts on the fluid, which is what fix fdm/output records
(S_fluid + S_subgrid; a sphere held in a shear flow records S_xy > 0; tests/test_pair_shear_stresslet.py
checks the sign against Faxen's law for a sphere held in the far field of a translating one). The sliding load (along y) and the rolling load (about -y, i.e. the y case
turned about d) make S_xy and S_xz: these two components of each sphere are compared. The difference
measured - theory has a box effect of its own (the images' strain), taken off as for the mobilities:
difference_inf + c L^-3 from two boxes (pairtangential.BOXES). Beyond xi ~ 0.3 no correction acts and the
difference is the solver's own stresslet error for these rotating spheres (at a1/Delta = 3 about 1 in these
units, as large as the theory's shear-mode stresslet there: compare differences, not ratios, at large gaps).

What it says: with the sub-grid lubrication off (`--model none`) how much of the shear-mode stresslet the
solver resolves at each gap (near contact the theory's log-singular Y^G, Y^H times the solver's too-fast
relative motion: far below the theory); with `--model calibrated` or `cutoff` whether the sub-grid stress
rows (Y^G_11 and Y^H_21 of C.2, with the calibrated Y^A, Y^B, Y^C) make the coupled stresslet the theory's.

    python3 -m fdmsubgrid.pairshearstresslet --a-over-delta 3 --ratio 1 1.4 --model calibrated cutoff none \\
        --out runs/pair_shear_stresslet.json
"""
from __future__ import annotations

import argparse
import json
import os
import time
from typing import Dict, List, Sequence

import numpy as np

from . import squeeze, theory
from .pairtangential import BOXES, GAPS, run_loaded_pair

# Offsets of the centre of the gap in its cell (fractions of Delta): one the calibrations used and one they
# did not (as pairtangential --validate)
OFFSETS = [(0.1, 0.2, 0.3), (0.23, 0.57, 0.71)]
COMPONENTS = (1, 2)    # xy, xz of (xx xy xz yy yz zz)


def theory_stresslet(ratio: float, xi: float, velocities: Dict[str, np.ndarray]) -> np.ndarray:
    """(2, 3, 3): the theory's stresslets S of spheres 1 and 2 (Kim-Karrila's: of the particle on the fluid;
    module docstring) in a quiescent fluid for the velocities U1, W1, U2, W2 (3 each), d = e_x."""
    f = theory.pair_full_range(1.0, ratio, xi)  # X^G, Y^G, Y^H of every ab: d from sphere 1 to 2
    d, eye = np.array([1.0, 0.0, 0.0]), np.eye(3)
    out = np.zeros((2, 3, 3))
    for a in range(2):
        for b in range(2):
            ab = "%d%d" % (a + 1, b + 1)
            u, w = velocities["U%d" % (b + 1)], velocities["W%d" % (b + 1)]
            du, wd = d @ u, np.cross(w, d)
            out[a] += f["XG" + ab] * (np.outer(d, d) - eye / 3) * du
            out[a] += f["YG" + ab] * (np.outer(d, u) + np.outer(u, d) - 2 * np.outer(d, d) * du)
            out[a] += f["YH" + ab] * (np.outer(wd, d) + np.outer(d, wd))
    return -out


def stresslet_components(run: dict, ratio: float) -> tuple:
    """(measured, theory), each (gaps, 2 spheres, 2 components xy, xz) of Kim-Karrila's S, of one
    run_loaded_pair(stresslets=True): the theory for the velocities of that run."""
    measured, theoretical = [], []
    for k, xi in enumerate(run["gaps"]):
        v = {key: np.asarray(run[key][k], dtype=float) for key in ("U1", "W1", "U2", "W2")}
        th = theory_stresslet(ratio, xi, v)
        m = np.asarray([run["S1"][k], run["S2"][k]], dtype=float)
        measured.append([[m[s][c] for c in COMPONENTS] for s in range(2)])
        theoretical.append([[th[s][0, 1], th[s][0, 2]] for s in range(2)])
    return np.array(measured), np.array(theoretical)


def measure(ratio: float, a_over_delta: float, workdir: str, model: str | None, gaps: Sequence[float] = GAPS,
            boxes: Sequence[float] = BOXES, offsets: Sequence[Sequence[float]] = OFFSETS,
            tol_lambda: float = 1e-5, np_fluid: int = 1) -> Dict:
    """Per gap the theory's S_xy, S_xz (the offsets' mean in the first box) and the measured minus the theory's,
    box-extrapolated as the mobilities (pairtangential.extrapolated_mobility): every offset in the first box,
    the first offset in the second, that offset's box correction added to the offsets' mean difference."""
    t0 = time.time()
    differences: Dict[float, List[np.ndarray]] = {}
    theories: List[np.ndarray] = []
    iterations = []
    for k, L in enumerate(boxes):
        differences[L] = []
        for off in (offsets if k == 0 else offsets[:1]):
            run = run_loaded_pair(workdir, ratio, gaps, a_over_delta, L, off, tol_lambda, np_fluid=np_fluid,
                                  model=model, stresslets=True)
            if not run["converged"]:
                raise RuntimeError("pair shear stresslet: ratio %g a/Delta %g L %g offset %s: a step did not converge"
                                   % (ratio, a_over_delta, L, off))
            measured, theoretical = stresslet_components(run, ratio)
            differences[L].append(measured - theoretical)
            if k == 0:
                theories.append(theoretical)
            iterations += run["inner_iterations"]
            print("pair shear stresslet: ratio %g a/Delta %g L %g offset %s model %s (%.0f s)"
                  % (ratio, a_over_delta, L, off, model or "none", run["wall_seconds"]), flush=True)
    L1, L2 = boxes[0], boxes[-1]
    first, second = differences[L1][0], differences[L2][0]
    box_correction = squeeze.extrapolate_box(first, second, L1, L2) - first
    per_offset = np.array(differences[L1]) + box_correction            # (offsets, gaps, spheres, components)
    difference, spread, th = per_offset.mean(axis=0), per_offset.std(axis=0), np.mean(theories, axis=0)
    rows = [dict(xi=xi, theory=th[g].tolist(), difference=difference[g].tolist(), spread=spread[g].tolist(),
                 relative=(difference[g] / th[g]).tolist(), box_correction=box_correction[g].tolist())
            for g, xi in enumerate(gaps)]
    return dict(ratio=ratio, a_over_delta=a_over_delta, model=model or "none", boxes=list(boxes),
                offsets=[list(o) for o in offsets], gaps=list(gaps), rows=rows, tol_lambda=tol_lambda,
                components="[sphere 1, sphere 2][S_xy (sliding), S_xz (rolling)], Kim-Karrila's S, eta = a1 = 1",
                mean_inner_iterations=float(np.mean(iterations)), wall_seconds=time.time() - t0)


def print_summary(result: Dict) -> None:
    print("pair shear stresslet, a2/a1 %g, a1/Delta %g, model %s: the theory's S and (measured - theory)/theory "
          "in %% (box-extrapolated, mean over %d offsets)" % (result["ratio"], result["a_over_delta"],
                                                             result["model"], len(result["offsets"])))
    print("  %-7s %-28s %-28s" % ("xi", "S_xy (sliding): 1, 2", "S_xz (rolling): 1, 2"))
    for r in result["rows"]:
        cells = []
        for c in range(2):
            cells += ["%7.3g %+6.1f %%" % (r["theory"][s][c], 100 * r["relative"][s][c]) for s in range(2)]
        print("  %-7g %s   %s     %s   %s" % (r["xi"], *cells))


def main(argv: Sequence[str] | None = None) -> List[Dict]:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--a-over-delta", type=float, default=3.0)
    p.add_argument("--ratio", type=float, nargs="+", default=[1.0, 1.4], help="a2/a1")
    p.add_argument("--model", nargs="+", default=["calibrated"], choices=["calibrated", "cutoff", "none"],
                   help="pair_style fdm/subgrid's sub-grid model, or none (the lubrication off: the solver alone)")
    p.add_argument("--gaps", type=float, nargs="+", default=GAPS, help="reduced gaps xi, largest first")
    p.add_argument("--boxes", type=float, nargs=2, default=list(BOXES), help="two cube sides (a1)")
    p.add_argument("--offsets", type=int, default=len(OFFSETS), help="how many of the offsets %s" % (OFFSETS,))
    p.add_argument("--workdir", default="runs/pairShearStresslet")
    p.add_argument("--out", default="runs/pair_shear_stresslet.json")
    args = p.parse_args(argv)
    if not 1 <= args.offsets <= len(OFFSETS):
        p.error("--offsets %d: between 1 and %d" % (args.offsets, len(OFFSETS)))
    results = []
    for model in args.model:
        for ratio in args.ratio:
            r = measure(ratio, args.a_over_delta, args.workdir, None if model == "none" else model, args.gaps,
                        args.boxes, OFFSETS[:args.offsets])
            print_summary(r)
            results.append(r)
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    with open(args.out, "w") as f:
        json.dump(results, f, indent=1)
    print("wrote %s" % args.out)
    return results


if __name__ == "__main__":
    main()
