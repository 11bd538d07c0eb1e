"""Checkpoints of a coupled run and what `fdmRun --resume` does with them (docs/coupling.md,
"Checkpoint and resume").

fdmFoam writes CASE/fluid/checkpoint/fluid.<step> (a text marker; the binary fields are in the
step's time directory), fdmDEM CASE/dem/checkpoint/dem.<step> (one binary file, layout in
dem/particle_checkpoint.h). Both are written to a temporary name and renamed once complete, and
each code keeps its two newest.

    python3 -m fdmsubgrid.checkpoint select CASE        the newest step both codes have complete (prints it;
                                                 says on stderr which newer ones were passed over and why)
    python3 -m fdmsubgrid.checkpoint truncate CASE STEP cut every record at STEP: fdmFoam's steps.dat,
                                                 particles.dat, walls.dat, fix fdm/couple's walls
                                                 file and the function objects' records keep
                                                 the steps up to STEP, the DEM's dumps the frames before
                                                 STEP (the resumed run writes STEP's frame again), and
                                                 time directories and checkpoints after STEP go
    python3 -m fdmsubgrid.checkpoint until INPUT L STEP  the run resumed from STEP to end at step L: the
                                                 LIGGGHTS input's `run N upto` becomes `run L upto`
                                                 (prints N; fdmRun --resume --until L)
    python3 -m fdmsubgrid.checkpoint stamp CASE INPUT    record which sub-grid calibration table the run
                                                 starts with (its path and SHA-256, CASE/.fdmRun-calibration)
    python3 -m fdmsubgrid.checkpoint check-stamp CASE INPUT [--new-calibration]
                                                 on a resume: refuse if that table changed since (a run
                                                 never mixes two sub-grid models), unless asked
"""
import hashlib
import json
import os
import re
import shlex
import shutil
import sys
import zlib

from .files import write_atomically

DEM_MAGIC = b"FDM-DEM-CHECKPOINT 1\n"
DEM_TRAILER = b"end FDM-DEM-CHECKPOINT\n"
FLUID_KEYS = ("step", "time", "timeIndex", "timeName", "stepsDone", "cells", "processors", "particles")


class CheckpointError(Exception):
    pass


def _steps(directory, prefix):
    out = []
    if os.path.isdir(directory):
        for name in os.listdir(directory):
            m = re.fullmatch(re.escape(prefix) + r"(\d+)", name)
            if m:
                out.append(int(m.group(1)))
    return sorted(out)


def dem_file(case_dir, step):
    return os.path.join(case_dir, "dem", "checkpoint", "dem.%d" % step)


def fluid_marker(case_dir, step):
    return os.path.join(case_dir, "fluid", "checkpoint", "fluid.%d" % step)


def dem_problem(path):
    """None if the particle checkpoint at path is complete and intact, else what is wrong."""
    try:
        with open(path, "rb") as f:
            data = f.read()
    except OSError as e:
        return "cannot be read (%s)" % e.strerror
    if not data.startswith(DEM_MAGIC):
        return "is not a particle checkpoint of fdmDEM"
    lines, pos = [], len(DEM_MAGIC)
    while True:
        end = data.find(b"\n", pos)
        if end < 0:
            return "is truncated inside its header (%d bytes)" % len(data)
        line = data[pos:end].decode(errors="replace")
        pos = end + 1
        if line.startswith("data "):
            m = re.fullmatch(r"data (\d+) crc32=(\d+)", line)
            if not m:
                return "has a damaged header line %r" % line
            size, crc = int(m.group(1)), int(m.group(2))
            break
        lines.append(line)
    expected = pos + size + len(DEM_TRAILER)
    if len(data) < expected:
        return "is truncated: %d bytes where its header says %d" % (len(data), expected)
    if data[pos + size:] != DEM_TRAILER:
        return "is damaged: no end line after its data"
    if zlib.crc32(data[pos:pos + size]) != crc:
        return "is damaged: the CRC-32 of its data differs from the one written with it"
    return None


def read_fluid_marker(path):
    """The entries of a fluid checkpoint marker as a dict; CheckpointError if it is incomplete."""
    try:
        with open(path) as f:
            words = [line.split() for line in f if line.strip() and not line.startswith("#")]
    except OSError as e:
        raise CheckpointError("%s cannot be read (%s)" % (path, e.strerror))
    entries = {w[0]: w[1] for w in words if len(w) == 2}
    if not words or words[-1] != ["end"] or any(k not in entries for k in FLUID_KEYS):
        raise CheckpointError("%s is not a complete fdmFoam checkpoint marker" % path)
    return entries


def fluid_problem(case_dir, step):
    """None if fdmFoam's checkpoint of step is complete (marker and field files), else what is wrong."""
    try:
        m = read_fluid_marker(fluid_marker(case_dir, step))
    except CheckpointError as e:
        return str(e)
    fluid = os.path.join(case_dir, "fluid")
    procs = int(m["processors"])
    dirs = [os.path.join(fluid, m["timeName"])] if procs == 1 else \
        [os.path.join(fluid, "processor%d" % p, m["timeName"]) for p in range(procs)]
    for d in dirs:
        for field in ("U", "p", "lambda"):
            if not os.path.isfile(os.path.join(d, field)) or os.path.getsize(os.path.join(d, field)) == 0:
                return "its field %s is missing or empty in %s" % (field, os.path.relpath(d, case_dir))
    return None


def select(case_dir):
    """(step, notes): the newest step whose checkpoints of both codes are complete, and why newer ones
    were passed over. CheckpointError if there is none."""
    fluid_steps = _steps(os.path.join(case_dir, "fluid", "checkpoint"), "fluid.")
    dem_steps = _steps(os.path.join(case_dir, "dem", "checkpoint"), "dem.")
    notes = []
    for step in sorted(set(fluid_steps) | set(dem_steps), reverse=True):
        problems = []
        if step not in dem_steps:
            problems.append("fdmDEM has no checkpoint of it (killed before or while writing it?)")
        else:
            p = dem_problem(dem_file(case_dir, step))
            if p:
                problems.append("dem/checkpoint/dem.%d %s" % (step, p))
        if step not in fluid_steps:
            problems.append("fdmFoam has no checkpoint of it (killed before or while writing it?)")
        else:
            p = fluid_problem(case_dir, step)
            if p:
                problems.append("fdmFoam's checkpoint: %s" % p)
        if not problems:
            return step, notes
        notes.append("step %d passed over: %s" % (step, "; ".join(problems)))
    raise CheckpointError("%s has no checkpoint that both codes completed%s: was the run started with "
                          "'checkpoint N' in fix fdm/couple? (docs/coupling.md)"
                          % (case_dir, " (" + "; ".join(notes) + ")" if notes else ""))


# the run command a resumable input ends with (docs/coupling.md): `run L upto`, maybe more keywords
_RUN_COMMAND = re.compile(r"^[ \t]*run[ \t]+.*$", re.M)
_RUN_UPTO = re.compile(r"^([ \t]*run[ \t]+)(\d+)([ \t]+upto\b.*)$")


def set_last_step(dem_input: str, last_step: int, resume_step: int) -> int:
    """Make a run resumed from `resume_step` end at `last_step` instead of where it was planned to (a
    finished run extended, a long one cut short): its LIGGGHTS input's one `run N upto` command becomes
    `run last_step upto`, the rest of the file unchanged (written to a temporary file, then renamed).
    Returns N. CheckpointError, with nothing changed, if the input has no run command or more than one,
    if its run is not `run N upto`, or if last_step is not after resume_step."""
    try:
        with open(dem_input) as f:
            text = f.read()
    except OSError as e:
        raise CheckpointError("%s cannot be read (%s)" % (dem_input, e.strerror))
    commands = list(_RUN_COMMAND.finditer(text))
    if len(commands) != 1:
        raise CheckpointError("%s has %d run commands: a run can be extended only if its input has one, "
                              "'run N upto'" % (dem_input, len(commands)))
    found = _RUN_UPTO.match(commands[0].group(0))
    if not found:
        raise CheckpointError("%s: its run command '%s' is not 'run N upto', which a resumed run needs "
                              "(docs/coupling.md)" % (dem_input, commands[0].group(0).strip()))
    if last_step <= resume_step:
        raise CheckpointError("the run resumes from step %d, so it cannot end at step %d: give a later step"
                              % (resume_step, last_step))
    planned = int(found.group(2))
    start, end = commands[0].span()
    line = found.group(1) + str(last_step) + found.group(3)
    write_atomically(dem_input, text[:start] + line + text[end:])
    return planned


def _is_time(name):
    try:
        float(name)
        return True
    except ValueError:
        return False


def _cut_lines(path, keep):
    """Keep the comment lines and the complete lines whose first number passes keep(value)."""
    with open(path) as f:
        text = f.read()
    lines = text.splitlines(keepends=True)
    if lines and not lines[-1].endswith("\n"):
        lines = lines[:-1]  # cut by the kill
    out, dropped = [], 0
    for line in lines:
        words = line.split()
        if not words or line.lstrip().startswith("#"):
            out.append(line)
            continue
        try:
            value = float(words[0])
        except ValueError:
            out.append(line)
            continue
        if keep(value):
            out.append(line)
        else:
            dropped += 1
    write_atomically(path, "".join(out))
    return dropped


def _cut_dump(path, step):
    """Keep the frames of a LIGGGHTS text dump before `step`; returns the frames dropped."""
    with open(path, "rb") as f:
        data = f.read()
    starts = [m.start() for m in re.finditer(rb"^ITEM: TIMESTEP\n", data, re.M)]
    keep_to, dropped = len(data), 0
    for s in starts:
        end = data.find(b"\n", s + 15)
        try:
            frame_step = int(data[s + 15:end])
        except ValueError:
            frame_step = step
        if frame_step >= step:
            keep_to = min(keep_to, s)
            dropped += 1
    if keep_to < len(data):
        write_atomically(path, data[:keep_to])
    return dropped


def truncate(case_dir, step):
    """Cut every record of the run at the checkpoint `step` (module docstring); returns a summary."""
    fluid = os.path.join(case_dir, "fluid")
    marker = read_fluid_marker(fluid_marker(case_dir, step))
    t_step = float(marker["time"])
    eps = 1e-9 * max(abs(t_step), 1e-300)
    summary = []
    # fdmFoam's records: by DEM step
    for name in ("steps.dat", "particles.dat", "walls.dat", "channelProfile.dat"):
        path = os.path.join(fluid, "postProcessing", "fdm", name)
        if os.path.isfile(path):
            summary.append("%s: %d lines after step %d removed" % (name, _cut_lines(path, lambda v: v <= step + 0.5),
                                                                   step))
    # function objects: postProcessing/<name>/<start time>/<file>, first column the time
    post = os.path.join(fluid, "postProcessing")
    if os.path.isdir(post):
        for fo in sorted(os.listdir(post)):
            if fo == "fdm" or not os.path.isdir(os.path.join(post, fo)):
                continue
            for start in os.listdir(os.path.join(post, fo)):
                d = os.path.join(post, fo, start)
                if _is_time(start) and float(start) > t_step + eps:
                    shutil.rmtree(d)
                    continue
                if os.path.isdir(d):
                    for f in os.listdir(d):
                        if os.path.isfile(os.path.join(d, f)):
                            _cut_lines(os.path.join(d, f), lambda v: v <= t_step + eps)
    # fields written after the checkpoint (the resumed run writes them again)
    for base in [fluid] + [os.path.join(fluid, p) for p in os.listdir(fluid) if p.startswith("processor")]:
        for name in os.listdir(base):
            if _is_time(name) and float(name) > t_step + eps and os.path.isdir(os.path.join(base, name)):
                shutil.rmtree(os.path.join(base, name))
    # the DEM's dumps (files it created, listed by fdmRun): frames from the checkpoint step on
    listed = os.path.join(case_dir, ".fdmRun-dem-outputs")
    if os.path.isfile(listed):
        with open(listed) as f:
            for rel in f.read().split("\n"):
                path = os.path.join(case_dir, "dem", rel)
                if rel and os.path.isfile(path):
                    with open(path, "rb") as g:
                        head = g.read(15)
                    if head == b"ITEM: TIMESTEP\n":
                        summary.append("%s: %d frames from step %d on removed" % (rel.lstrip("./"),
                                                                                  _cut_dump(path, step), step))
                    elif head == b"# fix fdm/coupl":   # fix fdm/couple walls FILE: a line per step
                        summary.append("%s: %d lines after step %d removed" % (
                            rel.lstrip("./"), _cut_lines(path, lambda v: v <= step + 0.5), step))
    # checkpoints after this one (an earlier attempt's, or incomplete)
    for directory, prefix in ((os.path.join(fluid, "checkpoint"), "fluid."),
                              (os.path.join(case_dir, "dem", "checkpoint"), "dem.")):
        if os.path.isdir(directory):
            for name in os.listdir(directory):
                m = re.fullmatch(re.escape(prefix) + r"(\d+)(\.tmp)?", name)
                if name.endswith(".tmp") or (m and int(m.group(1)) > step):
                    os.remove(os.path.join(directory, name))
    return summary


CALIBRATION_STAMP = ".fdmRun-calibration"


def calibration_table(dem_input: str) -> str | None:
    """The sub-grid calibration table the LIGGGHTS input's `pair_style fdm/subgrid` reads: its `calibration
    FILE` (relative to the input's folder), else the shipped table ($FDM_ROOT/dem/resistance/data/
    subgrid_calibration.dat, as the pair style finds it); None without that pair style, with `model cutoff`
    or with `lubrication no` (no table enters the run)."""
    with open(dem_input) as f:
        text = f.read().replace("&\n", " ")          # LIGGGHTS joins a line ending in '&' to the next
    table = None
    for line in text.splitlines():
        words = shlex.split(line.split("#", 1)[0])
        if len(words) < 2 or words[0] != "pair_style" or words[1] != "fdm/subgrid":
            continue
        keys = {k: v for k, v in zip(words[2:], words[3:]) if k in ("model", "calibration", "lubrication")}
        if keys.get("lubrication") == "no" or (keys.get("model") == "cutoff" and "calibration" not in keys):
            table = None
        elif "calibration" in keys:
            table = os.path.join(os.path.dirname(os.path.abspath(dem_input)), keys["calibration"])
        else:
            root = os.environ.get("FDM_ROOT") or os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
            table = os.path.normpath(os.path.join(root, "dem", "resistance", "data", "subgrid_calibration.dat"))
    return table


def _table_identity(table: str | None) -> dict:
    """{"table": path, "sha256": hex digest of its bytes} (None, None without a table)."""
    if table is None:
        return dict(table=None, sha256=None)
    if not os.path.isfile(table):
        raise CheckpointError("the sub-grid calibration table %s (pair_style fdm/subgrid) is missing" % table)
    with open(table, "rb") as f:
        return dict(table=table, sha256=hashlib.sha256(f.read()).hexdigest())


def stamp(case_dir: str, dem_input: str) -> str:
    """Record in CASE/.fdmRun-calibration the calibration table the run starts with; returns a line for the log."""
    identity = _table_identity(calibration_table(dem_input))
    write_atomically(os.path.join(case_dir, CALIBRATION_STAMP), json.dumps(identity))
    if identity["table"] is None:
        return "no sub-grid calibration table"
    return "calibration table %s (sha256 %s)" % (identity["table"], identity["sha256"][:12])


def check_stamp(case_dir: str, dem_input: str, accept_new: bool = False) -> str:
    """On a resume: the table the input reads now against the one recorded when the run started. Raises
    CheckpointError naming both if it changed (unless accept_new, which records the new one). A run started
    before the record existed gets it now. Returns a line for the log."""
    path = os.path.join(case_dir, CALIBRATION_STAMP)
    now = _table_identity(calibration_table(dem_input))
    if not os.path.isfile(path):
        write_atomically(path, json.dumps(now))
        return "no record of the calibration table the run started with (a run older than the record): recorded now"
    with open(path) as f:
        then = json.load(f)
    if then == now:
        return "the same calibration table as at the start"
    describe = lambda d: "no table" if d["table"] is None else "%s with sha256 %s" % (d["table"], d["sha256"][:12])
    if not accept_new:
        raise CheckpointError(
            "the sub-grid calibration table changed since this run started: it began with %s (recorded in %s), "
            "the input now reads %s. Resuming would mix two sub-grid models in one run: restore the table the run "
            "started with (git log -- dem/resistance/data), or resume with --new-calibration to continue with "
            "the new one knowingly" % (describe(then), path, describe(now)))
    write_atomically(path, json.dumps(now))
    return "--new-calibration: continues with %s (it began with %s)" % (describe(now), describe(then))


def main(argv):
    if len(argv) >= 2 and argv[0] == "select":
        try:
            step, notes = select(argv[1])
        except CheckpointError as e:
            print(e, file=sys.stderr)
            return 1
        for n in notes:
            print("fdmRun --resume: " + n, file=sys.stderr)
        print(step)
        return 0
    if len(argv) >= 3 and argv[0] == "truncate":
        for line in truncate(argv[1], int(argv[2])):
            print(line)
        return 0
    if len(argv) >= 4 and argv[0] == "until":
        try:
            print(set_last_step(argv[1], int(argv[2]), int(argv[3])))
        except CheckpointError as e:
            print(e, file=sys.stderr)
            return 1
        return 0
    if len(argv) >= 3 and argv[0] in ("stamp", "check-stamp"):
        try:
            if argv[0] == "stamp":
                print(stamp(argv[1], argv[2]))
            else:
                print(check_stamp(argv[1], argv[2], accept_new="--new-calibration" in argv[3:]))
        except CheckpointError as e:
            print(e, file=sys.stderr)
            return 1
        return 0
    print(__doc__, file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
