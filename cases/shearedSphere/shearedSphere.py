#!/usr/bin/env python3
"""A free sphere at the centre of a wide channel in simple shear: the dilute limit of the stresslet
(issue 11 item 4; paper 5.2.2, Fig. 10) and the momentum balance of the fluid on the walls.

Walls y = 0 and y = H move at -U and +U along x (shear rate gamma_dot = 2U/H = 1), x and z periodic
(L_x = L_z = L). One sphere of radius a = 1 at the box centre, shifted by --offset (fractions of a
mesh cell), free (force- and torque-free: it rotates at -gamma_dot/2 and stays), one time step from
the linear shear profile (the far field is already converged; the inner iterations build the
disturbance of the sphere). Units: a = 1 m, eta = 1 Pa s, gamma_dot = 1 1/s.

What it measures:
  S* = S_xy / ((10/3) pi eta a^3 gamma_dot)            (1 for a sphere in unbounded shear; S_xy of the
                                                       hydrodynamic stresslet S^H, Eq. 12)
  the momentum balance: the fluid's shear force on the walls, mean of the two, per unit area,
      tau_w = eta gamma_dot + S_xy / V                 (V = L^2 H: the gap average of the stress,
                                                       fdmsubgrid.rheology.gap_shear_stress), its relative error
  the rotation Omega_z / (-gamma_dot/2)

  shearedSphere.py                       CI size: L = 12 a, H = 20 a, a/Delta = 3 (about 10 s)
  shearedSphere.py --size 16 20 16       a wider box
  shearedSphere.py --sweep               the box-size dependence: L = 8, 12, 16, 20 (H = 20) and
                                         H = 20, 30 (L = 12), a few minutes
  shearedSphere.py --help                every option
Writes results.json here (docs/cases.md).
"""
import argparse
import os
import shutil
import time
from typing import List

import numpy as np

from fdmsubgrid import case, channelscenes, output, profiles, rheology
from fdmsubgrid.results import Row, relative, write_results

HERE = os.path.dirname(os.path.abspath(__file__))

ETA = 1.0
SHEAR_RATE = 1.0
A = 1.0


def run(workdir: str, size=(12.0, 20.0, 12.0), a_over_delta: float = 3.0, offset=(0.0, 0.0, 0.0),
        tol_lambda: float = 1e-5, np_fluid: int = 1, keep: bool = False) -> dict:
    """One scene; returns its numbers (module docstring)."""
    delta = A / a_over_delta
    L, H, Lz = (float(v) for v in size)
    for v, name in ((L, "L_x"), (H, "H"), (Lz, "L_z")):
        if abs(v / delta - round(v / delta)) > 1e-9 * v / delta:
            raise ValueError("shearedSphere: %s = %g a is not a whole number of cells of a/%g" % (name, v, a_over_delta))
        if v < 2 * A + 2 * delta:
            raise ValueError("shearedSphere: %s = %g a leaves no room for the sphere (2 a plus two cells)" % (name, v))
    name = "L%gx%gx%g_ad%g_off%g_%g_%g" % (L, H, Lz, a_over_delta, *offset)
    run_dir = os.path.join(workdir, name)
    if os.path.isdir(run_dir):
        shutil.rmtree(run_dir)
    channel = channelscenes.ShearedChannel(L, H, Lz, delta, SHEAR_RATE)
    box = channel.box
    centre = tuple(0.5 * s + o * delta for s, o in zip((L, H, Lz), offset))
    # no pair style: the sphere far from both walls, no sub-grid correction
    channelscenes.write_sheared_channel(run_dir, channel, [centre + (A,)], [case.RECORD_EVERY_STEP, "run 1"],
                                        "in.shearedSphere", tol_lambda, ETA)
    fluid = os.path.join(run_dir, "fluid")
    wall = case.run(run_dir, np_fluid=np_fluid)
    rec = output.read_particle_records(os.path.join(run_dir, "dem", "particles.records"))
    s_xy = float(rec["S_fluid"][-1, 0, 1] + rec["S_subgrid"][-1, 0, 1])
    omega = rec["omega"][-1, 0]
    velocity = rec["U"][-1, 0]
    steps = output.steps(fluid)
    loads = output.read_wall_loads(run_dir, dem_file=None)
    channel = profiles.Channel((0, 0, 0), (L, H, Lz))
    tau = rheology.wall_shear_stresses(loads, channel)["fluid"][-1]
    predicted = ETA * SHEAR_RATE + s_xy / channel.volume
    if not keep:
        case.delete_fields(run_dir)
    return dict(size=[L, H, Lz], a_over_delta=a_over_delta, offset=list(offset), cells=int(np.prod(box.n)),
                S_xy=s_xy, S_star=s_xy / channelscenes.unbounded_shear_stresslet(A, ETA, SHEAR_RATE),
                omega_z_over_minus_half_gamma=float(omega[2] / (-0.5 * SHEAR_RATE)),
                velocity=[float(v) for v in velocity],
                wall_stress_lo=float(tau[0]), wall_stress_hi=float(tau[1]),
                wall_stress=float(tau.mean()), wall_stress_predicted=predicted,
                wall_balance_rel_error=rheology.relative_difference(predicted, float(tau.mean())),
                wall_excess_over_eta_gamma=float(tau.mean() - ETA * SHEAR_RATE),
                stresslet_excess=s_xy / channel.volume,
                inner_iterations=int(steps["innerIterations"][-1]), converged=bool(steps["converged"][-1]),
                residual=float(steps["residualLambda"][-1]), wall_seconds=wall, run_dir=run_dir)


def cell_positions(k: int) -> list:
    """k^3 offsets (in mesh cells) of the sphere's centre from a mesh vertex: the midpoints of a
    k x k x k grid on [0, 1/2]^3. The shear flow u = gamma_dot y e_x is symmetric under each of
    x -> -x, y -> -y, z -> -z (with S_xy unchanged) and so is the mesh about a vertex: offset o_i
    and 1 - o_i give the same S_xy, and [0, 1/2]^3 holds every position once."""
    g = (np.arange(k) + 0.5) / (2 * k)
    return [(float(x), float(y), float(z)) for x in g for y in g for z in g]


def average(group: list) -> dict:
    """The mean over positions of one box (S*, its spread, the rotation, the walls' balance)."""
    s = np.array([r["S_star"] for r in group])
    return dict(size=group[0]["size"], a_over_delta=group[0]["a_over_delta"], positions=len(group),
                S_star=float(s.mean()), S_star_min=float(s.min()), S_star_max=float(s.max()),
                S_star_std=float(s.std(ddof=1)) if len(s) > 1 else 0.0,
                omega_z_over_minus_half_gamma=float(np.mean([r["omega_z_over_minus_half_gamma"] for r in group])),
                wall_balance_rel_error_max=float(max(r["wall_balance_rel_error"] for r in group)),
                wall_seconds=float(sum(r["wall_seconds"] for r in group)))


def validation_rows(results: dict) -> List[Row]:
    """S* and the rotation against the unbounded sphere's 1, and the walls' momentum balance, per box."""
    rows = []
    for a in results["averages"]:
        config = "L×H×L = %g×%g×%g a, a/Δ %g, %d positions" % (*a["size"], a["a_over_delta"], a["positions"])
        rows.append(Row("S* (unbounded: 1)", config, a["S_star"], 1.0, "→ 1 as H grows (Fig. 10)",
                        relative(a["S_star"], 1.0), spread=a["S_star_std"] or None))
        rows.append(Row("Ω_z/(−γ̇/2)", config, a["omega_z_over_minus_half_gamma"], 1.0, "→ 1 as H grows (Fig. 10)",
                        relative(a["omega_z_over_minus_half_gamma"], 1.0)))
        rows.append(Row("momentum balance on the walls (largest)", config, a["wall_balance_rel_error_max"],
                        percent=True))
    return rows


SWEEP = [(8, 20, 8), (12, 20, 12), (16, 20, 16), (20, 20, 20), (12, 30, 12)]


def main(argv=None) -> dict:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--size", type=float, nargs=3, default=[12.0, 20.0, 12.0], metavar=("LX", "H", "LZ"),
                   help="box in units of a (walls normal to y, H the gap)")
    p.add_argument("--a-over-delta", type=float, default=3.0, help="a/Delta, mesh cells per radius")
    p.add_argument("--offset", type=float, nargs=3, default=[0.0, 0.0, 0.0],
                   help="the sphere's shift from the box centre, in mesh cells (0 0 0: on a mesh vertex)")
    p.add_argument("--positions", type=int, default=1, metavar="K",
                   help="average over K^3 positions of the sphere in a mesh cell (midpoints of [0, 1/2]^3, the "
                        "cell modulo the flow's mirror symmetries); 1: the --offset only")
    p.add_argument("--sweep", action="store_true", help="the box sizes of SWEEP (module docstring)")
    case.add_run_options(p, HERE, tol_lambda=1e-5)
    args = p.parse_args(argv)
    started = time.time()
    sizes = SWEEP if args.sweep else [tuple(args.size)]
    offsets = [tuple(args.offset)] if args.positions <= 1 else cell_positions(args.positions)
    runs, averages = [], []
    for size in sizes:
        group = []
        for offset in offsets:
            r = run(args.workdir, size, args.a_over_delta, offset, args.tol_lambda, args.np_fluid, args.keep)
            runs.append(r)
            group.append(r)
            print("L x H x L = %g x %g x %g a, a/Delta %g, %d cells: S* = %.5f, Omega_z/(-gamma/2) = %.5f; walls: "
                  "tau = %.6f (eta gamma + S_xy/V = %.6f, rel. error %.2e); offset %s cells, %d inner iterations, "
                  "%.1f s" % (*r["size"], r["a_over_delta"], r["cells"], r["S_star"], r["omega_z_over_minus_half_gamma"],
                              r["wall_stress"], r["wall_stress_predicted"], r["wall_balance_rel_error"],
                              " ".join("%g" % o for o in r["offset"]), r["inner_iterations"], r["wall_seconds"]))
        averages.append(average(group))
        if len(group) > 1:
            print("  mean over %d positions in a cell: S* = %.5f (min %.5f, max %.5f), Omega_z/(-gamma/2) = %.5f"
                % (len(group), averages[-1]["S_star"], averages[-1]["S_star_min"], averages[-1]["S_star_max"],
                   averages[-1]["omega_z_over_minus_half_gamma"]))
    results = dict(case="shearedSphere", runs=runs, averages=averages)
    write_results(args.out, __file__, argv, args, validation_rows, results, started)
    print("wrote", args.out)
    return results


if __name__ == "__main__":
    main()
