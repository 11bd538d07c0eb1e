"""The scene of a frictional bidisperse suspension between two walls (paper section 6): the contact
springs by the rules of docs/contact.md and the fluid and particle inputs of a run, shared by the
Couette (cases/couette, section 6.1) and Poiseuille (cases/poiseuille, section 6.2) cases.

Units: a1 = 1 m, eta = 1 Pa s. The suspension: by default the paper's spheres of radii a1 and a2 = 1.4 a1 in
equal volumes, or any size distribution (packing.SizeDistribution: radii in units of a1 with their shares of
the particle volume, one LIGGGHTS atom type per species; fdmsubgrid.packing.channel_packing), frictional contact with h_r = 5e-3 a1 and mu_s = 0.5 (pairs and
walls), sub-grid lubrication for pairs and walls, stresslets on. The walls are normal to y, x and z
periodic; each wall moves along x at its own speed, and a uniform pressure gradient may drive the flow.

The contact springs (docs/contact.md, "A recipe"):
  F_max = 6 pi a_max^2 tau                           the design load: the Stokes drag scale of the largest
                                                     sphere (a2 = 1.4 a1 in the paper's suspension) under
                                                     the suspension's shear stress tau
                                                     (Couette: eta gamma_dot_0 eta_MP(phi), the relative
                                                     viscosity from the paper's Maron-Pierce fit, Eq. 55;
                                                     Poiseuille: the wall shear stress |dP0/dx| L_y/2)
  k_n   = 2 F_max / h_r                              a contact under F_max sits at h = h_r/2 (recipe step 2)
  k_t   = k_n                                        recipe step 3, whatever dt: the implicit springs with
                                                     Coulomb's law at the end of the step (docs/contact.md
                                                     2c) hold at any k_t dt/zeta_t (docs/benchmarks.md,
                                                     "Coulomb's law at the end of the step")
with zeta_n, zeta_t the normal and slip resistances of a free pair of the smallest spheres at the gap h_r/2
(Stokes drag plus the sub-grid block of the scene's sub-grid model at this a1/Delta, fdmResistance; the
contact points in the middle of the gap). They set only the explicit springs' limits that Springs.describe
reports.

The smallest sphere sets the mesh and the time step (check_resolution, time_step_factor): the mesh must
resolve it (a_min/Delta at least MIN_A_OVER_DELTA, and a calibration for each of its pairs), and the
measured time steps (couettescene.MEASURED_DT_LIMITS, poiseuille.MEASURED_PARTICLE_DT, all measured with
the paper's suspension) carry over with the relaxation time zeta_n/k_n of its contacts.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass

import numpy as np

from . import contactstability, deminput, foamcase, output, packing, rheology, theory

A1 = 1.0
A2 = packing.A2_OVER_A1 * A1
PAPER_SIZES = packing.PAPER_SUSPENSION   # radii a1 and a2 = 1.4 a1 in equal volumes (section 6)
ETA = 1.0
ROUGHNESS = 5e-3 * A1         # h_r (section 6)
FRICTION = 0.5                # mu_s (section 6)
# relTol of the linear solves in each inner iteration (momentum predictor, first and last pressure
# corrector), never below tol_u and tol_p: instead of solving each to tol_u and tol_p every time, an
# inner iteration far from convergence costs less and one near it starts close to its answer. The
# same fixed point: as few fluid solves per step and particle velocities as close to the answer, at
# about half the time per step (docs/benchmarks.md, "Linear solves inside the inner iteration").
# The momentum predictor is one symGaussSeidel sweep with no residual computed (u_sweeps 1): relTol 0.3 was
# met by one sweep in 94 % of its solves, and the residuals it computed cost as much as the sweep; the same
# inner iterations and errors at half the momentum solve's time (docs/benchmarks.md, "The momentum
# predictor as one sweep")
LINEAR_SOLVE_REL_TOL = dict(u_rel_tol=0.3, u_sweeps=1, p_rel_tol=0.05, p_final_rel_tol=0.05)


def maron_pierce_viscosity(phi: float) -> float:
    """The paper's relative viscosity (Eq. 55, rheology.PAPER_MARON_PIERCE), held finite above 0.9 phi_m."""
    alpha, phi_m = rheology.PAPER_MARON_PIERCE
    return float(rheology.maron_pierce(min(phi, 0.9 * phi_m), alpha, phi_m))


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
                "kt = %.4g N/m, mu_s = %g, h_r = %g a1; a pair of the smallest spheres at h_r/2: zeta_n = %.4g, zeta_t = %.4g N s/m; "
                "explicit springs would need dt below (ab2) %.4g normal, %.4g tangential (the springs are implicit, "
                "with Coulomb's law at the end of the step), dt = %g is %.2f of the smaller"
                % (self.design_load, self.kn, self.kt, self.mu_s, self.h_r / A1, self.zeta_n, self.zeta_t,
                   self.dt_limit_normal, self.dt_limit_tangential, dt,
                   dt / min(self.dt_limit_normal, self.dt_limit_tangential)))


MIN_A_OVER_DELTA = 2.0
"""The fewest mesh cells per radius of any sphere in a scene: the sub-grid model was measured for a/Delta 2 ... 20
(docs/dem.md, "a/Delta"); below, the fictitious domain no longer resolves the sphere (the calibrated model
needs more: the table's a/Delta, deminput.uncalibrated)."""


def check_resolution(sizes: packing.SizeDistribution, a_over_delta: float) -> None:
    """The smallest sphere sets the mesh: SizeDistributionError naming the radius unless every radius is at least
    MIN_A_OVER_DELTA cells at a1/Delta = a_over_delta (Delta = a1/a_over_delta, a1 = 1 the unit of length)."""
    cells = sizes.smallest * A1 * a_over_delta / A1
    if cells < MIN_A_OVER_DELTA * (1 - 1e-9):
        raise packing.SizeDistributionError(
            "the radius %g a1 is %.3g mesh cells at a1/Delta %g, below the %g cells a sphere needs (docs/dem.md, "
            "'a/Delta'): the smallest sphere sets the mesh: --a-over-delta %.3g or more"
            % (sizes.smallest, cells, a_over_delta, MIN_A_OVER_DELTA, MIN_A_OVER_DELTA / sizes.smallest))


def time_step_factor(sizes: packing.SizeDistribution) -> float:
    """What the time steps measured with the paper's suspension (radii 1 and 1.4) become for `sizes`: the ratio of
    the relaxation time zeta_n/k_n of the scene's stiffest contact to the measured one, at most 1.

    Why: the particle step is limited by how fast a loaded contact closes against the lubrication of its gap
    (the position update's gap targets, couettescene.MEASURED_DT_LIMITS). The smallest pair resists least
    (zeta_n grows as a_min^2 at a given gap) and the springs are designed for the largest sphere's load (k_n =
    2 F_max/h_r grows as a_max^2), so the time scale goes as (a_min/a_max)^2. A scene whose ratio a_max/a_min
    is above 1.4 gets the measured steps shortened by this factor; one below keeps them (larger steps were not
    measured). The paper's suspension: exactly 1."""
    measured = (PAPER_SIZES.smallest / PAPER_SIZES.largest) ** 2
    scene = (sizes.smallest / sizes.largest) ** 2
    return min(1.0, scene / measured)


def scaled_time_step(dt: float, sizes: packing.SizeDistribution) -> float:
    """A measured time step dt carried to `sizes` (time_step_factor), rounded down to two digits (dt itself for
    a factor of 1)."""
    factor = time_step_factor(sizes)
    if factor >= 1.0:
        return dt
    scaled = dt * factor
    unit = 10.0 ** (math.floor(math.log10(scaled)) - 1)
    return round(math.floor(scaled / unit * (1 + 1e-12)) * unit, 12)


def holds_smallest_pair(radii) -> bool:
    """Whether a packing's radii hold two spheres of the smallest radius: the pair whose resistances
    choose_springs quotes (pair=), which a lone smallest sphere does not make."""
    radii = np.asarray(radii, dtype=float)
    return int(np.sum(np.isclose(radii, radii.min()))) >= 2


def choose_springs(stress: float, dt: float, delta: float, kn: float | None = None,
                   kt: float | None = None, sizes: packing.SizeDistribution | None = None,
                   model: str = "calibrated", pair: bool = True) -> Springs:
    """The springs by the rule of the module docstring for the shear stress `stress` [Pa] and the size distribution
    `sizes` (default the paper's), unless given (fdmsubgrid.contactstability: the design load, the recipe's k_n,
    the explicit springs' limits): the design load of the largest sphere, the resistances of a pair of the
    smallest. model: the scene's sub-grid model (pair_style fdm/subgrid model, write_case's), which sets zeta_n
    and zeta_t (not the springs); pair False: the scene holds no two of the smallest spheres (a lone sphere),
    so no calibration of their pair exists to be asked for, and zeta_n, zeta_t are the cut-off model's."""
    sizes = PAPER_SIZES if sizes is None else sizes
    design_load = contactstability.design_load(sizes.largest * A1, stress)
    a_min = sizes.smallest * A1
    # the contact points in the middle of the gap (docs/contact.md 2): lever arms a + h_r/4
    zeta_n, zeta_t = theory.pair_mode_resistances(a_min, a_min, 0.5 * ROUGHNESS, delta, ETA,
                                                  model=model if pair else "cutoff", contact_in_mid_gap=True)
    kn = contactstability.normal_stiffness(design_load, ROUGHNESS) if kn is None else kn
    # k_t independent of dt: until the return mapping of docs/contact.md 2c the rule was
    # min(k_n, 0.5 zeta_t/dt), which softened friction as dt grew (eta_s at phi 0.47 fell with dt)
    kt = kn if kt is None else kt
    return Springs(kn, kt, FRICTION, ROUGHNESS, design_load, zeta_n, zeta_t,
                   contactstability.explicit_time_step_limit(zeta_n, kn, "ab2"),
                   contactstability.explicit_time_step_limit(zeta_t, kt, "ab2"))


# fix fdm/couple's held_drag: how the particle steps between fluid steps hold the fluid's force; the first
# is what the toolkit writes (closer to solving the fluid at every step, docs/benchmarks.md)
HELD_DRAG = ("extrapolated", "constant")
# fix fdm/couple's coulomb_solve: how a contact slides within its step (docs/contact.md 2c); the first is the default
COULOMB_SOLVE = ("frozen", "consistent")


def coulomb_tag(coulomb_solve: str) -> str:
    """What a run folder's name adds for its coulomb_solve: nothing for the default, else e.g. _coulombConsistent."""
    return "" if coulomb_solve == COULOMB_SOLVE[0] else "_coulomb" + coulomb_solve.capitalize()


def write_case(run_dir: str, pack: packing.Packing, springs: Springs, a_over_delta: float, dt: float, steps: int,
               dump_every: int, tol_lambda: float, acceleration: str, n_max: int = 50, write_every: int = 100000,
               text_dump: bool = False, model: str = "calibrated", wall_velocities: tuple[float, float] = (0.0, 0.0),
               grad_p0: tuple[float, float, float] = (0.0, 0.0, 0.0), name: str = "in.suspension",
               fluid_options: dict | None = None, fluid_every: int = 1, held_drag: str = "extrapolated",
               calibration: deminput.SceneCalibration | None = None, coulomb_solve: str = COULOMB_SOLVE[0]) -> dict:
    """fluid/ and dem/ of the run; returns the scene's description. wall_velocities: the x velocities of
    the walls y = 0 and y = L_y; grad_p0: the uniform pressure gradient (Eq. 58) [Pa/m]. model:
    pair_style fdm/subgrid's sub-grid model (calibrated, the default: what the solver resolves, measured;
    or cutoff: the cut-off model; docs/dem.md). The particles are recorded every dump_every steps in dem/particles.records (fix
    fdm/output), and written for ParaView with the fluid fields every write_every steps
    (dem/vtk/particles.pvd, fluid/fluid.foam); text_dump: also the LIGGGHTS text dump
    dem/particles.dump of the same steps (for comparisons). fluid_options: more (or other) arguments
    of foamcase.write_fluid_case, e.g. first_step or mean_flow_damping. fluid_every: the fluid is solved every
    fluid_every-th particle step (fix fdm/couple ... fluid_every K, docs/dem.md "Particle steps between
    fluid steps"); dump_every and write_every (unless beyond the run's steps) must then be multiples of it,
    so that every snapshot is of a step the fluid solved. held_drag: how the steps between fluid steps hold
    the fluid's force (fix fdm/couple ... held_drag: extrapolated, from the last two fluid steps, or constant;
    docs/benchmarks.md "The held drag extrapolated"). calibration: the table the scene runs with
    (deminput.scene_calibration; None or the shipped one: the pair style's default), written into dem/ and
    named by the pair style's `calibration` keyword when it holds interpolated blocks. coulomb_solve: fix
    fdm/couple's coulomb_solve (written when not the default frozen)."""
    if fluid_every < 1:
        raise ValueError("fluid_every must be at least 1, got %r" % fluid_every)
    if held_drag not in HELD_DRAG:
        raise ValueError("held_drag must be one of %s, got %r" % (", ".join(HELD_DRAG), held_drag))
    if coulomb_solve not in COULOMB_SOLVE:
        raise ValueError("coulomb_solve must be one of %s, got %r" % (", ".join(COULOMB_SOLVE), coulomb_solve))
    for what, every in (("dump_every", dump_every), ("write_every", write_every)):
        if every % fluid_every and every <= steps:
            raise ValueError("%s = %d steps is not a multiple of fluid_every = %d: a snapshot would fall between "
                             "fluid steps" % (what, every, fluid_every))
    delta = A1 / a_over_delta
    Lx, Ly, Lz = (float(v) for v in pack.box)
    u_lo, u_hi = (float(u) for u in wall_velocities)
    box = foamcase.Box((0, 0, 0), (Lx, Ly, Lz), delta, faces=("cyclic", ((u_lo, 0, 0), (u_hi, 0, 0)), "cyclic"))
    fluid = dict(nu=ETA, rho=1.0, grad_p0=tuple(grad_p0), tol_lambda=tol_lambda, n_max=n_max,
                 first_step=(tol_lambda / 10, 3000), n_particles=pack.n, tol_u=1e-5, tol_p=1e-3,
                 acceleration=acceleration, write_interval=write_every, **LINEAR_SOLVE_REL_TOL)
    fluid.update(fluid_options or {})
    foamcase.write_fluid_case(os.path.join(run_dir, "fluid"), box, **fluid)
    table = calibration.table() if calibration is not None else None
    pair = ("fdm/subgrid model %s%s contact %r %r %r %r wall ylo %r 0 0 wall yhi %r 0 0"
            % (model, "" if table is None else " calibration %s" % table, springs.kn, springs.kt, springs.mu_s,
               springs.h_r, u_lo, u_hi))
    spheres = [tuple(x) + (float(a), int(t)) for x, a, t in zip(pack.positions, pack.radii, pack.types)]
    runs = (["fix             output all fdm/output records %d particles.records vtk %d vtk"
             % (dump_every, write_every)]
            + (output.dump_custom_command("particles", dump_every, "particles.dump") if text_dump else [])
            + ["thermo_style    custom step f_couple[1] f_couple[2] f_couple[6] f_couple[7] f_couple[8]",
               "thermo          %d" % dump_every,
               "run             %d upto" % steps])   # upto: a resumed run ends at the same step
    # a checkpoint every 10 snapshots and at the end: fdmRun --resume continues a killed run (docs/coupling.md)
    deminput.write_dem_input(os.path.join(run_dir, "dem"), box, spheres, dt=dt, pair_style=pair,
                         fix_options="stresslets yes checkpoint %d walls walls.dat%s"
                         % (10 * dump_every, " fluid_every %d held_drag %s" % (fluid_every, held_drag)
                            if fluid_every > 1 else "")
                         + ("" if coulomb_solve == COULOMB_SOLVE[0] else " coulomb_solve %s" % coulomb_solve), runs=runs,
                         name=name)
    packing.write_data(os.path.join(run_dir, "dem", "packing.data"), pack)
    if table is not None:
        calibration.write(os.path.join(run_dir, "dem"))
    scene = dict(box=[Lx, Ly, Lz], cells=box.n[0] * box.n[1] * box.n[2], mesh=list(box.n), steps=steps,
                 wall_velocities=[u_lo, u_hi], grad_p0=list(grad_p0), dt=dt, dump_every=dump_every,
                 write_every=write_every, subgrid_model=model, fluid_every=fluid_every,
                 held_drag=held_drag if fluid_every > 1 else None, coulomb_solve=coulomb_solve)
    if table is not None:
        # the interpolated blocks the run reads (dem/<table>), each with its measured error bound
        def entry(e) -> dict:
            return dict(kind=e.kind, radii=[e.pair[0]] if e.kind == "wall" else list(e.pair),
                        a_over_delta=e.a_over_delta, ratio=e.ratio)
        scene["calibration_interpolated"] = [dict(entry(e), error=e.error) for e in calibration.interpolated]
        # and those measured on demand, with the tables they come from
        scene["calibration_measured"] = [entry(e) for e in calibration.measured]
        scene["calibration_measured_tables"] = list(calibration.tables)
    return scene
