"""Pressure-driven suspension flow (paper section 6.2, Eqs. 58-63): the profiles, the migration and the
momentum balance of a run folder of cases/poiseuille, and the comparison with the Suspension Balance
Model (fdmsubgrid.sbm).

The channel: walls at rest at y = 0 and y = L_y, x and z periodic, the uniform pressure gradient
dP0/dx = -8 eta U_c/L_y^2 (Eq. 58). Times are in units of L_y/(2 U_c), velocities u* = u/(2 U_c) and
y* = (y - L_y/2)/L_y (Eq. 61).

What `analyse` measures (docs/profiles.md, "Pressure-driven flow"):
- the migration transient: phi in the central slab |y*| < a1/L_y (2 a1 wide) and in the wall layers
  (within 2.5 a1 of either wall) at every particle snapshot; the steady window found from the data
  (steady_window: the time constant tau of the central series' exponential approach, fit_approach, the
  window from 3 tau on, the series' trend over it flat within 2 error bars), or from a given time;
- the central plateau (central_plateau: the width above phi 0.6 in bins of a1, with block errors), the
  stresses across the channel (stress_profiles, contact_normal_stress) and the SBM with the material
  functions fitted to this project's Table 8 rows (steady_results, sbm_differences);
- the steady profiles, time-averaged with block-averaging errors: fine (planes every 0.02 a1) and coarse
  (bins of width a1, Eq. 60) phi(y) (Eq. 49) and u_p*(y) (Eqs. 59, 61), Sigma^c_yy(y) and Sigma_xy(y);
- the momentum balance: in steady Stokes flow the total shear stress is exactly Sigma_xy(y) =
  (dP0/dx)(y - L_y/2). Its parts on the cell faces: the fluid term eta d<u>/dy from the plane averages
  of the whole velocity field (fluid and rigid particle interiors, fdmFoam's channelProfile.dat,
  output.channel_profile), and
  the particle terms Sigma^h_xy + Sigma^c_xy of Eq. 53; the deviation from the line, over the wall
  stress tau_w = |dP0/dx| L_y/2, in the core and in the wall layers, in the bins of a1 (Eq. 60, each
  term its exact bin average: the reported error) and on the cell faces (the `_fine_` keys: layering
  at the scale of a sphere shows there). The line is anchored at the walls'
  own shear stresses (fluid + sub-grid + contact, every step): the slab between a wall and the plane y
  balances exactly, Sigma_xy(y) = tau_lo + (dP0/dx)(y - y_lo), and tau_lo - tau_hi = 2 tau_w (the
  wall force balance, reported); tau_lo + tau_hi vanishes only in a symmetric state (the wall
  asymmetry, reported);
- the jammed zone: the width of the central coarse bins where phi >= phi_m;
- the SBM (Eqs. 62a, 62b, 63) solved over the region 2.5 a1 from the walls with the measured mean phi of
  that region and the measured u_p* at its edge; the rms differences of phi and u* from the coarse
  profiles inside it.
"""
from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass
from typing import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import output, packing, profiles, rheology, sbm, shear, suspension, timeseries
# the steady window (re-exported: the channel's analysis is where users meet them)
from .steadystate import (MIN_SNAPSHOTS, STEADY_AFTER_TAUS, STEADY_WINDOW_TAUS, SLOPE_SIGMAS, Approach, SteadyWindow, Trend, fit_approach,  # noqa: F401
                          profile_change, steady_window, trend)

CENTRAL_HALF_WIDTH = 1.0        # a1: the central slab of the migration series
WALL_LAYER = sbm.LAYER_OVER_A1  # a1: the wall layers (the region the SBM leaves out)


class PoiseuilleRunError(ValueError):
    """A run folder that is not a pressure-driven channel; the message names the file."""


@dataclass(frozen=True)
class Scales:
    """The flow's scales from its pressure gradient: G = dP0/dx, U_c = -G L_y^2/(8 eta) (Eq. 58),
    tau_w = |G| L_y/2, the time unit L_y/(2 U_c)."""

    grad: float
    u_c: float
    tau_w: float
    time_unit: float
    width: float


def scales(run: shear.ShearRun) -> Scales:
    """The scales of a run, after checking it is a pressure-driven channel (walls at rest, dP0/dx < 0
    along the flow axis x, no gradient along the walls' normal)."""
    path = os.path.join(run.run_dir, "fluid", "constant", "fdmProperties")
    g = run.grad_p0
    if not (g[0] < 0 and g[1] == 0):
        raise PoiseuilleRunError("%s: gradP0 = (%g %g %g) Pa/m: a pressure-driven channel needs dP0/dx < 0 along x "
                                 "and none along the walls' normal y" % (path, *g))
    if any(abs(u) > 0 for u in run.wall_velocities):
        raise PoiseuilleRunError("%s: the walls move (%g, %g): a pressure-driven channel has walls at rest"
                                 % (shear.dem_input(run.run_dir), *run.wall_velocities))
    width = float(run.box[1])
    u_c = -g[0] * width ** 2 / (8 * run.eta)
    return Scales(grad=float(g[0]), u_c=u_c, tau_w=abs(g[0]) * width / 2, time_unit=width / (2 * u_c), width=width)


def fluid_shear_stress(u: NDArray, delta: float, eta: float) -> tuple[NDArray, NDArray]:
    """(faces y (n+1,), eta d<u_x>/dy on them) of the mean profile u (n,) of the cell planes (cell width
    delta, from the low wall at 0): centred differences between the planes' centres, and from the wall
    (at rest) to the first centre."""
    n = len(u)
    faces = delta * np.arange(n + 1)
    slope = np.empty(n + 1)
    slope[1:-1] = np.diff(u) / delta
    slope[0] = u[0] / (0.5 * delta)
    slope[-1] = -u[-1] / (0.5 * delta)
    return faces, eta * slope


def fluid_shear_stress_in_bins(u: NDArray, delta: float, eta: float, edges: NDArray) -> NDArray:
    """eta d<u_x>/dy averaged over each bin [edges[k], edges[k+1]] (edges from the low wall at 0) of the
    mean profile u (n,), exactly: eta (<u>(e1) - <u>(e0))/(e1 - e0), <u> on the cell faces the mean of
    its two cells (the walls' value, at rest, on the walls), linear between faces."""
    faces = delta * np.arange(len(u) + 1)
    u_faces = np.concatenate([[0.0], 0.5 * (u[1:] + u[:-1]), [0.0]])
    at = np.interp(edges, faces, u_faces)
    return eta * np.diff(at) / np.diff(edges)


def packing_from_records(path: str, size) -> packing.Packing:
    """The particles of the last complete block of a particle records file (fix fdm/output) as the
    packing of a new channel run of the same size (walls normal to y): a dense state reached by an
    earlier run, to start a short run there (e.g. the time-step measurements where the core is
    densest). Raises ValueError if the file's box is not `size`, or if it has no walls on y."""
    records = output.read_particle_records(path)
    if len(records) == 0:
        raise ValueError("%s holds no complete block" % path)
    lo = np.asarray(records.header["box_lo"], dtype=float)
    hi = np.asarray(records.header["box_hi"], dtype=float)
    if not np.allclose(hi - lo, np.asarray(size, dtype=float)) or np.any(lo != 0):
        raise ValueError("%s: box %s to %s, not the channel [0, %s]" % (path, lo.tolist(), hi.tolist(),
                                                                          list(size)))
    if list(records.header.get("periodic", [])) != [1, 0, 1]:
        raise ValueError("%s: periodic %s, not a channel with walls normal to y (1 0 1)"
                         % (path, records.header.get("periodic")))
    last = records.blocks[-1]["particles"]
    order = np.argsort(last["tag"])
    return packing.Packing(last["x"][order], last["radius"][order], last["type"][order], hi - lo,
                           dict(records=os.path.basename(path), step=int(records.steps[-1])), walls=(1,))


# The channel's measured time steps (docs/benchmarks.md, "The channel's time step"; times in L_y/(2 U_c)):
# the bulk velocity within 0.3 % (rms 0.8-1.4 %) of the finest step with the particles at 0.05 and the
# fluid every 0.2, in the migrating and in the steady core (the fluid every 0.4: 1.4 %, rms 2.2 %); the
# particles at 0.1 miss a rearrangement of the steady core (rms 4 %), at 0.2 they go 8 % rms off.
MEASURED_PARTICLE_DT = 0.05
MEASURED_FLUID_DT = 0.4
DEFAULT_DT, DEFAULT_FLUID_EVERY = 0.05, 4
# The channel's stability map (docs/benchmarks.md, "The channel's stability map"): from the steady dense core
# (phi_center 0.58), every particle step up to 0.4 with the recipe's springs times 0.1 to 10 held its contacts
# (the deepest overlap 3e-3 a1, at 0.4 and the springs times 0.1; fdmDEM stops at 0.05): beyond these the
# contacts' stability is not known
MAPPED_PARTICLE_DT = 0.4
MAPPED_SPRING_FACTORS = (0.1, 10.0)


def time_step_warning(dt: float, fluid_every: int, sizes: packing.SizeDistribution | None = None,
                      spring_factors: tuple[float, ...] = (1.0,)) -> str | None:
    """A warning when the particle step dt or the fluid's step fluid_every*dt (in L_y/(2 U_c)) is beyond
    what was measured good in the channel (with the paper's radii 1 and 1.4; for other sizes the particle steps
    carried over by suspension.time_step_factor), or the step or the springs (spring_factors: k_n and k_t over
    the recipe's) beyond the channel's stability map; else None."""
    beyond = []
    particle_dt = MEASURED_PARTICLE_DT if sizes is None else suspension.scaled_time_step(MEASURED_PARTICLE_DT, sizes)
    mapped_dt = MAPPED_PARTICLE_DT if sizes is None else suspension.scaled_time_step(MAPPED_PARTICLE_DT, sizes)
    if dt > particle_dt * (1 + 1e-9):
        beyond.append("the particle step %g above %g (%sat 0.1 the bulk velocity of the dense core went 4 %% rms "
                      "off, at 0.2 8 %%)" % (dt, particle_dt, "" if particle_dt == MEASURED_PARTICLE_DT else
                                            "the measured %g times %.3g for these sizes, suspension.time_step_factor; "
                                            % (MEASURED_PARTICLE_DT, suspension.time_step_factor(sizes))))
    if dt > mapped_dt * (1 + 1e-9):
        beyond.append("the particle step %g beyond the stability map's %g (the contacts' stability not known: "
                      "docs/benchmarks.md, \"The channel's stability map\")" % (dt, mapped_dt))
    outside = [f for f in spring_factors
               if not MAPPED_SPRING_FACTORS[0] * (1 - 1e-9) <= f <= MAPPED_SPRING_FACTORS[1] * (1 + 1e-9)]
    if outside:
        beyond.append("the springs %s times the recipe's, outside the stability map's %g to %g (docs/benchmarks.md, "
                      "\"The channel's stability map\")" % (" and ".join("%.3g" % f for f in outside),
                                                              *MAPPED_SPRING_FACTORS))
    if dt * fluid_every > MEASURED_FLUID_DT * (1 + 1e-9):
        beyond.append("the fluid's step %g (dt %g x fluid_every %d) above %g, not measured"
                      % (dt * fluid_every, dt, fluid_every, MEASURED_FLUID_DT))
    if not beyond:
        return None
    return ("WARNING: %s: docs/benchmarks.md, \"The channel's time step\" (the measured defaults: --dt %g "
            "--fluid-every %d)" % ("; ".join(beyond), DEFAULT_DT, DEFAULT_FLUID_EVERY))


def budget(run_dir: str, duration: float) -> dict:
    """The wall time a channel run would take for `duration` (in L_y/(2 U_c)), predicted from a short run
    of the same scene (run_dir: at least two fluid steps): the median seconds of a fluid step after the
    first (fluid solve, the particle steps between, exchange; fdmFoam's steps.dat), times the fluid steps
    the duration needs, plus the first (cold) step as measured. A run at the same load as the short one
    is assumed: quote the load beside it."""
    steps = output.steps(os.path.join(run_dir, "fluid"))
    if len(steps["step"]) < 2:
        raise ValueError("%s: %d fluid step(s) in steps.dat; the budget needs at least two (the first is cold)"
                         % (run_dir, len(steps["step"])))
    times = np.asarray(steps["time"]) / scales(shear.read_run(run_dir)).time_unit
    fluid_dt = float(np.median(np.diff(times[1:]))) if len(times) > 2 else float(times[1] - times[0])
    parts = {k: np.asarray(steps[k + "Seconds"], dtype=float) for k in ("fluid", "particle", "exchange")}
    per_step = {k: float(np.median(v[1:])) for k, v in parts.items()}
    first = float(sum(v[0] for v in parts.values()))
    each = sum(per_step.values())
    fluid_steps = int(math.ceil(duration / fluid_dt))
    seconds = first + (fluid_steps - 1) * each
    return dict(duration=duration, fluid_dt=fluid_dt, fluid_steps=fluid_steps, measured_fluid_steps=len(times),
                first_step_seconds=first, seconds_per_fluid_step=each, parts_per_fluid_step=per_step,
                inner_iterations_per_fluid_step=float(np.median(np.asarray(steps["innerIterations"])[1:])),
                predicted_seconds=seconds, predicted_hours=seconds / 3600)


def required_duration(rungs: Sequence[dict], width: float, window_taus: float = STEADY_AFTER_TAUS) -> dict:
    """How long a channel of wall distance `width` (a1) must run from a uniform start to its steady state and an
    averaging window, from the migration times the ladder measured (`rungs`: the `data` of analysed runs, each
    with `L` and `migration_time` ± `migration_time_err`). In units of L_y/(2 U_c) the shear-induced migration
    time grows as (L_y/a)^2 (its diffusivity scales with a^2 times the shear rate, about U_c/L_y), so
    tau = c L_y^2 is fitted through the rungs (least squares weighted by 1/err^2), and the duration is the
    analysis's STEADY_AFTER_TAUS time constants before its window plus `window_taus` of them in it.
    Returns the fit (c, its error and chi^2 per rung), tau at `width` and the duration, each with its error."""
    rows = [(float(r["L"][1]), float(r["migration_time"]), float(r["migration_time_err"])) for r in rungs
            if r.get("migration_time") is not None and r.get("migration_time_err")]
    if not rows:
        raise ValueError("required_duration: no rung with a measured migration time (analyse a ladder run first)")
    L, tau, err = (np.array(v) for v in zip(*rows))
    w = 1.0 / err ** 2
    c = float(np.sum(w * tau * L ** 2) / np.sum(w * L ** 4))
    c_err = float(1.0 / math.sqrt(np.sum(w * L ** 4)))
    taus = STEADY_AFTER_TAUS + window_taus
    return dict(c=c, c_err=c_err, chi2_per_rung=float(np.sum(w * (tau - c * L ** 2) ** 2) / len(L)),
                rungs=[dict(width=float(l), migration_time=float(t), migration_time_err=float(e),
                            fitted=c * float(l) ** 2) for l, t, e in rows],
                width=width, migration_time=c * width ** 2, migration_time_err=c_err * width ** 2,
                window_taus=window_taus, steady_from=STEADY_AFTER_TAUS * c * width ** 2,
                duration=taus * c * width ** 2, duration_err=taus * c_err * width ** 2)


# The paper's central plateau in its 40 x 40 x 20 a1 channel (section 6.2, Fig. 23): phi about 0.63 over about 6 a1
PAPER_PLATEAU_PHI = 0.63
PAPER_PLATEAU_WIDTH = 6.0


def ladder_table(rungs: Sequence[dict]) -> list[dict]:
    """The ladder of channel sizes side by side: per analysed run (the `data` of its results.json), sorted by
    L_y, what the size changes, each with its error bar: phi_center, the central plateau (its width above the
    run's plateau threshold and its phi), the migration time, u_p* at the centre, whether and from when it is
    steady, how far it ran and its wall time. `start` is 'sbm' for a run started near the SBM's profile
    (poiseuille.py --start sbm: its run folder's name holds 'startSbm'), whose migration time is that of the
    last approach, not of the migration from a uniform start, else 'uniform'."""
    rows = []
    for r in rungs:
        missing = [k for k in ("L", "phi_center", "migration_time", "plateau_width_over_a1", "time") if k not in r]
        if missing:
            raise PoiseuilleRunError("a ladder rung's results lack %s (%s): analyse the run again"
                                     % (", ".join(missing), r.get("run_dir", "?")))
        rows.append(dict(
            width=float(r["L"][1]), L=[float(v) for v in r["L"]], n_particles=r.get("n_particles"),
            start="sbm" if "startSbm" in os.path.basename(str(r.get("run_dir", "")).rstrip("/")) else "uniform",
            time=float(r["time"]), steady=bool(r.get("steady_detected")), steady_from=r.get("steady_from"),
            phi_center=float(r["phi_center"]), phi_center_err=_number(r.get("phi_center_err")),
            plateau_threshold=float(r.get("plateau_threshold", PLATEAU_THRESHOLD)),
            plateau_width=float(r["plateau_width_over_a1"]), plateau_width_err=_number(r.get("plateau_width_over_a1_err")),
            plateau_phi=_number(r.get("plateau_phi")), plateau_phi_err=_number(r.get("plateau_phi_err")),
            migration_time=_number(r["migration_time"]), migration_time_err=_number(r.get("migration_time_err")),
            u_center_star=_number(r.get("u_center_star")), wall_seconds=_number(r.get("wall_seconds")),
            core_seconds=_number(r.get("core_seconds"))))
    return sorted(rows, key=lambda row: (row["width"], row["start"]))


def _number(value) -> float:
    return math.nan if value is None else float(value)


def plot_ladder(path: str, rows: Sequence[dict]) -> str:
    """The ladder's figure: phi_center, the central plateau's width and the migration time against L_y, with
    their error bars; the paper's plateau (phi 0.63 over about 6 a1) marked; tau = c L_y^2 fitted through the
    uniform starts (required_duration); runs started near the SBM's profile drawn open."""
    import matplotlib
    matplotlib.use("Agg")
    from matplotlib.figure import Figure
    fig = Figure(figsize=(13, 4))
    axes = fig.subplots(1, 3)
    thresholds = sorted({r["plateau_threshold"] for r in rows})
    panels = (("phi_center", "phi at the centre (|y| < a1)", PAPER_PLATEAU_PHI),
              ("plateau_width", "central plateau width / a1 (phi >= %s)" % " or ".join("%g" % v for v in thresholds),
               PAPER_PLATEAU_WIDTH),
              ("migration_time", "migration time tau (L_y/(2U_c))", None))
    for ax, (key, label, paper) in zip(axes, panels):
        for start, marker, face in (("uniform", "o", None), ("sbm", "s", "none")):
            sel = [r for r in rows if r["start"] == start and math.isfinite(r[key])]
            if sel:
                ax.errorbar([r["width"] for r in sel], [r[key] for r in sel],
                            yerr=[0 if not math.isfinite(r[key + "_err"]) else r[key + "_err"] for r in sel],
                            fmt=marker, mfc=face, capsize=3,
                            label="uniform start" if start == "uniform" else "started near the SBM profile")
        if paper is not None:
            ax.axhline(paper, color="k", lw=0.8, ls=":", label="the paper's 40 a1 channel")
        ax.set_xlabel("L_y / a1")
        ax.set_ylabel(label)
        ax.legend(fontsize=7)
    uniform = [dict(L=r["L"], migration_time=r["migration_time"], migration_time_err=r["migration_time_err"])
               for r in rows if r["start"] == "uniform" and math.isfinite(r["migration_time"])
               and math.isfinite(r["migration_time_err"]) and r["migration_time_err"] > 0]
    if uniform:
        fit = required_duration(uniform, 1.0)
        widths = np.linspace(0, 1.05 * max(r["width"] for r in rows), 50)
        axes[2].plot(widths, fit["c"] * widths ** 2, "k-", lw=0.8,
                     label="tau = %.3g L_y^2 (uniform starts)" % fit["c"])
        axes[2].legend(fontsize=7)
    fig.suptitle("The ladder of channel sizes (phi_bulk 0.45)")
    fig.tight_layout(rect=(0, 0, 1, 0.94))
    fig.savefig(path, dpi=110)
    return path


def flow_rate(run_dir: str) -> tuple[NDArray, NDArray]:
    """The bulk velocity of the channel at every fluid step: times (in L_y/(2 U_c)) and the mean of U_x
    over the whole box (fluid and particle interiors, fdmFoam's steps.dat) over 2 U_c, the Newtonian
    parabola's being 1/3. At an imposed pressure gradient this is what a suspension's viscosity sets,
    as the wall stress is at an imposed shear rate: the quantity the time-step measurements compare."""
    steps = output.steps(os.path.join(run_dir, "fluid"))
    sc = scales(shear.read_run(run_dir))
    return np.asarray(steps["time"]) / sc.time_unit, np.asarray(steps["meanUx"]) / (2 * sc.u_c)


def _layer_mask(y: NDArray, channel: profiles.Channel) -> NDArray:
    return (y - channel.y_lo < WALL_LAYER - 1e-9) | (channel.y_hi - y < WALL_LAYER - 1e-9)


def momentum_balance(run_dir: str, eta: float, sc: Scales, channel: profiles.Channel,
                     snapshots: list, coarse: profiles.ProfileAverage, t0: float) -> dict:
    """The shear stress against the exact line (module docstring), time-averaged from t0: on the cell
    faces and in the coarse bins, with the walls' stresses; a dict of the results' keys and, under
    "figure", the profiles."""
    xy = profiles.component(0, 1)
    prof = output.channel_profile(os.path.join(run_dir, "fluid"))
    # the suspension's mean velocity over the same window as the particles
    u = prof["u"][prof["time"] / sc.time_unit >= t0 - 1e-9, :, 0].mean(axis=0)
    faces, fluid = fluid_shear_stress(u, prof["delta"], eta)
    y_faces = faces + channel.y_lo
    particle = profiles.average_profiles(snapshots, channel, y=y_faces, errors=False).sigma_p[:, xy]
    loads = output.read_wall_loads(run_dir)
    tau = rheology.wall_shear_stresses(loads, channel)["total"]
    wsel = np.asarray(loads.times, dtype=float) / sc.time_unit >= t0 - 1e-9
    tau_lo, tau_hi = (float(v) for v in tau[wsel].mean(axis=0))

    def line(y: NDArray) -> NDArray:
        # the exact balance of the slab between a wall and the plane y: Sigma_xy(y) = tau_lo + G (y - y_lo)
        # = tau_hi + G (y - y_hi); the mean of the two. It is G (y - y_mid) once the two walls carry
        # equal loads (a symmetric steady state); their difference is the wall asymmetry
        return 0.5 * (tau_lo + sc.grad * (y - channel.y_lo) + tau_hi + sc.grad * (y - channel.y_hi))

    total = fluid + particle
    deviation = np.abs(total - line(y_faces)) / sc.tau_w
    layer = _layer_mask(y_faces, channel)
    # the same in the bins of a1 (Eq. 60: the scale of the profiles), each term its exact bin average
    edges = coarse.edges
    coarse_total = fluid_shear_stress_in_bins(u, prof["delta"], eta, edges - channel.y_lo) + coarse.sigma_p[:, xy]
    coarse_deviation = np.abs(coarse_total - line(0.5 * (edges[1:] + edges[:-1]))) / sc.tau_w
    coarse_layer = (edges[:-1] < channel.y_lo + WALL_LAYER - 1e-9) | (edges[1:] > channel.y_hi - WALL_LAYER + 1e-9)
    return dict(
        shear_stress_linearity_rel_error=float(np.max(coarse_deviation[~coarse_layer])),
        shear_stress_linearity_wall_layer_rel_error=float(np.max(coarse_deviation[coarse_layer])),
        shear_stress_linearity_fine_rel_error=float(np.max(deviation[~layer])),
        shear_stress_linearity_fine_wall_layer_rel_error=float(np.max(deviation[layer])),
        wall_force_balance_rel_error=abs(tau_lo - tau_hi - 2 * sc.tau_w) / (2 * sc.tau_w),
        wall_shear_stress_asymmetry=abs(tau_lo + tau_hi) / sc.tau_w,
        shear_stress_exact_line_rel_error=exact_line_deviation(0.5 * (edges[1:] + edges[:-1]), coarse_total, sc,
                                                               channel, ~coarse_layer),
        figure=dict(faces=y_faces, total=total, fluid=fluid, particle=particle, line=line(y_faces),
                    coarse_total=coarse_total, coarse_line=line(0.5 * (edges[1:] + edges[:-1])),
                    coarse_layer=coarse_layer))


def jammed_width(coarse: profiles.ProfileAverage, y_mid: float, phi_m: float) -> float:
    """The width of the contiguous coarse bins around the centre with phi >= phi_m (0 if none)."""
    jammed = coarse.phi >= phi_m
    centre = int(np.argmin(np.abs(coarse.y - y_mid)))
    if not jammed[centre]:
        return 0.0
    lo, hi = centre, centre
    while lo > 0 and jammed[lo - 1]:
        lo -= 1
    while hi < len(jammed) - 1 and jammed[hi + 1]:
        hi += 1
    return float(coarse.edges[hi + 1] - coarse.edges[lo])


def sbm_comparison(material: sbm.MaterialFunctions, snapshots: list, channel: profiles.Channel, sc: Scales,
                   coarse: profiles.ProfileAverage, fine: profiles.ProfileAverage
                   ) -> tuple[sbm.SBMProfile, float, float, float]:
    """The SBM over the region 2.5 a1 from the walls with the measured mean phi of that region and the
    measured u_p* at its edge; returns (model, rms difference of phi, of u*, the region's phi), the
    differences over the coarse bins inside the region (the model averaged over each bin, u* weighted
    by phi as Eq. 59)."""
    region = (channel.y_lo + WALL_LAYER, channel.y_hi - WALL_LAYER)
    phi_region = float(np.mean([profiles.volume_fraction(s, channel, *region) for s in snapshots]))
    u_fine = fine.u_p[:, 0] / (2 * sc.u_c)
    edge_u = float(np.nanmean(np.interp(region, fine.y, np.nan_to_num(u_fine))))
    model = sbm.solve(material, phi_region, y_edge=0.5 - WALL_LAYER / sc.width, u_edge=edge_u)
    inside = (coarse.edges[:-1] >= region[0] - 1e-9) & (coarse.edges[1:] <= region[1] + 1e-9)
    if not inside.any():
        return model, math.nan, math.nan, phi_region
    model_phi, model_u = [], []
    for a, b in zip(coarse.edges[:-1][inside], coarse.edges[1:][inside]):
        phi, u = model.at(np.linspace(a - channel.y_mid, b - channel.y_mid, 201) / sc.width)
        model_phi.append(np.mean(phi))
        model_u.append(np.sum(phi * u) / np.sum(phi))
    dphi = coarse.phi[inside] - np.array(model_phi)
    du = coarse.u_p[inside, 0] / (2 * sc.u_c) - np.array(model_u)
    return model, float(np.sqrt(np.mean(dphi ** 2))), float(np.sqrt(np.mean(du ** 2))), phi_region


def earlier_series(segments: Sequence[dict], before: float) -> dict:
    """The migration series of kept segments (migration_series, write_segment) joined in time and cut before
    `before` (the first record of the run folder that continues them): a run continued from a compact snapshot
    on a new machine has only its own records, its history lives in the segments. A record present in two
    segments is taken once; no segments give empty series."""
    time, centre, walls, profile = [], [], [], []
    y = None
    for seg in sorted(segments, key=lambda d: d["time"][0]):
        if y is not None and len(seg["y"]) != len(y):
            raise PoiseuilleRunError("the kept segments have profiles in %d and %d bins: not of one channel"
                                     % (len(y), len(seg["y"])))
        y = seg["y"]
        for k, t in enumerate(seg["time"]):
            if t < before - 1e-6 and (not time or t > time[-1] + 1e-6):
                time.append(t)
                centre.append(seg["phi_center"][k])
                walls.append(seg["phi_wall_layer"][k])
                profile.append(seg["phi_profile"][k])
    return dict(time=np.array(time, dtype=float), phi_center=np.array(centre, dtype=float),
                phi_wall_layer=np.array(walls, dtype=float),
                phi_profile=profile, y=y)


def read_segments(folder: str) -> list[dict]:
    """The segment files (segment_<t0>_<t1>.json) of a folder, e.g. cases/poiseuille/ladder20/segments."""
    names = sorted(n for n in os.listdir(folder) if n.startswith("segment_") and n.endswith(".json"))
    if not names:
        raise PoiseuilleRunError("%s holds no segment_<t0>_<t1>.json" % folder)
    out = []
    for name in names:
        with open(os.path.join(folder, name)) as f:
            out.append(json.load(f))
    return out


def analyse(run_dir: str, material: sbm.MaterialFunctions | None = None, from_time: float | None = None,
            table8: sbm.MaterialFunctions | None = None, plateau_threshold: float | None = None,
            segments: Sequence[dict] = ()) -> tuple[dict, dict]:
    """The results of a run (a flat dict, the keys of cases/poiseuille/results.json; `species` one dict per
    species, profiles.species_summary with its phi_center in the central band |y - mid| < a1 in place of
    phi_core) and what the figure needs. material: the SBM's material functions (default the paper's,
    sbm.MaterialFunctions); table8: a second set drawn beside them, fitted to this project's Table 8 rows
    (sbm.from_couette_results), or None; plateau_threshold: the phi above which the central plateau is
    measured (central_plateau; default PLATEAU_THRESHOLD, 0.6); segments: the kept migration series of the run
    before this folder's first record (read_segments), for a run continued from a compact snapshot: the steady
    window, the migration's fit, phi_center and the series run over them and this folder's records; the
    profiles are averaged over this folder's records in the window."""
    material = material or sbm.MaterialFunctions.maron_pierce_power_law()
    run = shear.read_run(run_dir)
    sc = scales(run)
    channel = run.channel
    steps = output.steps(os.path.join(run_dir, "fluid"))
    if len(steps["time"]) == 0:
        raise PoiseuilleRunError("%s/fluid/postProcessing/fdm/steps.dat: no step recorded yet" % run_dir)
    snapshots, _ = output.record_snapshots(os.path.join(run_dir, "dem", "particles.records"), 1.0 / sc.time_unit)
    if len(snapshots) < MIN_SNAPSHOTS:
        raise PoiseuilleRunError("%s: %d particle snapshots are too few for time averages (%d at least): run longer"
                         % (run_dir, len(snapshots), MIN_SNAPSHOTS))
    mid = channel.y_mid
    phi_integral = np.array([profiles.volume_fraction(s, channel) for s in snapshots])
    # the run's history before this folder (a compact snapshot's continuation): the kept segments, if any
    whole = _with_earlier_series(snapshot_series(snapshots, channel), segments, run_dir)
    n_before, times = whole["n_before"], whole["time"]
    phi_center, phi_walls, rms_change = whole["phi_center"], whole["phi_wall_layer"], whole["rms_change"]
    # the steady window from the data (steady_window: the migration's approach fitted, phi_center's trend
    # over the window checked), unless a start is given
    window = steady_window(times, phi_center, rms_change)
    if from_time is not None:
        start = int(np.searchsorted(times, from_time - 1e-9))
        steady_detected = True
    else:
        start, steady_detected = window.start, window.steady
    # the profiles are this folder's records: the window holds MIN_SNAPSHOTS of them at least
    start = min(start, len(times) - MIN_SNAPSHOTS)
    t0 = float(times[start])
    kept = snapshots[max(0, start - n_before):]
    window_trend = trend(times[start:], phi_center[start:])

    coarse = profiles.average_profiles(kept, channel)
    fine = profiles.average_profiles(kept, channel, y=channel.planes(0.02), errors=False)
    # each species alone: phi(y) on the same bins, its volume fraction in the central band |y - mid| < a1
    species = profiles.species_profiles(kept, channel, edges=coarse.edges,
                                        h_layer=0.5 * channel.width - CENTRAL_HALF_WIDTH)
    species_rows = profiles.species_summary(species, float(np.prod(run.box)))
    for row in species_rows:   # the band is the channel's centre, not a Couette core
        row["phi_center"], row["phi_center_err"] = row.pop("phi_core"), row.pop("phi_core_err")
    balance = momentum_balance(run_dir, run.eta, sc, channel, kept, coarse, t0)
    model, sbm_phi_rms, sbm_u_rms, phi_region = sbm_comparison(material, kept, channel, sc, coarse, fine)
    phi_m = material.phi_m

    wall_seconds, ranks = shear.run_seconds(run_dir, steps)
    inner = steps["innerIterations"]
    pack = run.packing
    u_center = float(np.interp(mid, coarse.y, coarse.u_p[:, 0] / (2 * sc.u_c)))
    results = dict(
        phi_bulk=pack.phi, phi_bulk_integral_max_error=float(np.max(np.abs(phi_integral - pack.phi))),
        L=list(run.box), time=float(times[-1]), steady_from=t0, steady_detected=bool(steady_detected),
        snapshots_averaged=len(kept), profiles_from=float(kept[0].time), records_from_segments=n_before,
        phi_center=float(np.mean(phi_center[start:])),
        phi_center_err=(float(timeseries.block_average(phi_center[start:]).error)
                        if len(times) - start >= 2 * timeseries.MIN_BLOCKS else math.nan),
        phi_center_initial=float(phi_center[0]),
        phi_wall_layer=float(np.mean(phi_walls[start:])),
        phi_sbm_region=phi_region,
        jammed_width_over_a1=jammed_width(coarse, mid, phi_m), phi_m=phi_m,
        u_center_star=u_center, u_center_star_newtonian=0.5,
        **{k: v for k, v in balance.items() if k != "figure"},
        sbm_phi_rms_diff=sbm_phi_rms, sbm_u_rms_diff=sbm_u_rms, sbm_jammed_width_over_a1=2 * model.y_jammed * sc.width,
        sbm_material=material.describe,
        grad_p0=sc.grad, u_c=sc.u_c, tau_w=sc.tau_w, time_unit=sc.time_unit,
        cells=run.cells, mesh=list(run.mesh), n_particles=pack.n, n_a1=int(np.sum(pack.types == 1)),
        n_a2=int(np.sum(pack.types == 2)), dt=run.dt / sc.time_unit, steps=int(len(inner)),
        steps_planned=run.steps_planned, inner_iterations_mean=float(inner.mean()),
        inner_iterations_max=int(inner.max()), unconverged_steps=int(np.sum(steps["converged"] == 0)),
        wall_seconds=wall_seconds, ranks=ranks, core_seconds=wall_seconds * ranks, springs=dict(run.springs),
        species=species_rows, species_profile_y=coarse.y.tolist())
    figure = dict(channel=channel, scales=sc, coarse=coarse, fine=fine, species=species, times=times,
                  phi_center=phi_center,
                  phi_walls=phi_walls, model=model, start=t0, phi_m=phi_m, **balance["figure"])
    plateau = central_plateau(kept, channel, coarse, PLATEAU_THRESHOLD if plateau_threshold is None else plateau_threshold)
    steady = steady_results(window, window_trend, from_time, plateau, balance,
                            material, table8, kept, channel, sc, coarse, fine, float(pack.radii.min()))
    results.update(steady["results"], plateau_shear_rate=plateau_shear_rate(fine, plateau, sc),
                   # the series the window was found from (to refit, or to set runs of several sizes side by side)
                   series=dict(time=times.round(6).tolist(), phi_center=phi_center.round(6).tolist(),
                               phi_wall_layer=phi_walls.round(6).tolist(), rms_change=rms_change.round(6).tolist()))
    figure.update(rms_change=rms_change, window=window, **steady["figure"])
    return results, figure


def plot(path: str, fig: dict) -> str:
    """The figure of a run (Fig. 23 and more): phi(y*) and u_p*(y*) fine and coarse with error bars and
    the SBM and the Newtonian parabola; the migration transient; the shear stress against the line."""
    import matplotlib
    matplotlib.use("Agg")
    from matplotlib.figure import Figure
    sc: Scales = fig["scales"]
    ch: profiles.Channel = fig["channel"]

    def ys(y):
        return (np.asarray(y) - ch.y_mid) / sc.width

    def us(u):
        return np.asarray(u) / (2 * sc.u_c)

    coarse, fine, model = fig["coarse"], fig["fine"], fig["model"]
    f = Figure(figsize=(17, 8.5))
    ax = f.subplots(2, 3)
    a = ax[0, 0]
    a.plot(ys(fine.y), fine.phi, ":", color="0.5", lw=0.8, label="simulation (fine)")
    a.errorbar(ys(coarse.y), coarse.phi, yerr=coarse.phi_error, fmt="o", ms=4, capsize=2, label="simulation (bins a1)")
    if len(fig.get("species") or []) > 1:
        for sp in fig["species"]:
            a.errorbar(ys(sp.average.y), sp.average.phi, yerr=sp.average.phi_error, fmt="--.", ms=3, lw=0.8,
                       capsize=1, label="type %d (a %g)" % (sp.type, sp.radius))
    a.plot(model.y, model.phi, "-", color="C3", label="SBM (Eqs. 62-63)")
    a.axhline(fig["phi_m"], color="0.7", lw=0.5, label="phi_m")
    a.set_xlabel("y*"), a.set_ylabel("phi"), a.legend(fontsize=8), a.set_title("volume fraction")
    a = ax[0, 1]
    a.plot(ys(fine.y), us(fine.u_p[:, 0]), ":", color="0.5", lw=0.8, label="simulation (fine)")
    a.errorbar(ys(coarse.y), us(coarse.u_p[:, 0]), yerr=us(coarse.u_p_error[:, 0]) if coarse.u_p_error is not None else None,
               fmt="o", ms=4, capsize=2, label="simulation (bins a1)")
    a.plot(model.y, model.u, "-", color="C3", label="SBM")
    yy = np.linspace(-0.5, 0.5, 201)
    a.plot(yy, (1 - 4 * yy ** 2) / 2, "--", color="0.6", label="Newtonian (1 - 4y*^2)/2")
    a.set_xlabel("y*"), a.set_ylabel("u_p* = u_p/(2U_c)"), a.legend(fontsize=8), a.set_title("particle velocity")
    a = ax[1, 0]
    a.plot(fig["times"], fig["phi_center"], label="centre |y| < a1")
    a.plot(fig["times"], fig["phi_walls"], label="wall layers (2.5 a1)")
    a.axvline(fig["start"], color="0.6", ls="--", lw=0.8, label="steady from")
    a.set_xlabel("t 2U_c/L_y"), a.set_ylabel("phi"), a.legend(fontsize=8), a.set_title("migration")
    a = ax[1, 1]
    a.plot(ys(fig["faces"]), fig["total"] / sc.tau_w, ".", ms=3, color="0.5", label="total (cell faces)")
    a.plot(ys(coarse.y), fig["coarse_total"] / sc.tau_w, "s", ms=5, color="C0", label="total (bins a1)")
    a.plot(ys(fig["faces"]), fig["fluid"] / sc.tau_w, "-", lw=0.8, label="fluid eta d<u>/dy")
    a.plot(ys(fig["faces"]), fig["particle"] / sc.tau_w, "-", lw=0.8, label="particles (Eq. 53)")
    a.plot(ys(fig["faces"]), fig["line"] / sc.tau_w, "k--", lw=0.8, label="walls' stress + (dP0/dx) y")
    a.set_xlabel("y*"), a.set_ylabel("Sigma_xy / tau_w"), a.legend(fontsize=8), a.set_title("momentum balance")
    plot_steady(ax, fig)
    f.tight_layout()
    f.savefig(path, dpi=110)
    return path


# ---- the steady state, the central plateau, the stresses across the channel (issue 48) -------------------

PLATEAU_THRESHOLD = 0.6   # the central plateau: the region around the centre where phi (bins of a1) >= this
PLATEAU_BLOCKS = 8        # the plateau width's error: from the widths of this many consecutive blocks of the window
CORE_LINE_TOLERANCE = 0.05   # the shear stress within 5 % of tau_w of the exact line in the core
WALL_FORCE_TOLERANCE = 0.01  # the walls carry the pressure gradient's force within 1 %


def plateau_width(y: ArrayLike, phi: ArrayLike, y_mid: float, threshold: float = PLATEAU_THRESHOLD
                  ) -> tuple[float, float, float]:
    """(width, y_lo, y_hi) of the central region where the piecewise-linear profile through (y, phi)
    (e.g. the bin centres of a1 and their phi) is >= threshold: the crossings on either side of y_mid
    interpolated linearly; (0, nan, nan) if phi at y_mid is below the threshold. Ends at the outermost
    points if the profile never falls below it."""
    yy = np.asarray(y, dtype=float)
    p = np.asarray(phi, dtype=float)
    if np.interp(y_mid, yy, p) < threshold:
        return 0.0, math.nan, math.nan

    def crossing(order: NDArray) -> float:
        # walk from the centre outward along `order` (indices of points beyond y_mid, nearest first)
        prev_y, prev_p = y_mid, float(np.interp(y_mid, yy, p))
        for k in order:
            if p[k] < threshold:
                return prev_y + (threshold - prev_p) * (yy[k] - prev_y) / (p[k] - prev_p)
            prev_y, prev_p = yy[k], p[k]
        return prev_y

    up = np.where(yy > y_mid)[0]
    down = np.where(yy < y_mid)[0][::-1]
    hi, lo = crossing(up), crossing(down)
    return float(hi - lo), float(lo), float(hi)


@dataclass(frozen=True)
class Plateau:
    """The central plateau over the steady window: width (of the time-averaged profile in bins of a1)
    and its standard error from the widths of PLATEAU_BLOCKS consecutive blocks of the window; bounds
    (y_lo, y_hi); phi its mean volume fraction (exact average over the bounds) with the block-averaging
    error; threshold."""

    width: float
    width_err: float
    y_lo: float
    y_hi: float
    phi: float
    phi_err: float
    threshold: float
    block_widths: tuple


def central_plateau(snapshots: list, channel: profiles.Channel, coarse: profiles.ProfileAverage,
                    threshold: float = PLATEAU_THRESHOLD, blocks: int = PLATEAU_BLOCKS) -> Plateau:
    """The central plateau (Plateau) of the snapshots of the steady window, on coarse's bins."""
    width, lo, hi = plateau_width(coarse.y, coarse.phi, channel.y_mid, threshold)
    n = len(snapshots)
    nb = min(blocks, n)
    widths = []
    for part in np.array_split(np.arange(n), nb):
        block = profiles.average_profiles([snapshots[k] for k in part], channel, edges=coarse.edges, errors=False)
        widths.append(plateau_width(block.y, block.phi, channel.y_mid, threshold)[0])
    width_err = float(np.std(widths, ddof=1) / math.sqrt(nb)) if nb > 1 else math.nan
    if width > 0:
        series = np.array([profiles.volume_fraction(s, channel, lo, hi) for s in snapshots])
        phi = float(series.mean())
        phi_err = (float(timeseries.block_average(series).error) if n >= 2 * timeseries.MIN_BLOCKS else math.nan)
    else:
        phi, phi_err = math.nan, math.nan
    return Plateau(width=width, width_err=width_err, y_lo=lo, y_hi=hi, phi=phi, phi_err=phi_err,
                   threshold=threshold, block_widths=tuple(float(w) for w in widths))


def exact_line_deviation(y: ArrayLike, total: ArrayLike, sc: Scales, channel: profiles.Channel,
                         core: ArrayLike) -> float:
    """The largest |Sigma_xy(y) - (dP0/dx)(y - L_y/2)|/tau_w over the points y where `core` is True:
    the shear stress against the exact line of a symmetric steady state (zero at the centre plane)."""
    yy = np.asarray(y, dtype=float)
    dev = np.abs(np.asarray(total, dtype=float) - sc.grad * (yy - channel.y_mid)) / sc.tau_w
    c = np.asarray(core, dtype=bool)
    return float(np.max(dev[c])) if c.any() else math.nan


def stress_profiles(coarse: profiles.ProfileAverage, balance: dict, sc: Scales, channel: profiles.Channel) -> dict:
    """The stresses across the channel in the bins of a1, over tau_w, with their block-averaging errors:
    the particles' hydrodynamic (fluid + sub-grid stresslets) and contact parts of Eq. 53, xy and yy, the
    fluid's eta d<u>/dy, their total, the exact line (dP0/dx)(y - L_y/2) and the line through the walls'
    own stresses (momentum_balance). y_star = (y - L_y/2)/L_y."""
    xy, yy = profiles.component(0, 1), profiles.component(1, 1)

    def col(a, k):
        return (np.asarray(a)[:, k] / sc.tau_w).tolist() if a is not None else None

    mids = coarse.y
    fluid = balance["coarse_total"] - coarse.sigma_p[:, xy]
    return dict(
        y_star=((mids - channel.y_mid) / sc.width).tolist(),
        sigma_h_xy=col(coarse.sigma_h, xy), sigma_h_xy_err=col(coarse.sigma_h_error, xy),
        sigma_c_xy=col(coarse.sigma_c, xy), sigma_c_xy_err=col(coarse.sigma_c_error, xy),
        sigma_h_yy=col(coarse.sigma_h, yy), sigma_h_yy_err=col(coarse.sigma_h_error, yy),
        sigma_c_yy=col(coarse.sigma_c, yy), sigma_c_yy_err=col(coarse.sigma_c_error, yy),
        fluid_xy=(fluid / sc.tau_w).tolist(), total_xy=(balance["coarse_total"] / sc.tau_w).tolist(),
        total_xy_err=col(coarse.sigma_p_error, xy),
        exact_line=(sc.grad * (mids - channel.y_mid) / sc.tau_w).tolist(),
        walls_line=(balance["coarse_line"] / sc.tau_w).tolist())


def sbm_differences(model: sbm.SBMProfile, coarse: profiles.ProfileAverage, channel: profiles.Channel,
                    sc: Scales) -> dict:
    """The SBM against the coarse profiles in the bins of a1 inside the region it is solved over (2.5 a1
    from the walls): the rms difference of phi over all of them, over those inside the model's jammed zone
    (their centres at |y*| < y_jammed, where the model holds phi = phi_m) and over the others, and of u*
    (the model averaged over each bin, u* weighted by phi as Eq. 59). nan where no bin is."""
    region = (channel.y_lo + WALL_LAYER, channel.y_hi - WALL_LAYER)
    inside = (coarse.edges[:-1] >= region[0] - 1e-9) & (coarse.edges[1:] <= region[1] + 1e-9)
    model_phi, model_u = [], []
    for a, b in zip(coarse.edges[:-1], coarse.edges[1:]):
        phi, u = model.at(np.clip(np.linspace(a - channel.y_mid, b - channel.y_mid, 201) / sc.width,
                                  -model.y_edge, model.y_edge))
        model_phi.append(np.mean(phi))
        model_u.append(np.sum(phi * u) / np.sum(phi))
    dphi = coarse.phi - np.array(model_phi)
    du = coarse.u_p[:, 0] / (2 * sc.u_c) - np.array(model_u)
    jammed = np.abs((coarse.y - channel.y_mid) / sc.width) < model.y_jammed

    def rms(d: NDArray, mask: NDArray) -> float:
        return float(np.sqrt(np.mean(d[mask] ** 2))) if mask.any() else math.nan

    return dict(phi_rms_diff=rms(dphi, inside), phi_rms_diff_jammed=rms(dphi, inside & jammed),
                phi_rms_diff_outside_jammed=rms(dphi, inside & ~jammed), u_rms_diff=rms(du, inside),
                bins_compared=int(inside.sum()), bins_jammed=int((inside & jammed).sum()))


def steady_results(window: SteadyWindow, window_trend: Trend, from_time: float | None, plateau: Plateau,
                   balance: dict, material: sbm.MaterialFunctions, table8: sbm.MaterialFunctions | None,
                   kept: list, channel: profiles.Channel, sc: Scales, coarse: profiles.ProfileAverage,
                   fine: profiles.ProfileAverage, a1: float) -> dict:
    """The results' keys of the steady state (docs/cases/poiseuille.md): the window and how it was found,
    the migration times, phi_center's trend over the window, the central plateau, the exact line and the
    two tolerances of the momentum balance, the stresses across the channel, and the SBM with the
    material functions fitted to Table 8 (table8, if given) beside the one of `material`. Returns
    {"results": ..., "figure": ...}."""
    c, p = window.center, window.profile
    res = dict(
        steady_method="from_time" if from_time is not None else "fit",
        steady_after_taus=STEADY_AFTER_TAUS, steady_reason=window.reason if from_time is None else "",
        steady_from_fit=window.start_time, steady_from_mser=window.mser_start_time,
        migration_time=c.tau, migration_time_err=c.tau_err, phi_center_fit_inf=c.plateau,
        phi_center_fit_inf_err=c.plateau_err, migration_time_profile=p.tau, migration_time_profile_err=p.tau_err,
        phi_center_slope=window_trend.slope, phi_center_slope_err=window_trend.slope_err,
        phi_center_window_change=window_trend.change, phi_center_window_change_err=window_trend.change_err,
        phi_center_stopped_rising=bool(window_trend.slope <= SLOPE_SIGMAS * window_trend.slope_err),
        plateau_threshold=plateau.threshold, plateau_width_over_a1=plateau.width / a1,
        plateau_width_over_a1_err=plateau.width_err / a1,
        plateau_y_star=[(v - channel.y_mid) / sc.width for v in (plateau.y_lo, plateau.y_hi)],
        plateau_phi=plateau.phi, plateau_phi_err=plateau.phi_err,
        plateau_block_widths_over_a1=[w / a1 for w in plateau.block_widths],
        momentum_balance_core_within_5pct=bool(balance["shear_stress_exact_line_rel_error"] <= CORE_LINE_TOLERANCE),
        walls_line_core_within_5pct=bool(balance["shear_stress_linearity_rel_error"] <= CORE_LINE_TOLERANCE),
        wall_force_balance_within_1pct=bool(balance["wall_force_balance_rel_error"] <= WALL_FORCE_TOLERANCE),
        stress_profile=stress_profiles(coarse, balance["figure"], sc, channel),
        **contact_normal_stress(coarse, channel, sc))
    fig = dict(plateau=plateau, window_trend=window_trend)
    if table8 is not None:
        model, _, _, _ = sbm_comparison(table8, kept, channel, sc, coarse, fine)
        diff = sbm_differences(model, coarse, channel, sc)
        res.update({"sbm_table8_" + k: v for k, v in diff.items()})
        res.update(sbm_table8_material=table8.describe, sbm_table8_phi_m=table8.phi_m,
                   sbm_table8_jammed_width_over_a1=2 * model.y_jammed * sc.width / a1,
                   sbm_table8_u_center_star=float(model.at(0.0)[1]),
                   sbm_table8_phi_edge=model.phi_edge,
                   # Eq. 62b's first integral: Sigma^c_22 = Sigma_hat_22 |Sigma_xy| = -2 C tau_w, uniform
                   sbm_table8_contact_normal_stress=-2 * model.invariant)
        fig.update(model_table8=model, table8_phi_m=table8.phi_m)
    return dict(results=res, figure=fig)


def plot_steady(ax, fig: dict) -> None:
    """The steady state's parts of the figure (plot's 2 x 3 axes): the SBM with the Table 8 material
    functions and the central plateau on the phi and u_p* panels, the fit of phi_center's approach and the
    window on the migration panel, the exact line on the momentum balance, the particles' hydrodynamic and
    contact stresses across the channel (xy and yy, bins of a1 with error bars), and the profile's rms
    change against its final profile with its fitted approach."""
    sc: Scales = fig["scales"]
    ch: profiles.Channel = fig["channel"]
    coarse = fig["coarse"]
    window: SteadyWindow = fig["window"]
    plateau: Plateau = fig["plateau"]
    ys = (coarse.y - ch.y_mid) / sc.width
    model = fig.get("model_table8")
    if model is not None:
        ax[0, 0].plot(model.y, model.phi, "--", color="C2", label="SBM, Table 8 rows (phi_m %.3f)" % fig["table8_phi_m"])
        ax[0, 1].plot(model.y, model.u, "--", color="C2", label="SBM, Table 8 rows")
    ax[0, 0].axhline(plateau.threshold, color="C1", lw=0.6, ls=":", label="plateau threshold %g" % plateau.threshold)
    if plateau.width > 0:
        ax[0, 0].axvspan((plateau.y_lo - ch.y_mid) / sc.width, (plateau.y_hi - ch.y_mid) / sc.width, color="C1",
                         alpha=0.12, label="plateau %.2f +- %.2f wide, phi %.3f" % (plateau.width, plateau.width_err, plateau.phi))
    for a in ax[0, 0], ax[0, 1]:
        a.legend(fontsize=7)
    a = ax[1, 0]
    t = fig["times"]
    if window.center.ok:
        a.plot(t, window.center(t), "k-", lw=0.8, label="fit: tau %.3g +- %.2g" % (window.center.tau, window.center.tau_err))
    a.axvspan(fig["start"], t[-1], color="C2", alpha=0.1,
              label="window (%s)" % ("steady" if window.steady else "not steady"))
    a.axvline(window.mser_start_time, color="C3", ls=":", lw=0.8, label="MSER start")
    a.legend(fontsize=7)
    a = ax[1, 1]
    a.plot(ys, sc.grad * (coarse.y - ch.y_mid) / sc.tau_w, "-", color="C3", lw=0.8, label="exact (dP0/dx)(y - L_y/2)")
    if coarse.sigma_p_error is not None:
        a.errorbar(ys, fig["coarse_total"] / sc.tau_w, yerr=coarse.sigma_p_error[:, profiles.component(0, 1)] / sc.tau_w,
                   fmt="none", ecolor="C0", capsize=2)
    a.legend(fontsize=7)
    a = ax[0, 2]
    xy, yy = profiles.component(0, 1), profiles.component(1, 1)
    for data, err, k, name, mk in ((coarse.sigma_h, coarse.sigma_h_error, xy, "hydrodynamic xy", "o"),
                                   (coarse.sigma_c, coarse.sigma_c_error, xy, "contact xy", "s"),
                                   (coarse.sigma_h, coarse.sigma_h_error, yy, "hydrodynamic yy", "v"),
                                   (coarse.sigma_c, coarse.sigma_c_error, yy, "contact yy", "^")):
        a.errorbar(ys, data[:, k] / sc.tau_w, yerr=None if err is None else err[:, k] / sc.tau_w, fmt=mk + "-",
                   ms=4, lw=0.6, capsize=2, label=name)
    a.axhline(0, color="0.7", lw=0.5)
    a.set_xlabel("y*"), a.set_ylabel("Sigma^p / tau_w (Eq. 53, bins a1)"), a.legend(fontsize=7)
    a.set_title("particle stresses across the channel")
    a = ax[1, 2]
    a.plot(t, fig["rms_change"], lw=0.8, label="rms of phi(y) - final phi(y), bins a1")
    if window.profile.ok:
        a.plot(t, window.profile(t), "k-", lw=0.8, label="fit: tau %.3g +- %.2g" % (window.profile.tau, window.profile.tau_err))
    a.set_xlabel("t 2U_c/L_y"), a.set_ylabel("rms change of phi"), a.legend(fontsize=7)
    a.set_title("the profile's approach")


def contact_normal_stress(coarse: profiles.ProfileAverage, channel: profiles.Channel, sc: Scales) -> dict:
    """The particles' contact normal stress along y, Sigma^c_yy/tau_w, over the bins of a1 of the region the
    SBM is solved in (2.5 a1 from the walls): its mean with the error of that mean (the bins' errors
    combined as independent), and chi^2 per degree of freedom of a uniform profile (the SBM's steady
    state, no particle flux, has it uniform: about 1 when it is). nan without error bars."""
    yy = profiles.component(1, 1)
    inside = ((coarse.edges[:-1] >= channel.y_lo + WALL_LAYER - 1e-9)
              & (coarse.edges[1:] <= channel.y_hi - WALL_LAYER + 1e-9))
    s = coarse.sigma_c[inside, yy] / sc.tau_w
    if coarse.sigma_c_error is None or inside.sum() < 2:
        return dict(contact_normal_stress_core=float(np.mean(s)) if len(s) else math.nan,
                    contact_normal_stress_core_err=math.nan, contact_normal_stress_core_chi2=math.nan)
    e = coarse.sigma_c_error[inside, yy] / sc.tau_w
    w = 1.0 / e ** 2
    mean = float(np.sum(w * s) / np.sum(w))
    return dict(contact_normal_stress_core=mean, contact_normal_stress_core_err=float(1 / np.sqrt(np.sum(w))),
                contact_normal_stress_core_chi2=float(np.sum(w * (s - mean) ** 2) / (len(s) - 1)))


def plateau_shear_rate(fine: profiles.ProfileAverage, plateau: Plateau, sc: Scales) -> float:
    """The mean |du_p*/dy*| (in 2 U_c/L_y) over the central plateau, from the fine profile of u_p: the
    paper's 7e-4 against 0.2 at the walls (section 6.2). nan without a plateau."""
    if not plateau.width > 0:
        return math.nan
    inside = (fine.y >= plateau.y_lo) & (fine.y <= plateau.y_hi)
    u = fine.u_p[inside, 0] / (2 * sc.u_c)
    y = fine.y[inside] / sc.width
    if inside.sum() < 2:
        return math.nan
    return float(np.mean(np.abs(np.diff(u) / np.diff(y))))


def centre_and_wall_series(snapshots: list, channel: profiles.Channel) -> tuple[NDArray, NDArray]:
    """Per snapshot, phi in the central slab |y - mid| < CENTRAL_HALF_WIDTH and the mean of the two wall
    layers WALL_LAYER deep: the migration as analyse() and migration_series() follow it."""
    mid = channel.y_mid
    centre = np.array([profiles.volume_fraction(s, channel, mid - CENTRAL_HALF_WIDTH, mid + CENTRAL_HALF_WIDTH)
                       for s in snapshots])
    walls = np.array([0.5 * (profiles.volume_fraction(s, channel, channel.y_lo, channel.y_lo + WALL_LAYER)
                             + profiles.volume_fraction(s, channel, channel.y_hi - WALL_LAYER, channel.y_hi))
                      for s in snapshots])
    return centre, walls


def snapshot_series(snapshots: list, channel: profiles.Channel) -> dict:
    """Per snapshot: its time (in L_y/(2U_c)), phi in the central slab and in the wall layers
    (centre_and_wall_series), phi(y) in bins of a1 (arrays; y the bins' centres)."""
    phi_center, phi_walls = centre_and_wall_series(snapshots, channel)
    phi_y = [profiles.profiles_in_bins(s, channel) for s in snapshots]
    return dict(time=np.array([s.time for s in snapshots], dtype=float), phi_center=phi_center,
                phi_wall_layer=phi_walls, y=phi_y[0].y, phi_profile=[p.phi for p in phi_y])


def _record_series(run_dir: str) -> dict:
    """snapshot_series of the run's records."""
    run = shear.read_run(run_dir)
    snapshots, _ = output.record_snapshots(os.path.join(run_dir, "dem", "particles.records"),
                                           1.0 / scales(run).time_unit)
    if not snapshots:
        raise PoiseuilleRunError("%s/dem/particles.records: no record yet" % run_dir)
    return snapshot_series(snapshots, run.channel)


def _with_earlier_series(own: dict, segments: Sequence[dict], run_dir: str) -> dict:
    """A run folder's series (snapshot_series) after the kept segments before its first record
    (earlier_series), joined: time, phi_center, phi_wall_layer, the profile's rms change against its final
    profile (profile_change) and n_before, the records from the segments. Segments of another channel (profiles
    in other bins) are refused by name."""
    before = earlier_series(segments, float(own["time"][0]))
    if before["y"] is not None and len(before["y"]) != len(own["y"]):
        raise PoiseuilleRunError("the kept segments have profiles in %d bins, %s in %d: not this channel"
                                 % (len(before["y"]), run_dir, len(own["y"])))
    rms_change, _ = profile_change(list(before["phi_profile"]) + list(own["phi_profile"]))
    return dict(n_before=len(before["time"]), time=np.concatenate([before["time"], own["time"]]),
                phi_center=np.concatenate([before["phi_center"], own["phi_center"]]),
                phi_wall_layer=np.concatenate([before["phi_wall_layer"], own["phi_wall_layer"]]),
                rms_change=rms_change)


def migration_series(run_dir: str) -> dict:
    """The migration as the run's records hold it, small enough to keep beside a compact snapshot when the
    run folder may be lost (a long run in segments, cases/poiseuille/paperRun): per record its time (in
    L_y/(2U_c)), phi in the central slab |y - mid| < a1 and in the wall layers, and phi(y) in bins of a1."""
    series = _record_series(run_dir)
    return dict(
        time=[round(float(v), 6) for v in series["time"]],
        phi_center=[round(float(v), 5) for v in series["phi_center"]],
        phi_wall_layer=[round(float(v), 5) for v in series["phi_wall_layer"]],
        y=[round(float(v), 6) for v in series["y"]],
        phi_profile=[[round(float(v), 5) for v in p] for p in series["phi_profile"]])


def steady_check(run_dir: str, segments: Sequence[dict] = ()) -> SteadyWindow:
    """The steady window of a run as it stands (steady_window on its migration series, the kept segments
    before its first record included, as analyse() finds it) without the profiles' averages, the momentum
    balance or the SBM: what a run that goes on until it is steady (cases/poiseuille/ladderRun --until-steady)
    asks between its chunks."""
    whole = _with_earlier_series(_record_series(run_dir), segments, run_dir)
    if len(whole["time"]) < MIN_SNAPSHOTS:
        raise PoiseuilleRunError("%s: %d records are too few for a steady window (%d at least): run longer"
                                 % (run_dir, len(whole["time"]), MIN_SNAPSHOTS))
    return steady_window(whole["time"], whole["phi_center"], whole["rms_change"])


def write_segment(run_dir: str, folder: str) -> str:
    """migration_series of run_dir written to folder/segment_<first>_<last>.json (times rounded to the
    record); a segment file of the same first time is replaced (the run went on since)."""
    series = migration_series(run_dir)
    first = series["time"][0]
    os.makedirs(folder, exist_ok=True)
    for name in os.listdir(folder):
        if name.startswith("segment_%g_" % first) and name.endswith(".json"):
            os.remove(os.path.join(folder, name))
    path = os.path.join(folder, "segment_%g_%g.json" % (first, series["time"][-1]))
    with open(path + ".tmp", "w") as f:
        json.dump(series, f, separators=(",", ":"))
    os.replace(path + ".tmp", path)
    return path


def arrival(time: ArrayLike, phi_center: ArrayLike, levels: Sequence[float], at: Sequence[float] = (),
            half_window: float = 25.0) -> dict:
    """How fast a channel's centre arrives (runs of two starts side by side): phi_center averaged over
    +-half_window time units, read at the times `at`, and the first time that average reaches each of `levels`
    (None if it never does)."""
    t = np.asarray(time, dtype=float)
    phi = np.asarray(phi_center, dtype=float)
    mean = np.array([phi[np.abs(t - x) <= half_window].mean() for x in t])
    first = {}
    for level in levels:
        reached = np.nonzero(mean >= level)[0]
        first[level] = float(t[reached[0]]) if reached.size else None
    return dict(at={x: float(np.interp(x, t, mean)) for x in at}, first=first, half_window=half_window)


def _series_of(path: str) -> dict:
    """The migration series of an analysed run (its results.json: data.series) or of a folder of segments."""
    if os.path.isdir(path):
        joined = earlier_series(read_segments(path), math.inf)
        return dict(time=joined["time"], phi_center=joined["phi_center"])
    with open(path) as f:
        data = json.load(f)
    series = data.get("data", data)["series"]
    return dict(time=series["time"], phi_center=series["phi_center"])


USAGE = """usage: python3 -m fdmsubgrid.poiseuille series RUN_DIR FOLDER
  the migration series of the run's records into FOLDER/segment_<t0>_<t1>.json
       python3 -m fdmsubgrid.poiseuille steady RUN_DIR [SEGMENTS]
  whether the run as it stands is steady (steady_check; SEGMENTS: the folder of its kept segments): the
  verdict on one line, exit status 0 if steady, 1 if not yet, 2 if it cannot say
       python3 -m fdmsubgrid.poiseuille arrival LEVELS TIMES SOURCE...
  per SOURCE (an analysed run's results.json, or a folder of segments) phi_center averaged over +-25 time units
  at the comma-separated TIMES and the first time it reaches each of the comma-separated LEVELS"""


if __name__ == "__main__":
    import sys
    if len(sys.argv) == 4 and sys.argv[1] == "series":
        print(write_segment(sys.argv[2], sys.argv[3]))
    elif len(sys.argv) in (3, 4) and sys.argv[1] == "steady":
        try:
            w = steady_check(sys.argv[2], read_segments(sys.argv[3]) if len(sys.argv) == 4 else ())
        except (PoiseuilleRunError, OSError) as e:
            print("fdmsubgrid.poiseuille steady: %s" % e, file=sys.stderr)
            sys.exit(2)
        print("%s at t %.6g: migration time %.4g +- %.2g; %s" % (
            sys.argv[2], w.end_time, w.center.tau, w.center.tau_err,
            "steady from t %.6g (phi_center's slope %.3g +- %.3g per time unit over the window)"
            % (w.start_time, w.trend.slope, w.trend.slope_err) if w.steady else "not steady: " + w.reason))
        sys.exit(0 if w.steady else 1)
    elif len(sys.argv) >= 5 and sys.argv[1] == "arrival":
        try:
            levels = [float(v) for v in sys.argv[2].split(",")]
            times = [float(v) for v in sys.argv[3].split(",")]
        except ValueError:
            raise SystemExit(USAGE)
        for source in sys.argv[4:]:
            found = arrival(**_series_of(source), levels=levels, at=times)
            print("%s: phi_center %s; first reaching %s" % (
                source, ", ".join("%.3f at t %g" % (v, x) for x, v in found["at"].items()),
                ", ".join("%g at t %s" % (lv, "never" if tt is None else "%g" % tt)
                          for lv, tt in found["first"].items())))
    else:
        raise SystemExit(USAGE)
