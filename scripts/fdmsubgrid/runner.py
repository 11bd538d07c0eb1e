"""Running a coupled case folder (fluid/ + dem/) with fdmRun, reading what it recorded, and deleting the
bulky fields afterwards (docs/running.md)."""
from __future__ import annotations

import os
import shutil
import subprocess
import time

from .environment import program, run_environment

# the sub-grid calibration tables the runs of this process started with (fdmRun's record in each folder) and
# when each run started, for the results file (fdmsubgrid.results: its `calibration`)
_CALIBRATIONS: list = []


def calibrations_run(since: float = float("-inf")) -> list:
    """{"table": absolute path or None, "sha256": ...} of every run this process started (run) at or after the
    time `since` (time.time(); a case passes its own start, so that a notebook's earlier runs do not count), in
    order."""
    return [identity for started, identity in _CALIBRATIONS if started >= since]


def _remember_calibration(case_dir: str, started: float) -> None:
    import json
    from .checkpoint import CALIBRATION_STAMP
    path = os.path.join(case_dir, CALIBRATION_STAMP)
    if os.path.isfile(path):
        with open(path) as f:
            _CALIBRATIONS.append((started, json.load(f)))


def run(case_dir, np_fluid=1, np_dem=1, quiet=True, extra=()):
    """Run fdmRun on case_dir; returns the wall time in seconds. Raises RuntimeError with the
    end of fdmRun's report if the run fails. Remembers the calibration table the run started with
    (calibrations_run)."""
    cmd = [program("fdmRun"), "-f", str(np_fluid), "-d", str(np_dem)]
    if quiet:
        cmd.append("--quiet")
    cmd += list(extra) + [case_dir]
    t0 = time.time()
    proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, errors="replace",
                          env=run_environment())
    wall = time.time() - t0
    _remember_calibration(case_dir, t0)
    if proc.returncode != 0:
        raise RuntimeError("fdmRun %s failed (exit %d):\n%s" % (case_dir, proc.returncode, proc.stdout[-4000:]))
    return wall



def read_held_steps(run_dir: str, n: int, who: str):
    """The particle records (dem/particles.records, RECORD_EVERY_STEP) and fdmFoam's step records of
    a run of n held configurations (held_step_runs), checked to hold at least n steps; the last n blocks are
    the n steps (a block at step 0, if written, holds no solution). Returns (records, steps); a run that
    recorded fewer is a RuntimeError naming `who` and the folder."""
    from . import output
    records = output.read_particle_records(os.path.join(run_dir, "dem", "particles.records"), mmap=False)
    steps = output.steps(os.path.join(run_dir, "fluid"))
    if len(records) < n or len(steps["step"]) < n:
        raise RuntimeError("%s: %s recorded %d particle blocks and %d fluid steps for %d configurations"
                           % (who, run_dir, len(records), len(steps["step"]), n))
    return records, steps



def run_and_read(run_dir, np_fluid=1, keep=False):
    """Run the coupled case in run_dir (fluid/ + dem/) and read fdmFoam's records; unless keep,
    then delete the mesh and the time directories (fields for ParaView), which the figures do not
    need and which are the bulk of the disk space. Returns (wall seconds, particles, steps) with
    the arrays of output.particles and output.steps."""
    from . import output
    fluid = os.path.join(run_dir, "fluid")
    wall = run(run_dir, np_fluid=np_fluid)
    particles, steps = output.particles(fluid), output.steps(fluid)
    if not keep:
        delete_fields(run_dir)
    return wall, particles, steps


def delete_fields(run_dir):
    """Delete the mesh and the time directories of run_dir/fluid (the fields for ParaView, the bulk
    of the disk space; the records and the checkpoints stay)."""
    fluid = os.path.join(run_dir, "fluid")
    shutil.rmtree(os.path.join(fluid, "constant", "polyMesh"), ignore_errors=True)
    for d in os.listdir(fluid):
        if d != "0" and d.replace(".", "").replace("e-", "").isdigit():
            shutil.rmtree(os.path.join(fluid, d), ignore_errors=True)


def last_error(run_dir: str) -> str | None:
    """The first line of the last error either code wrote in its log (log.dem's `ERROR ...`, log.fluid's
    `FOAM FATAL` with the two lines after it), at most 400 characters; None if neither wrote one."""
    for name in ("log.dem", "log.fluid"):
        path = os.path.join(run_dir, name)
        if not os.path.exists(path):
            continue
        with open(path, errors="replace") as f:
            lines = f.read().splitlines()
        for k in range(len(lines) - 1, -1, -1):
            if lines[k].startswith("ERROR") or "FOAM FATAL" in lines[k]:
                text = lines[k] if lines[k].startswith("ERROR") else " ".join(lines[k + 1:k + 3]).strip()
                return text[:400]
    return None


def records_finite(run_dir: str) -> bool | None:
    """Whether every position and velocity of the run's particle records (dem/particles.records) is finite;
    None without records or with records the reader cannot take (a block cut by a stop is dropped by it)."""
    import numpy as np
    from . import output
    path = os.path.join(run_dir, "dem", "particles.records")
    if not os.path.exists(path):
        return None
    try:
        snapshots, _ = output.record_snapshots(path, 1.0)
    except Exception:   # anything but a cut block: reported as unknown, the error itself is the run's
        return None
    return bool(all(np.all(np.isfinite(s.positions)) and np.all(np.isfinite(s.velocities)) for s in snapshots))
