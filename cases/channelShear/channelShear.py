#!/usr/bin/env python3
"""A free sphere at the centre of a channel sheared by both walls, from confined (H -> 2a) to wide
(paper 5.2.2, Figs. 9-10; issue 15 item 2).

Walls y = 0 and y = H move at -U and +U along x (shear rate gamma_dot = 2U/H = 1), x and z periodic
(L_x x L_z; the paper: 60a x 40a, "large enough to mimic infinite planes"). One free sphere of radius
a (a1 = 1 or a2 = 1.4, the paper's two radii, on the same mesh: Delta = a1/(a1/Delta)) at the centre
of the channel, held in place (`fix fdm/couple ... move no`): by symmetry it does not translate. One
coupled time step per position of its centre in a mesh cell, the first from the undisturbed linear
profile, the next ones warm-started from the previous. Units: a1 = 1 m, eta = 1 Pa s, gamma_dot = 1 1/s.

What it measures, against H/a:
  Wz_norm = Omega_z / (-gamma_dot/2)                     (1 for a sphere in unbounded shear)
  S*      = S_xy / ((10/3) pi eta a^3 gamma_dot)         (the paper's normalisation, Eq. 46's S*; S_xy of
                                                         the hydrodynamic stresslet S^H, Eq. 12: the fluid
                                                         part plus the sub-grid part of the wall blocks)
  Ux, Uy, Uz                                             (0 by symmetry; the largest |U|/(gamma_dot a) is kept)
averaged over positions of the centre in one mesh cell (mean and standard deviation; the paper finds
oscillations of at most 3 % in Omega). The centre stays on the channel's mid-plane y = H/2 (so the
walls are symmetric about it); it moves in x and z only. Both walls are declared to
`pair_style fdm/subgrid` (`wall ylo -U 0 0 wall yhi U 0 0`), so the wall lubrication correction
(Eq. D.6) acts once the gap eps = H/(2a) - 1 is below its range (eps = 1 with the default calibrated
model, 0.75 Delta/a with --model cutoff; docs/dem.md); --no-subgrid switches it off (`lubrication no`),
--compare-subgrid runs the smallest H both ways. The calibrated model covers a/Delta 3 to 5 against a
wall: a scene outside it is refused before it runs (use --model cutoff).

  channelShear.py                        default: a1 = 1, H/a = 7/3 ... 20, 12a x 12a walls,
                                         a1/Delta = 3, 16 positions (4 computed), the smallest H also
                                         without the sub-grid correction (a few minutes)
  channelShear.py --radius both          a1 = 1 and a2 = 1.4 (each radius its own default H/a list)
  channelShear.py --H-over-a 2.333333 4 --size 24 24 --positions 4
                                         chosen gaps, a wider box, 4 positions (1 computed)
  channelShear.py --full --model cutoff  the paper's: 60a x 40a walls, a1/Delta = 5, 16 positions, both
                                         radii (hours; runnable, not run here; a2/Delta = 7 has no
                                         wall calibration)
  channelShear.py --help                 every option
Writes results.json here (or --out) and results_channelShear.png next to it (docs/cases.md).

Positions (--positions N, N = 4 K^2): the flow u = gamma_dot (y - H/2) e_x between symmetric walls is
unchanged by the rotation by pi about the z axis through the centre and by the mirror z -> -z, and so
is the mesh about a vertex line (x and z periodic, uniform; H/2 a vertex or a cell-centre plane of
the symmetric channel), with Omega_z and S_xy unchanged: the offsets o and 1 - o (fractions of Delta)
give the same numbers in x and in z. The N midpoints of a 2K x 2K grid over the cell are therefore
the K^2 midpoints of a K x K grid on [0, 1/2]^2, each standing for four; N = 16 is the paper's count.
"""
from __future__ import annotations

import argparse
import math
import os
import shutil
import time
from typing import List, Sequence

import numpy as np

from fdmsubgrid import case, channelscenes, output, theory
from fdmsubgrid.results import Row, relative, write_results

HERE = os.path.dirname(os.path.abspath(__file__))

ETA = 1.0
SHEAR_RATE = 1.0
A1 = 1.0
RADII = {"1": (1.0,), "1.4": (1.4,), "both": (1.0, 1.4)}

# Default gaps H/a per radius at a1/Delta = 3: whole numbers of cells (H = n Delta, Delta = 1/3), from
# the most confined one the mesh allows (eps = H/2a - 1 = 1/6 for a1, 1/14 for a2: inside the wall
# cut-off, 0.25 and 0.18) to the wide channel. a2 = 1.4: H/a = n/4.2.
DEFAULT_H = {1.0: [7 / 3, 8 / 3, 3.0, 4.0, 6.0, 10.0, 20.0],
             1.4: [9 / 4.2, 10 / 4.2, 12 / 4.2, 14 / 4.2, 5.0, 10.0, 20.0]}
# --full at a1/Delta = 5 (the paper's mesh: "the value Delta = a1/5 will not be changed", its section 4):
# H/a = n/5 (a1) and n/7 (a2), about 2.2 to 20 as in the paper
FULL_H = {1.0: [2.2, 2.4, 2.6, 3.0, 4.0, 6.0, 10.0, 20.0],
          1.4: [15 / 7, 16 / 7, 18 / 7, 3.0, 4.0, 6.0, 10.0, 20.0]}


def cells(length: float, delta: float) -> float:
    """length / delta, the number of mesh cells it spans (not rounded)."""
    return length / delta


def is_whole(x: float) -> bool:
    return abs(x - round(x)) <= 1e-6 * max(1.0, abs(x))


def check_gap(H_over_a: float, radius: float, a_over_delta: float, snap: bool) -> float:
    """The gap H/a the mesh can hold for this radius: H > 2a and H a whole number of cells
    (the walls are the faces y = 0, H of the mesh; to 1e-6 of a cell). With snap, the nearest whole
    number of cells above 2a is taken; otherwise a ValueError names the bad value and the
    nearest good ones."""
    delta = A1 / a_over_delta
    if not H_over_a > 2.0:
        raise ValueError("channelShear: --H-over-a %g: the gap must exceed 2 a (the sphere of radius %g touches or "
                         "crosses the walls at H <= 2a)" % (H_over_a, radius))
    n = cells(H_over_a * radius, delta)
    if is_whole(n):
        return round(n) * delta / radius
    lo, hi = math.floor(n), math.ceil(n)
    if snap:
        k = round(n) if round(n) * delta > 2 * radius else hi
        return k * delta / radius
    good = [k * delta / radius for k in (lo, hi) if k * delta > 2 * radius]
    raise ValueError("channelShear: --H-over-a %g with radius %g is %.4g mesh cells at a1/Delta = %g: the walls are "
                     "mesh faces, H must be a whole number of cells (nearest: H/a = %s; or --snap)"
                     % (H_over_a, radius, n, a_over_delta, ", ".join("%.10g" % g for g in good)))


def wall_cells(L_over_a: float, radius: float, a_over_delta: float) -> int:
    """The periodic length L (given in units of a) in whole mesh cells (rounded: only the box's size,
    not the gap, depends on it); at least 2a plus two cells."""
    delta = A1 / a_over_delta
    n = int(round(cells(L_over_a * radius, delta)))
    if n * delta < 2 * radius + 2 * delta:
        raise ValueError("channelShear: --size %g (in units of a) leaves no room for the sphere of radius %g "
                         "(2 a plus two cells)" % (L_over_a, radius))
    return n


def cell_offsets(n_positions: int) -> list[tuple[float, float]]:
    """The K^2 offsets (x, z), fractions of Delta from a mesh vertex, that stand for n_positions = 4 K^2
    positions evenly spread over a cell (module docstring)."""
    k = math.isqrt(max(n_positions, 0) // 4)
    if n_positions < 4 or 4 * k * k != n_positions:
        raise ValueError("channelShear: --positions %d: give 4 K^2 positions (4, 16, 36, 64: the K x K midpoints of "
                         "the half cell [0, 1/2]^2, each standing for four by symmetry)" % n_positions)
    g = (np.arange(k) + 0.5) / (2 * k)
    return [(float(x), float(z)) for x in g for z in g]


def run_gap(workdir: str, radius: float, H_over_a: float, size: Sequence[float], a_over_delta: float,
            offsets: Sequence[tuple[float, float]], subgrid: bool = True, tol_lambda: float = 1e-5,
            np_fluid: int = 1, keep: bool = False, model: str = "calibrated") -> dict:
    """One channel (radius, gap H/a, walls size = (L_x/a, L_z/a)), one coupled step per offset of the
    centre in its cell (x, z fractions of Delta from a vertex). Returns per-position lists and the
    scene's description (module docstring). model: pair_style fdm/subgrid's sub-grid model."""
    delta = A1 / a_over_delta
    a = float(radius)
    ny = int(round(cells(H_over_a * a, delta)))
    nx = wall_cells(size[0], a, a_over_delta)
    nz = wall_cells(size[1], a, a_over_delta)
    Lx, H, Lz = nx * delta, ny * delta, nz * delta
    name = "a%g_H%gcells_L%gx%g_ad%g_%s" % (a, ny, nx, nz, a_over_delta, "subgrid" if subgrid else "nosubgrid")
    run_dir = os.path.join(workdir, name)
    if os.path.isdir(run_dir):
        shutil.rmtree(run_dir)
    channel = channelscenes.ShearedChannel(Lx, H, Lz, delta, SHEAR_RATE)
    # offsets from the vertex nearest the box centre in x and z; y on the mid-plane (a vertex plane
    # when ny is even, a cell-centre plane when odd)
    x0, z0 = (nx // 2) * delta, (nz // 2) * delta

    def centre(o: tuple[float, float]) -> tuple[float, float, float]:
        return (x0 + o[0] * delta, H / 2, z0 + o[1] * delta)

    runs = [case.RECORD_EVERY_STEP]
    runs += case.held_step_runs([[centre(o)] for o in offsets])
    # both no-slip walls at the fluid case's velocities (the pair style checks they agree with 0/U; docs/dem.md)
    channelscenes.write_sheared_channel(run_dir, channel, [centre(offsets[0]) + (a,)], runs, "in.channelShear",
                                        tol_lambda, ETA, case.subgrid_pair_style(channel.walls, subgrid, model=model))
    fluid = os.path.join(run_dir, "fluid")
    wall = case.run(run_dir, np_fluid=np_fluid)
    rec = output.read_particle_records(os.path.join(run_dir, "dem", "particles.records"))
    steps = output.steps(fluid)
    if len(rec) != len(offsets):
        raise RuntimeError("channelShear: %s: %d records for %d positions" % (run_dir, len(rec), len(offsets)))
    # stresslets (T, N, 6) in the order xx xy xz yy yz zz (docs/profiles.md): column 1 is S_xy
    s_fluid = np.array(rec["S_fluid"][:, 0, 1], dtype=float)
    s_subgrid = np.array(rec["S_subgrid"][:, 0, 1], dtype=float)
    stokes_s = channelscenes.unbounded_shear_stresslet(a, ETA, SHEAR_RATE)
    omega = np.array(rec["omega"][:, 0], dtype=float)
    velocity = np.array(rec["U"][:, 0], dtype=float)
    if not keep:
        case.delete_fields(run_dir)
    wall_range = theory.wall_subgrid_range(a, delta, model)     # eps below which the wall block acts
    return dict(radius=a, H_over_a=H / a, H_cells=ny, centre_y_in_cell=0.5 * (ny % 2),
                box=[Lx / a, H / a, Lz / a], cells=nx * ny * nz,
                a_over_delta=a_over_delta, a_over_delta_sphere=a / delta, eps=H / (2 * a) - 1,
                subgrid=subgrid, model=model if subgrid else None,
                wall_block_acts=bool(subgrid and H / (2 * a) - 1 < wall_range),
                wall_subgrid_range=wall_range,
                offsets=[list(o) for o in offsets],
                Wz_norm=[float(w) for w in omega[:, 2] / (-0.5 * SHEAR_RATE)],
                S_star=[float(s) for s in (s_fluid + s_subgrid) / stokes_s],
                S_star_subgrid=[float(s) for s in s_subgrid / stokes_s],
                U_over_gamma_a=[[float(u) for u in v / (SHEAR_RATE * a)] for v in velocity],
                W_xy=[[float(w) for w in v[:2]] for v in omega],
                inner_iterations=[int(n) for n in steps["innerIterations"]],
                converged=bool(np.all(steps["converged"] > 0)), wall_seconds=wall, run_dir=run_dir)


def summarise(scene: dict, n_positions: int) -> dict:
    """One row of results.json from a scene of run_gap: means and (population) standard deviations
    over the positions (each computed offset stands for 4 equal ones, the same mean and deviation)."""
    w, s = np.array(scene["Wz_norm"]), np.array(scene["S_star"])
    u = np.abs(np.array(scene["U_over_gamma_a"]))
    return dict(radius=scene["radius"], H_over_a=scene["H_over_a"], eps=scene["eps"], H_cells=scene["H_cells"],
                centre_y_in_cell=scene["centre_y_in_cell"],
                Wz_norm=float(w.mean()), Wz_norm_std=float(w.std()), Wz_norm_min=float(w.min()),
                Wz_norm_max=float(w.max()),
                S_star=float(s.mean()), S_star_std=float(s.std()), S_star_min=float(s.min()), S_star_max=float(s.max()),
                S_star_subgrid=float(np.mean(scene["S_star_subgrid"])),
                U_max=float(u.max()), Ux_max=float(u[:, 0].max()), Uy_max=float(u[:, 1].max()),
                Uz_max=float(u[:, 2].max()),
                box=scene["box"], cells=scene["cells"], a_over_delta=scene["a_over_delta"],
                a_over_delta_sphere=scene["a_over_delta_sphere"], n_positions=n_positions,
                n_computed=len(scene["offsets"]), subgrid=scene["subgrid"], wall_block_acts=scene["wall_block_acts"],
                wall_subgrid_range=scene["wall_subgrid_range"],
                inner_iterations=scene["inner_iterations"], converged=scene["converged"],
                wall_seconds=scene["wall_seconds"],
                per_position=dict(offsets=scene["offsets"], Wz_norm=scene["Wz_norm"], S_star=scene["S_star"]))


def plot(rows: list[dict], path: str, title: str) -> None:
    """Fig. 10 of the paper: Omega_z/(-gamma_dot/2) and S* against H/a, error bars the spread over
    positions, the unbounded limits as lines. Circles: the centre on a vertex plane of the mesh in y
    (H an even number of cells), triangles: on a cell-centre plane (odd); open squares: without the
    sub-grid correction."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import NullFormatter, ScalarFormatter
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for key, ax, label in (("Wz_norm", axes[0], r"$\Omega_z / (-\dot\gamma/2)$"), ("S_star", axes[1], r"$S^*$")):
        for i, radius in enumerate(sorted({r["radius"] for r in rows})):
            color = "C%d" % i
            on = sorted((r for r in rows if r["radius"] == radius and r["subgrid"]), key=lambda r: r["H_over_a"])
            off = sorted((r for r in rows if r["radius"] == radius and not r["subgrid"]), key=lambda r: r["H_over_a"])
            if on:
                ax.plot([r["H_over_a"] for r in on], [r[key] for r in on], "-", color=color, lw=0.8,
                        label="a = %g" % radius)
            for sel, marker, mfc, text in (
                    ([r for r in on if r["centre_y_in_cell"] == 0], "o", color, "centre on a vertex plane"),
                    ([r for r in on if r["centre_y_in_cell"] != 0], "^", color, "centre on a cell-centre plane"),
                    (off, "s", "none", "no sub-grid correction")):
                if sel:
                    ax.errorbar([r["H_over_a"] for r in sel], [r[key] for r in sel],
                                yerr=[r[key + "_std"] for r in sel], fmt=marker, mfc=mfc, color=color, capsize=3,
                                label="a = %g, %s" % (radius, text))
        ax.axhline(1.0, color="k", lw=0.8, ls="--", label="unbounded shear")
        ax.set_xscale("log")
        ticks = [t for t in (2.2, 3, 4, 6, 10, 20) if min(r["H_over_a"] for r in rows) * 0.95 <= t
                 <= max(r["H_over_a"] for r in rows) * 1.05]
        ax.xaxis.set_major_formatter(ScalarFormatter())
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xticks(ticks)
        ax.set_xlabel("H / a")
        ax.set_ylabel(label)
        ax.legend(fontsize=7)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def print_row(r: dict) -> None:
    print("a %-4g H/a %-8.4g eps %-7.3g %-10s Wz/(-g/2) %.4f +- %.4f  S* %.4f +- %.4f (sub-grid part %.4f)  "
          "|U|max %.1e  %d pos. (%d run)  iter %s  %.0f s"
          % (r["radius"], r["H_over_a"], r["eps"], "sub-grid" if r["subgrid"] else "FDM alone", r["Wz_norm"],
             r["Wz_norm_std"], r["S_star"], r["S_star_std"], r["S_star_subgrid"], r["U_max"], r["n_positions"],
             r["n_computed"], ",".join(str(n) for n in r["inner_iterations"]), r["wall_seconds"]), flush=True)


def validation_rows(r: dict) -> List[Row]:
    """Omega_z/(-gamma/2) and S* at the centre of a channel against H/a; no tabulated reference (Sangani et
    al.'s numbers are not available): the unbounded limit 1 is the reference from H/a = 10 on."""
    rows = []
    for row in r["rows"]:
        config = "a %g, H/a %.4g, %s, box %s a, a/Δ %g, %d positions" % (
            row["radius"], row["H_over_a"], "sub-grid on" if row["subgrid"] else "FDM alone",
            "×".join("%g" % v for v in row["box"]), row["a_over_delta_sphere"], row["n_positions"])
        wide = row["H_over_a"] >= 10
        for q, key in (("Ω_z/(−γ̇/2)", "Wz_norm"), ("S*", "S_star")):
            rows.append(Row(q + (" (unbounded: 1)" if wide else ""), config, row[key], 1.0 if wide else None,
                            "Fig. 10 (Sangani et al. 2011); Ω oscillates ≤ 3 % over positions",
                            relative(row[key], 1.0) if wide else None, spread=row[key + "_std"] or None,
                            headline=row["subgrid"]))
    return rows


def main(argv: Sequence[str] | None = None) -> dict:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--H-over-a", type=float, nargs="+", default=None, metavar="H",
                   help="gaps H/a (each a whole number of cells for every radius run; default: DEFAULT_H of the "
                        "radius at a1/Delta = 3, FULL_H with --full)")
    p.add_argument("--radius", choices=sorted(RADII), default="1", help="the sphere's radius a (a1 = 1, a2 = 1.4) "
                   "or both")
    p.add_argument("--size", type=float, nargs=2, default=[12.0, 12.0], metavar=("LX", "LZ"),
                   help="periodic lengths of the walls in units of a (rounded to whole cells; default 12 12)")
    p.add_argument("--a-over-delta", type=float, default=3.0, help="a1/Delta, mesh cells per radius a1 = 1 (a2 = 1.4 "
                   "has 1.4 times more)")
    p.add_argument("--positions", type=int, default=16, metavar="N",
                   help="positions of the centre in a cell, N = 4 K^2 (K^2 computed; default 16, the paper's)")
    p.add_argument("--snap", action="store_true", help="take the nearest whole number of cells for a gap that is "
                   "not one (instead of refusing it)")
    sub = p.add_mutually_exclusive_group()
    sub.add_argument("--no-subgrid", action="store_true",
                     help="every gap without the sub-grid correction (pair_style fdm/subgrid lubrication no)")
    sub.add_argument("--compare-subgrid", choices=("smallest", "none", "all"), default="smallest",
                     help="which gaps to run again without the sub-grid correction (default: the smallest of each "
                          "radius)")
    p.add_argument("--full", action="store_true", help="the paper's: walls 60a x 40a, a1/Delta = 5, 16 positions, "
                   "both radii, FULL_H")
    case.add_run_options(p, HERE, tol_lambda=1e-5, model=True)
    args = p.parse_args(argv)
    if args.full:
        args.size, args.a_over_delta, args.positions, args.radius = [60.0, 40.0], 5.0, 16, "both"
    try:
        if args.a_over_delta <= 0:
            raise ValueError("channelShear: --a-over-delta %g must be positive" % args.a_over_delta)
        if args.tol_lambda <= 0:
            raise ValueError("channelShear: --tol-lambda %g must be positive" % args.tol_lambda)
        offsets = cell_offsets(args.positions)
        plan = []
        for radius in RADII[args.radius]:
            wall_cells(args.size[0], radius, args.a_over_delta)
            wall_cells(args.size[1], radius, args.a_over_delta)
            gaps = args.H_over_a or (FULL_H if args.full else DEFAULT_H)[radius]
            gaps = sorted({round(check_gap(h, radius, args.a_over_delta, args.snap), 12) for h in gaps})
            again = {"smallest": gaps[:1], "none": [], "all": gaps}[args.compare_subgrid]
            for h in gaps:
                for subgrid in ([False] if args.no_subgrid else [True] + ([False] if h in again else [])):
                    plan.append((radius, h, subgrid))
        if not args.no_subgrid:
            # one sphere at a time: only each radius against the walls needs a calibration
            missing = case.uncalibrated(RADII[args.radius], A1 / args.a_over_delta, walls=True, model=args.model,
                                        pairs=False)
            if missing:
                raise ValueError(case.refusal("channelShear", missing))
    except ValueError as e:
        p.error(str(e))
    os.makedirs(args.workdir, exist_ok=True)
    t0 = time.time()
    rows = []
    for radius, h, subgrid in plan:
        scene = run_gap(args.workdir, radius, h, args.size, args.a_over_delta, offsets, subgrid, args.tol_lambda,
                        args.np_fluid, args.keep, args.model)
        rows.append(summarise(scene, args.positions))
        print_row(rows[-1])
    results = dict(case="channelShear", size_over_a=args.size, a_over_delta=args.a_over_delta,
                   positions=args.positions, tol_lambda=args.tol_lambda, model=args.model,
                   rows=rows)
    write_results(args.out, __file__, argv, args, validation_rows, results, t0)
    png = os.path.join(os.path.dirname(os.path.abspath(args.out)), "results_channelShear.png")
    plot(rows, png, "Free sphere at the centre of a sheared channel: walls %g a x %g a, a1/Delta = %g, %d positions"
         % (args.size[0], args.size[1], args.a_over_delta, args.positions))
    print("wrote %s and %s (%.0f s)" % (args.out, png, results["wall_seconds"]))
    return results


if __name__ == "__main__":
    main()
