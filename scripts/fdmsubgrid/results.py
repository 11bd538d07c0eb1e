"""The one shape of a case's results file (`results.json`), its writer and its reader.

Every case script in `cases/` writes its results through `write_results`, and everything that reads a
case's results (the validation report, `table8.py`, the notebooks) reads them through `read_results` or
`read_data`. The file is one JSON object:

    {
      "shape":        "fdmsubgrid.results/1",      # this layout; a file without it is an older one
      "case":         "periodicArray",             # the case (cases/NAME/NAME.py)
      "command":      "cases/periodicArray/periodicArray.py --full",   # the command line, project-relative
      "commit":       "54de517",                   # the project's commit ("... with local changes" if dirty)
      "date":         "YYYY-MM-DD",
      "wall_seconds": 123.4,
      "scene":        {...},                       # the scene's parameters: the script's options
      "calibration":  [{"table": "dem/resistance/data/subgrid_calibration.dat", "sha256": "9f2c..."}],
                                                   # the sub-grid calibration table(s) the case's runs read
      "rows":         [ROW, ...],                  # what the case measured, beside its reference
      "data":         {...}                        # the case's own numbers (profiles, series, per run)
    }

`calibration` lists each distinct table the runs behind the file started with, as fdmRun recorded it in
each run folder (CASE/.fdmRun-calibration, fdmsubgrid.checkpoint.stamp): its path relative to the project
and the SHA-256 of its bytes; {"table": null, "sha256": null} for runs that read no table (`model cutoff`
or `lubrication no`); an empty list when no run folder is known (a case that runs no coupled solver, or a
run older than the record). The runs are those this process started since the case began (fdmsubgrid.
runner.run; write_results' `started`) and the folder named by the record's `run_dir` (a run analysed later). A file written before the key reads with an
empty list.

A ROW (`Row`) is one measured quantity in one configuration:

    quantity        "K (Eq. 40)"                   what is measured
    configuration   "L/a 8, a/Δ 5, c 0.3, 64 positions"
    value           1.5335 or null                 this project's value (null: not measured in this run)
    reference       1.5321 or null                 the independent reference (theory, published computation)
    paper           "1.532059 (+0.11 %)"           the paper's value or statement for the same quantity
    error           0.0009 or null                 (value - reference)/|reference|, or absolute (error_unit)
    error_unit      "%"                            "%": error is relative (shown in per cent), else its unit
    spread          0.0021 or null                 the error bar: the standard deviation over positions in
                                                   a mesh cell, or that of a time average
    headline        true                           false: a comparison run (e.g. the FDM alone)
    percent         false                          the value is a fraction, shown in per cent

`data` is each case's own record, the dict the case's `main()` returns (without `wall_seconds` and
`date`, which are the document's; `read_data` puts them back): its keys are listed on the case's page
in docs/cases/. Plots and notebooks read it; the validation report reads only `rows`.

    from fdmsubgrid import results
    doc = results.read_results("cases/periodicArray/results.json")
    for row in doc.rows:
        print(row.quantity, row.configuration, row.value, row.reference, row.error_text())

Results files written before this shape (a bare dict of the case's numbers) still read: `read_results`
gives them as `data` with no rows (`Results.legacy`), and `read_data` returns them unchanged.
"""
from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import time
from dataclasses import asdict, dataclass, field, fields
from typing import Any, Callable, Dict, Iterable, List, Optional, Sequence, Union

from . import files

SHAPE = "fdmsubgrid.results/1"

# the document's own keys, beside `data`
DOCUMENT_KEYS = ("shape", "case", "command", "commit", "date", "wall_seconds", "scene", "calibration", "rows",
                 "data")

# options that say where a case writes, not what it computes: left out of `scene`
NOT_SCENE = ("out", "workdir", "keep")


@dataclass
class Row:
    """One measured quantity in one configuration, beside its reference (the module docstring)."""
    quantity: str
    configuration: str
    value: Optional[float]              # this project; None: not measured in this run (e.g. no contact)
    reference: Optional[float] = None   # the independent reference (theory, published computation)
    paper: str = "—"                    # the paper's value or statement for the same quantity
    error: Optional[float] = None       # (value - reference) / |reference|, or an absolute error (see unit)
    error_unit: str = "%"               # "%": relative error in per cent; otherwise the unit of an absolute one
    spread: Optional[float] = None      # standard deviation over positions in the cell, or of a time average
    headline: bool = True               # False: a comparison run (the FDM alone), left out of the summary
    percent: bool = False               # the value is a fraction, shown in per cent (a balance's error)

    def error_text(self) -> str:
        if self.error is None or not math.isfinite(self.error):
            return "—"
        if self.error_unit == "%":
            return "%+.2f %%" % (100 * self.error)
        return "%+.3g %s" % (self.error, self.error_unit)

    @classmethod
    def from_dict(cls, d: Dict[str, Any]) -> "Row":
        """A row from its JSON object; an unknown key is an error (a file of another shape)."""
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(d) - known)
        if unknown:
            raise KeyError("a results row has unknown key(s) %s (the keys are %s)"
                           % (", ".join(unknown), ", ".join(sorted(known))))
        return cls(**d)


def relative(value: float, reference: Optional[float]) -> Optional[float]:
    """(value - reference)/|reference|, or None without a (non-zero) reference."""
    if reference is None or reference == 0:
        return None
    return (value - reference) / abs(reference)


@dataclass
class Results:
    """A results file as read (the module docstring gives each field)."""
    case: str
    command: str
    commit: str
    date: str
    wall_seconds: Optional[float]
    scene: Dict[str, Any] = field(default_factory=dict)
    rows: List[Row] = field(default_factory=list)
    calibration: List[Dict[str, Any]] = field(default_factory=list)   # the module docstring
    data: Dict[str, Any] = field(default_factory=dict)
    shape: Optional[str] = SHAPE       # None: a file written before this shape (its numbers in data, no rows)

    @property
    def legacy(self) -> bool:
        return self.shape is None


def project_commit(folder: str) -> str:
    """The short commit of the git work tree holding folder, '... with local changes' if tracked files
    differ from it; 'unknown' outside git."""
    try:
        head = subprocess.run(["git", "-C", folder, "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
        if head.returncode != 0:
            return "unknown"
        dirty = subprocess.run(["git", "-C", folder, "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True).stdout.strip()
        return head.stdout.strip() + (" with local changes" if dirty else "")
    except OSError:
        return "unknown"


def project_root(script: str) -> str:
    """The project folder of a case script (cases/NAME/NAME.py): two folders up."""
    return os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(script))))


def relative_token(token: str, start: str) -> str:
    """An absolute path written relative to start (a results file names no folder of the machine)."""
    return os.path.relpath(token, start) if os.path.isabs(token) else token


def command_line(script: str, argv: Optional[Sequence[str]]) -> str:
    """The command that ran a case: its script and options, every absolute path relative to the project."""
    root = project_root(script)
    argv = sys.argv[1:] if argv is None else list(argv)
    return " ".join([os.path.relpath(os.path.abspath(script), root)] +
                    [relative_token(str(a), root) for a in argv])


def scene_of(options: Any, script: Optional[str] = None) -> Dict[str, Any]:
    """The scene's parameters from a case's options (an argparse Namespace or a dict): every option but
    where the case writes (NOT_SCENE), paths relative to the project."""
    values = dict(vars(options) if not isinstance(options, dict) else options)
    scene = {k: v for k, v in values.items() if k not in NOT_SCENE}
    start = project_root(script) if script else os.getcwd()
    return files.relative_paths(scene, start)


def calibration_of_runs(run_dirs: Iterable[str], root: str, since: float = -math.inf) -> List[Dict[str, Any]]:
    """The distinct sub-grid calibration tables the run folders started with (fdmRun's CASE/.fdmRun-calibration;
    a folder without the record is left out) and those of the runs this process started at or after `since`
    (fdmsubgrid.runner.calibrations_run), each {"table": path relative to root or None, "sha256": ...}."""
    from . import checkpoint, runner
    found: List[Dict[str, Any]] = []
    identities = list(runner.calibrations_run(since))
    for run_dir in run_dirs:
        path = os.path.join(run_dir, checkpoint.CALIBRATION_STAMP)
        if os.path.isfile(path):
            with open(path) as f:
                identities.append(json.load(f))
    for identity in identities:
        table = identity.get("table")
        entry = dict(table=None if table is None else os.path.relpath(table, root), sha256=identity.get("sha256"))
        if entry not in found:
            found.append(entry)
    return found


def json_value(value: Any) -> Any:
    """json.dumps' fallback: numpy scalars and arrays as Python numbers and lists."""
    if hasattr(value, "tolist"):
        return value.tolist()
    raise TypeError("%s is not JSON serialisable" % type(value).__name__)


def write_results(path: str, script: str, argv: Optional[Sequence[str]], options: Any,
                  rows: Union[Iterable[Row], Callable[[Dict[str, Any]], Iterable[Row]], None],
                  data: Dict[str, Any], started: float) -> Dict[str, Any]:
    """Write a case's results file in the one shape (module docstring), whole or not at all.

    script: the case script (its __file__; the case is its name), argv: its options as given (None:
    sys.argv[1:]), options: its parsed options (the scene), rows: what it measured against its
    references, or the case's function that makes them from data (a record it cannot read, e.g. of a
    partial run, then gives a file without rows and a line on stderr rather than no file), data: its
    own record, started: time.time() at its start. The document's calibration: the tables its runs read
    (calibration_of_runs; the module docstring). The document's wall_seconds is
    data's own where it has one (a suspension's run, analysed later), else the time since started.
    Returns data, stamped with wall_seconds and date as the document has them (what main() returns)."""
    # a record that carries its own wall time (a suspension run's, analysed later) keeps it
    if callable(rows):
        try:
            rows = list(rows(data))
        except (KeyError, IndexError, TypeError, ValueError) as exc:
            print("%s: no rows from this record (%s: %s); %s written without them"
                  % (os.path.basename(script), type(exc).__name__, exc, path), file=sys.stderr)
            rows = []
    wall_seconds = data.get("wall_seconds") if data.get("wall_seconds") is not None else time.time() - started
    date = time.strftime("%Y-%m-%d")
    document = dict(shape=SHAPE, case=os.path.splitext(os.path.basename(script))[0],
                    command=command_line(script, argv), commit=project_commit(os.path.dirname(os.path.abspath(script))),
                    date=date, wall_seconds=wall_seconds, scene=scene_of(options, script),
                    calibration=calibration_of_runs([data["run_dir"]] if isinstance(data.get("run_dir"), str) else [],
                                                    project_root(script), since=started),
                    rows=[asdict(row) for row in rows or []],
                    data={k: v for k, v in data.items() if k not in ("wall_seconds", "date")})
    files.write_json(path, document, default=json_value)
    data["wall_seconds"] = wall_seconds
    data["date"] = date
    return data


def from_document(document: Dict[str, Any]) -> Results:
    """A Results from a results file's JSON object (an older file: its numbers as data, no rows)."""
    if not isinstance(document, dict):
        raise TypeError("a results file holds a JSON object, not %s" % type(document).__name__)
    if "shape" not in document:
        return Results(case=str(document.get("case", "")), command="", commit="", date=str(document.get("date", "")),
                       wall_seconds=document.get("wall_seconds"), data=document, shape=None)
    if document["shape"] != SHAPE:
        raise ValueError("results of shape %r; this package reads %r" % (document["shape"], SHAPE))
    unknown = sorted(set(document) - set(DOCUMENT_KEYS))
    if unknown:
        raise KeyError("a results file has unknown key(s) %s" % ", ".join(unknown))
    return Results(case=document["case"], command=document["command"], commit=document["commit"],
                   date=document["date"], wall_seconds=document["wall_seconds"], scene=document["scene"],
                   rows=[Row.from_dict(r) for r in document["rows"]], data=document["data"], shape=SHAPE,
                   calibration=list(document.get("calibration", [])))


def read_results(path: str) -> Results:
    """A case's results file (either shape). ValueError, KeyError or TypeError if it is not one."""
    with open(path) as f:
        return from_document(json.load(f))


def read_data(path: str) -> Dict[str, Any]:
    """A results file's own record, as the case's main() returned it (with wall_seconds and date): the
    `data` of the current shape, or an older file whole."""
    read = read_results(path)
    if read.legacy:
        return read.data
    return dict(read.data, wall_seconds=read.wall_seconds, date=read.date)
