#!/usr/bin/env python3
"""A frictional bidisperse suspension in plane Couette flow (paper section 6.1, Table 8, Eqs. 49-57).

Walls y = 0 and y = L_y move at -U and +U along x (nominal shear rate gamma_dot_0 = 2U/L_y = 1),
x and z are periodic. The suspension: spheres of radii a1 = 1 and a2 = 1.4 a1 in equal volumes
(phi_1 = phi_2 = phi_bulk/2), placed at random without overlap and clear of the walls
(fdm.packing.channel_packing), frictional contact with h_r = 5e-3 a1 and mu_s = 0.5 (pairs and
walls), sub-grid lubrication for pairs and walls, stresslets on. Units: a1 = 1 m, eta = 1 Pa s,
gamma_dot_0 = 1 1/s (time = strain).

The contact springs follow the rules of docs/contact.md ("A recipe"), computed and printed:
  F_max = 6 pi eta a2^2 gamma_dot_0 eta_MP(phi)      the design load: the Stokes drag scale of the large
                                                     sphere times the suspension's relative viscosity
                                                     from the paper's Maron-Pierce fit (Eq. 55:
                                                     alpha = 0.803, phi_m = 0.59)
  k_n   = 2 F_max / h_r                              a contact under F_max sits at h = h_r/2 (recipe step 2)
  k_t   = min(k_n, 0.5 zeta_t / dt)                  the tangential spring within half its explicit ab2
                                                     limit: the implicit tangential springs are not stable
                                                     at k_t dt/zeta_t of 100 or more in a suspension
                                                     (docs/benchmarks.md, "Stability map": k_t = k_n
                                                     blew up phi 0.47 at dt 0.02 within 10 steps)
with zeta_n, zeta_t the normal and slip resistances of a free a1-a1 pair at the gap h_r/2 (Stokes drag
plus the sub-grid block at this a1/Delta, fdmResistance); the time steps zeta_n/k_n and zeta_t/k_t
that would bound explicit springs (ab2) are printed.

  couette.py                         the small scene (about 40 spheres, 10 x 12 x 8 a1, a1/Delta = 3,
                                     3 strain units at dt = 0.02): a few minutes
  couette.py --acceleration none     the same with the plain inner iteration (issue 13, benchmark c)
  couette.py --table8 0.27           writes the paper's Table 8 scene for phi_bulk = 0.27 (box, N_P, dt)
                                     and stops (run it with fdmRun, or --run)
  couette.py --help                  every option
Writes <workdir>/<run>/ (fluid/, dem/), results.json and results_couette.png here (docs/cases.md).
"""

import argparse
import json
import math
import os
import re
import shutil
import sys
import time
import dataclasses
from dataclasses import asdict, dataclass

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "scripts"))
from fdm import case, output, packing, profiles, rheology, theory  # noqa: E402

A1 = 1.0
TANGENTIAL_SAFETY = 0.5       # k_t dt / zeta_t of the rule (docs/contact.md recipe step 4)
A2 = packing.A2_OVER_A1 * A1
ETA = 1.0
SHEAR_RATE = 1.0
ROUGHNESS = 5e-3 * A1        # h_r (section 6)
FRICTION = 0.5               # mu_s (section 6)
MARON_PIERCE = (0.803, 0.59)  # alpha, phi_m of the paper's fit (Eq. 55, Fig. 21)
PAIR_CUTOFF = 0.65            # pair_style fdm/subgrid default cut-off (mesh cells)

# Table 8: phi_bulk -> (phi_core, gamma_core/gamma_0, (Lx, Ly, Lz)/a1, N_P, dt)
TABLE8 = {
    0.27: (0.303, 0.923, (20, 20, 20), 350, 1e-4),
    0.32: (0.359, 0.885, (20, 20, 20), 416, 1e-4),
    0.37: (0.405, 0.873, (20, 20, 20), 481, 1e-4),
    0.42: (0.458, 0.773, (20, 20, 20), 547, 1e-4),
    0.47: (0.493, 0.745, (25, 25, 20), 956, 1e-4),
    0.52: (0.543, 0.563, (25, 25, 20), 1057, 1e-4),
    0.54: (0.570, 0.391, (25, 25, 20), 1098, 2e-5),
}


@dataclass(frozen=True)
class Springs:
    """The contact parameters of pair_style fdm/subgrid and how they were chosen."""

    kn: float
    kt: float
    mu_s: float
    h_r: float
    design_load: float
    zeta_n: float
    zeta_t: float
    dt_limit_normal: float
    dt_limit_tangential: float

    def describe(self, dt: float) -> str:
        return ("contact springs (docs/contact.md recipe): design load F_max = %.4g N, kn = 2 F_max/h_r = %.4g N/m, "
                "kt = %.4g N/m, mu_s = %g, h_r = %g a1; a1-a1 pair at h_r/2: zeta_n = %.4g, zeta_t = %.4g N s/m; "
                "explicit springs would need dt below (ab2) %.4g normal, %.4g tangential (the springs are implicit; "
                "k_t is kept at half its limit), dt = %g is %.2f of the smaller"
                % (self.design_load, self.kn, self.kt, self.mu_s, self.h_r / A1, self.zeta_n, self.zeta_t,
                   self.dt_limit_normal, self.dt_limit_tangential, dt,
                   dt / min(self.dt_limit_normal, self.dt_limit_tangential)))


def pair_mode_resistances(a_i: float, a_j: float, gap: float, delta: float, eta: float = ETA,
                          cutoff: float = PAIR_CUTOFF) -> tuple[float, float]:
    """(zeta_n, zeta_t) of two free spheres at surface gap `gap`: the force per unit closing speed
    under equal and opposite loads along the line of centres, and per unit slip speed of the contact
    points under equal and opposite tangential loads there (with their torques); the resistance is
    the isolated Stokes drag (6 pi eta a, 8 pi eta a^3) plus the sub-grid pair block of fdmResistance
    (Eq. 21), as in Eq. (31) without the fluid's resolved part (docs/contact.md, 3c)."""
    out = theory.resistance("matrix", "--x1", 0, 0, 0, "--x2", "%.17g" % (a_i + a_j + gap), 0, 0, "--a1", a_i,
                            "--a2", a_j, "--delta", "%.17g" % delta, "--eta", eta, "--cutoff", cutoff)
    drag = [6 * math.pi * eta * a_i] * 3 + [8 * math.pi * eta * a_i ** 3] * 3 \
        + [6 * math.pi * eta * a_j] * 3 + [8 * math.pi * eta * a_j ** 3] * 3
    resistance = np.diag(drag) + np.array(out["R"])
    d = np.array([1.0, 0.0, 0.0])       # from sphere i to sphere j
    t = np.array([0.0, 1.0, 0.0])
    zero = np.zeros(3)
    u = np.linalg.solve(resistance, np.concatenate([-d, zero, d, zero]))   # pulled apart
    zeta_n = 1.0 / float((u[6:9] - u[0:3]) @ d)
    u = np.linalg.solve(resistance, np.concatenate([t, np.cross(a_i * d, t), -t, np.cross(-a_j * d, -t)]))
    slip = u[0:3] + np.cross(u[3:6], a_i * d) - u[6:9] - np.cross(u[9:12], -a_j * d)
    zeta_t = 1.0 / float(slip @ t)
    return zeta_n, zeta_t


def choose_springs(phi: float, dt: float, delta: float, kn: float | None = None, kt: float | None = None) -> Springs:
    """The springs by the rule of the module docstring (docs/contact.md), unless given."""
    alpha, phi_m = MARON_PIERCE
    relative_viscosity = alpha / (1.0 - min(phi, 0.9 * phi_m) / phi_m) ** 2
    design_load = 6 * math.pi * ETA * A2 ** 2 * SHEAR_RATE * relative_viscosity
    zeta_n, zeta_t = pair_mode_resistances(A1, A1, 0.5 * ROUGHNESS, delta)
    kn = 2.0 * design_load / ROUGHNESS if kn is None else kn
    # k_t dt/zeta_t <= 0.5: stiffer implicit tangential springs blew up dense suspensions (growth x10
    # per step at k_t dt/zeta_t ~ 300-400, docs/benchmarks.md "Stability map")
    kt = min(kn, TANGENTIAL_SAFETY * zeta_t / dt) if kt is None else kt
    return Springs(kn, kt, FRICTION, ROUGHNESS, design_load, zeta_n, zeta_t, zeta_n / kn, zeta_t / kt)


def write_case(run_dir: str, pack: packing.Packing, springs: Springs, a_over_delta: float, dt: float, strain: float,
               dump_every: int, tol_lambda: float, acceleration: str, n_max: int = 50, write_every: int = 100000,
               text_dump: bool = False) -> dict:
    """fluid/ and dem/ of the run; returns the scene's description. The particles are recorded every
    dump_every steps in dem/particles.records (fix fdm/output), and written for ParaView with the
    fluid fields every write_every steps (dem/vtk/particles.pvd, fluid/fluid.foam); text_dump: also
    the LIGGGHTS text dump dem/particles.dump of the same steps (for comparisons)."""
    delta = A1 / a_over_delta
    Lx, Ly, Lz = (float(v) for v in pack.box)
    U = SHEAR_RATE * Ly / 2
    box = case.Box((0, 0, 0), (Lx, Ly, Lz), delta, faces=("cyclic", ((-U, 0, 0), (U, 0, 0)), "cyclic"))
    steps = int(round(strain / (SHEAR_RATE * dt)))
    case.write_fluid_case(os.path.join(run_dir, "fluid"), box, nu=ETA, rho=1.0, tol_lambda=tol_lambda, n_max=n_max,
                          first_step=(tol_lambda / 10, 3000), n_particles=pack.n, tol_u=1e-5, tol_p=1e-3,
                          acceleration=acceleration, write_interval=write_every)
    pair = ("fdm/subgrid contact %r %r %r %r wall ylo %r 0 0 wall yhi %r 0 0"
            % (springs.kn, springs.kt, springs.mu_s, springs.h_r, -U, U))
    spheres = [tuple(x) + (float(a), int(t)) for x, a, t in zip(pack.positions, pack.radii, pack.types)]
    runs = (["fix             output all fdm/output records %d particles.records vtk %d vtk"
             % (dump_every, write_every)]
            + (output.dump_custom_command("particles", dump_every, "particles.dump") if text_dump else [])
            + ["thermo_style    custom step f_couple[1] f_couple[2] f_couple[6] f_couple[7] f_couple[8]",
               "thermo          %d" % dump_every,
               "run             %d upto" % steps])   # upto: a resumed run ends at the same step
    # a checkpoint every 10 snapshots and at the end: fdmRun --resume continues a killed run (docs/coupling.md)
    case.write_dem_input(os.path.join(run_dir, "dem"), box, spheres, dt=dt, pair_style=pair,
                         fix_options="stresslets yes checkpoint %d walls walls.dat" % (10 * dump_every), runs=runs, name="in.couette")
    return dict(box=[Lx, Ly, Lz], cells=box.n[0] * box.n[1] * box.n[2], mesh=list(box.n), steps=steps,
                wall_velocity=U, dt=dt, dump_every=dump_every, write_every=write_every)


def minimum_gaps(snapshots: list[profiles.Snapshot], box: np.ndarray) -> tuple[float, float]:
    """Smallest surface gap between spheres and between a sphere and a wall over the snapshots."""
    pair, wall = math.inf, math.inf
    for s in snapshots:
        pair = min(pair, _pair_gap(s, box))
        wall = min(wall, float(np.min(np.minimum(s.positions[:, 1] - s.radii, box[1] - s.positions[:, 1] - s.radii))))
    return pair, wall


def _pair_gap(s: profiles.Snapshot, box: np.ndarray) -> float:
    i, j, d = packing.neighbour_pairs(s.positions, box, 2 * float(s.radii.max()) + 0.5, walls=(1,))
    return float(np.min(d - s.radii[i] - s.radii[j])) if len(i) else math.inf


def analyse(run_dir: str, scene: dict, pack: packing.Packing, wall_seconds: float, ranks: int,
            h_layer: float) -> tuple[dict, list]:
    """results of one run: the profiles and rheology (fdm.profiles, fdm.rheology), the inner
    iterations, the gaps."""
    fluid = os.path.join(run_dir, "fluid")
    steps = output.steps(fluid)
    snapshots, _ = output.record_snapshots(os.path.join(run_dir, "dem", "particles.records"), SHEAR_RATE)
    box = np.array(scene["box"])
    channel = profiles.Channel((0, 0, 0), tuple(box))
    phi_integral = [profiles.bulk_volume_fraction(s, channel) for s in snapshots]
    series = profiles.core_series(snapshots, channel, h_layer=h_layer)
    if len(snapshots) >= 16:
        r = rheology.shear_rheology(series, eta=ETA)    # the steady part from MSER-m (docs/profiles.md)
    elif len(snapshots) >= 8:  # too few snapshots for the transient rule: the last 8 or more, flagged
        r = rheology.shear_rheology(series, eta=ETA, start_time=float(series.times[min(len(snapshots) // 2,
                                                                                          len(snapshots) - 8)]))
        r = dataclasses.replace(r, steady=False)
    else:
        raise ValueError("couette: %d particle snapshots are too few for time averages (8 at least): run longer "
                         "or lower --dump-every" % len(snapshots))
    # the momentum balance (docs/profiles.md "Stress balance"): the core stress of Eq. 51 against the
    # walls' shear stress (fluid traction + sub-grid lubrication + contact), both over the steady part;
    # and at every snapshot the gap-averaged stress against the mean of the two walls (exact)
    loads = output.read_wall_loads(run_dir)
    balance = rheology.stress_balance(r, loads, channel, SHEAR_RATE)
    tau = rheology.wall_shear_stresses(loads, channel)["total"].mean(axis=1)
    step_of = {int(st): k for k, st in enumerate(loads.steps)}
    gap_errors = []
    for s in snapshots:
        k = step_of.get(int(round(s.time / (SHEAR_RATE * scene["dt"]))))
        if k is not None:
            gap = rheology.gap_shear_stress(s, channel, ETA, 2 * scene["wall_velocity"] / box[1])
            gap_errors.append(rheology.relative_difference(gap, float(tau[k])))
    avg = profiles.average_profiles(snapshots, channel, start_time=r.start_time)
    fine = profiles.average_profiles(snapshots, channel, y=channel.planes(0.02), start_time=r.start_time, errors=False)
    pair_gap, wall_gap = minimum_gaps(snapshots, box)
    strain = float(steps["time"][-1] * SHEAR_RATE)
    inner = steps["innerIterations"]

    def est(e: rheology.Estimate) -> float:
        return float(e.value)

    res = dict(
        phi_bulk=pack.phi, phi_bulk_integral_max_error=float(np.max(np.abs(np.array(phi_integral) - pack.phi))),
        phi_core=est(r.phi_core), phi_core_err=r.phi_core.error,
        gamma_core_over_gamma0=est(r.gamma_dot_core) / SHEAR_RATE, gamma_core_err=r.gamma_dot_core.error,
        eta_s=est(r.eta_s), eta_s_err=r.eta_s.error, eta_s_n_eff=r.eta_s.n_eff,
        N1_hat=est(r.n1_hat), N1_hat_err=r.n1_hat.error, N2_hat=est(r.n2_hat), N2_hat_err=r.n2_hat.error,
        Sigma_c_hat=[est(e) for e in r.sigma_c_hat], Sigma_c_hat_err=[e.error for e in r.sigma_c_hat],
        strain_units=strain, steady_from_strain=r.start_time, steady_detected=r.steady, samples_averaged=r.n_samples,
        h_layer=h_layer, n_particles=pack.n, n_a1=int(np.sum(pack.types == 1)), n_a2=int(np.sum(pack.types == 2)),
        cells=scene["cells"], mesh=scene["mesh"], box=scene["box"], dt=scene["dt"], steps=int(len(inner)),
        wall_seconds=wall_seconds, ranks=ranks,
        core_seconds_per_strain_unit=wall_seconds * ranks / strain,
        inner_iterations_mean=float(inner.mean()), inner_iterations_max=int(inner.max()),
        unconverged_steps=int(np.sum(steps["converged"] == 0)),
        min_pair_gap=pair_gap, min_wall_gap=wall_gap,
        mean_particle_velocity=np.mean([s.velocities.mean(axis=0) for s in snapshots], axis=0).tolist(),
        snapshots=len(snapshots))
    res.update(balance.as_dict())
    res.update(stress_gap_rel_error_max=float(np.max(gap_errors)) if gap_errors else float("nan"),
               stress_gap_snapshots=len(gap_errors))
    return res, [channel, avg, fine, snapshots]


def table8_row(phi: float) -> dict:
    """The paper's Table 8 row of phi_bulk."""
    return dict(zip(("phi_core", "gamma_core_over_gamma0", "size", "n_particles", "dt"), TABLE8[phi]))


def report(run_dir: str, scene: dict, pack: packing.Packing, wall: float, ranks: int, h_layer: float, out: str,
           extra: dict) -> dict:
    """analyse() the run, write `out` (results.json, with `extra`) and the profile figure beside it,
    print the summary; returns the results."""
    results, (channel, avg, fine, _) = analyse(run_dir, scene, pack, wall, ranks, h_layer)
    results.update(extra)
    figure = os.path.join(os.path.dirname(os.path.abspath(out)), "results_couette.png")
    if out.endswith(".json") and os.path.basename(out) != "results.json":
        figure = out[:-len(".json")] + ".png"
    profiles.plot_profiles(figure, channel, avg, fine)
    results["figure"] = os.path.basename(figure)
    with open(out, "w") as f:
        json.dump(results, f, indent=1)
    keys = ("phi_bulk phi_core gamma_core_over_gamma0 eta_s eta_s_err N1_hat N2_hat Sigma_c_hat strain_units "
            "steady_from_strain n_particles cells dt wall_seconds core_seconds_per_strain_unit inner_iterations_mean "
            "inner_iterations_max unconverged_steps min_pair_gap min_wall_gap").split()
    for k in keys:
        print("%-30s %s" % (k, results[k]))
    print("stress balance (Eq. 51 core against the walls, from strain %g, %d steps):"
          % (results["stress_balance_from_strain"], results["stress_balance_steps"]))
    print("  core  eta gamma_core + Sigma^h_12 + Sigma^c_12 = %.4g +- %.2g" % (results["stress_core"],
                                                                           results["stress_core_err"]))
    print("  walls %.4g +- %.2g (low %.4g, high %.4g): fluid %.4g + sub-grid %.3g + contact %.3g"
          % tuple(results[k] for k in ("stress_wall", "stress_wall_err", "stress_wall_lo", "stress_wall_hi",
                                       "stress_wall_fluid", "stress_wall_subgrid", "stress_wall_contact")))
    print("  stress_balance_rel_error = %.4g +- %.2g; gap-averaged stress against the walls at the %d snapshots: "
          "at most %.2g" % (results["stress_balance_rel_error"], results["stress_balance_rel_error_err"],
                            results["stress_gap_snapshots"], results["stress_gap_rel_error_max"]))
    print("wrote %s and %s" % (out, figure))
    return results


def read_run(run_dir: str) -> tuple[dict, packing.Packing, dict]:
    """(scene, packing, springs) of a run folder written by write_case, from its own files (the
    packing data, blockMeshDict, the LIGGGHTS input): what --analyse needs to analyse a run that
    was resumed, stopped or is still going."""
    pack = packing.read_data(os.path.join(run_dir, "dem", "packing.data"), walls=(1,))
    with open(os.path.join(run_dir, "fluid", "system", "blockMeshDict")) as f:
        mesh = [int(v) for v in re.search(r"hex \([\d ]+\) \((\d+) (\d+) (\d+)\)", f.read()).groups()]
    with open(os.path.join(run_dir, "dem", "in.couette")) as f:
        dem = f.read()
    dt = float(re.search(r"^timestep\s+(\S+)", dem, re.M).group(1))
    steps = int(re.search(r"^run\s+(\d+)", dem, re.M).group(1))
    contact = re.search(r"fdm/subgrid contact (\S+) (\S+) (\S+) (\S+)", dem)
    springs = dict(zip(("kn", "kt", "mu_s", "h_r"), (float(v) for v in contact.groups()))) if contact else {}
    box = [float(v) for v in pack.box]
    scene = dict(box=box, cells=mesh[0] * mesh[1] * mesh[2], mesh=mesh, steps=steps,
                 wall_velocity=SHEAR_RATE * box[1] / 2, dt=dt)
    return scene, pack, springs


def run_seconds(run_dir: str) -> tuple[float, int]:
    """(wall seconds, ranks) of a run from its step records (the sum over sessions of a resumed run:
    fluid solve + particle work + exchange of every step), ranks: fluid processor folders (or 1)
    plus one particle rank."""
    steps = output.steps(os.path.join(run_dir, "fluid"))
    seconds = float(np.sum(steps["fluidSeconds"]) + np.sum(steps["particleSeconds"]) + np.sum(steps["exchangeSeconds"]))
    fluid_ranks = len([d for d in os.listdir(os.path.join(run_dir, "fluid")) if d.startswith("processor")]) or 1
    return seconds, fluid_ranks + 1


def main(argv: list[str] | None = None) -> dict:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--phi", type=float, default=0.3, help="phi_bulk, the volume fraction of the spheres in the box")
    p.add_argument("--size", type=float, nargs=3, default=[10.0, 12.0, 8.0], metavar=("LX", "LY", "LZ"),
                   help="box in units of a1 (walls normal to y); each a whole number of cells")
    p.add_argument("--a-over-delta", type=float, default=3.0, help="a1/Delta, mesh cells per small radius")
    p.add_argument("--dt", type=float, default=None, help="time step in units of 1/gamma_dot_0 (default 0.02; "
                   "with --table8, Table 8's)")
    p.add_argument("--strain", type=float, default=3.0, help="strain units to run")
    p.add_argument("--seed", type=int, default=1, help="seed of the random packing")
    p.add_argument("--dump-every", type=float, default=0.1, help="strain between two particle snapshots")
    p.add_argument("--write-every", type=float, default=1.0, help="strain between two writes of the fluid fields "
                   "and of the particles' ParaView files (dem/vtk/particles.pvd; the fluid fields are deleted after the run unless --keep)")
    p.add_argument("--text-dump", action="store_true", help="also write the LIGGGHTS text dump dem/particles.dump "
                   "(the binary records dem/particles.records are what the analysis reads)")
    p.add_argument("--h-layer", type=float, default=5.0, help="H_layer/a1: the core is |y| < L_y/2 - H_layer")
    p.add_argument("--kn", type=float, default=None, help="normal spring [N/m] (default: the rule above)")
    p.add_argument("--kt", type=float, default=None, help="tangential spring [N/m] (default: the rule above)")
    p.add_argument("--n-max", type=int, default=50, help="fdmFoam's innerIterations nMax: a step that reaches it "
                   "unconverged is counted in unconverged_steps")
    p.add_argument("--np-dem", type=int, default=1, help="MPI ranks of fdmDEM")
    p.add_argument("--table8", type=float, default=None, metavar="PHI",
                   help="the paper's Table 8 scene for phi_bulk = PHI (box, N_P, dt): written, not run")
    p.add_argument("--run", action="store_true", help="with --table8: run it too")
    p.add_argument("--overwrite", action="store_true", help="replace a run folder that already exists")
    p.add_argument("--analyse", metavar="RUN_DIR", default=None,
                   help="analyse this run folder as it stands (a resumed, stopped or running run) and write --out")
    case.add_run_options(p, HERE, tol_lambda=1e-3)
    args = p.parse_args(argv)

    if args.analyse:
        # a run folder as it stands (finished, stopped or still going): its own files say the scene
        scene, pack, springs_used = read_run(args.analyse)
        wall, ranks = run_seconds(args.analyse)
        name = os.path.basename(os.path.normpath(args.analyse))
        table8 = None
        if name.startswith("table8_"):
            table8 = table8_row(min(TABLE8, key=lambda k: abs(k - pack.phi)))
        return report(args.analyse, scene, pack, wall, ranks, args.h_layer, args.out,
                      dict(case="couette", run=name, run_dir=os.path.abspath(args.analyse), springs=springs_used,
                           steps_planned=scene["steps"], table8=table8))

    n_particles = None
    phi = args.phi
    if args.table8 is not None:
        key = min(TABLE8, key=lambda k: abs(k - args.table8))
        if abs(key - args.table8) > 1e-9:
            p.error("--table8 %g: Table 8 has phi_bulk = %s" % (args.table8, ", ".join("%g" % k for k in TABLE8)))
        _, _, size, n_particles, dt_paper = TABLE8[key]
        args.size, phi = list(size), key
        args.dt = dt_paper if args.dt is None else args.dt
    dt = 0.02 if args.dt is None else args.dt
    delta = A1 / args.a_over_delta
    for L, name in zip(args.size, "xyz"):
        if abs(L / delta - round(L / delta)) > 1e-9 * L / delta:
            p.error("--size: L%s = %g a1 is not a whole number of cells of a1/%g" % (name, L, args.a_over_delta))
    if args.strain <= 0 or dt <= 0:
        p.error("--strain and --dt must be positive")

    pack = packing.channel_packing(args.size, phi=None if n_particles else phi, n=n_particles, seed=args.seed,
                                   min_gap=2 * ROUGHNESS, wall_gap=2 * ROUGHNESS)
    print("packing:", pack.summary())
    springs = choose_springs(pack.phi, dt, delta, args.kn, args.kt)
    print(springs.describe(dt))

    name = "phi%g_%gx%gx%g_ad%g_dt%g_seed%d%s" % (pack.phi if n_particles is None else phi, *args.size,
                                                  args.a_over_delta, dt, args.seed,
                                                  "" if args.acceleration == "anderson" else "_" + args.acceleration)
    if args.table8 is not None:
        name = "table8_" + name
    run_dir = os.path.join(args.workdir, name)
    if os.path.exists(run_dir):
        if not args.overwrite:
            raise SystemExit("couette: %s already holds a run; --overwrite replaces it" % run_dir)
        shutil.rmtree(run_dir)
    every = max(1, int(round(args.dump_every / (SHEAR_RATE * dt))))
    write_every = max(1, int(round(args.write_every / (SHEAR_RATE * dt))))
    scene = write_case(run_dir, pack, springs, args.a_over_delta, dt, args.strain, every, args.tol_lambda,
                       args.acceleration, args.n_max, write_every, args.text_dump)
    packing.write_data(os.path.join(run_dir, "dem", "packing.data"), pack)
    print("wrote %s: %d spheres (%d a1, %d a2), phi %.4f, box %s a1, %d cells, %d steps of dt %g, a snapshot "
          "every %d steps" % (run_dir, pack.n, np.sum(pack.types == 1), np.sum(pack.types == 2), pack.phi,
                              " x ".join("%g" % v for v in args.size), scene["cells"], scene["steps"], dt, every))
    if args.table8 is not None and not args.run:
        print("Table 8 scene written, not run: fdmRun -f N -d M %s" % run_dir)
        return dict(run_dir=run_dir, **scene)

    wall = case.run(run_dir, np_fluid=args.np_fluid, np_dem=args.np_dem)
    results = report(run_dir, scene, pack, wall, args.np_fluid + args.np_dem, args.h_layer, args.out,
                     dict(case="couette", run=name, run_dir=run_dir, acceleration=args.acceleration,
                          tol_lambda=args.tol_lambda, n_max=args.n_max, a_over_delta=args.a_over_delta,
                          seed=args.seed, springs=asdict(springs),
                          table8=None if args.table8 is None else table8_row(phi)))
    if not args.keep:
        fluid = os.path.join(run_dir, "fluid")
        shutil.rmtree(os.path.join(fluid, "constant", "polyMesh"), ignore_errors=True)
        for d in os.listdir(fluid):
            if d != "0" and d.replace(".", "").replace("e-", "").isdigit():
                shutil.rmtree(os.path.join(fluid, d), ignore_errors=True)
    return results


if __name__ == "__main__":
    main()
