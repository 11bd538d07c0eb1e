"""The squeeze stresslet of a pair (paper section 2.2, Appendix B): how much of the stresslet X^G the
fictitious-domain solver resolves when two spheres approach along their line of centres, what each sub-grid
model adds to it, and the coupled result.

What is run: the squeeze scene of calibration.py (squeeze.run_pair: spheres of radii 1 and `ratio` along x in
a periodic cube, pushed together by +-F), held at each gap for one coupled step with `stresslets yes`, at the
calibration's 4 positions in the cell and 2 box sizes; the sub-grid lubrication off (the solver alone), or on
with `--model` (the coupled solver, stresslet = fluid + sub-grid parts). Each sphere's stresslet S (fix
fdm/output's S_fluid + S_subgrid: Kim-Karrila's S, of the particle on the fluid, S = -G.U in a quiescent
fluid; the sign checked in tests/test_pair_shear_stresslet.py) has the traceless part
S_xx - tr S/3 = -(2/3) (g_11 U1 + g_12 U2) for motion along the line of centres x. One loading
cannot split g_11 from g_12: the response to a rigid translation of the pair, g_11 + g_12, is taken as the
theory's X^G_11 + X^G_12 (the far field, which the solver resolves, and which the frame-invariant sub-grid
matrix leaves alone), so

    g_11 = (S_1 - (X^G_11 + X^G_12) U2) / (U1 - U2),

compared with the theory's X^G_11 (sphere 2 gives the relabelled pair's). Box effect: g at L = 8 and 12 a1
extrapolated as g_inf + c L^-3 (the images of a force dipole), then averaged over the positions.

What the models add. The sub-grid stresslet is not the base function X11G alone: Appendix C.2's frame
invariance ties X^G_21 = -X^G_11 - r X^A_21, and pair_style fdm/subgrid averages the two labellings
(subgridPairFunctions), so the X^G_11 it applies is (X11G(a1, a2) - X11G(a2, a1) - r X^A_21)/2: for equal
spheres exactly -r X^A_21/2, each sphere taking half of the force dipole r F^SG of the squeeze correction,
whatever X11G is. The probe takes the applied value from `fdmResistance pair --subgrid [--calibrated]`
(dimensional_over_eta XG11) and, from the solver-alone runs, predicts the coupled error of each model; a run
with `--model` measures it.

The theory is the library's full-range X^G (`fdmResistance pair --theory --full`: Jeffrey 1992's series
matched to the near-field forms, within 5.3e-4 of Townsend's exact values at s' >= 2.025).

    python3 -m fdmsubgrid.pairstresslet --a-over-delta 3 --ratio 1 1.4 --out runs/pair_stresslet.json
    python3 -m fdmsubgrid.pairstresslet --a-over-delta 3 --ratio 1 --model calibrated --out runs/coupled.json
    python3 -m fdmsubgrid.pairstresslet --reanalyse runs/pair_stresslet.json    (the models' columns again)
"""
from __future__ import annotations

import argparse
import functools
import json
import math
import os
from typing import Dict, List, Sequence

import numpy as np

from . import squeeze, theory
from .calibration import BOXES, GAPS, OFFSETS
from .squeeze import extrapolate_box

MODELS = ("cutoff", "calibrated")   # pair_style fdm/subgrid's sub-grid models

FORCE = 6 * math.pi   # eta = a1 = 1: velocities in F/(6 pi eta a1)


def run_squeeze(workdir: str, ratio: float, a_over_delta: float, L_over_a: float, offset: Sequence[float],
                gaps: Sequence[float] = GAPS, np_fluid: int = 1, model: str | None = None) -> Dict[str, np.ndarray]:
    """One coupled run of the squeeze scene held at each gap (largest first) with the stresslets on, the
    sub-grid lubrication off (model None) or on with `model`; returns U1, U2 (velocities along x) and S1, S2
    (S_fluid + S_subgrid, xx xy xz yy yz zz) per gap."""
    run = squeeze.run_pair(os.path.join(workdir, model or "solver"), ratio, gaps, subgrid=model is not None,
                           a_over_delta=a_over_delta, L_over_a=L_over_a, tol_lambda=1e-5, np_fluid=np_fluid,
                           offset=offset, pair_options="model %s" % model if model else "", stresslets=True)
    return dict(U1=run["U1"], U2=run["U2"], S1=run["S1_fluid"] + run["S1_subgrid"],
                S2=run["S2_fluid"] + run["S2_subgrid"])


def kim_karrila_xx(S: np.ndarray) -> np.ndarray:
    """-(3/2) of the traceless xx part of a recorded S (Kim-Karrila's, S = -G.U): X^G U for motion along x."""
    S = np.asarray(S, dtype=float)
    return -1.5 * (S[..., 0] - (S[..., 0] + S[..., 3] + S[..., 5]) / 3)


@functools.lru_cache(maxsize=None)
def theory_xg(a1: float, a2: float, xi: float) -> tuple:
    """The library's X^G_11, X^G_12, X^G_21, X^G_22 (dimensional, eta = 1; full-range forms)."""
    d = theory.pair_full_range(a1, a2, xi)
    return d["XG11"], d["XG12"], d["XG21"], d["XG22"]


@functools.lru_cache(maxsize=None)
def applied_x11g(a1: float, a2: float, xi: float, delta: float, model: str) -> float:
    """The X^G_11 (sphere 1 of radius a1) that pair_style fdm/subgrid applies with `model` at its default
    cut-offs: Appendix C.2's expansion averaged over the labellings (module docstring)."""
    return theory.resistance("pair", "--a1", a1, "--a2", a2, "--xi", xi, "--subgrid", "--delta", delta,
                             *theory.subgrid_options(model))["dimensional_over_eta"]["XG11"]


def solver_x11g(run: Dict[str, np.ndarray], ratio: float, gaps: Sequence[float]) -> tuple:
    """g_11 of the solver for sphere 1 and for sphere 2 relabelled as the first (module docstring)."""
    s1, s2 = kim_karrila_xx(run["S1"]), kim_karrila_xx(run["S2"])
    u1, u2 = np.asarray(run["U1"]), np.asarray(run["U2"])
    g1, g2 = [], []
    for k, xi in enumerate(gaps):
        x11, x12, x21, x22 = theory_xg(1.0, ratio, xi)
        g1.append((s1[k] - (x11 + x12) * u2[k]) / (u1[k] - u2[k]))
        # relabelled (d -> -d): X^G is odd in d
        g2.append(-(s2[k] - (x21 + x22) * u1[k]) / (u2[k] - u1[k]))
    return np.array(g1), np.array(g2)


def measure(ratio: float, a_over_delta: float, workdir: str, gaps: Sequence[float] = GAPS,
            boxes: Sequence[float] = BOXES, offsets: Sequence[Sequence[float]] = OFFSETS,
            model: str | None = None) -> Dict:
    """g_11 (both labellings) at every gap, box-extrapolated and averaged over the offsets, of the solver alone
    (model None) or of the coupled solver with `model`, beside the theory (analyse() adds the comparisons)."""
    per_box = {}
    for L in boxes:
        g = [solver_x11g(run_squeeze(workdir, ratio, a_over_delta, L, o, gaps, model=model), ratio, gaps)
             for o in offsets]
        per_box[L] = np.array(g)        # (offsets, 2 labellings, gaps)
    L1, L2 = boxes[0], boxes[-1]
    measured = extrapolate_box(per_box[L1], per_box[L2], L1, L2)
    mean, spread = measured.mean(axis=0), measured.std(axis=0)
    rows = [dict(xi=xi, measured=mean[:, k].tolist(), measured_spread=spread[:, k].tolist())
            for k, xi in enumerate(gaps)]
    return analyse(dict(ratio=ratio, a_over_delta=a_over_delta, model=model, boxes=list(boxes),
                        offsets=[list(o) for o in offsets], rows=rows))


def analyse(result: Dict) -> Dict:
    """Adds to each row the theory, and: for the solver alone, what it misses ('needed') and what each model
    applies with the coupled error that predicts; for a coupled run, its error. (The first version of the probe
    stored the solver's values as 'solver' and compared the base function X11G alone, not what the pair style
    applies; such a result is read and analysed anew.)"""
    ratio, delta = result["ratio"], 1.0 / result["a_over_delta"]
    model = result.get("model")
    for r in result["rows"]:
        if "solver" in r:                 # the first version's keys
            r["measured"], r["measured_spread"] = r.pop("solver"), r.pop("solver_spread")
            for old in ("needed", "cutoff", "cutoff_total_error"):
                r.pop(old, None)
        xi, g = r["xi"], r["measured"]
        th = [theory_xg(1.0, ratio, xi)[0], theory_xg(ratio, 1.0, xi)[0]]
        r["theory"] = th
        if model:
            r["coupled_error"] = [(g[j] - th[j]) / th[j] for j in range(2)]
            continue
        r["needed"] = [th[j] - g[j] for j in range(2)]
        r["applied"], r["predicted_error"] = {}, {}
        for m in MODELS:
            applied = [applied_x11g(1.0, ratio, xi, delta, m), applied_x11g(ratio, 1.0, xi, delta, m)]
            r["applied"][m] = applied
            r["predicted_error"][m] = [(g[j] + applied[j] - th[j]) / th[j] for j in range(2)]
    return result


def print_summary(result: Dict) -> None:
    model = result.get("model")
    print("a1/Delta %g, a2/a1 %g, %s: X11G of sphere 1 | sphere 2 relabelled"
          % (result["a_over_delta"], result["ratio"], "coupled with model %s" % model if model else "solver alone"))
    if model:
        print("%-7s %10s %10s | %10s %10s  %8s %8s" % ("xi", "theory", "coupled", "theory", "coupled", "err 1", "err 2"))
        for r in result["rows"]:
            print("%-7g %10.3f %10.3f | %10.3f %10.3f  %+7.1f%% %+7.1f%%" % (
                r["xi"], r["theory"][0], r["measured"][0], r["theory"][1], r["measured"][1],
                100 * r["coupled_error"][0], 100 * r["coupled_error"][1]))
        return
    print("%-7s %9s %9s %9s | %9s %9s %9s | predicted error: %-15s %-15s" % (
        "xi", "theory", "solver", "needed", "theory", "solver", "needed", "cut-off", "calibrated"))
    for r in result["rows"]:
        e = r["predicted_error"]
        print("%-7g %9.3f %9.3f %9.3f | %9.3f %9.3f %9.3f | %+6.1f%% %+6.1f%%  %+6.1f%% %+6.1f%%" % (
            r["xi"], r["theory"][0], r["measured"][0], r["needed"][0], r["theory"][1], r["measured"][1],
            r["needed"][1], 100 * e["cutoff"][0], 100 * e["cutoff"][1], 100 * e["calibrated"][0],
            100 * e["calibrated"][1]))


def main(argv: Sequence[str] | None = None) -> List[Dict]:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--a-over-delta", type=float, default=3.0)
    p.add_argument("--ratio", type=float, nargs="+", default=[1.0, 1.4])
    p.add_argument("--model", choices=MODELS, default=None,
                   help="run the coupled solver with this sub-grid model (default: the solver alone, lubrication off)")
    p.add_argument("--workdir", default=os.path.join("runs", "pairstresslet"))
    p.add_argument("--out", default=None, help="JSON of the results")
    p.add_argument("--reanalyse", metavar="JSON", default=None,
                   help="analyse the results of an earlier call again (written back to --out, default the same file)")
    args = p.parse_args(argv)
    if args.reanalyse:
        with open(args.reanalyse) as f:
            results = [analyse(r) for r in json.load(f)]
        args.out = args.out or args.reanalyse
    else:
        results = [measure(ratio, args.a_over_delta, args.workdir, model=args.model) for ratio in args.ratio]
    for result in results:
        print_summary(result)
    if args.out:
        with open(args.out, "w") as f:
            json.dump(results, f, indent=1)
    return results


if __name__ == "__main__":
    main()
