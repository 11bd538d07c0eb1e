#!/usr/bin/env python3
"""The paper's Table 8 and Fig. 21 (section 6.1) from one command: each phi_bulk's scene written,
run or resumed, analysed, then the viscosity curve with the Maron-Pierce fit (Eq. 55).

  table8.py                                 phi_bulk 0.27, 0.37, 0.47 (25 strain units, tolLambda 1e-2,
                                            each row's particles at the largest time step measured good
                                            there: 0.04, 0.02, 0.01, and the fluid every 0.04 up to 0.42,
                                            0.02 beyond: couettescene.fluid_every, 1, 2 and 2 particle steps
                                            per fluid step)
  table8.py --paper --jobs 2                all seven rows of the paper's Fig. 21 (= --phis 0.27 0.32 0.37
                                            0.42 0.47 0.52 0.54), two at a time
  table8.py --analyse-only                  the runs as they stand (partial runs reported with the
                                            strain they reached), nothing run
  table8.py --progress-minutes 10           every 10 minutes a line per running row: the strain it
                                            reached of its target and fdmFoam's ETA (0: none)
  table8.py --session-hours 2.5             stop launching runs after this long (a run in progress is
                                            checkpointed every strain unit; the next call resumes it)
  table8.py --jobs 2                        rows run at once (default: one per --np-fluid cores this
                                            process may use; a row's particle rank mostly waits)
  table8.py --snapshots DIR [--save]        keep each row's compact snapshot in DIR (--save writes them and
                                            stops); a row whose run folder is new continues from its
                                            snapshot there: a run of several sessions outlives its machine
  table8.py --min-average 20                each finished run whose averaging window (after the transient
                                            its MSER rule finds) is shorter is extended (fdmRun --resume
                                            --until) until it holds 20 strain units, up to --max-strain

Rows are launched densest first: the dense rows cost the most (docs/validation.md, Table 8), and the
longest first leaves the short ones to fill the cores at the end. The summary's `budget` adds the rows'
measured wall times and gives the wall time the call would take from nothing at --jobs rows at a time in
that order (`makespan`): the cost of the whole curve from one command.

Each run is `couette.py --table8 PHI` (the paper's box and particle count, this project's time step
and a1/Delta), in <workdir>/table8_phi..., run with fdmRun; a call finds each folder again: a
finished run is analysed, one with a checkpoint is resumed (`fdmRun --resume`), one without is
started again; a finished run averaged over fewer than --min-average strain units (default 20, the
paper's "a few tens of strain units") is extended from its last checkpoint, so that no row is reported
over a silently shortened window (a row still short, at --max-strain, says so). Rows run --jobs at a
time; a row whose run stops is named at the end, after the other rows have run and the summary is
written. Killing this script (or the session ending) loses at most one checkpoint interval.

--rows-from JSON... adds the rows of earlier summaries (their run folders elsewhere or gone) for the
phi_bulk not run here; a row whose particle step exceeds couettescene.largest_good_dt at its phi_bulk (one run
before that limit was measured) is listed and plotted, not fitted.

Writes --out (default docs/data/table8.json): per phi_bulk the paper's row, this project's phi_core,
gamma_core/gamma_0, eta_s, N1_hat, N2_hat, Sigma_c_hat with error bars, the stress balance, the strain
reached and the cost; the Maron-Pierce fit with its uncertainty against the paper's alpha = 0.803,
phi_m = 0.59 (over 3 or more finished rows whose window is full: partial and short rows are plotted
and listed, not fitted); and the figures beside it: Fig. 21 with error bars, and Fig. 22 (the normal
stress differences and the contact normal stresses with their error bars) as <out>_normal_stresses.png.
"""
import argparse
import contextlib
import glob
import heapq
import json
import math
import os
import re
import subprocess
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from typing import Dict, Iterator, List, Optional, Tuple

from fdmsubgrid import checkpoint, couettescene, demonly, files, output, results, rheology, suspension  # couettescene: a row's time step
from fdmsubgrid.shear import steps_planned

HERE = os.path.dirname(os.path.abspath(__file__))
PROJECT = os.path.dirname(os.path.dirname(HERE))

PAPER_FIT = dict(zip(("alpha", "phi_m"), rheology.PAPER_MARON_PIERCE))   # paper section 6.1, Eq. (55)
# The time step of a row unless --dt says one: couettescene.largest_good_dt(phi_bulk), the largest measured good
# (0.04 at 0.27, 0.02 from 0.32 to 0.42, 0.01 at 0.47, smaller beyond; couettescene.MEASURED_DT_LIMITS,
# docs/benchmarks.md "What limits the time step"). Until 2026-11-27 0.04 below phi_bulk 0.30 (0.45, then
# 0.40 before that) and 0.02 above it: the rows 0.32 and 0.37 of docs/validation.md ran at 0.04, 0.47 at 0.02.
DEFAULT_PHIS = [0.27, 0.37, 0.47]          # a curve with three points, the fit's least
MIN_STRAIN_TO_REPORT = 2.0                  # below this a run is listed as started, not analysed


def row_dt(phi: float, args: argparse.Namespace) -> float:
    """The (particle) time step of the row phi_bulk: --dt if given, else couettescene.largest_good_dt(phi)."""
    if args.dt is not None:
        return args.dt
    return couettescene.largest_good_dt(phi)


def row_fluid_every(phi: float, args: argparse.Namespace) -> int:
    """Particle steps per fluid step of the row phi_bulk: --fluid-every if given, else
    couettescene.fluid_every(phi, dt) (the fluid every couettescene.fluid_dt(phi) or so; 1 where the particle step is
    that large already)."""
    if getattr(args, "fluid_every", None) is not None:
        return args.fluid_every
    return couettescene.fluid_every(phi, row_dt(phi, args))


def default_jobs(np_fluid: int) -> int:
    """Rows run at once unless --jobs says: one per np_fluid cores this process may use (a row's fdmDEM
    rank waits for the fluid most of the time: 5-9 % of a core in the phi 0.42 and 0.47 rows)."""
    return max(1, len(os.sched_getaffinity(0)) // max(1, np_fluid))


def launch_order(phis: List[float]) -> List[float]:
    """The order rows are launched in: densest first (the longest runs first, the short ones fill the
    cores at the end)."""
    return sorted(phis, reverse=True)


def makespan(walls: List[float], jobs: int) -> float:
    """The wall time of running jobs of these wall times `jobs` at a time, each next one (in the given
    order) on the first slot free: what a ThreadPoolExecutor of `jobs` workers takes for them."""
    slots = [0.0] * max(1, jobs)
    for wall in walls:
        heapq.heapreplace(slots, slots[0] + wall)
    return max(slots)


def find_run(workdir: str, phi: float, a_over_delta: float, dt: float, seed: int, model: str,
             fluid_every: int = 1, coulomb_solve: str = suspension.COULOMB_SOLVE[0]) -> Optional[str]:
    """The run folder couette.py --table8 wrote for this row, sub-grid model, fluid_every and coulomb_solve, if
    any (a folder without the model in its name is from before the name said it: the cut-off model's)."""
    pattern = os.path.join(workdir, "table8_phi%g_*_ad%g_dt%g_seed%d" % (phi, a_over_delta, dt, seed))
    every = "_fluidEvery%d" % fluid_every if fluid_every > 1 else ""
    every += suspension.coulomb_tag(coulomb_solve)
    found = sorted(d for d in glob.glob(pattern + "_" + model + every)
                   + (glob.glob(pattern + every) if model == "cutoff" else []) if os.path.isdir(d))
    return found[0] if found else None


def row_run(phi: float, args: argparse.Namespace) -> Optional[str]:
    """The run folder of this row under the command's options (find_run), if any."""
    return find_run(args.workdir, phi, args.a_over_delta, row_dt(phi, args), args.seed, args.model,
                    row_fluid_every(phi, args), args.coulomb_solve)


def steps_done(run_dir: str) -> int:
    path = os.path.join(run_dir, "fluid", "postProcessing", "fdm", "steps.dat")
    if not os.path.exists(path):
        return 0
    steps = output.steps(os.path.join(run_dir, "fluid"))
    return int(steps["step"][-1]) if len(steps["step"]) else 0


def running_elsewhere(run_dir: str) -> bool:
    """Whether another process (an fdmRun started by hand, another table8.py) is running this
    folder: a process whose command line names it."""
    target = os.path.realpath(run_dir)
    name = os.path.basename(target)
    for cmdline in glob.glob("/proc/[0-9]*/cmdline"):
        if cmdline == "/proc/%d/cmdline" % os.getpid():
            continue
        try:
            with open(cmdline, "rb") as f:
                words = f.read().decode(errors="replace").split("\0")
        except OSError:
            continue
        if any(w and (os.path.basename(os.path.normpath(w)) == name or w.startswith(target + "/")) for w in words[1:]):
            return True
    return False


# fdmFoam's progress line as fdmRun copies it into a row's log: "Step N t = T  inner ... | ETA S s"
PROGRESS_LINE = re.compile(r"^Step (\d+) t = \S+\s.*\| ETA (\S+) s\s*$")
_running: Dict[str, Tuple[float, float, int]] = {}   # run folder -> (phi_bulk, dt, last step) of the runs going
_running_lock = threading.Lock()


def last_progress(log: str) -> Optional[Tuple[int, float]]:
    """The step and the ETA (s) of the last progress line in a row's log (fdmFoam's, through fdmRun), or
    None while it has none. Reads the log's last 64 kB only: the logs of long runs grow to many MB."""
    try:
        with open(log, "rb") as f:
            f.seek(0, os.SEEK_END)
            f.seek(max(0, f.tell() - 65536))
            tail = f.read().decode(errors="replace")
    except FileNotFoundError:
        return None
    for line in reversed(tail.splitlines()):
        m = PROGRESS_LINE.match(line.strip())
        if m:
            try:
                return int(m.group(1)), float(m.group(2))
            except ValueError:
                continue
    return None


@contextlib.contextmanager
def running(run_dir: str, phi: float, dt: float, last_step: int) -> Iterator[None]:
    """Lists the run as going (for progress_report) while the block runs."""
    with _running_lock:
        _running[run_dir] = (phi, dt, last_step)
    try:
        yield
    finally:
        with _running_lock:
            _running.pop(run_dir, None)


def progress_report(waiting: List[float]) -> Optional[str]:
    """One line on the runs going: per row the strain reached of its target and fdmFoam's ETA for it; then
    the rows not launched yet. None when nothing runs or waits."""
    with _running_lock:
        going = sorted(_running.items(), key=lambda item: item[1][0])
    parts = []
    for run_dir, (phi, dt, last_step) in going:
        progress = last_progress(run_dir + ".log")
        if progress is None:
            parts.append("phi_bulk %g starting" % phi)
            continue
        step, eta = progress
        parts.append("phi_bulk %g at strain %.1f of %.1f, ETA %.1f h" % (phi, step * dt, last_step * dt, eta / 3600))
    if waiting:
        parts.append("waiting: " + ", ".join("%g" % phi for phi in sorted(waiting)))
    if not parts:
        return None
    return "table8 progress %s: %s" % (time.strftime("%H:%M"), "; ".join(parts))


def _fdmrun(run_dir: str, args: argparse.Namespace, until: Optional[int] = None, phi: Optional[float] = None) -> None:
    """Start the run in run_dir, or resume it from its checkpoint (to step `until` if given); phi names the
    row in the line that says so (one print: with --jobs 2 the rows' lines must not interleave)."""
    fdmrun = [os.path.join(PROJECT, "scripts", "fdmRun"), "-f", str(args.np_fluid)]
    kept = snapshot_folder(run_dir, args)
    try:
        checkpoint.select(run_dir)
        cmd = fdmrun + ["--resume"] + (["--until", str(until)] if until else []) + [run_dir]
    except checkpoint.CheckpointError:
        if kept and not steps_done(run_dir):
            # the run folder is new (a new machine): the particles from the kept snapshot, the fluid from rest
            cmd = fdmrun + ["--from-snapshot", kept] + (["--until", str(until)] if until else []) + [run_dir]
        elif until and steps_done(run_dir) >= steps_planned(run_dir):
            raise   # a finished run without a checkpoint cannot be extended
        else:
            cmd = fdmrun + (["--overwrite"] if steps_done(run_dir) else []) + [run_dir]
    log = run_dir + ".log"
    print("table8: %s%s (log %s)" % ("" if phi is None else "phi_bulk %g: " % phi, " ".join(cmd), log), flush=True)
    with open(log, "a") as f:
        done = subprocess.run(cmd, stdout=f, stderr=subprocess.STDOUT)
    if done.returncode != 0:
        # fdmRun has said why at the end of the log; the checkpoints are kept
        raise SystemExit("table8: fdmRun stopped with exit code %d on %s: the end of %s says why; the same "
                         "table8.py command resumes the run from its last checkpoint" % (done.returncode, run_dir, log))


def kept_snapshot_path(run_dir: str, snapshots: str) -> str:
    """Where --snapshots keeps the compact snapshot of this run: a folder named as the run folder."""
    return os.path.join(snapshots, os.path.basename(os.path.normpath(run_dir)))


def snapshot_folder(run_dir: str, args: argparse.Namespace) -> Optional[str]:
    """The compact snapshot of this run kept under --snapshots, if any."""
    if not getattr(args, "snapshots", None):
        return None
    folder = kept_snapshot_path(run_dir, args.snapshots)
    return folder if os.path.exists(os.path.join(folder, "README")) else None


def save_snapshots(args: argparse.Namespace) -> None:
    """--save: each row's newest checkpoint as a compact snapshot in --snapshots (replacing the one there),
    the rows without a run folder or checkpoint named."""
    for phi in args.phis:
        run_dir = row_run(phi, args)
        if run_dir is None:
            print("table8 --save: phi_bulk %g: no run folder in %s" % (phi, args.workdir))
            continue
        dest = kept_snapshot_path(run_dir, args.snapshots)
        try:
            snap = checkpoint.snapshot(run_dir, dest)
        except checkpoint.CheckpointError as e:
            print("table8 --save: phi_bulk %g: %s" % (phi, e))
            continue
        print("table8 --save: phi_bulk %g: step %d kept in %s (%.0f kB)" % (phi, snap["step"], dest, snap["bytes"] / 1e3))


def extension(row: Dict, args: argparse.Namespace, dt: float) -> Optional[int]:
    """The step a finished run must be continued to so that its averaging window (after the
    transient) holds --min-average strain units, at most --max-strain; None if it holds them, or
    if it has reached --max-strain. A run is extended by its shortfall and by at least a tenth of
    --min-average: MSER's end of the transient moves a little later as a run grows (its batches
    grow with it), so extending by the shortfall alone came up short again by a fraction of a unit
    (the 0.32 row: 19.3 units averaged at strain 35.2, then again at 35.9), each time paying a
    resume. The chase is bounded: MSER never puts the transient's end past half the run, so a run of
    2 --min-average holds the window."""
    averaged = row.get("strain_averaged", 0.0)
    short = args.min_average - averaged
    last = int(round(args.max_strain / dt))
    if short <= 1e-9 or row["steps_done"] >= last:
        return None
    more = max(short, 0.1 * args.min_average)
    return min(row["steps_done"] + int(math.ceil(more / dt - 1e-9)), last)


def run_row(phi: float, args: argparse.Namespace) -> Optional[Dict]:
    """Write, start or resume the run of one phi_bulk until it finishes, then extend it while its
    averaging window is short of --min-average; returns the analysis of the run as it ends (analyse_row),
    or None if none was made (--min-average 0). A run that another process is running is waited for,
    never started a second time."""
    dt = row_dt(phi, args)
    every = row_fluid_every(phi, args)
    run_dir = row_run(phi, args)
    if run_dir is not None and running_elsewhere(run_dir):
        print("table8: phi_bulk %g: %s is running in another process; waiting for it" % (phi, run_dir), flush=True)
        while running_elsewhere(run_dir):
            time.sleep(60)
    if run_dir is None:
        subprocess.run([sys.executable, os.path.join(HERE, "couette.py"), "--table8", str(phi), "--dt", str(dt),
                        "--strain", str(args.strain), "--a-over-delta", str(args.a_over_delta),
                        "--seed", str(args.seed), "--n-max", str(args.n_max), "--tol-lambda", str(args.tol_lambda),
                        "--model", args.model, "--fluid-every", str(every), "--coulomb-solve", args.coulomb_solve,
                        "--workdir", args.workdir], check=True)
        run_dir = row_run(phi, args)
    if steps_done(run_dir) < steps_planned(run_dir):
        # to the input's last step: an extension killed before its first checkpoint resumes from one
        # written for the shorter run, which fdmDEM accepts only with -until
        with running(run_dir, phi, dt, steps_planned(run_dir)):
            _fdmrun(run_dir, args, until=steps_planned(run_dir), phi=phi)
    row = None
    while args.min_average > 0:
        row = analyse_row(phi, run_dir, args)
        until = extension(row, args, dt)
        if until is None:
            break
        print("table8: phi_bulk %g: averaged over %.1f strain units after the transient, short of --min-average "
              "%g: extended to strain %g" % (phi, row.get("strain_averaged", 0.0), args.min_average, until * dt),
              flush=True)
        with running(run_dir, phi, dt, until):
            _fdmrun(run_dir, args, until=until, phi=phi)
    return row


def analyse_row(phi: float, run_dir: Optional[str], args: argparse.Namespace) -> Dict:
    """couette.py --analyse of the run as it stands, with the paper's row."""
    row: Dict = dict(phi_bulk_table8=phi, run_dir=run_dir, fluid_every=row_fluid_every(phi, args))
    dt = row_dt(phi, args)
    if run_dir is None:
        return row | dict(status="not started")
    done, planned = steps_done(run_dir), steps_planned(run_dir)
    row.update(steps_done=done, steps_planned=planned, strain_reached=done * dt)
    if done * dt < MIN_STRAIN_TO_REPORT:
        return row | dict(status="started")
    out = run_dir + ".results.json"
    subprocess.run([sys.executable, os.path.join(HERE, "couette.py"), "--analyse", run_dir, "--out", out], check=True,
                   stdout=subprocess.DEVNULL)
    r = results.read_data(out)
    keep = ("phi_bulk phi_core phi_core_err gamma_core_over_gamma0 gamma_core_err eta_s eta_s_err N1_hat N1_hat_err "
            "N2_hat N2_hat_err Sigma_c_hat Sigma_c_hat_err steady_from_strain steady_detected strain_units "
            "stress_balance_rel_error stress_balance_rel_error_err stress_gap_rel_error_max n_particles cells dt "
            "wall_seconds core_seconds_per_strain_unit inner_iterations_mean unconverged_steps min_pair_gap "
            "min_wall_gap table8 springs position_update").split()
    row.update({k: r.get(k) for k in keep})
    row["status"] = "finished" if done >= planned else "partial"
    row["strain_averaged"] = r["strain_units"] - r["steady_from_strain"]
    row["window_short"] = row["strain_averaged"] < args.min_average
    return row


def step_too_large(row: Dict) -> bool:
    """The run's position update limited more than demonly.LIMITED_RATE_LIMIT gap targets per particle and
    step: its time step was too large and its particle stress is low (docs/benchmarks.md, "What limits the
    time step")."""
    return demonly.time_step_too_large(row.get("position_update")) is not None


def beyond_good_step(row: Dict) -> bool:
    """The row's (particle) time step exceeds couettescene.largest_good_dt at its phi_bulk (a row run before that
    limit was measured, e.g. phi_bulk 0.32 or 0.37 at 0.04: 7 and 12-15 % low, docs/benchmarks.md)."""
    dt = row.get("dt")
    return dt is not None and dt > couettescene.largest_good_dt(row["phi_bulk_table8"]) * (1 + 1e-9)


def fitted_rows(rows: List[Dict]) -> List[Dict]:
    """The rows the Maron-Pierce fit takes: finished runs whose window holds --min-average units and whose
    time step was neither too large for its run (the position update's counts) nor beyond the largest
    measured good at its phi_bulk."""
    return [r for r in rows if "eta_s" in r and r["status"] == "finished" and not r.get("window_short")
            and not step_too_large(r) and not beyond_good_step(r)]


def earlier_rows(paths: List[str], phis: List[float]) -> List[Dict]:
    """The rows of earlier table8.py summaries (--rows-from; their run folders elsewhere, or gone with
    another machine) for the phi_bulk not in phis, the first file's row of each phi_bulk; each says where
    it came from (`from`)."""
    found: Dict[float, Dict] = {}
    for path in paths:
        with open(path) as f:
            summary = json.load(f)
        if "rows" not in summary:
            raise SystemExit("table8: --rows-from %s is not a table8.py summary (no 'rows')" % path)
        for r in summary["rows"]:
            phi = r["phi_bulk_table8"]
            if "eta_s" in r and all(abs(phi - q) > 1e-9 for q in phis) and phi not in found:
                found[phi] = dict(r, fluid_every=r.get("fluid_every", 1), **{"from": path})
    return [found[phi] for phi in sorted(found)]


def summarise(rows: List[Dict], args: argparse.Namespace) -> Dict:
    """The Maron-Pierce fit (over 3 or more finished rows whose window holds --min-average strain
    units: a partial or short row is plotted and listed, not fitted) and Fig. 21."""
    done = [r for r in rows if "eta_s" in r]
    fitted = fitted_rows(rows)
    def dt_of(r: Dict) -> float:       # a row from an earlier summary keeps its own
        return r["dt"] if "from" in r else row_dt(r["phi_bulk_table8"], args)

    dts = sorted({dt_of(r) for r in rows})
    summary: Dict = dict(rows=rows, paper_fit=PAPER_FIT, a_over_delta=args.a_over_delta,
                         dt={"%g" % r["phi_bulk_table8"]: dt_of(r) for r in rows},
                         # analyse_row and earlier_rows give each row its own (a row without one: every step)
                         fluid_every={"%g" % r["phi_bulk_table8"]: r.get("fluid_every", 1) for r in rows},
                         tol_lambda=args.tol_lambda, strain=args.strain, seed=args.seed)
    timed_by_phi = {r["phi_bulk_table8"]: r for r in done if r.get("wall_seconds")}
    timed = [timed_by_phi[phi] for phi in launch_order(list(timed_by_phi))]
    if timed:
        summary["budget"] = dict(rows=[r["phi_bulk_table8"] for r in timed], jobs=args.jobs,
                                 wall_seconds_rows=float(sum(r["wall_seconds"] for r in timed)),
                                 projected_wall_seconds=makespan([r["wall_seconds"] for r in timed], args.jobs),
                                 # a row still running counts with the wall time it has taken so far
                                 unfinished=[r["phi_bulk_table8"] for r in timed if r.get("status") != "finished"])
    fit = None
    if len(fitted) >= 3:
        fit = rheology.fit_maron_pierce([r["phi_core"] for r in fitted], [r["eta_s"] for r in fitted],
                                        [r["eta_s_err"] for r in fitted])
        summary["fit"] = dict(alpha=fit.alpha, alpha_error=fit.alpha_error, phi_m=fit.phi_m,
                              phi_m_error=fit.phi_m_error, chi2=fit.chi2, dof=fit.dof,
                              rows=[r["phi_bulk_table8"] for r in fitted],
                              not_fitted=[r["phi_bulk_table8"] for r in done if r not in fitted])
    if done:
        figure = os.path.splitext(args.out)[0] + ".png"
        rheology.plot_viscosity(figure, [r["phi_core"] for r in done], [r["eta_s"] for r in done],
                                [r["eta_s_err"] for r in done], fit=fit,
                                phi_core_error=[r.get("phi_core_err") or 0.0 for r in done],
                                label="this project (a1/Δ = %g, Δt = %s)" % (args.a_over_delta, ", ".join(
                                    "%g" % d for d in dts) + (";\nparticle steps between fluid steps"
                                                              if any(k > 1 for k in summary["fluid_every"].values()) else "")),
                                title="Fig. 21: η_s(φ_core)", reference=rheology.PAPER_MARON_PIERCE,
                                not_fitted=[r not in fitted for r in done] if fit is not None else None)
        summary["figure"] = os.path.basename(figure)
        stressed = [r for r in done if r.get("N1_hat") is not None and r.get("Sigma_c_hat") is not None]
        if stressed:
            figure22 = os.path.splitext(args.out)[0] + "_normal_stresses.png"
            rheology.plot_normal_stresses(figure22, [r["phi_core"] for r in stressed],
                                          [r["N1_hat"] for r in stressed], [r.get("N1_hat_err") or 0.0 for r in stressed],
                                          [r["N2_hat"] for r in stressed], [r.get("N2_hat_err") or 0.0 for r in stressed],
                                          [r["Sigma_c_hat"] for r in stressed],
                                          [r.get("Sigma_c_hat_err") or [0.0] * 3 for r in stressed],
                                          label="this project (a1/Δ = %g)" % args.a_over_delta,
                                          title="Fig. 22: normal stresses and their contact parts",
                                          not_fitted=[r not in fitted for r in stressed] if fit is not None
                                          else None)
            summary["figure_normal_stresses"] = os.path.basename(figure22)
    return summary


def print_table(summary: Dict) -> None:
    print("%-6s %-9s %-16s %-16s %-14s %-14s %-14s %-9s %-8s %-15s %s" % (
        "phi_b", "status", "phi_core (paper)", "g_core (paper)", "eta_s", "N1_hat", "N2_hat", "balance", "strain",
        "averaged", "core-s/strain"))
    for r in summary["rows"]:
        if "eta_s" not in r:
            print("%-6g %-9s (strain %.2f)" % (r["phi_bulk_table8"], r["status"], r.get("strain_reached", 0)))
            continue
        t = r.get("table8") or {}

        def v(key: str) -> float:      # a row of an earlier summary may lack a column
            value = r.get(key)
            return float("nan") if value is None else value

        averaged = "%.1f%s" % (v("strain_averaged"), " (short)" if r.get("window_short") else "")
        print("%-6g %-9s %.3f (%.3f)    %.3f (%.3f)    %.2f ± %.2f    %+.3f ± %.3f %+.3f ± %.3f %5.1f %%  %-8.1f %-15s %.0f%s" % (
            r["phi_bulk_table8"], r["status"], r["phi_core"], t.get("phi_core", float("nan")),
            v("gamma_core_over_gamma0"), t.get("gamma_core_over_gamma0", float("nan")), r["eta_s"], r["eta_s_err"],
            v("N1_hat"), v("N1_hat_err"), v("N2_hat"), v("N2_hat_err"), 100 * v("stress_balance_rel_error"),
            v("strain_units"), averaged, v("core_seconds_per_strain_unit"),
            "  (from %s)" % os.path.basename(r["from"]) if "from" in r else ""))
    if "fit" in summary:
        f = summary["fit"]
        print("Maron-Pierce fit over phi_bulk %s: alpha = %.3f ± %.3f, phi_m = %.3f ± %.3f (chi2 %.2f for %d dof); "
              "paper 0.803, 0.59%s" % (", ".join("%g" % x for x in f["rows"]), f["alpha"], f["alpha_error"], f["phi_m"],
                                       f["phi_m_error"], f["chi2"], f["dof"],
                                       "; not fitted (partial, short, or a step too large or beyond the good one): "
                                       + ", ".join("%g" % x for x in f["not_fitted"]) if f["not_fitted"] else ""))
    else:
        print("Maron-Pierce fit: needs 3 finished rows with a full window and a good step, has %d"
              % len(fitted_rows(summary["rows"])))
    if "budget" in summary:
        b = summary["budget"]
        print("The rows' runs (phi_bulk %s) took %.1f h of wall time in all: from nothing, %d at a time densest "
              "first, %.1f h" % (", ".join("%g" % x for x in b["rows"]), b["wall_seconds_rows"] / 3600, b["jobs"],
                                 b["projected_wall_seconds"] / 3600)
              + ("; unfinished rows counted as they stand: %s" % ", ".join("%g" % x for x in b["unfinished"])
                 if b.get("unfinished") else ""))
    for r in summary["rows"]:
        warning = demonly.time_step_too_large(r.get("position_update"))
        if warning:
            print("phi_bulk %g: %s" % (r["phi_bulk_table8"], warning))


def main(argv: Optional[List[str]] = None) -> Dict:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--phis", type=float, nargs="+", default=None,
                   help="Table 8 rows (phi_bulk; default %s)" % " ".join("%g" % phi for phi in DEFAULT_PHIS))
    p.add_argument("--paper", action="store_true",
                   help="all seven rows of the paper's Table 8 and Fig. 21 (phi_bulk %s), instead of --phis"
                        % " ".join("%g" % phi for phi in sorted(couettescene.TABLE8)))
    p.add_argument("--strain", type=float, default=25.0, help="strain units per run (transient + averaging)")
    p.add_argument("--dt", type=float, default=None, help="time step in units of 1/gamma_dot_0 of every row "
                   "(default: the largest measured good at its phi_bulk, couettescene.largest_good_dt: %s)"
                   % ", ".join("%g at %g" % (couettescene.largest_good_dt(phi), phi) for phi in sorted(couettescene.TABLE8)))
    p.add_argument("--fluid-every", type=int, default=None, metavar="K",
                   help="particle steps per fluid step of every row (default couettescene.fluid_every: the fluid every "
                   "couettescene.fluid_dt(phi), %s)" % ", ".join(
                       "%d at %g" % (couettescene.fluid_every(phi), phi) for phi in sorted(couettescene.TABLE8)))
    p.add_argument("--a-over-delta", type=float, default=3.0)
    p.add_argument("--coulomb-solve", choices=suspension.COULOMB_SOLVE, default=suspension.COULOMB_SOLVE[0],
                   help="how a contact slides within its step (fix fdm/couple coulomb_solve, docs/contact.md 2c)")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--model", choices=("calibrated", "cutoff"), default="calibrated",
                   help="pair_style fdm/subgrid's sub-grid model (docs/dem.md); the rows of docs/validation.md "
                        "up to 2026-11-26 ran with cutoff")
    p.add_argument("--np-fluid", type=int, default=1, help="MPI ranks of fdmFoam per run")
    p.add_argument("--n-max", type=int, default=50, help="fdmFoam's innerIterations nMax for scenes written now "
                   "(the dense rows stop at 50 in most steps: docs/benchmarks.md, 'Stability map')")
    p.add_argument("--tol-lambda", type=float, default=1e-2, help="fdmFoam's innerIterations tolLambda for scenes "
                   "written now (1e-2, the rows of docs/validation.md, keeps eta_s within its error bar of 1e-3's "
                   "at 2.4 times fewer fluid solves: docs/benchmarks.md, 'Sheared suspension: run time against error')")
    p.add_argument("--min-average", type=float, default=20.0,
                   help="strain units a row is averaged over after its transient: a finished run short of it is "
                        "extended from its last checkpoint (0: never extended)")
    p.add_argument("--max-strain", type=float, default=60.0,
                   help="the strain a run is extended to at most (a row still short there is reported as short)")
    p.add_argument("--workdir", default=os.path.join(HERE, "runs"))
    p.add_argument("--out", default=os.path.join(PROJECT, "docs", "data", "table8.json"))
    p.add_argument("--analyse-only", action="store_true", help="report the runs as they stand; run nothing")
    p.add_argument("--snapshots", metavar="DIR", default=None,
                   help="a folder keeping each row's compact snapshot (DIR/<run folder name>/; docs/coupling.md "
                        "\"Compact snapshot\"), to commit: a row whose run folder is new continues from it (the "
                        "particles from its step, the fluid from rest), so that a run outlives its machine")
    p.add_argument("--save", action="store_true", help="with --snapshots: write each row's newest checkpoint "
                   "into its snapshot folder (replacing the one there) and stop")
    p.add_argument("--rows-from", nargs="+", default=[], metavar="JSON",
                   help="add the rows of earlier table8.py summaries (runs made elsewhere, or whose folders are "
                   "gone) for the phi_bulk not in --phis, e.g. docs/data/validation_table8_calibrated.json; fitted by the "
                   "same rules (a row beyond the largest good time step at its phi_bulk is listed, not fitted)")
    p.add_argument("--progress-minutes", type=float, default=10.0,
                   help="minutes between progress lines (each running row's strain and ETA; 0: none)")
    p.add_argument("--session-hours", type=float, default=None,
                   help="launch no further run after this many hours (the run in progress finishes)")
    p.add_argument("--jobs", type=int, default=None,
                   help="rows run at once, each with --np-fluid fluid ranks and one particle rank (default: "
                        "the cores this process may use divided by --np-fluid)")
    args = p.parse_args(argv)
    if args.paper and args.phis:
        p.error("--paper runs all seven rows: give it or --phis, not both")
    args.phis = sorted(couettescene.TABLE8) if args.paper else (args.phis or DEFAULT_PHIS)
    args.jobs = args.jobs or default_jobs(args.np_fluid)   # the pool's size and the budget's
    if args.save:
        if not args.snapshots:
            p.error("--save writes into the --snapshots folder: give it")
        save_snapshots(args)
        return {}
    os.makedirs(args.workdir, exist_ok=True)
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)   # the figures are written first
    start = time.time()

    waiting = list(args.phis)          # the rows not launched yet (for the progress lines)

    def launch(phi: float) -> Optional[Dict]:
        waiting.remove(phi)
        if args.session_hours is not None and time.time() - start > 3600 * args.session_hours:
            print("table8: phi_bulk %g: --session-hours reached, not launched; the next call continues" % phi,
                  flush=True)
            return None
        return run_row(phi, args)

    def report_progress(stop: threading.Event) -> None:
        while not stop.wait(60 * args.progress_minutes):
            line = progress_report(list(waiting))
            if line:
                print(line, flush=True)

    analysed: Dict[float, Dict] = {}   # the rows run_row analysed as their runs ended
    stopped: List[str] = []            # why the runs that fdmRun stopped ended (run_row's SystemExit)
    if not args.analyse_only:
        stop_progress = threading.Event()
        if args.progress_minutes > 0:
            threading.Thread(target=report_progress, args=(stop_progress,), daemon=True).start()
        with ThreadPoolExecutor(max_workers=args.jobs) as pool:
            launched = [(phi, pool.submit(launch, phi)) for phi in launch_order(args.phis)]
            for phi, future in launched:
                try:
                    row = future.result()
                except SystemExit as stop:
                    stopped.append(str(stop))
                    continue
                if row is not None:
                    analysed[phi] = row
        stop_progress.set()
    rows = [analysed.get(phi) or analyse_row(phi, row_run(phi, args), args) for phi in args.phis]
    rows = sorted(rows + earlier_rows(args.rows_from, args.phis), key=lambda r: r["phi_bulk_table8"])
    summary = summarise(rows, args)
    summary["command"] = "cases/couette/table8.py " + " ".join(argv if argv is not None else sys.argv[1:])
    summary = files.relative_paths(summary)   # run folders relative to here: a summary may be shipped (docs/data)
    files.write_json(args.out, summary)
    print_table(summary)
    print("wrote %s" % args.out)
    if stopped:
        raise SystemExit("\n".join(stopped))
    return summary


if __name__ == "__main__":
    main()
