"""The Couette suspension of paper section 6.1 (Table 8, Eqs. 49-57) as the case cases/couette and the
benchmarks write it: the paper's Table 8, the largest time steps measured good with the case's springs,
the springs' rule, and the run folder (fluid/ + dem/) of one scene.

Walls y = 0 and y = L_y move at -U and +U along x (nominal shear rate gamma_dot_0 = 2U/L_y = 1), x and z
periodic; the bidisperse frictional suspension of fdmsubgrid.suspension. Units: a1 = 1 m, eta = 1 Pa s,
gamma_dot_0 = 1 1/s (time = strain). Any size distribution (packing.SizeDistribution, write_run's sizes; the
paper's radii 1 and 1.4 in equal volumes by default). docs/cases/couette.md.

    pack = packing.channel_packing((10, 12, 8), phi=0.3, seed=1, min_gap=2 * ROUGHNESS, wall_gap=2 * ROUGHNESS)
    written = write_run("runs", pack, dt=0.02, strain=3.0)      # the case's defaults otherwise
"""
from __future__ import annotations

import math
import os
import shutil

import numpy as np

from . import deminput, packing, suspension

A1 = suspension.A1
A2 = suspension.A2
ETA = suspension.ETA
SHEAR_RATE = 1.0
ROUGHNESS = suspension.ROUGHNESS   # h_r (section 6)
FRICTION = suspension.FRICTION     # mu_s (section 6)

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


# The largest time step measured good with the case's springs (phi_bulk -> dt gamma_dot_0, a1/Delta = 3,
# seed 1): the run holds (no overlap beyond h_r) and its viscosity is that of smaller steps within the error
# bars. History (docs/benchmarks.md, "Stability map", "The time step at phi 0.37 / 0.42"): the coupled
# runs' error bars (3-7 % over 8-16 strain units) could not resolve it; the particle side alone in a
# background shear (fix fdm/couple background_shear; cases/couette/timeStepWithoutFluid.py, "Without the
# fluid: the time step") does, in minutes: with k_t = k_n, dt 0.04 gives eta_r 0.7 % below dt 0.02 at
# phi_bulk 0.27, 7 % at 0.32, 12-15 % at 0.37 and 21 % at 0.42 (as the coupled runs), dt 0.02 within
# 3 % of 0.01 and 0.005 up to 0.42; at 0.47 dt 0.02 is 30 % below 0.01, which agrees with 0.005
# (14.8 +- 0.7, 21.1 +- 0.9, 20.9 +- 0.7, 2026-11-27: "What limits the time step"). What sets the limit
# is the position update: where it limits more than 0.005 gap targets per particle and step (gaps asked to
# change by more than a factor e in a step; 0.010-0.027 in the runs 12-30 % low, 0.0002-0.0027 in the good
# ones) its targets contradict each other in most steps and the particle stress is low; a run reports it
# (demonly.position_update_counts, docs/errors.md 27f). Beyond the densest measured row the
# limit is carried with the stress scale, dt proportional to 1/eta_MP(phi) (Eq. 55): the loads in the
# contacts, and the closing rates of loaded gaps, grow with it (0.0034 at 0.52, 0.0024 at 0.54).
MEASURED_DT_LIMITS = {0.27: 0.04, 0.32: 0.02, 0.37: 0.02, 0.42: 0.02, 0.47: 0.01}


# The largest fluid step measured good with particle steps between fluid steps (fix fdm/couple ... fluid_every K,
# docs/dem.md "Particle steps between fluid steps"; phi_bulk -> fluid dt gamma_dot_0, the denser row's applies,
# the densest's beyond it). Measured on the first strain unit of the small scenes, where runs from one packing
# stay together and their wall-stress curves differ by the time-step error (cases/couette/fluidEvery.py,
# docs/benchmarks.md "Particle steps between fluid steps"): the particle step sets the error, the fluid's the
# cost. At 0.42 the fluid every 0.04 with the particles at 0.02 or 0.01 is within 2.3 % of the run at 0.005
# throughout (0.04 throughout: 6.6 % low); at 0.47 the fluid every 0.02 with the particles at 0.01-0.0025 is
# within 3 % (0.02 throughout: 10 % low), every 0.04 as close on average but 8 % rms; on a second packing
# (seed 2) every 0.02 -3.8 %, every 0.04 -5.6 %, 0.02 throughout -9.7 %.
MEASURED_FLUID_DT = {0.42: 0.04, 0.47: 0.02}


def _nearest_denser(measured: dict, phi: float) -> float | None:
    """The nearest volume fraction of `measured` at or above phi (within 0.01: a measured row counts for the
    packings of its nominal phi_bulk), None beyond the densest."""
    denser = [p for p in sorted(measured) if p >= phi - 0.01]
    return denser[0] if denser else None


def fluid_dt(phi: float) -> float:
    """The fluid step [1/gamma_dot_0] at phi_bulk: MEASURED_FLUID_DT of the nearest measured row at or above
    phi (within 0.01), the densest's beyond."""
    reference = _nearest_denser(MEASURED_FLUID_DT, phi)
    return MEASURED_FLUID_DT[max(MEASURED_FLUID_DT) if reference is None else reference]


def fluid_every(phi: float, dt: float | None = None) -> int:
    """Particle steps per fluid step at phi_bulk with the particle step dt (default largest_good_dt(phi)):
    fluid_dt(phi) / dt rounded, at least 1."""
    step = largest_good_dt(phi) if dt is None else dt
    return max(1, int(round(fluid_dt(phi) / step)))


def measured_reference(phi: float) -> float | None:
    """The nearest volume fraction of MEASURED_DT_LIMITS at or above phi (within 0.01), None beyond the
    densest."""
    return _nearest_denser(MEASURED_DT_LIMITS, phi)


def largest_good_dt(phi: float, sizes: packing.SizeDistribution | None = None) -> float:
    """The largest time step [1/gamma_dot_0] measured good at measured_reference(phi); beyond the densest,
    that row's limit scaled by eta_MP(densest)/eta_MP(phi). For a size distribution other than the paper's
    (the measured one), carried over by suspension.time_step_factor (the smallest sphere's contacts)."""
    if sizes is not None and sizes != suspension.PAPER_SIZES:
        return suspension.scaled_time_step(largest_good_dt(phi), sizes)
    reference = measured_reference(phi)
    if reference is not None:
        return MEASURED_DT_LIMITS[reference]
    densest = max(MEASURED_DT_LIMITS)
    scaled = MEASURED_DT_LIMITS[densest] * (suspension.maron_pierce_viscosity(densest)
                                            / suspension.maron_pierce_viscosity(phi))
    unit = 10.0 ** (math.floor(math.log10(scaled)) - 1)
    return round(math.floor(scaled / unit * (1 + 1e-12)) * unit, 12)   # rounded down to two digits


def time_step_warning(phi: float, dt: float, sizes: packing.SizeDistribution | None = None) -> str | None:
    """A warning if dt exceeds largest_good_dt(phi, sizes), else None."""
    limit = largest_good_dt(phi, sizes)
    if dt <= limit * (1 + 1e-9):
        return None
    reference = measured_reference(phi)
    if sizes is not None and sizes != suspension.PAPER_SIZES:
        where = ("%g, the limit measured with the paper's radii 1 and 1.4 times %.3g for the radii %s (suspension."
                 "time_step_factor: the smallest sphere's contacts)" % (limit, suspension.time_step_factor(sizes),
                                                                      " ".join("%g" % r for r in sizes.radii)))
    elif reference is not None:
        where = "the largest time step measured good at phi_bulk %g with these springs, %g" % (reference, limit)
    else:
        where = ("%g, the limit at phi_bulk %g scaled by the stress, 1/eta_MP(phi) (phi_bulk %.3g is denser "
                 "than any measured)" % (limit, max(MEASURED_DT_LIMITS), phi))
    return ("WARNING: dt = %g/gamma_dot_0 is beyond %s (docs/benchmarks.md, 'What limits the time step'): "
            "expect a viscosity below that of smaller steps, or overlapping spheres; a smaller --dt is safe, "
            "and with --fluid-every K (the fluid every K steps) it costs little more: --dt %g --fluid-every %d"
            % (dt, where, limit, max(1, int(round(dt / limit)))))


def choose_springs(phi: float, dt: float, delta: float, kn: float | None = None, kt: float | None = None,
                   sizes: packing.SizeDistribution | None = None, model: str = "calibrated",
                   pair: bool = True) -> suspension.Springs:
    """The springs by the rule of the module docstring (docs/contact.md) for the shear stress
    eta gamma_dot_0 eta_MP(phi) and the sizes (default the paper's), unless given; model, pair: the scene's
    sub-grid model and whether it holds two of the smallest spheres (suspension.choose_springs)."""
    return suspension.choose_springs(ETA * SHEAR_RATE * suspension.maron_pierce_viscosity(phi), dt, delta, kn, kt,
                                     sizes, model=model, pair=pair)


def write_case(run_dir: str, pack: packing.Packing, springs: suspension.Springs, a_over_delta: float, dt: float,
               strain: float, dump_every: int, tol_lambda: float, acceleration: str, n_max: int = 50,
               write_every: int = 100000, text_dump: bool = False, model: str = "calibrated",
               fluid_options: dict | None = None, fluid_every: int = 1, held_drag: str = "extrapolated",
               calibration: deminput.SceneCalibration | None = None,
               coulomb_solve: str = suspension.COULOMB_SOLVE[0]) -> dict:
    """fluid/ and dem/ of the run (suspension.write_case with the walls at -U and +U); returns the
    scene's description. fluid_options: more arguments of case.write_fluid_case; fluid_every: particle
    steps per fluid step; held_drag: how the steps between hold the fluid's force (fix fdm/couple);
    calibration: the table the scene runs with (deminput.scene_calibration; None: the shipped one)."""
    U = SHEAR_RATE * float(pack.box[1]) / 2
    steps = int(round(strain / (SHEAR_RATE * dt)))
    scene = suspension.write_case(run_dir, pack, springs, a_over_delta, dt, steps, dump_every, tol_lambda,
                                  acceleration, n_max, write_every, text_dump, model, wall_velocities=(-U, U),
                                  name="in.couette", fluid_options=fluid_options, fluid_every=fluid_every,
                                  held_drag=held_drag, calibration=calibration, coulomb_solve=coulomb_solve)
    scene.update(wall_velocity=U)
    return scene


def species_text(pack: packing.Packing) -> str:
    """What a packing holds of each species, e.g. '21 of radius 1 (0.5 of the volume), 8 of radius 1.4 (0.5)'."""
    return ", ".join("%d of radius %g (%.3g of the volume, type %d)" % (n, a, share, t)
                     for t, a, n, share in pack.species())


def table8_row(phi: float) -> dict:
    """The paper's Table 8 row of phi_bulk."""
    return dict(zip(("phi_core", "gamma_core_over_gamma0", "size", "n_particles", "dt"), TABLE8[phi]))


# the scene refused: the calibration does not cover the packing's radii at this mesh size, not even by
# interpolation within its measured tolerance (deminput.scene_calibration)
UncalibratedScene = deminput.UncalibratedScene


def sizes_tag(sizes: packing.SizeDistribution | None) -> str:
    """The part of a run folder's name that says its size distribution: empty for the paper's, else
    '_r<radii>_f<volume fractions>' (e.g. _r1-1.2-1.4_f0.5-0.3-0.2)."""
    if sizes is None or sizes == suspension.PAPER_SIZES:
        return ""
    return "_r%s_f%s" % ("-".join("%.4g" % r for r in sizes.radii), "-".join("%.3g" % f for f in sizes.volume_fractions))


def run_name(phi: float, size, a_over_delta: float, dt: float, seed: int, acceleration: str = "anderson",
             model: str = "calibrated", fluid_every: int = 1, table8: bool = False,
             sizes: packing.SizeDistribution | None = None, coulomb_solve: str = suspension.COULOMB_SOLVE[0]) -> str:
    """The run folder's name: the scene's phi_bulk (the packing's, or Table 8's row), box, mesh, step, seed and
    the options that change the run (the size distribution if not the paper's: sizes_tag)."""
    name = "phi%g_%gx%gx%g_ad%g_dt%g_seed%d%s" % (phi, *size, a_over_delta, dt, seed,
                                                  ("" if acceleration == "anderson" else "_" + acceleration)
                                                  + "_" + model)
    if fluid_every > 1:
        name += "_fluidEvery%d" % fluid_every
    name += suspension.coulomb_tag(coulomb_solve) + sizes_tag(sizes)
    if table8:
        name = "table8_" + name
    return name


def write_run(workdir: str, size, dt: float, strain: float, phi: float | None = None, n_particles: int | None = None,
              seed: int = 1, a_over_delta: float = 3.0, dump_every: float = 0.1, write_every: float = 1.0,
              tol_lambda: float = 1e-3, acceleration: str = "anderson", n_max: int = 50, text_dump: bool = False,
              model: str = "calibrated", fluid_every: int = 1, held_drag: str = suspension.HELD_DRAG[0],
              kn: float | None = None, kt: float | None = None, table8: bool = False,
              overwrite: bool = False, sizes: packing.SizeDistribution | None = None,
              coulomb_solve: str = suspension.COULOMB_SOLVE[0]) -> dict:
    """One Couette scene written in workdir/<run_name>/ (fluid/ and dem/), printing the packing, the springs
    and a warning if dt is beyond the measured limit: the random packing of phi_bulk `phi` (or of
    n_particles spheres, a Table 8 row: table8 names the folder after it) in the box `size` (a1), the springs
    of choose_springs (kn, kt if given), strain/dt steps with a snapshot every dump_every and the fields every
    write_every strain units (on steps the fluid solves: multiples of fluid_every). The defaults are
    cases/couette/couette.py's; sizes: the size distribution (packing.SizeDistribution, default the paper's).
    SizeDistributionError if the mesh does not resolve the smallest sphere (suspension.check_resolution),
    UncalibratedScene if the calibration does not cover the packing's radii, not even interpolated within its
    measured 2 % (its message one line per refused pair, deminput.scene_calibration; where it does, the
    interpolated table is written into dem/ and a line says so), FileExistsError if the folder exists and not overwrite. Returns dict(run_dir, name, pack, springs,
    dump_every_steps, scene) with the scene's description (write_case)."""
    delta = A1 / a_over_delta
    suspension.check_resolution(sizes or suspension.PAPER_SIZES, a_over_delta)
    pack = packing.channel_packing(size, phi=None if n_particles else phi, n=n_particles, seed=seed,
                                   min_gap=2 * ROUGHNESS, wall_gap=2 * ROUGHNESS, sizes=sizes)
    print("packing:", pack.summary())
    calibration = deminput.scene_calibration("couette", pack.radii, delta, walls=True, model=model)
    if calibration.line():
        print(calibration.line(), flush=True)
    springs = choose_springs(pack.phi, dt, delta, kn, kt, sizes, model=model,
                             pair=suspension.holds_smallest_pair(pack.radii))
    print(springs.describe(dt))
    warning = time_step_warning(pack.phi, dt, sizes)
    if warning:
        print(warning, flush=True)

    name = run_name(pack.phi if n_particles is None or phi is None else phi, size, a_over_delta, dt, seed, acceleration, model,
                    fluid_every, table8, sizes, coulomb_solve)
    run_dir = os.path.join(workdir, name)
    if os.path.exists(run_dir):
        if not overwrite:
            raise FileExistsError("couette: %s already holds a run; --overwrite replaces it" % run_dir)
        shutil.rmtree(run_dir)
    # snapshots on steps the fluid solved: multiples of K
    K = fluid_every
    every = K * max(1, int(round(dump_every / (SHEAR_RATE * dt * K))))
    write_every_steps = K * max(1, int(round(write_every / (SHEAR_RATE * dt * K))))
    scene = write_case(run_dir, pack, springs, a_over_delta, dt, strain, every, tol_lambda, acceleration, n_max,
                       write_every_steps, text_dump, model, fluid_every=fluid_every, held_drag=held_drag,
                       calibration=calibration, coulomb_solve=coulomb_solve)
    print("wrote %s: %d spheres (%s), phi %.4f, box %s a1, %d cells, %d steps of dt %g, a snapshot every %d steps"
          % (run_dir, pack.n, species_text(pack), pack.phi, " x ".join("%g" % v for v in size), scene["cells"],
             scene["steps"], dt, every))
    return dict(run_dir=run_dir, name=name, pack=pack, springs=springs, dump_every_steps=every, scene=scene)
