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
    python3 -m fdmsubgrid.checkpoint processors CASE STEP  the fluid ranks STEP's checkpoint was written on and
                                                 its time directory (prints "N TIME")
    python3 -m fdmsubgrid.checkpoint set-processors CASE STEP N
                                                 once fdmRun --resume on another -f has redistributed STEP's
                                                 fields (reconstructPar, decomposePar -time): its marker
                                                 says N ranks
    python3 -m fdmsubgrid.checkpoint stamp CASE INPUT    record which sub-grid calibration table the run
                                                 starts with (its path and SHA-256, CASE/.fdmRun-calibration)
    python3 -m fdmsubgrid.checkpoint check-stamp CASE INPUT [--new-calibration]
                                                 on a resume: refuse if that table changed since (a run
                                                 never mixes two sub-grid models), unless asked; if the
                                                 project keeps the table the run started with (by its
                                                 SHA-256: table_by_hash), the input is pointed at it

A compact snapshot (docs/coupling.md, "Compact snapshot") is the particle state of the newest checkpoint
in a small folder of plain files, to keep (e.g. in git) when the run folder may be lost; fdmRun
--from-snapshot continues from it in a case folder freshly written by the same scene command, the fluid
recomputed from the particles:

    python3 -m fdmsubgrid.checkpoint snapshot CASE DEST [--scene COMMAND] [--dem-input NAME]
                                                 write DEST (replacing the snapshot there): dem.STEP.xz
                                                 (the DEM checkpoint, compacted), fluid.STEP (the
                                                 fluid marker), the LIGGGHTS input, calibration.json (the
                                                 run's CASE/.fdmRun-calibration), scene (the command that
                                                 writes the scene: --scene, else CASE/scene) and README
    python3 -m fdmsubgrid.checkpoint snapshot-check DEST CASE INPUT [L]
                                                 fdmRun --from-snapshot, before anything changes: DEST is
                                                 complete and of CASE's scene (input, particles, box,
                                                 calibration table: the one the snapshot's run used, by
                                                 SHA-256, or the project keeps it), the run goes on after
                                                 its step; prints
                                                 "STEP LAST" (L: --until)
    python3 -m fdmsubgrid.checkpoint snapshot-install DEST CASE INPUT NP_FLUID [L]
                                                 then, once meshed (and decomposed): the same mesh; DEM
                                                 checkpoint, fluid marker (fromRest: the fields of 0/) and
                                                 calibration record installed as CASE's checkpoint of STEP
"""
import array
import errno
import hashlib
import json
import lzma
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


def _steps(directory, prefix, suffix=""):
    out = []
    if os.path.isdir(directory):
        for name in os.listdir(directory):
            m = re.fullmatch(re.escape(prefix) + r"(\d+)" + re.escape(suffix), name)
            if m:
                out.append(int(m.group(1)))
    return sorted(out)


def dem_file(case_dir, step):
    return os.path.join(case_dir, "dem", "checkpoint", "dem.%d" % step)


def fluid_marker(case_dir, step):
    return os.path.join(case_dir, "fluid", "checkpoint", "fluid.%d" % step)


def _dem_bytes(path: str) -> bytes:
    """The bytes of a particle checkpoint: the file, or a compact snapshot's dem.STEP.xz decompressed."""
    with open(path, "rb") as f:
        data = f.read()
    if path.endswith(SNAPSHOT_DEM_SUFFIX):
        try:
            return lzma.decompress(data)
        except lzma.LZMAError as e:
            raise OSError(errno.EIO, "not an intact xz file: %s" % e)
    return data


def dem_problem(path):
    """None if the particle checkpoint at path (or a snapshot's dem.STEP.xz) is complete and intact, else what is
    wrong."""
    try:
        data = _dem_bytes(path)
    except OSError as e:
        return "cannot be read (%s)" % e.strerror
    return _dem_data_problem(data)


def _dem_data_problem(data: bytes):
    """dem_problem of a checkpoint's bytes."""
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
    # a compact snapshot's restart (fromRest) has the fields of 0/ there, lambda only if 0/ has it
    fields = ("U", "p") if m.get("fromRest") == "1" else ("U", "p", "lambda")
    for d in dirs:
        for field in fields:
            if not os.path.isfile(os.path.join(d, field)) or os.path.getsize(os.path.join(d, field)) == 0:
                return "its field %s is missing or empty in %s" % (field, os.path.relpath(d, case_dir))
    return None


def marker_processors(case_dir, step) -> tuple[int, str]:
    """(the number of fluid ranks, the time directory) of fdmFoam's checkpoint of step."""
    m = read_fluid_marker(fluid_marker(case_dir, step))
    return int(m["processors"]), m["timeName"]


def set_marker_processors(case_dir, step, processors: int) -> None:
    """Rewrite the marker of step for its fields redistributed to `processors` fluid ranks (fdmRun --resume with
    another -f: the fields of its time directory reconstructed and/or decomposed before), the rest as it was."""
    path = fluid_marker(case_dir, step)
    before = read_fluid_marker(path)
    with open(path) as f:
        lines = f.read().splitlines()
    out = ["processors %d" % processors if line.split()[:1] == ["processors"] else line for line in lines]
    out.insert(0, "# fdmRun --resume: the fields of %s/ redistributed from %s to %d fluid ranks"
               % (before["timeName"], before["processors"], processors))
    write_atomically(path, "\n".join(out) + "\n")


def _marker_problem(case_dir, step):
    """None if fdmFoam's marker of step is complete, else what is wrong."""
    try:
        read_fluid_marker(fluid_marker(case_dir, step))
    except CheckpointError as e:
        return str(e)
    return None


def select(case_dir, fields=True):
    """(step, notes): the newest step whose checkpoints of both codes are complete, and why newer ones
    were passed over. CheckpointError if there is none. fields=False: the fluid's marker suffices (a
    compact snapshot does not take the fluid fields, which a case script may have deleted)."""
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
            p = fluid_problem(case_dir, step) if fields else _marker_problem(case_dir, step)
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


# Where the project keeps its shipped table and, beside it, each earlier one a run or a snapshot may have
# started with, named by the first 8 hex digits of its SHA-256 (subgrid_calibration_<8 hex>.dat)
TABLE_FOLDER = os.path.join("dem", "resistance", "data")


def table_by_hash(sha256: str | None) -> str | None:
    """The project's calibration table whose bytes have this SHA-256: the shipped one or an earlier one kept
    beside it (TABLE_FOLDER/subgrid_calibration*.dat, the one named by the hash's first 8 hex digits first);
    None if none has it."""
    from .environment import project_dir
    root = project_dir()
    if not sha256 or root is None:
        return None
    folder = os.path.join(root, TABLE_FOLDER)
    named = os.path.join(folder, "subgrid_calibration_%s.dat" % sha256[:8])
    others = sorted(os.path.join(folder, n) for n in os.listdir(folder)
                    if n.startswith("subgrid_calibration") and n.endswith(".dat")) if os.path.isdir(folder) else []
    for path in [named] + [o for o in others if o != named]:
        if os.path.isfile(path) and _table_identity(path)["sha256"] == sha256:
            return path
    return None


def _searched_tables() -> str:
    """Where table_by_hash looks, for a message."""
    return os.path.join(TABLE_FOLDER, "subgrid_calibration*.dat")


def use_table(dem_input: str, table: str) -> str:
    """Make the LIGGGHTS input read `table`: a copy of it beside the input (its file name kept) named by every
    `pair_style fdm/subgrid` line's `calibration` (replaced, or added after the style's name). Returns the
    copy's path; CheckpointError if the input does not read it afterwards."""
    folder = os.path.dirname(os.path.abspath(dem_input))
    name = os.path.basename(table)
    copy = os.path.join(folder, name)
    if os.path.abspath(table) != copy:
        shutil.copyfile(table, copy)
    with open(dem_input) as f:
        lines = f.read().split("\n")
    k = 0
    while k < len(lines):
        words = lines[k].split("#", 1)[0].split()
        end = k
        while end + 1 < len(lines) and lines[end].split("#", 1)[0].rstrip().endswith("&"):
            end += 1
        if words[:2] == ["pair_style", "fdm/subgrid"]:
            found = False
            for j in range(k, end + 1):
                code, sep, comment = lines[j].partition("#")
                code, n = re.subn(r"(\bcalibration\s+)\S+", lambda m: m.group(1) + name, code)
                if n:
                    lines[j], found = code + sep + comment, True
            if not found:
                lines[k] = re.sub(r"(pair_style\s+fdm/subgrid)", r"\1 calibration " + name, lines[k], count=1)
        k = end + 1
    write_atomically(dem_input, "\n".join(lines))
    if calibration_table(dem_input) != copy:
        raise CheckpointError("%s: could not point pair_style fdm/subgrid at the calibration table %s"
                              % (dem_input, copy))
    return copy


def stamp(case_dir: str, dem_input: str) -> str:
    """Record in CASE/.fdmRun-calibration the calibration table the run starts with; returns a line for the log."""
    identity = _table_identity(calibration_table(dem_input))
    write_atomically(os.path.join(case_dir, CALIBRATION_STAMP), json.dumps(identity))
    if identity["table"] is None:
        return "no sub-grid calibration table"
    return "calibration table %s (sha256 %s)" % (identity["table"], identity["sha256"][:12])


def check_stamp(case_dir: str, dem_input: str, accept_new: bool = False) -> str:
    """On a resume: the table the input reads now against the one recorded when the run started. Raises
    CheckpointError naming both if it changed (unless accept_new, which records the new one), except where the
    project keeps the table the run started with (table_by_hash: an earlier table beside the shipped one): the
    input is then pointed at a copy of it (use_table) and the record names the copy. The same bytes at another
    path (the case or the project moved) are the same table. A run started before the record existed gets it
    now. Returns a line for the log."""
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
    if now["sha256"] == then["sha256"]:         # the same bytes elsewhere (the case folder moved)
        write_atomically(path, json.dumps(now))
        return "the same calibration table as at the start, now %s" % now["table"]
    earlier = None if accept_new else table_by_hash(then["sha256"])
    if earlier is not None:
        copy = use_table(dem_input, earlier)
        write_atomically(path, json.dumps(_table_identity(copy)))
        return ("continues with the calibration table it started with (sha256 %s): %s, copied to %s and named by "
                "the input's pair_style (the input read %s)" % (then["sha256"][:12], earlier, copy, describe(now)))
    if not accept_new:
        raise CheckpointError(
            "the sub-grid calibration table changed since this run started: it began with %s (recorded in %s), "
            "the input now reads %s, and no table of the project (%s) has sha256 %s. Resuming would mix two "
            "sub-grid models in one run: restore the table the run started with (git log -- dem/resistance/data), "
            "or resume with --new-calibration to continue with the new one knowingly"
            % (describe(then), path, describe(now), _searched_tables(), then["sha256"]))
    write_atomically(path, json.dumps(now))
    return "--new-calibration: continues with %s (it began with %s)" % (describe(now), describe(then))


# ---- compact snapshot ----------------------------------------------------------------------------

SCENE_FILE = "scene"                 # in a case folder and in a snapshot: the command that writes the scene
SNAPSHOT_CALIBRATION = "calibration.json"
# the options of a case script that say where (or how far, or with which history), not what: left out of the
# scene command it records
_WHERE_OPTIONS = ("--workdir", "--out", "--from-snapshot", "--until", "--segments")
_WHERE_FLAGS = ("--overwrite", "--keep")


def scene_command(script: str, argv: list[str]) -> str:
    """The command line that writes a case script's scene again: the script (relative to the repository,
    run from its root) and its options, without those that say where it is written, how far a continued run
    goes or what happens to an older folder (--workdir, --out, --from-snapshot, --until, --segments,
    --overwrite, --keep)."""
    root = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
    path = os.path.relpath(os.path.abspath(script), root)
    kept, skip = [], False
    for word in argv:
        if skip:
            skip = False
            continue
        name = word.split("=", 1)[0]
        if name in _WHERE_OPTIONS:
            skip = "=" not in word
            continue
        if word in _WHERE_FLAGS:
            continue
        kept.append(word)
    return shlex.join(["python3", path] + kept)


def write_scene_command(case_dir: str, script: str, argv: list[str]) -> str:
    """Record in CASE/scene the command that writes this scene (scene_command), for a snapshot of its run."""
    command = scene_command(script, argv)
    write_atomically(os.path.join(case_dir, SCENE_FILE), command + "\n")
    return command


def _dem_header(path: str, data: bytes | None = None) -> dict:
    """The header entries of a DEM checkpoint (step, lastStep, natoms, dt, boxlo, boxhi); data: its bytes, if read."""
    words = (_dem_bytes(path) if data is None else data).split(b"\n", 2)[1].decode(errors="replace").split()
    entries = dict(w.split("=", 1) for w in words if "=" in w)
    try:
        return dict(step=int(entries["step"]), lastStep=int(entries["lastStep"]), natoms=int(entries["natoms"]),
                    dt=float(entries["dt"]), boxlo=[float(v) for v in entries["boxlo"].split(",")],
                    boxhi=[float(v) for v in entries["boxhi"].split(",")])
    except (KeyError, ValueError):
        raise CheckpointError("%s: its header line %r is not that of a particle checkpoint" % (path, " ".join(words)))


def read_dem_checkpoint(path: str) -> tuple[dict, dict]:
    """(header, arrays) of a DEM checkpoint file (dem/particle_checkpoint.h): the header entries as
    _dem_header gives them and {name: list of floats} for each array, e.g. arrays["atoms"] (14 per particle)
    or arrays["heldDragLast"]. CheckpointError if the file is not complete and intact."""
    _, header, arrays = _read_dem(path)
    return header, arrays


def _checked_dem(path: str) -> tuple[bytes, dict]:
    """The checkpoint's bytes (decompressed), read once, and its header; CheckpointError if it is not complete
    and intact."""
    try:
        data = _dem_bytes(path)
    except OSError as e:
        raise CheckpointError("%s cannot be read (%s)" % (path, e.strerror))
    problem = _dem_data_problem(data)
    if problem:
        raise CheckpointError("%s %s" % (path, problem))
    return data, _dem_header(path, data)


def _read_dem(path: str) -> tuple[bytes, dict, dict]:
    """read_dem_checkpoint with the checkpoint's bytes (decompressed), read once."""
    data, header = _checked_dem(path)
    counts, pos = [], len(DEM_MAGIC)
    pos = data.index(b"\n", pos) + 1                       # the header line
    while not data.startswith(b"data ", pos):
        end = data.index(b"\n", pos)
        _, name, count = data[pos:end].decode().split()
        counts.append((name, int(count)))
        pos = end + 1
    pos = data.index(b"\n", pos) + 1
    arrays = {}
    for name, count in counts:
        values = array.array("d")
        values.frombytes(data[pos:pos + 8 * count])
        arrays[name] = values.tolist()
        pos += 8 * count
    return data, header, arrays


# A compact snapshot's particle checkpoint, dem.STEP.xz: fdmDEM's checkpoint with the arrays every step
# recomputes from the others set to zero (the last step's sub-grid forces and stresslet sums), the velocity-like
# ones rounded to single precision (their rounding, 6e-8 of themselves, is far below the inner iteration's
# tolerance, which the snapshot's fluid from rest already costs: docs/coupling.md, "Compact snapshot"), then
# xz-compressed. Positions, image flags, radii, the contact histories (integers kept in their bits) and the
# position update's x_n stay exact. It installs as a plain checkpoint (snapshot_install).
SNAPSHOT_DEM_SUFFIX = ".xz"
SNAPSHOT_RECOMPUTED = ("stress", "subgrid")
SNAPSHOT_SINGLE = ("currentVelocity", "previousVelocity", "moveRate", "solution", "hydro", "fluidStress",
                   "heldDragLast", "heldDragBefore")


def encode_dem_checkpoint(header_line: bytes, arrays: dict) -> bytes:
    """The bytes of a particle checkpoint (dem/particle_checkpoint.h) of the header line (step=... boxhi=...,
    without its newline) and {name: doubles}, the arrays in name order, with the CRC-32 of their data."""
    names = sorted(arrays)
    payload = b"".join(array.array("d", arrays[n]).tobytes() for n in names)
    lines = b"".join(b"array %s %d\n" % (n.encode(), len(arrays[n])) for n in names)
    return (DEM_MAGIC + header_line + b"\n" + lines + b"data %d crc32=%d\n" % (len(payload), zlib.crc32(payload)) +
            payload + DEM_TRAILER)


def compact_dem_checkpoint(path: str) -> bytes:
    """The compact snapshot form (dem.STEP.xz, above) of the particle checkpoint at path."""
    data, _, arrays = _read_dem(path)
    for name in SNAPSHOT_RECOMPUTED:
        if name in arrays:
            arrays[name] = [0.0] * len(arrays[name])
    for name in SNAPSHOT_SINGLE:
        if name in arrays:
            arrays[name] = array.array("d", array.array("f", arrays[name])).tolist()
    header_line = data.split(b"\n", 2)[1]
    return lzma.compress(encode_dem_checkpoint(header_line, arrays), preset=9 | lzma.PRESET_EXTREME)


def _dem_input_name(case_dir: str, dem_input: str | None) -> str:
    if dem_input:
        return dem_input
    names = sorted(n for n in os.listdir(os.path.join(case_dir, "dem")) if n.startswith("in."))
    if len(names) != 1:
        raise CheckpointError("%s/dem has %d in.* files (%s): name the LIGGGHTS input with --dem-input"
                              % (case_dir, len(names), ", ".join(names) or "none"))
    return names[0]


def snapshot(case_dir: str, dest: str, scene: str | None = None, dem_input: str | None = None) -> dict:
    """Write the compact snapshot of the run in case_dir to the folder dest (module docstring), replacing
    whatever snapshot dest held: the newest step both codes checkpointed completely (select). The new
    folder is written beside dest and then put in its place. Returns {step, files: {name: bytes}, bytes}."""
    step, _ = select(case_dir, fields=False)
    name = _dem_input_name(case_dir, dem_input)
    if scene is None:
        path = os.path.join(case_dir, SCENE_FILE)
        if not os.path.isfile(path):
            raise CheckpointError("%s has no %s file (the command that writes the scene; the case scripts write it): "
                                  "give it with --scene COMMAND" % (case_dir, SCENE_FILE))
        with open(path) as f:
            scene = f.read().strip()
    stamp_path = os.path.join(case_dir, CALIBRATION_STAMP)
    if not os.path.isfile(stamp_path):
        raise CheckpointError("%s is missing: the run's record of its calibration table (fdmRun writes it when a run "
                              "starts or resumes)" % stamp_path)
    marker = read_fluid_marker(fluid_marker(case_dir, step))
    dest = os.path.abspath(dest)
    new = dest + ".new"
    shutil.rmtree(new, ignore_errors=True)
    os.makedirs(new)
    with open(os.path.join(new, "dem.%d%s" % (step, SNAPSHOT_DEM_SUFFIX)), "wb") as f:
        f.write(compact_dem_checkpoint(dem_file(case_dir, step)))
    shutil.copyfile(fluid_marker(case_dir, step), os.path.join(new, "fluid.%d" % step))
    shutil.copyfile(os.path.join(case_dir, "dem", name), os.path.join(new, name))
    # the table by its hash (what a continued run is checked against) and its path as the project names it:
    # a snapshot is committed, and no machine's path goes with it
    with open(stamp_path) as f:
        identity = json.load(f)
    if identity.get("table"):
        from .environment import project_dir
        root = os.path.normpath(project_dir() or os.sep)
        table = os.path.normpath(identity["table"])
        shipped = TABLE_FOLDER + os.sep
        if project_dir() and table.startswith(root + os.sep):
            identity["table"] = os.path.relpath(table, root)
        elif shipped in table:      # the shipped table of another checkout of the project
            identity["table"] = table[table.rindex(shipped):]
        else:
            identity["table"] = os.path.basename(table)
    with open(os.path.join(new, SNAPSHOT_CALIBRATION), "w") as f:
        json.dump(identity, f)
    with open(os.path.join(new, SCENE_FILE), "w") as f:
        f.write(scene + "\n")
    with open(os.path.join(new, "README"), "w") as f:
        f.write("Compact snapshot of a coupled run at step %d (time %s), docs/coupling.md \"Compact snapshot\".\n"
                "To continue it: write the scene with the command in %s (in a new folder CASE), then\n"
                "    fdmRun --from-snapshot THIS_FOLDER CASE\n"
                "(case scripts: add --from-snapshot THIS_FOLDER to the command). The fluid restarts from rest.\n"
                "dem.%d.xz: the particles, their contact history and the position update's history (fdmDEM's\n"
                "checkpoint, dem/particle_checkpoint.h, compacted); fluid.%d: the fluid's step, time and step count;\n"
                "%s: the LIGGGHTS input; %s: the calibration table the run used.\n"
                % (step, marker["time"], SCENE_FILE, step, step, name, SNAPSHOT_CALIBRATION))
    check_snapshot(new)
    old = dest + ".old"
    shutil.rmtree(old, ignore_errors=True)
    if os.path.exists(dest):
        os.rename(dest, old)
    os.rename(new, dest)
    shutil.rmtree(old, ignore_errors=True)
    files = {n: os.path.getsize(os.path.join(dest, n)) for n in sorted(os.listdir(dest))}
    return dict(step=step, files=files, bytes=sum(files.values()))


def check_snapshot(dest: str) -> dict:
    """The parts of the snapshot in dest, checked complete: {step, dem, marker, input, scene, calibration}
    (paths, the marker's entries and the DEM header). CheckpointError naming the file otherwise."""
    if not os.path.isdir(dest):
        raise CheckpointError("%s is not a folder (a compact snapshot: python3 -m fdmsubgrid.checkpoint snapshot)"
                              % dest)
    names = os.listdir(dest)
    compact = _steps(dest, "dem.", SNAPSHOT_DEM_SUFFIX)
    dem = sorted(_steps(dest, "dem.") + compact)     # a snapshot taken before they were compacted: dem.STEP
    fluid = _steps(dest, "fluid.")
    inputs = [n for n in names if n.startswith("in.")]
    if len(dem) != 1 or fluid != dem:
        raise CheckpointError("%s is not a complete snapshot: it needs one dem.STEP.xz (or dem.STEP) and the fluid.STEP of the same "
                              "step, it has %s" % (dest, ", ".join(sorted(n for n in names if n.startswith(("dem.", "fluid."))))
                                                   or "neither"))
    if len(inputs) != 1:
        raise CheckpointError("%s is not a complete snapshot: it needs one LIGGGHTS input in.*, it has %d"
                              % (dest, len(inputs)))
    for n in (SCENE_FILE, SNAPSHOT_CALIBRATION):
        if n not in names:
            raise CheckpointError("%s is not a complete snapshot: %s is missing" % (dest, n))
    step = dem[0]
    path = os.path.join(dest, "dem.%d%s" % (step, SNAPSHOT_DEM_SUFFIX if compact else ""))
    _, header = _checked_dem(path)
    marker = read_fluid_marker(os.path.join(dest, "fluid.%d" % step))
    if header["step"] != step or int(marker["step"]) != step:
        raise CheckpointError("%s: dem.%d holds step %d and fluid.%d step %s" % (dest, step, header["step"], step,
                                                                                  marker["step"]))
    with open(os.path.join(dest, SNAPSHOT_CALIBRATION)) as f:
        calibration = json.load(f)
    return dict(step=step, dem=path, header=header, marker=marker, input=os.path.join(dest, inputs[0]),
                scene=os.path.join(dest, SCENE_FILE), calibration=calibration)


# the table a pair style names (`calibration FILE`): fdmRun --resume adds it when a run goes on with the table it
# started with; which table a snapshot's run read is checked by its hash (snapshot_table), not by its name
_CALIBRATION_KEYWORD = re.compile(r"[ \t]+calibration[ \t]+\S+")
_SUBGRID_PAIR_STYLE = re.compile(r"^[ \t]*pair_style[ \t]+fdm/subgrid\b")


def _without_run(text: str) -> list[str]:
    """The input's lines, its run command masked (the run's length is the case's) and the pair style's
    calibration keyword left out (the table is compared by its hash)."""
    return ["run ..." if _RUN_COMMAND.fullmatch(line)
            else _CALIBRATION_KEYWORD.sub("", line) if _SUBGRID_PAIR_STYLE.match(line) else line
            for line in text.splitlines()]


def _last_step(dem_input: str) -> int:
    with open(dem_input) as f:
        commands = list(_RUN_COMMAND.finditer(f.read()))
    found = _RUN_UPTO.match(commands[0].group(0)) if len(commands) == 1 else None
    if not found:
        raise CheckpointError("%s: a run continued from a snapshot needs one run command 'run N upto' (docs/coupling.md)"
                              % dem_input)
    return int(found.group(2))


def _data_file(dem_input: str) -> str | None:
    """The data file the input reads (read_data FILE, relative to the input's folder), or None."""
    with open(dem_input) as f:
        for line in f:
            words = line.split("#", 1)[0].split()
            if len(words) >= 2 and words[0] == "read_data":
                return os.path.join(os.path.dirname(os.path.abspath(dem_input)), words[1])
    return None


def _data_scene(path: str) -> tuple[int, list[float], list[float]]:
    """(atoms, box lo, box hi) of a LIGGGHTS data file's header."""
    atoms, lo, hi = None, [None] * 3, [None] * 3
    with open(path) as f:
        for line in f:
            words = line.split()
            if len(words) == 2 and words[1] == "atoms":
                atoms = int(words[0])
            elif len(words) == 4 and words[2] in ("xlo", "ylo", "zlo"):
                d = "xyz".index(words[2][0])
                lo[d], hi[d] = float(words[0]), float(words[1])
            elif words and words[0] in ("Atoms", "Velocities"):
                break
    if atoms is None or None in lo:
        raise CheckpointError("%s: no 'N atoms' or box lines in its header" % path)
    return atoms, lo, hi


def snapshot_table(snap: dict, dest: str, dem_input: str) -> str | None:
    """The calibration table a run continued from the snapshot (check_snapshot's `snap`, in dest) must read: None if
    the input reads the one the snapshot's run used (the same SHA-256), else the project's table with that hash
    (table_by_hash: an earlier table kept beside the shipped one, which snapshot_install points the input at).
    CheckpointError naming the snapshot's record and the hash if the project has no such table."""
    now = _table_identity(calibration_table(dem_input))
    then = snap["calibration"]
    if now["sha256"] == then.get("sha256"):
        return None
    earlier = table_by_hash(then.get("sha256"))
    if earlier is not None:
        return earlier
    describe = lambda d: "no table" if d.get("table") is None else "%s (sha256 %s)" % (d["table"], d["sha256"][:12])
    raise CheckpointError("the sub-grid calibration table differs from the run's: the snapshot's run used %s "
                          "(recorded in %s), %s reads %s, and no table of the project (%s) has sha256 %s. Continuing "
                          "would mix two sub-grid models in one run: check out the table the run used (git log -- "
                          "dem/resistance/data)" % (describe(then), os.path.join(dest, SNAPSHOT_CALIBRATION), dem_input,
                                                    describe(now), _searched_tables(), then.get("sha256")))


def snapshot_check(dest: str, case_dir: str, dem_input: str, until: int | None = None) -> tuple[int, int]:
    """Before fdmRun --from-snapshot changes anything: the snapshot in dest is complete and of the scene in
    case_dir (its LIGGGHTS input the snapshot's but for the run command; the particle count and box of its
    data file the checkpoint's; the calibration table it reads the one the run used, by SHA-256, or the project
    keeps that one: snapshot_table), and the
    run goes on after the snapshot's step (to the input's last step, or `until`). Returns (step, last step)."""
    snap = check_snapshot(dest)
    step, header = snap["step"], snap["header"]
    with open(snap["input"]) as f:
        theirs = _without_run(f.read())
    with open(dem_input) as f:
        ours = _without_run(f.read())
    if theirs != ours:
        k = next((k for k, (a, b) in enumerate(zip(theirs, ours)) if a != b), min(len(theirs), len(ours)))
        line = lambda lines: repr(lines[k]) if k < len(lines) else "(the end of the file)"
        raise CheckpointError("%s is not the input of the snapshot's run %s: line %d is %s there, %s here. Write the "
                              "case with the command in %s" % (dem_input, snap["input"], k + 1, line(theirs), line(ours),
                                                               snap["scene"]))
    data = _data_file(dem_input)
    if data and os.path.isfile(data):
        atoms, lo, hi = _data_scene(data)
        if atoms != header["natoms"]:
            raise CheckpointError("%s has %d particles, the snapshot %s holds %d" % (data, atoms, snap["dem"],
                                                                                   header["natoms"]))
        for d in range(3):
            span = header["boxhi"][d] - header["boxlo"][d]
            if abs(lo[d] - header["boxlo"][d]) + abs(hi[d] - header["boxhi"][d]) > 1e-12 * span:
                raise CheckpointError("%s: the box spans %.17g .. %.17g in %s, the snapshot %s's %.17g .. %.17g"
                                      % (data, lo[d], hi[d], "xyz"[d], snap["dem"], header["boxlo"][d],
                                         header["boxhi"][d]))
    snapshot_table(snap, dest, dem_input)
    last = until if until is not None else _last_step(dem_input)
    if last <= step:
        raise CheckpointError("the snapshot is of step %d but %s runs to step %d: write the scene for a longer run, "
                              "or give --until L" % (step, dem_input if until is None else "--until", last))
    return step, last


def _mesh_cells(fluid: str) -> int:
    from .decomposition import DecompositionError, _read_foam_file
    try:
        header, _ = _read_foam_file(os.path.join(fluid, "constant", "polyMesh", "owner"))
    except DecompositionError as e:
        raise CheckpointError(str(e))
    found = re.search(r"nCells:\s*(\d+)", header.get("note", ""))
    if not found:
        raise CheckpointError("%s/constant/polyMesh/owner: no nCells in its note" % fluid)
    return int(found.group(1))


def snapshot_install(dest: str, case_dir: str, dem_input: str, np_fluid: int, until: int | None = None) -> tuple[int, int]:
    """fdmRun --from-snapshot, once snapshot_check passed and the case is meshed (and decomposed): the same
    number of cells as the snapshot's run; then the snapshot installed as the case's checkpoint of its step:
    dem/checkpoint/dem.STEP (its last step the run's), fluid/checkpoint/fluid.STEP (the snapshot's time, time index and step count, this
    case's cells and processors, fromRest 1) with the files of 0/ copied to the step's time directory (each
    processor's in parallel), the input pointed at the table the snapshot's run used if the project keeps it
    beside the shipped one (snapshot_table, use_table), and the calibration record of this case. Returns (step,
    last step)."""
    step, last = snapshot_check(dest, case_dir, dem_input, until)
    snap = check_snapshot(dest)
    marker = snap["marker"]
    fluid = os.path.join(case_dir, "fluid")
    cells = _mesh_cells(fluid)
    if cells != int(marker["cells"]):
        raise CheckpointError("%s has %d cells, the snapshot's run had %s (%s): write the case with the command in %s"
                              % (os.path.join(fluid, "constant", "polyMesh"), cells, marker["cells"],
                                 os.path.join(dest, "fluid.%d" % step), snap["scene"]))
    if until is not None:
        set_last_step(dem_input, until, step)
    earlier = snapshot_table(snap, dest, dem_input)
    if earlier is not None:
        use_table(dem_input, earlier)
    bases = [fluid] if np_fluid == 1 else [os.path.join(fluid, "processor%d" % p) for p in range(np_fluid)]
    for base in bases:
        source, target = os.path.join(base, "0"), os.path.join(base, marker["timeName"])
        if not os.path.isdir(source):
            raise CheckpointError("%s is missing: the fluid restarts from the fields of 0/" % source)
        os.makedirs(target, exist_ok=True)
        for n in os.listdir(source):
            if os.path.isfile(os.path.join(source, n)):
                shutil.copyfile(os.path.join(source, n), os.path.join(target, n))
    # the DEM checkpoint as if this run had written it: its last step this run's (the header line, outside the
    # CRC of the data), so that a plain --resume from it, before the run's own first checkpoint, ends there too
    data = _dem_bytes(snap["dem"])
    start = len(DEM_MAGIC)
    end = data.index(b"\n", start)
    line = re.sub(rb"\blastStep=\d+", b"lastStep=%d" % last, data[start:end])
    os.makedirs(os.path.join(case_dir, "dem", "checkpoint"), exist_ok=True)
    write_atomically(dem_file(case_dir, step), data[:start] + line + data[end:])
    entries = dict(marker, cells=str(cells), processors=str(np_fluid), regularOutput="0", fromRest="1")
    os.makedirs(os.path.join(fluid, "checkpoint"), exist_ok=True)
    write_atomically(fluid_marker(case_dir, step),
                     "# fdmRun --from-snapshot %s: the fields of 0/ in %s/ (the fluid from rest)\n"
                     % (dest, marker["timeName"]) + "".join("%s %s\n" % kv for kv in entries.items()) + "end\n")
    stamp(case_dir, dem_input)
    return step, last


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
    try:
        if len(argv) == 3 and argv[0] == "processors":
            print("%d %s" % marker_processors(argv[1], int(argv[2])))
            return 0
        if len(argv) == 4 and argv[0] == "set-processors":
            set_marker_processors(argv[1], int(argv[2]), int(argv[3]))
            return 0
        if len(argv) >= 3 and argv[0] == "snapshot":
            options = dict(zip(argv[3::2], argv[4::2]))
            unknown = set(options) - {"--scene", "--dem-input"}
            if unknown or len(argv[3:]) % 2:
                print(__doc__, file=sys.stderr)
                return 2
            done = snapshot(argv[1], argv[2], options.get("--scene"), options.get("--dem-input"))
            print("snapshot of step %d in %s: %s; %d bytes" % (done["step"], argv[2], ", ".join(
                "%s %d" % kv for kv in done["files"].items()), done["bytes"]))
            return 0
        if len(argv) in (4, 5) and argv[0] == "snapshot-check":
            print("%d %d" % snapshot_check(argv[1], argv[2], argv[3], int(argv[4]) if len(argv) == 5 else None))
            return 0
        if len(argv) in (5, 6) and argv[0] == "snapshot-install":
            print("%d %d" % snapshot_install(argv[1], argv[2], argv[3], int(argv[4]),
                                             int(argv[5]) if len(argv) == 6 else None))
            return 0
    except (CheckpointError, OSError) as e:
        print(e, file=sys.stderr)
        return 1
    print(__doc__, file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
