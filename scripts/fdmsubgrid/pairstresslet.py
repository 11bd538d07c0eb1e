"""The solver's own squeeze stresslet of a pair (paper section 2.2, Appendix B): how much of the stresslet
X^G the fictitious-domain solver resolves when two spheres approach along their line of centres, and what
the cut-off model adds to it. A probe, not yet a calibration: `model calibrated` takes its stresslet
functions (X^G, Y^G, Y^H, X^P) from the cut-off model (docs/resistance.md).

What is run: the squeeze scene of calibration.py (spheres of radii 1 and `ratio` along x in a periodic
cube, pushed together by +-F, the sub-grid lubrication off), held at each gap for one coupled step with
`stresslets yes`, at the calibration's 4 positions in the cell and 2 box sizes. Each sphere's fluid
stresslet S (fix fdm/output's S_fluid, the force the fluid exerts; Kim-Karrila's S is its opposite) has
the traceless part S_xx - tr S/3 = (2/3) (g_11 U1 + g_12 U2) for motion along the line of centres x.
One loading cannot split g_11 from g_12: the solver's response to a rigid translation of the pair,
g_11 + g_12, is taken as the theory's X^G_11 + X^G_12 (the far field, which the solver resolves), so

    g_11 = (S_1 - (X^G_11 + X^G_12) U2) / (U1 - U2),

and the correction the coupled solver needs is X^G_11 - g_11 (C.2's base function X11G; sphere 2 gives the
relabelled pair's). Box effect: g at L = 8 and 12 a1 extrapolated as g_inf + c L^-3 (the images of a force
dipole), then averaged over the positions.

The theory is the library's full-range X^G (`fdmResistance pair --theory --full`: Jeffrey 1992's series
matched to the near-field forms, within 5.3e-4 of Townsend's exact values at s' >= 2.025). The cut-off
model subtracts the near-field form, as the pair style does.

    python3 -m fdmsubgrid.pairstresslet --a-over-delta 3 --ratio 1 1.4 --out runs/pair_stresslet.json
"""
from __future__ import annotations

import argparse
import functools
import json
import math
import os
from typing import Dict, List, Sequence

import numpy as np

from . import case, theory
from .calibration import BOXES, GAPS, OFFSETS
from .pairtangential import centres
from .squeeze import extrapolate_box

FORCE = 6 * math.pi   # eta = a1 = 1: velocities in F/(6 pi eta a1)


def run_squeeze(workdir: str, ratio: float, a_over_delta: float, L_over_a: float, offset: Sequence[float],
                gaps: Sequence[float] = GAPS, np_fluid: int = 1) -> Dict[str, np.ndarray]:
    """One coupled run of the squeeze scene held at each gap (largest first) with the lubrication off and
    the stresslets on; returns U1, U2 (velocities along x) and S1, S2 (S_fluid, xx xy xz yy yz zz) per gap."""
    delta = 1.0 / a_over_delta
    L = L_over_a
    run_dir = os.path.join(workdir, "ratio%g_ad%g_L%g_offset%g" % (ratio, a_over_delta, L_over_a, offset[0]))
    box = case.Box((0, 0, 0), (L, L, L), delta)
    middle = [L / 2 + o * delta for o in offset]
    case.write_fluid_case(os.path.join(run_dir, "fluid"), box, nu=1.0, rho=1.0, tol_lambda=1e-5, n_max=3000,
                          n_particles=2)
    p1, p2 = centres(ratio, gaps[0], middle)
    runs = ["fix             output all fdm/output records 1 particles.records"]
    runs += case.held_step_runs([centres(ratio, xi, middle) for xi in gaps])
    case.write_dem_input(os.path.join(run_dir, "dem"), box, [p1 + (1.0,), p2 + (ratio,)], dt=1.0,
                         fix_options="move no stresslets yes", pair_style="fdm/subgrid lubrication no",
                         before_run="group           one id 1\ngroup           two id 2\n"
                                    "fix             push1 one addforce %r 0 0\n"
                                    "fix             push2 two addforce %r 0 0" % (FORCE, -FORCE),
                         runs=runs, name="in.pairStresslet")
    case.run(run_dir, np_fluid=np_fluid)
    records, _ = case.read_held_steps(run_dir, len(gaps), "pairstresslet")
    n = len(gaps)
    U = np.array(records["U"][-n:, :, 0], dtype=float)
    S = np.array(records["S_fluid"][-n:], dtype=float)
    case.delete_fields(run_dir)
    return dict(U1=U[:, 0], U2=U[:, 1], S1=S[:, 0], S2=S[:, 1])


def kim_karrila_xx(S: np.ndarray) -> np.ndarray:
    """(3/2) of the traceless xx part of S_fluid with Kim-Karrila's sign: X^G U for motion along x."""
    S = np.asarray(S, dtype=float)
    return -1.5 * (S[..., 0] - (S[..., 0] + S[..., 3] + S[..., 5]) / 3)


@functools.lru_cache(maxsize=None)
def theory_xg(a1: float, a2: float, xi: float) -> tuple:
    """The library's X^G_11, X^G_12, X^G_21, X^G_22 (dimensional, eta = 1; full-range forms)."""
    d = theory.resistance("pair", "--a1", a1, "--a2", a2, "--xi", xi, "--theory", "--full")["dimensional_over_eta"]
    return d["XG11"], d["XG12"], d["XG21"], d["XG22"]


@functools.lru_cache(maxsize=None)
def cutoff_x11g(a1: float, a2: float, xi: float, delta: float) -> float:
    """The cut-off model's base X11G (sphere 1 of radius a1) at pair_style fdm/subgrid's default cut-off."""
    return theory.resistance("pair", "--a1", a1, "--a2", a2, "--xi", xi, "--subgrid", "--delta", delta,
                             "--cutoff", theory.PAIR_CUTOFF)["base"]["X11G"]


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
            boxes: Sequence[float] = BOXES, offsets: Sequence[Sequence[float]] = OFFSETS) -> Dict:
    """The solver's X11G (both labellings) at every gap, box-extrapolated and averaged over the offsets,
    beside the theory and the cut-off model's correction."""
    per_box = {}
    for L in boxes:
        g = [solver_x11g(run_squeeze(workdir, ratio, a_over_delta, L, o, gaps), ratio, gaps) for o in offsets]
        per_box[L] = np.array(g)        # (offsets, 2 labellings, gaps)
    L1, L2 = boxes[0], boxes[-1]
    solver = extrapolate_box(per_box[L1], per_box[L2], L1, L2)
    mean, spread = solver.mean(axis=0), solver.std(axis=0)
    delta = 1.0 / a_over_delta
    rows = []
    for k, xi in enumerate(gaps):
        th = (theory_xg(1.0, ratio, xi)[0], theory_xg(ratio, 1.0, xi)[0])
        cut = (cutoff_x11g(1.0, ratio, xi, delta), cutoff_x11g(ratio, 1.0, xi, delta))
        rows.append(dict(xi=xi, theory=list(th), solver=mean[:, k].tolist(), solver_spread=spread[:, k].tolist(),
                         needed=[th[j] - mean[j, k] for j in range(2)], cutoff=list(cut),
                         cutoff_total_error=[(mean[j, k] + cut[j] - th[j]) / th[j] for j in range(2)]))
    return dict(ratio=ratio, a_over_delta=a_over_delta, boxes=list(boxes), offsets=[list(o) for o in offsets],
                rows=rows)


def print_summary(result: Dict) -> None:
    print("a1/Delta %g, a2/a1 %g: X11G of sphere 1 | sphere 2 relabelled; coupled error with the cut-off model"
          % (result["a_over_delta"], result["ratio"]))
    print("%-7s %10s %10s %10s %10s | %10s %10s %10s %10s  %8s %8s" % (
        "xi", "theory", "solver", "needed", "cut-off", "theory", "solver", "needed", "cut-off", "err 1", "err 2"))
    for r in result["rows"]:
        print("%-7g %10.3f %10.3f %10.3f %10.3f | %10.3f %10.3f %10.3f %10.3f  %+7.1f%% %+7.1f%%" % (
            r["xi"], r["theory"][0], r["solver"][0], r["needed"][0], r["cutoff"][0], r["theory"][1], r["solver"][1],
            r["needed"][1], r["cutoff"][1], 100 * r["cutoff_total_error"][0], 100 * r["cutoff_total_error"][1]))


def main(argv: Sequence[str] | None = None) -> List[Dict]:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--a-over-delta", type=float, default=3.0)
    p.add_argument("--ratio", type=float, nargs="+", default=[1.0, 1.4])
    p.add_argument("--workdir", default=os.path.join("runs", "pairstresslet"))
    p.add_argument("--out", default=None, help="JSON of the results")
    args = p.parse_args(argv)
    results = []
    for ratio in args.ratio:
        results.append(measure(ratio, args.a_over_delta, args.workdir))
        print_summary(results[-1])
    if args.out:
        with open(args.out, "w") as f:
            json.dump(results, f, indent=1)
    return results


if __name__ == "__main__":
    main()
