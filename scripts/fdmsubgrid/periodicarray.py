"""The periodic array of spheres (paper section 5.1): the drag coefficient K of a simple cubic array
against Hasimoto's (Eq. 41, with Sangani & Acrivos's further terms), computed by the coupled solver.
The case script cases/periodicArray/periodicArray.py and scripts/benchmarkPeriodicArray.py run it."""
from __future__ import annotations

import math
import os
import shutil

from . import deminput, foamcase, output, runner


def hasimoto_K(phi: float) -> float:
    """Eq. (41) with the further terms of Sangani & Acrivos (1982) for a simple cubic array."""
    c13 = phi ** (1.0 / 3.0)
    return 1.0 / (1 - 1.7601 * c13 + phi - 1.5593 * phi ** 2 + 3.9799 * phi ** (8.0 / 3.0)
                  - 3.0734 * phi ** (10.0 / 3.0))


def positions_in_cell(n_positions: int, corner, delta: float) -> tuple[list, int]:
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
{hold}
fix             couple all fdm/couple portfile ../fluid/coupling.port move no
{positions}
"""


def run_configuration(workdir: str, L_over_a: float, a_over_delta: float, n_positions: int, b=5.0, c=0.3, tol_lambda=1e-4,
                      tol_first=None, n_max=2000, tol_u=1e-6, tol_p=5e-6, np_fluid=1,
                      pseudo_time_factor=1.0, direction=0, points=None, keep=False, acceleration="anderson") -> dict:
    """One periodic-array configuration (paper 5.1, Eqs. 41-43): a sphere of radius a = 1 in a cubic
    periodic box of side L_over_a, mesh a/Delta = a_over_delta, held by the force that balances the
    imposed pressure gradient along `direction`, visited at n_positions lattice points of one mesh
    cell (positions_in_cell) or at `points`, one coupled step each. Returns the drag coefficient K
    (mean over the positions, each K = F/(6 pi eta a U_s)), its error against hasimoto_K, the
    Eq. (43) balance, rigid-body and symmetry errors, inner iterations and times (a dict)."""
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
    box = foamcase.Box((0, 0, 0), (L, L, L), delta)
    # the cell whose lower corner is the node nearest the centre of the box
    corner = [round(L / 2 / delta) * delta] * 3
    pts = list(points) if points else positions_in_cell(n_positions, corner, delta)[0]
    foamcase.write_fluid_case(os.path.join(run_dir, "fluid"), box, nu=nu, rho=rho, grad_p0=tuple(gradient),
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
                                 skin=0.1 * a, dt=1.0, hold=deminput.balancing_force_line(box, gradient),
                                 positions="\n".join(lines)))

    wall = runner.run(run_dir, np_fluid=np_fluid)

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
