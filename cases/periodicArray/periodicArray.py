#!/usr/bin/env python3
"""Stokes flow through a simple cubic periodic array of spheres (paper section 5.1).

One free sphere of radius a in a fully periodic cube of side L, an imposed mean pressure gradient
grad P0 along x, and an external force on the sphere that balances it (Eqs. 42-43). The drag
coefficient K = F / (6 pi eta a U_s) (Eq. 40) with F = V0 |grad P0| (Eq. 43) and the slip velocity
U_s = <u> - U (Eq. 44) is averaged over sphere positions spread evenly inside one mesh cell, and
compared with Hasimoto's series (Eq. 41).

All positions of one configuration run in one coupled run, one position per time step (the
sphere is held: fix fdm/couple move no), each step warm-started from the previous flow.

  periodicArray.py                 L/a = 8, a/Delta = 5, 64 positions (8 computed), a few minutes
  periodicArray.py --full          L/a = 8, 10, 20 with 64 positions, and the c sweep of Table 2
  periodicArray.py --help          every option
"""
import argparse
import json
import math
import os
import shutil
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "scripts"))
from fdm import case, output  # noqa: E402


def hasimoto_K(phi):
    """Eq. (41) with the further terms of Sangani & Acrivos (1982) for a simple cubic array."""
    c13 = phi ** (1.0 / 3.0)
    return 1.0 / (1 - 1.7601 * c13 + phi - 1.5593 * phi ** 2 + 3.9799 * phi ** (8.0 / 3.0)
                  - 3.0734 * phi ** (10.0 / 3.0))


def positions_in_cell(n_positions, corner, delta):
    """The paper's n_positions = m^3 points on an m x m x m lattice at offsets (i + 1/2)/m inside the
    cell [corner, corner + delta]^3, reduced by the cell's mirror symmetries: the drag coefficient
    is the same at a position and at its mirror image in each mid-plane of the cell (the mesh is
    symmetric, and reversing the flow does not change K), so for even m the lattice points of one
    octant, equally weighted, give exactly the m^3-point mean at 1/8 of the cost.
    Returns (points computed, number of lattice points they stand for)."""
    m = round(n_positions ** (1.0 / 3.0))
    if m ** 3 != n_positions:
        raise ValueError("--positions must be a cube (1, 8, 27, 64, ...), got %d" % n_positions)
    offsets = [(i + 0.5) / m for i in range(m // 2 if m % 2 == 0 else m)]
    pts = [tuple(corner[d] + o * delta for d, o in enumerate((ox, oy, oz)))
           for oz in offsets for oy in offsets for ox in offsets]
    return pts, n_positions


DEM_INPUT = """# Periodic array of spheres (paper 5.1): one sphere held in place (move no) by an external
# force balancing the imposed pressure gradient, visited at {n} positions inside one mesh cell
# (one octant of the lattice, by symmetry), one position per coupled time step.
atom_style      sphere
atom_modify     map array sort 0 0.0
boundary        p p p
newton          off
communicate     single vel yes
units           si
region          box block 0 {L!r} 0 {L!r} 0 {L!r} units box
create_box      1 box
create_atoms    1 single {x0!r} {y0!r} {z0!r} units box
set             atom 1 diameter {d!r} density 1000
pair_style      none
neighbor        {skin!r} bin
timestep        {dt!r}
# external force F_ext = V0 grad P0 (Eq. 43)
fix             hold all addforce {fext}
fix             couple all fdm/couple portfile ../fluid/coupling.port move no
{positions}
"""


def run_configuration(workdir, L_over_a, a_over_delta, n_positions, b=5.0, c=0.3, tol_lambda=1e-4,
                      tol_first=None, n_max=2000, tol_u=1e-6, tol_p=5e-6, np_fluid=1,
                      pseudo_time_factor=1.0, direction=0, points=None, keep=False, acceleration="anderson"):
    a = 1.0
    delta = a / a_over_delta
    L = L_over_a * a
    eta = nu = rho = 1.0
    V0 = L ** 3
    # grad P0 chosen so that F = 6 pi eta a: U_s = 1/K
    F = 6 * math.pi * eta * a
    grad_p0 = -F / V0
    name = "L%g_ad%g_c%g_b%g_tol%g_n%d_np%d_%s" % (L_over_a, a_over_delta, c, b, tol_lambda, n_positions, np_fluid,
                                                "xyz"[direction])
    if points:
        name += "_points%d" % len(points)
    gradient = [0.0, 0.0, 0.0]
    gradient[direction] = grad_p0
    run_dir = os.path.join(workdir, name)
    if os.path.isdir(run_dir):
        shutil.rmtree(run_dir)
    box = case.Box((0, 0, 0), (L, L, L), delta)
    # the cell whose lower corner is the node nearest the centre of the box
    corner = [round(L / 2 / delta) * delta] * 3
    pts = list(points) if points else positions_in_cell(n_positions, corner, delta)[0]
    case.write_fluid_case(os.path.join(run_dir, "fluid"), box, nu=nu, rho=rho, grad_p0=tuple(gradient),
                          indicator=(b, c), tol_lambda=tol_lambda, n_max=n_max,
                          first_step=(tol_first if tol_first else tol_lambda / 10, n_max * 4),
                          tol_u=tol_u, tol_p=tol_p, n_particles=1, pseudo_time_factor=pseudo_time_factor,
                          acceleration=acceleration)
    lines = []
    for i, (x, y, z) in enumerate(pts):
        if i > 0:
            lines.append("set             atom 1 x %r y %r z %r" % (x, y, z))
        lines.append("run             1")
    os.makedirs(os.path.join(run_dir, "dem"))
    with open(os.path.join(run_dir, "dem", "in.periodicArray"), "w") as f:
        f.write(DEM_INPUT.format(n=len(pts), L=L, x0=pts[0][0], y0=pts[0][1], z0=pts[0][2], d=2 * a,
                                 skin=0.1 * a, dt=1.0, fext=" ".join(repr(g * V0) for g in gradient), positions="\n".join(lines)))

    wall = case.run(run_dir, np_fluid=np_fluid)

    steps = output.steps(os.path.join(run_dir, "fluid"))
    parts = output.particles(os.path.join(run_dir, "fluid"))
    axis = "xyz"[direction]
    Us = steps["meanU" + axis] - parts["U" + axis]
    K = F / (6 * math.pi * eta * a * Us)
    phi = 4.0 / 3.0 * math.pi * a ** 3 / V0
    K_h = hasimoto_K(phi)
    K_mean = float(K.mean())
    # Eq. (43): the total force of lambda on the liquid equals V0 grad P0
    eq43 = float(abs(steps["lambdaForce" + axis.upper()] + V0 * grad_p0).max() / abs(V0 * grad_p0))
    # Rigid-body motion inside the particles and the symmetry of the drag (no lift, no rotation)
    core_slip = float((steps["maxCoreSlip"] / abs(Us)).max())
    others = [d for d in "xyz" if d != axis]
    lateral = float(max(abs(parts["U" + d] - steps["meanU" + d]).max() for d in others) / abs(Us).min())
    rotation = float(max(abs(parts["W" + d]).max() for d in "xyz") * a / abs(Us).min())
    result = dict(L_over_a=L_over_a, a_over_delta=a_over_delta, b=b, c=c, tol_lambda=tol_lambda,
                  tol_u=tol_u, tol_p=tol_p, np_fluid=np_fluid, phi=phi, n_positions=n_positions,
                  cells=int(box.n[0] * box.n[1] * box.n[2]), K=K_mean, K_hasimoto=K_h,
                  rel_error=(K_mean - K_h) / K_h, sigma_K=float(K.std()), K_positions=[float(k) for k in K],
                  positions_computed=len(pts),
                  inner_iterations=[int(n) for n in steps["innerIterations"]],
                  converged=bool(steps["converged"].all()),
                  eq43_rel_error=eq43, core_slip=core_slip, lateral_velocity=lateral,
                  rotation=rotation, direction=axis, wall_seconds=wall,
                  fluid_seconds=float(steps["fluidSeconds"].sum()),
                  particle_seconds=float(steps["particleSeconds"].sum()),
                  exchange_seconds=float(steps["exchangeSeconds"].sum()))
    if not keep:
        for sub in ("fluid/constant/polyMesh", "fluid/processor0", "fluid/processor1"):
            shutil.rmtree(os.path.join(run_dir, sub), ignore_errors=True)
    return result


def plot(results, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(5, 3.6))
    Ls = sorted({r["L_over_a"] for r in results if abs(r["c"] - 0.3) < 1e-12})
    sim = [next(r for r in results if r["L_over_a"] == L and abs(r["c"] - 0.3) < 1e-12) for L in Ls]
    import numpy as np
    Lf = np.linspace(min(Ls) * 0.9, max(Ls) * 1.1, 100)
    ax.plot(Lf, [hasimoto_K(4 / 3 * math.pi / L ** 3) for L in Lf], "k-", label="Hasimoto (1958)")
    ax.errorbar(Ls, [r["K"] for r in sim], yerr=[r["sigma_K"] for r in sim], fmt="o", color="C3",
                label="fdmFoam + fdmDEM")
    ax.set_xlabel("L/a")
    ax.set_ylabel("K")
    ax.legend()
    ax.set_title("Periodic array of spheres (b, c) = (5, 0.3)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--full", action="store_true", help="L/a = 8, 10, 20 with 64 positions and the c sweep")
    p.add_argument("--L-over-a", type=float, nargs="+", default=[8.0])
    p.add_argument("--a-over-delta", type=float, default=5.0)
    p.add_argument("--positions", type=int, default=64,
                   help="lattice points in the cell, a cube: 1, 8, 27, 64 (even m: one octant computed)")
    p.add_argument("--c", type=float, nargs="+", default=[0.3], help="indicator parameter c (Eq. 36)")
    p.add_argument("--b", type=float, default=5.0, help="indicator parameter b (Eq. 37)")
    case.add_run_options(p, HERE, tol_lambda=0.0001)
    p.add_argument("--tol-u", type=float, default=1e-6)
    p.add_argument("--tol-p", type=float, default=5e-6)
    args = p.parse_args(argv)

    configs = []
    if args.full:
        for L in (8.0, 10.0, 20.0):
            configs.append(dict(L_over_a=L, c=0.3, n_positions=64))
        for c in (0.2, 0.4):
            configs.append(dict(L_over_a=8.0, c=c, n_positions=64))
    else:
        for L in args.L_over_a:
            for c in args.c:
                configs.append(dict(L_over_a=L, c=c, n_positions=args.positions))

    os.makedirs(args.workdir, exist_ok=True)
    t0 = time.time()
    results = []
    for cfg in configs:
        r = run_configuration(args.workdir, cfg["L_over_a"], args.a_over_delta, cfg["n_positions"],
                              b=args.b, c=cfg["c"], tol_lambda=args.tol_lambda, tol_u=args.tol_u,
                              tol_p=args.tol_p, np_fluid=args.np_fluid, keep=args.keep,
                              acceleration=args.acceleration)
        print("L/a %-5g a/Delta %-3g c %-4g positions %-3d  K = %.6f  K_Hasimoto = %.6f  error %+.3f %%"
              "  sigma_K %.4f  inner iterations %s  %.1f s"
              % (r["L_over_a"], r["a_over_delta"], r["c"], r["n_positions"], r["K"], r["K_hasimoto"],
                 100 * r["rel_error"], r["sigma_K"], r["inner_iterations"], r["wall_seconds"]), flush=True)
        results.append(r)

    main_result = results[0]
    summary = {k: main_result[k] for k in ("K", "K_hasimoto", "rel_error", "sigma_K", "n_positions", "cells",
                                           "L_over_a", "a_over_delta", "b", "c")}
    summary["wall_seconds"] = time.time() - t0
    summary["runs"] = results
    summary["figures"] = []
    if any(abs(r["c"] - 0.3) < 1e-12 for r in results):
        fig = os.path.splitext(args.out)[0] + "_K_vs_L.png"
        plot(results, fig)
        summary["figures"].append(os.path.basename(fig))
    with open(args.out, "w") as f:
        json.dump(summary, f, indent=2)
    print("wrote %s" % args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
