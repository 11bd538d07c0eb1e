"""The analysis of a sheared-suspension run folder (plane Couette flow, paper section 6.1): from the
folder's own files (the packing, the mesh, the LIGGGHTS input, the particle records, the step and
wall records) to the profiles, the core rheology (Eqs. 49-57), the momentum balance and the cost,
written as a JSON summary and a figure. cases/couette/couette.py calls it after a run; the command
fdmProfiles (shear.main) calls it on any run folder, finished, resumed, stopped or still going.

    from fdmsubgrid import shear
    run = shear.read_run("runs/phi0.3_10x12x8_ad3_dt0.02_seed1_calibrated")
    results, figures = shear.analyse(run)
    results["eta_s"], results["eta_s_err"]

Geometry: walls normal to y at y = 0 and y = L_y moving along x, periodic in x and z (what
cases/couette writes); the profile module itself (profiles.Channel) takes any wall and flow axes."""
from __future__ import annotations

import argparse
import dataclasses
import glob
import json
import math
import os
import re
import sys
from dataclasses import dataclass
from typing import Callable

import numpy as np

from . import demonly, output, packing, profiles, rheology
from .results import Row, relative

H_LAYER = 5.0    # the default wall layer H_layer in units of a1 (paper section 6.1)
MIN_SAMPLES = 8  # the fewest snapshots a time average takes (block averaging: 4 blocks of 2)
SUMMARY_KEYS = ("phi_bulk phi_core gamma_core_over_gamma0 eta_s eta_s_err N1_hat N2_hat Sigma_c_hat strain_units "
                "steady_from_strain n_particles cells dt wall_seconds core_seconds_per_strain_unit "
                "inner_iterations_mean inner_iterations_max unconverged_steps min_pair_gap min_wall_gap").split()


class RunFolderError(ValueError):
    """A run folder that lacks what the analysis needs; the message names the file."""


@dataclass(frozen=True)
class ShearRun:
    """A sheared-suspension run folder as its own files describe it (read_run)."""

    run_dir: str
    packing: packing.Packing
    box: tuple[float, float, float]
    mesh: tuple[int, int, int]
    dt: float
    steps_planned: int
    wall_velocities: tuple[float, float]   # x velocity of the walls y = 0 and y = L_y
    eta: float
    springs: dict
    grad_p0: tuple[float, float, float] = (0.0, 0.0, 0.0)   # the imposed pressure gradient (Eqs. 42, 58)

    @property
    def cells(self) -> int:
        return self.mesh[0] * self.mesh[1] * self.mesh[2]

    @property
    def shear_rate(self) -> float:
        """The nominal shear rate gamma_dot_0 = (U_top - U_bottom)/L_y."""
        return (self.wall_velocities[1] - self.wall_velocities[0]) / self.box[1]

    @property
    def channel(self) -> profiles.Channel:
        return profiles.Channel((0.0, 0.0, 0.0), self.box)


def _read(path: str) -> str:
    try:
        with open(path) as f:
            return f.read()
    except OSError as e:
        raise RunFolderError("%s: cannot read it (%s): is this a run folder of cases/couette?" % (path, e.strerror))


def dem_input(run_dir: str) -> str:
    """The LIGGGHTS input of the run (dem/in.* with pair_style fdm/subgrid)."""
    for path in sorted(glob.glob(os.path.join(run_dir, "dem", "in.*"))):
        if "fdm/subgrid" in _read(path):
            return path
    raise RunFolderError("%s/dem: no LIGGGHTS input (in.*) with pair_style fdm/subgrid" % run_dir)


def _run_steps(text: str, path: str) -> int:
    """N of the `run N` command of a LIGGGHTS input (text, read from path)."""
    found = re.search(r"^run\s+(\d+)", text, re.M)
    if not found:
        raise RunFolderError("%s: no run command" % path)
    return int(found.group(1))


def steps_planned(run_dir: str) -> int:
    """The steps the run's LIGGGHTS input asks for (its `run N` command)."""
    path = dem_input(run_dir)
    return _run_steps(_read(path), path)


def read_run(run_dir: str) -> ShearRun:
    """The scene of a run folder from its own files: dem/packing.data (the spheres), fluid/system/
    blockMeshDict (the mesh), fluid/constant/transportProperties (eta = nu rho), the LIGGGHTS input
    (time step, steps, wall velocities and contact springs of pair_style fdm/subgrid), fluid/constant/
    fdmProperties (the imposed pressure gradient gradP0, zero if absent)."""
    pack = packing.read_data(os.path.join(run_dir, "dem", "packing.data"), walls=(1,))
    mesh_path = os.path.join(run_dir, "fluid", "system", "blockMeshDict")
    found = re.search(r"hex \([\d ]+\) \((\d+) (\d+) (\d+)\)", _read(mesh_path))
    if not found:
        raise RunFolderError("%s: no hex block with its cell counts" % mesh_path)
    mesh = tuple(int(v) for v in found.groups())
    transport_path = os.path.join(run_dir, "fluid", "constant", "transportProperties")
    transport = _read(transport_path)
    values = {}
    for key in ("nu", "rho"):
        m = re.search(r"^\s*%s\s+(?:\[[^\]]*\]\s*)?([0-9.eE+-]+)\s*;" % key, transport, re.M)
        if not m:
            raise RunFolderError("%s: no %s entry" % (transport_path, key))
        values[key] = float(m.group(1))
    path = dem_input(run_dir)
    dem = _read(path)
    dt = re.search(r"^timestep\s+(\S+)", dem, re.M)
    walls = {m.group(1): float(m.group(2)) for m in
             re.finditer(r"\bwall (ylo|yhi) (\S+) \S+ \S+", dem)}
    if not (dt and len(walls) == 2):
        raise RunFolderError("%s: needs timestep and pair_style fdm/subgrid ... wall ylo UX UY UZ wall yhi "
                             "UX UY UZ" % path)
    contact = re.search(r"fdm/subgrid\b[^\n]*?\bcontact (\S+) (\S+) (\S+) (\S+)", dem)
    springs = dict(zip(("kn", "kt", "mu_s", "h_r"), (float(v) for v in contact.groups()))) if contact else {}
    properties_path = os.path.join(run_dir, "fluid", "constant", "fdmProperties")
    grad = re.search(r"^\s*gradP0\s+\(([^)]*)\)\s*;", _read(properties_path), re.M)
    grad_p0 = tuple(float(v) for v in grad.group(1).split()) if grad else (0.0, 0.0, 0.0)
    return ShearRun(run_dir=run_dir, packing=pack, box=tuple(float(v) for v in pack.box), mesh=mesh,
                    dt=float(dt.group(1)), steps_planned=_run_steps(dem, path),
                    wall_velocities=(walls["ylo"], walls["yhi"]), eta=values["nu"] * values["rho"],
                    springs=springs, grad_p0=grad_p0)


def run_seconds(run_dir: str, steps: dict | None = None) -> tuple[float, int]:
    """(wall seconds, ranks) of a run from its step records (the sum over sessions of a resumed run:
    fluid solve + particle work + exchange of every step, the exchange with the particle steps between
    fluid steps; records written before 2026-11-30 left those out: docs/fluid.md, steps.dat), ranks:
    fluid processor folders (or 1) plus one particle rank. steps: the records (output.steps) if already
    read."""
    if steps is None:
        steps = output.steps(os.path.join(run_dir, "fluid"))
    seconds = float(np.sum(steps["fluidSeconds"]) + np.sum(steps["particleSeconds"]) + np.sum(steps["exchangeSeconds"]))
    fluid_ranks = len([d for d in os.listdir(os.path.join(run_dir, "fluid")) if d.startswith("processor")]) or 1
    return seconds, fluid_ranks + 1


def minimum_gaps(snapshots: list[profiles.Snapshot], box: np.ndarray) -> tuple[float, float]:
    """Smallest surface gap between spheres and between a sphere and a wall over the snapshots."""
    pair, wall = math.inf, math.inf
    for s in snapshots:
        i, j, d = packing.neighbour_pairs(s.positions, box, 2 * float(s.radii.max()) + 0.5, walls=(1,))
        if len(i):
            pair = min(pair, float(np.min(d - s.radii[i] - s.radii[j])))
        wall = min(wall, float(np.min(np.minimum(s.positions[:, 1] - s.radii, box[1] - s.positions[:, 1] - s.radii))))
    return pair, wall


def analyse(run: ShearRun, wall_seconds: float | None = None, ranks: int | None = None,
            h_layer: float = H_LAYER, from_strain: float | None = None) -> tuple[dict, list]:
    """The results of a run (a flat dict: docs/profiles.md lists the keys; `species` one dict per species,
    profiles.species_summary, its phi profile on the bins `species_profile_y`) and what the figure needs
    ([channel, coarse profiles, fine profiles, snapshots, species profiles]). The steady part starts where the MSER
    rule puts the end of the transient (docs/profiles.md), or at from_strain if given; the run time
    is the step records' (run_seconds) unless given."""
    rate = run.shear_rate
    steps = output.steps(os.path.join(run.run_dir, "fluid"))
    if wall_seconds is None or ranks is None:
        wall_seconds, ranks = run_seconds(run.run_dir, steps)
    if len(steps["time"]) == 0:
        raise RunFolderError("%s/fluid/postProcessing/fdm/steps.dat: no step recorded yet" % run.run_dir)
    snapshots, _ = output.record_snapshots(os.path.join(run.run_dir, "dem", "particles.records"), rate)
    box = np.array(run.box)
    channel = run.channel
    phi_integral = [profiles.bulk_volume_fraction(s, channel) for s in snapshots]
    series = profiles.core_series(snapshots, channel, h_layer=h_layer)
    if from_strain is not None:
        kept = int(np.sum(np.asarray(series.times) >= from_strain - 1e-9))
        if kept < MIN_SAMPLES:
            raise ValueError("%s: from strain %g on there are %d particle snapshots (the run's end at strain %g); "
                             "time averages need %d at least" % (run.run_dir, from_strain, kept,
                                                                 series.times[-1] if len(snapshots) else 0.0,
                                                                 MIN_SAMPLES))
        r = rheology.shear_rheology(series, eta=run.eta, start_time=from_strain)
    elif len(snapshots) >= 16:
        r = rheology.shear_rheology(series, eta=run.eta)    # the steady part from MSER-m (docs/profiles.md)
    elif len(snapshots) >= MIN_SAMPLES:  # too few snapshots for the transient rule: the last 8 or more, flagged
        start = float(series.times[min(len(snapshots) // 2, len(snapshots) - MIN_SAMPLES)])
        r = dataclasses.replace(rheology.shear_rheology(series, eta=run.eta, start_time=start), steady=False)
    else:
        raise ValueError("%s: %d particle snapshots are too few for time averages (%d at least): run longer or "
                         "record more often" % (run.run_dir, len(snapshots), MIN_SAMPLES))
    # the momentum balance (docs/profiles.md "Stress balance"): the core stress of Eq. 51 against the
    # walls' shear stress (fluid traction + sub-grid lubrication + contact), both over the steady part;
    # and at every snapshot the gap-averaged stress against the mean of the two walls (exact)
    loads = output.read_wall_loads(run.run_dir)
    balance = rheology.stress_balance(r, loads, channel, rate)
    tau = rheology.wall_shear_stresses(loads, channel)["total"].mean(axis=1)
    step_of = {int(st): k for k, st in enumerate(loads.steps)}
    gap_errors = []
    for s in snapshots:
        k = step_of.get(int(round(s.time / (rate * run.dt))))
        if k is not None:
            gap = rheology.gap_shear_stress(s, channel, run.eta, rate)
            gap_errors.append(rheology.relative_difference(gap, float(tau[k])))
    avg = profiles.average_profiles(snapshots, channel, start_time=r.start_time)
    fine = profiles.average_profiles(snapshots, channel, y=channel.planes(0.02), start_time=r.start_time, errors=False)
    # each species alone (atom type): phi(y) on the same bins, its core volume fraction over the same window
    species = profiles.species_profiles(snapshots, channel, h_layer=h_layer, edges=avg.edges, start_time=r.start_time)
    pair_gap, wall_gap = minimum_gaps(snapshots, box)
    strain = float(steps["time"][-1] * rate)
    inner = steps["innerIterations"]
    pack = run.packing

    def est(e: rheology.Estimate) -> float:
        return float(e.value)

    res = dict(
        phi_bulk=pack.phi, phi_bulk_integral_max_error=float(np.max(np.abs(np.array(phi_integral) - pack.phi))),
        phi_core=est(r.phi_core), phi_core_err=r.phi_core.error,
        gamma_core_over_gamma0=est(r.gamma_dot_core) / rate, gamma_core_err=r.gamma_dot_core.error / rate,
        eta_s=est(r.eta_s), eta_s_err=r.eta_s.error, eta_s_n_eff=r.eta_s.n_eff,
        N1_hat=est(r.n1_hat), N1_hat_err=r.n1_hat.error, N2_hat=est(r.n2_hat), N2_hat_err=r.n2_hat.error,
        Sigma_c_hat=[est(e) for e in r.sigma_c_hat], Sigma_c_hat_err=[e.error for e in r.sigma_c_hat],
        strain_units=strain, steady_from_strain=r.start_time, steady_detected=r.steady, samples_averaged=r.n_samples,
        h_layer=h_layer, n_particles=pack.n, n_a1=int(np.sum(pack.types == 1)), n_a2=int(np.sum(pack.types == 2)),
        cells=run.cells, mesh=list(run.mesh), box=list(run.box), dt=run.dt, steps=int(len(inner)),
        steps_planned=run.steps_planned, wall_seconds=wall_seconds, ranks=ranks,
        core_seconds_per_strain_unit=wall_seconds * ranks / strain if strain > 0 else math.nan,
        inner_iterations_mean=float(inner.mean()), inner_iterations_max=int(inner.max()),
        unconverged_steps=int(np.sum(steps["converged"] == 0)),
        min_pair_gap=pair_gap, min_wall_gap=wall_gap,
        mean_particle_velocity=np.mean([s.velocities.mean(axis=0) for s in snapshots], axis=0).tolist(),
        snapshots=len(snapshots), springs=dict(run.springs),
        species=profiles.species_summary(species, float(np.prod(box))), species_profile_y=avg.y.tolist())
    res.update(balance.as_dict())
    res.update(stress_gap_rel_error_max=float(np.max(gap_errors)) if gap_errors else float("nan"),
               stress_gap_snapshots=len(gap_errors))
    return res, [channel, avg, fine, snapshots, species]


def figure_path(out: str) -> str:
    """The profile figure beside the summary: results_couette.png beside results.json, else X.png
    beside X.json."""
    if out.endswith(".json") and os.path.basename(out) != "results.json":
        return out[:-len(".json")] + ".png"
    return os.path.join(os.path.dirname(os.path.abspath(out)), "results_couette.png")


def validation_rows(r: dict, configuration: str) -> list[Row]:
    """The rows (fdmsubgrid.results) of one sheared suspension's results `r` (analyse(); a row of
    cases/couette/table8.py's summary has the same keys): phi_core and gamma_core/gamma0 beside the paper's
    Table 8 where r['table8'] has the scene, eta_s beside the paper's fit of Fig. 21 (Eq. 55) at the run's
    own phi_core (Table 8 gives no eta_s), the normal-stress differences (Fig. 22) and the stress balance."""
    rows = []
    t = r.get("table8") or {}
    for q, key in (("φ_core", "phi_core"), ("γ̇_core/γ̇0", "gamma_core_over_gamma0")):
        paper = t.get(key)
        rows.append(Row(q, configuration, r[key], paper, "%g (Table 8)" % paper if paper is not None else "—",
                        relative(r[key], paper), spread=r.get(key + "_err") or r.get(key.split("_over")[0] + "_err")))
    paper_fit = float(rheology.maron_pierce(r["phi_core"], *rheology.PAPER_MARON_PIERCE))
    rows.append(Row("η_s", configuration, r["eta_s"], paper_fit, "%.4g (Fig. 21's fit at φ_core)" % paper_fit,
                    relative(r["eta_s"], paper_fit), spread=r["eta_s_err"]))
    rows.append(Row("N̂1", configuration, r["N1_hat"], spread=r.get("N1_hat_err"), paper="Fig. 22"))
    rows.append(Row("N̂2", configuration, r["N2_hat"], spread=r.get("N2_hat_err"), paper="Fig. 22"))
    rows.append(Row("stress balance (core against walls)", configuration, r["stress_balance_rel_error"],
                    percent=True))
    return rows


def write_json_summary(out: str, results: dict) -> None:
    """report()'s default writer: the summary as JSON (fdmProfiles --out)."""
    with open(out, "w") as f:
        json.dump(results, f, indent=1)


def report(run: ShearRun, out: str, extra: dict | None = None, wall_seconds: float | None = None,
           ranks: int | None = None, h_layer: float = H_LAYER, from_strain: float | None = None,
           quiet: bool = False, write: Callable[[str, dict], None] = write_json_summary) -> dict:
    """analyse() the run, write `out` (the JSON summary, with `extra`; `write(out, results)`: a case writes
    its results file in the shape of fdmsubgrid.results) and the profile figure beside it (figure_path),
    print the summary unless quiet; returns the results."""
    results, (channel, avg, fine, _, species) = analyse(run, wall_seconds, ranks, h_layer, from_strain)
    results.update(extra or {})
    # the position update's counts (fdmRun's log.dem, every session): too many limited targets mean too large a dt
    log_dem = os.path.join(run.run_dir, "log.dem")
    counts = demonly.position_update_counts(_read(log_dem)) if os.path.isfile(log_dem) else None
    results["position_update"] = counts
    warning = demonly.time_step_too_large(counts)
    if warning and not quiet:
        print(warning)
    figure = figure_path(out)
    profiles.plot_profiles(figure, channel, avg, fine, species=species)
    results["figure"] = os.path.basename(figure)
    write(out, results)
    if not quiet:
        print_summary(results)
        print("wrote %s and %s" % (out, figure))
    return results


def print_summary(results: dict) -> None:
    """The table of a run's results, its species and its stress balance, as fdmProfiles prints it."""
    for k in SUMMARY_KEYS:
        print("%-30s %s" % (k, results[k]))
    for sp in results.get("species") or []:
        error = sp["phi_core_err"]
        print("species type %d (radius %g, %d spheres): phi_bulk %.4f, phi_core %.4f%s"
              % (sp["type"], sp["radius"], sp["n"], sp["phi_bulk"], sp["phi_core"],
                 "" if error is None else " +- %.2g" % error))
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


def viscosity_curve(results: list[dict], figure: str | None = None) -> dict:
    """The Maron-Pierce fit eta_s = alpha/(1 - phi/phi_m)^2 (Eq. 55) through the runs' (phi_core,
    eta_s +- err), with its uncertainty (rheology.fit_maron_pierce), and the figure (Fig. 21 with
    error bars) if a path is given. Needs three runs or more."""
    if len(results) < 3:
        raise ValueError("the Maron-Pierce fit needs three runs or more (%d given)" % len(results))
    phi = [r["phi_core"] for r in results]
    eta_s = [r["eta_s"] for r in results]
    err = [r["eta_s_err"] for r in results]
    fit = rheology.fit_maron_pierce(phi, eta_s, err)
    if figure:
        rheology.plot_viscosity(figure, phi, eta_s, err, fit=fit)
    return dict(alpha=fit.alpha, alpha_err=fit.alpha_error, phi_m=fit.phi_m, phi_m_err=fit.phi_m_error,
                chi2=fit.chi2, dof=fit.dof, runs=len(results))


def command(argv: list[str] | None = None) -> int:
    """The fdmProfiles command (pyproject.toml's [project.scripts], scripts/fdmProfiles): main() with the
    exit status a command gives (0; argparse's 2 on bad options), not main's results, which
    sys.exit would print and turn into the status 1."""
    main(argv)
    return 0


def main(argv: list[str] | None = None) -> list[dict]:
    """fdmProfiles RUN_DIR [RUN_DIR ...]: the profiles and rheology of sheared-suspension runs."""
    p = argparse.ArgumentParser(
        prog="fdmProfiles",
        description="Profiles and rheology of sheared-suspension run folders (cases/couette): phi(y), u_p(y), "
                    "particle stresses, the core values (Eqs. 49-57) time-averaged over the steady part with "
                    "block-averaging error bars, and the momentum balance. Writes RUN_DIR/profiles.json and "
                    "RUN_DIR/profiles.png (or --out); with three runs or more, the Maron-Pierce fit (Eq. 55) "
                    "and the viscosity curve too (docs/profiles.md).")
    p.add_argument("run_dirs", nargs="+", metavar="RUN_DIR", help="a run folder (fluid/ and dem/), finished or not")
    p.add_argument("--core", type=float, default=H_LAYER, metavar="H_LAYER",
                   help="wall layer H_layer/a1 left out of the core: the core is |y - L_y/2| < L_y/2 - H_layer "
                        "(default %(default)g)")
    p.add_argument("--from-strain", type=float, default=None,
                   help="average from this strain on (default: the end of the transient by the MSER rule)")
    p.add_argument("--out", default=None, help="the JSON summary (one run only; default RUN_DIR/profiles.json)")
    p.add_argument("--curve", default="viscosity_curve",
                   help="with three runs or more: the fit and figure as CURVE.json and CURVE.png")
    args = p.parse_args(argv)
    if args.out and len(args.run_dirs) > 1:
        p.error("--out takes one RUN_DIR")
    results = []
    for run_dir in args.run_dirs:
        try:
            run = read_run(run_dir)
            out = args.out or os.path.join(run_dir, "profiles.json")
            print("== %s" % run_dir)
            results.append(report(run, out, dict(run_dir=os.path.abspath(run_dir)), h_layer=args.core,
                                  from_strain=args.from_strain))
        except (ValueError, FileNotFoundError) as e:   # RunFolderError is a ValueError
            p.exit(2, "fdmProfiles: %s\n" % e)
    if len(results) >= 3:
        fit = viscosity_curve(results, args.curve + ".png")
        with open(args.curve + ".json", "w") as f:
            json.dump(dict(fit=fit, runs=[{k: r[k] for k in ("run_dir", "phi_core", "phi_core_err", "eta_s",
                                                             "eta_s_err")} for r in results]), f, indent=1)
        print("Maron-Pierce fit (Eq. 55) over %d runs: alpha = %.3f +- %.3f, phi_m = %.3f +- %.3f; wrote %s.json "
              "and %s.png" % (len(results), fit["alpha"], fit["alpha_err"], fit["phi_m"], fit["phi_m_err"],
                              args.curve, args.curve))
    return results


if __name__ == "__main__":
    sys.exit(0 if main() else 1)
