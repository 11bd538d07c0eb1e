"""The validation report (issue 15 item 6): run every validation case at one size, then write one
markdown report of its tables, each row with the paper's value beside this project's, the reference,
the error and the wall time, from the cases' results files.

    from fdmsubgrid import results, validation
    report = validation.run_report(full=False)          # runs the cases, writes docs/data/validation_report.md
    rows = results.read_results("runs/validation/periodicArray/results.json").rows

The command is scripts/validationReport (`--help`). Each case is its own script, cases/NAME/NAME.py,
run as a new user would (its default size, or --full) with --workdir and --out in runs/validation/KEY/
(results.json, figures, log); a case that fails is reported as failed (its log kept) and the others
still run. Every case writes its results.json in the one shape of fdmsubgrid.results, its `rows` the
report's rows: one reader (`collect`) for all of them. A results file of the older, per-case shape
has no rows and is reported as failed, naming the shape (run the case again).
"""
from __future__ import annotations

import json
import math
import os
import shutil
import subprocess
import sys
import time
from dataclasses import asdict, dataclass, field
from typing import Dict, List, Optional, Sequence

from . import results as results_file
from . import rheology, shear
from .results import Row, relative

__all__ = ["Case", "CASES", "Row", "relative", "run_report", "collect", "table8_rows", "squeeze_calibration_rows"]

PROJECT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


@dataclass
class Case:
    """A validation case: how to run it (its results file gives the rows, in the one shape of
    fdmsubgrid.results)."""
    name: str
    section: str                        # the paper's section and what it shows
    reference_source: str               # what the reference column is
    default_args: List[str] = field(default_factory=list)
    full_args: List[str] = field(default_factory=lambda: ["--full"])

    def script_path(self) -> str:
        return os.path.join(PROJECT, "cases", self.name, self.name + ".py")


# Every case of the report, in the paper's order; pairShear runs twice (smooth, contact), keyed apart
CASES: Dict[str, Case] = {}
for _c in [
    Case("periodicArray", "5.1 periodic array of spheres: the drag K against Hasimoto (Table 4)",
         "Hasimoto's series (Eq. 41)"),
    Case("pairSqueeze", "3 / Appendix C: squeeze flow of a pair, with and without the sub-grid correction",
         "two-sphere theory (Jeffrey & Onishi 1984, full range); the box effect extrapolated away (L = 8 and "
         "12 a1: the theory is for an unbounded fluid)",
         default_args=["--box-extrapolate", "12"]),
    Case("wallSqueeze", "Appendix D: squeeze flow toward a wall, with and without the sub-grid correction",
         "Brenner (1961)"),
    Case("pairShear", "5.3 a sphere pair in simple shear without contact (reversibility)",
         "the initial offset (Stokes flow is reversible)"),
    Case("pairShear", "5.3 a sphere pair in simple shear with contact (the contact window)",
         "the paper's Fig. 14", default_args=["--contact"], full_args=["--contact", "--full"]),
    Case("shearedSphere", "5.2.2 (wide channel): the dilute stresslet and the momentum balance",
         "the unbounded sphere: S* = 1, Ω_z = −γ̇/2", full_args=["--sweep", "--positions", "2"]),
    Case("wallShear", "5.2.1 a free sphere in simple shear next to one wall",
         "the free sphere from the exact wall resistance functions and Goldman, Cox & Brenner's fixed sphere "
         "(U, Ω); Sangani et al.'s fit, Eq. (46) (S*)",
         # the calibrated tangential wall functions (a/Δ 3, 4 and 5); --full's a2 sphere (a/Δ 7) is not
         default_args=["--model", "calibrated"]),
    Case("channelShear", "5.2.2 a free sphere at the centre of a sheared channel, H/a from 2.2 to 20",
         "the unbounded limits Ω_z = −γ̇/2, S* = 1 (wide channels); no tabulated values"),
    Case("poiseuilleSphere", "5.2.3 a free sphere in plane Poiseuille flow",
         "Staben et al. (2003) on the centre plane at 2a/H 0.6; elsewhere Faxén's laws with the leading wall "
         "reflections (the centre 2 radii or more from both walls; none nearer)"),
    Case("pairPoiseuille", "5.4 two free spheres in a confined plane Poiseuille flow (H = 4a)",
         "no tabulated values (Bhattacharya et al. 2006 are plots): the sign change of U_y, lubrication near "
         "contact, the isolated spheres far apart"),
    Case("threeSpheres", "5.5 three spheres, one pushed toward the centroid",
         "far-field reflections with exact pairs in unbounded fluid (r/a ≥ 4)"),
]:
    CASES[_c.name + ("Contact" if "--contact" in _c.default_args else "")] = _c


def table8_rows(summary: dict) -> List[Row]:
    """The rows of a cases/couette/table8.py summary (Table 8 and Fig. 21), beside the paper's."""
    rows = []
    for r in summary.get("rows", []):
        if "eta_s" not in r:
            continue
        config = "φ_bulk %g, %s, %.1f strain units (%s)" % (r["phi_bulk_table8"], "%d particles" % r["n_particles"],
                                                           r["strain_units"], r.get("status", ""))
        rows += shear.validation_rows(r, config)
    fit = summary.get("fit")
    if fit:
        for q, key, paper in (("Maron–Pierce α", "alpha", rheology.PAPER_MARON_PIERCE[0]),
                              ("Maron–Pierce φ_m", "phi_m", rheology.PAPER_MARON_PIERCE[1])):
            rows.append(Row(q, "fit of the rows above (Eq. 55)", fit[key], paper, "%g (Fig. 21)" % paper,
                            relative(fit[key], paper), spread=fit.get(key + "_error")))
    return rows


# The squeeze calibration's measurements shipped beside its table (no run: the report reads them)
SQUEEZE_CALIBRATION = os.path.join(PROJECT, "dem", "resistance", "data", "squeeze_calibration.json")


def squeeze_calibration_rows(path: str = SQUEEZE_CALIBRATION) -> List[Row]:
    """Appendix B: per calibration (pair or wall, a1/Delta, a2/a1) the calibrated model's velocity at the gap
    where its mean over the calibration's positions in the cell is worst (± the spread over them), and at
    the worst position and gap, beside the floor no correction of the gap alone can pass there. Exact from
    the measurements (calibration.py: the squeeze resistances add)."""
    from . import calibration
    rows = []
    for e in calibration.position_errors(path):
        name = "ξ" if e["kind"] == "pair" else "ε"
        config = "%s, a1/Δ %g%s" % (e["kind"], e["a_over_delta"], ", a2/a1 %g" % e["ratio"] if e["kind"] == "pair"
                                    else "")
        quantity = "closing velocity" if e["kind"] == "pair" else "velocity toward the wall"
        k = max(range(len(e["gaps"])), key=lambda i: abs(e["mean"][i]))
        rows.append(Row(quantity + " (mean of %d positions)" % e["positions"],
                        "%s, %s %g (its worst gap)" % (config, name, e["gaps"][k]),
                        e["theory"][k] * (1 + e["mean"][k]), e["theory"][k], "Figs. B.24–B.25 (error bars)",
                        e["mean"][k], spread=e["theory"][k] * e["std"][k]))
        k = max(range(len(e["gaps"])), key=lambda i: abs(e["worst"][i]))
        rows.append(Row(quantity + " (worst position)",
                        "%s, %s %g (its worst gap; no correction of the gap alone does better than %.1f %% there)"
                        % (config, name, e["gaps"][k], 100 * e["floor"][k]),
                        e["theory"][k] * (1 + e["worst"][k]), e["theory"][k], "—", e["worst"][k]))
    return rows


@dataclass
class CaseResult:
    """What the report knows of one case after running (or reading) it."""
    key: str
    case: Case
    status: str                         # ran, read, failed, missing
    command: str
    wall_seconds: Optional[float]
    rows: List[Row]
    log: Optional[str] = None
    message: str = ""
    figures: List[str] = field(default_factory=list)
    provenance: str = ""                # read: when, at which commit and where the results were made


def shown_path(path: str) -> str:
    """A path as the report writes it: relative to the project (a report names no folder of the machine
    it was made on; tests/test_docs.py checks the tracked files for absolute paths)."""
    return os.path.relpath(path, PROJECT) if os.path.isabs(path) else path


def shown_command(command: str) -> str:
    """A command line as the report writes it: every absolute path in it relative to the project (also
    the commands of run records written before the report wrote them so)."""
    return " ".join(shown_path(token) if token.startswith(os.sep) else token for token in command.split(" "))


def case_command(case: Case, full: bool, folder: str) -> List[str]:
    return [sys.executable, case.script_path()] + list(case.full_args if full else case.default_args) + \
        ["--workdir", os.path.join(folder, "runs"), "--out", os.path.join(folder, "results.json")]


def collect(key: str, case: Case, folder: str, status: str, command: Optional[str], wall: Optional[float],
            log: Optional[str]) -> CaseResult:
    """Read a case's results file (fdmsubgrid.results) into the report's rows; a results file that does
    not parse, or is of the older shape without rows, is a failure. command None: the one the results
    file records."""
    path = os.path.join(folder, "results.json")
    if command is None:
        command = "(read: %s)" % shown_path(path)
    if not os.path.exists(path):
        return CaseResult(key, case, "missing" if status == "read" else "failed", command, wall, [], log,
                          "no results file %s" % shown_path(path))
    try:
        read = results_file.read_results(path)
    except (ValueError, KeyError, TypeError) as exc:
        return CaseResult(key, case, "failed", command, wall, [], log,
                          "%s: cannot read it (%s: %s)" % (shown_path(path), type(exc).__name__, exc))
    if read.legacy:
        return CaseResult(key, case, "failed", command, wall, [], log,
                          "%s: results of the older per-case shape, without rows (%s); run the case again"
                          % (shown_path(path), results_file.SHAPE))
    if wall is None:
        wall = read.wall_seconds
    provenance = ""
    if command.startswith("(read: ") and read.command:
        command = read.command
        provenance = "run on %s at commit %s, read from %s" % (read.date, read.commit, shown_path(folder))
    figures = sorted(os.path.join(folder, f) for f in os.listdir(folder) if f.endswith(".png"))
    return CaseResult(key, case, status, command, wall, read.rows, log, figures=figures, provenance=provenance)


RUN_RECORD = "validation_run.json"   # in a case's folder: the command that made its results, when and where


def run_case(key: str, case: Case, full: bool, folder: str) -> CaseResult:
    """Run one case as a user would (its own script) into folder, its output in folder/log, then read it.
    The command, the commit, the date and the wall time go into folder/RUN_RECORD, which a later
    --report-only shows (read_case)."""
    if os.path.isdir(folder):
        shutil.rmtree(folder)   # never report a previous run's numbers or figures as this one's
    os.makedirs(folder)
    command = case_command(case, full, folder)
    shown = " ".join(shown_path(c) for c in command[1:])
    log = os.path.join(folder, "log")
    started = time.strftime("%Y-%m-%d %H:%M")
    t0 = time.time()
    with open(log, "w") as f:
        done = subprocess.run(command, stdout=f, stderr=subprocess.STDOUT, cwd=PROJECT)
    wall = time.time() - t0
    with open(os.path.join(folder, RUN_RECORD), "w") as f:
        json.dump(dict(command=shown, commit=git_commit(), date=started, wall_seconds=wall,
                       exit_code=done.returncode), f, indent=1)
    if done.returncode != 0:
        return CaseResult(key, case, "failed", shown, wall, [], log,
                          "exit code %d (log %s)" % (done.returncode, shown_path(log)))
    return collect(key, case, folder, "ran", shown, wall, log)


def read_case(key: str, case: Case, folder: str) -> CaseResult:
    """A case's results as an earlier run left them in folder (--report-only): its command, commit and wall
    time from folder/RUN_RECORD where run_case wrote one, else those the results file records."""
    record_path = os.path.join(folder, RUN_RECORD)
    if not os.path.exists(record_path):
        return collect(key, case, folder, "read", None, None, None)
    with open(record_path) as f:
        record = json.load(f)
    read = collect(key, case, folder, "read", shown_command(record["command"]), record.get("wall_seconds"), None)
    read.provenance = "run on %s at commit %s, read from %s" % (record["date"], record["commit"], shown_path(folder))
    return read


def number(v: Optional[float]) -> str:
    if v is None or not isinstance(v, (int, float)) or not math.isfinite(v):
        return "—"
    return "%.4g" % v


def markdown(results: List[CaseResult], table8: Optional[dict], info: dict, figures_dir: str, out: str,
             calibration_rows: Optional[List[Row]] = None) -> str:
    """The report's text: a header saying how it was made, then one table per case."""
    lines = ["# Validation report", "",
             "Generated by `%s` on %s (commit %s, %s); wall time %.0f s, of which the cases' runs %.0f s. "
             "Each row: the quantity, "
             "the configuration, the paper's value or statement, this project's value (± its standard deviation "
             "over positions in a mesh cell, or the error bar of a time average), the reference and the error "
             "against it. docs/validation.md discusses every case; docs/cases.md gives their options."
             % (info["command"], info["date"], info["commit"], info["size"], info["wall_seconds"],
                info["cases_wall_seconds"]), ""]
    lines += ["| case | status | wall s | rows | largest \\|error\\| (the method as run, comparison runs aside) |",
              "|---|---|---|---|---|"]
    for r in results:
        errors = [abs(row.error) for row in r.rows if row.error is not None and row.error_unit == "%"
                  and math.isfinite(row.error) and row.headline]
        lines.append("| %s | %s%s | %s | %d | %s |" % (r.key, r.status, (": " + r.message) if r.message else "",
                                                      "%.0f" % r.wall_seconds if r.wall_seconds else "—", len(r.rows),
                                                      "%.2f %%" % (100 * max(errors)) if errors else "—"))
    lines.append("")
    for r in results:
        lines += ["## %s (`cases/%s`)" % (r.case.section, r.case.name), "",
                  "Command: `%s`; %s%s; wall time %s. Reference: %s." % (
                      r.command, r.status, " (%s)" % r.provenance if r.provenance else "",
                      "%.0f s" % r.wall_seconds if r.wall_seconds else "—", r.case.reference_source), ""]
        if r.message:
            lines += ["**%s**: %s" % (r.status, r.message), ""]
        lines += table(r.rows)
        for fig in r.figures:
            lines += figure_lines(fig, r.key, figures_dir, out)
    if calibration_rows is not None:
        lines += ["## Appendix B: the squeeze calibration at every position in the cell", "",
                  "From the solver's own measurements behind the shipped table (%s; no run): the calibrated "
                  "model's velocity averaged over the calibration's 4 positions in the cell, and at the worst one "
                  "(docs/validation.md, \"At every position in the cell\"). Reference: the two-sphere theory "
                  "(Jeffrey & Onishi), Brenner (1961) for the wall; units F/(6πηa1)."
                  % os.path.relpath(SQUEEZE_CALIBRATION, PROJECT), ""]
        lines += table(calibration_rows)
    if table8 is not None:
        lines += ["## 6.1 suspensions in simple shear: Table 8, Figs. 21 and 22 (`cases/couette/table8.py`)", "",
                  "From %s (the runs as they stand; a row's strain units say how far it got)." % info["table8"], ""]
        lines += table(table8_rows(table8))
        # the summary's own figures (Fig. 21; Fig. 22, the normal stresses), beside its JSON
        where = os.path.dirname(os.path.join(PROJECT, info["table8"]))
        for key in ("figure", "figure_normal_stresses"):
            fig = os.path.join(where, table8[key]) if table8.get(key) else None
            if fig and os.path.exists(fig):
                lines += figure_lines(fig, "table8", figures_dir, out)
    return "\n".join(lines) + "\n"


def figure_lines(fig: str, prefix: str, figures_dir: str, out: str) -> List[str]:
    """Copies a figure into the report's folder as PREFIX_NAME and returns its Markdown lines, linked
    relative to the report."""
    name = "%s_%s" % (prefix, os.path.basename(fig))
    shutil.copyfile(fig, os.path.join(figures_dir, name))
    return ["![%s](%s)" % (name, os.path.relpath(os.path.join(figures_dir, name), os.path.dirname(out))), ""]


def table(rows: List[Row]) -> List[str]:
    if not rows:
        return ["(no rows)", ""]
    lines = ["| quantity | configuration | paper | this project | reference | error |", "|---|---|---|---|---|---|"]
    for row in rows:
        value = ("%.2g %%" % (100 * row.value) if row.percent else number(row.value)) + \
            (" ± %s" % number(row.spread) if row.spread else "")
        lines.append("| %s | %s | %s | %s | %s | %s |" % (row.quantity, row.configuration, row.paper, value,
                                                         number(row.reference), row.error_text()))
    return lines + [""]


def git_commit() -> str:
    return results_file.project_commit(PROJECT)


DEFAULT_WORKDIR = os.path.join(PROJECT, "runs", "validation")


def run_report(keys: Optional[Sequence[str]] = None, full: bool = False, report_only: bool = False,
               out: str = os.path.join(PROJECT, "docs", "data", "validation_report.md"),
               table8: Optional[str] = None, workdir: str = DEFAULT_WORKDIR, command: str = "validationReport") -> dict:
    """Run (or, report_only, read) the cases and write the report: out (markdown), its .json and a folder of
    figures beside it. Each case runs in workdir/<key>/ (its results.json, figures, log and run folders)."""
    keys = list(keys or CASES)
    unknown = [k for k in keys if k not in CASES]
    if unknown:
        raise ValueError("validationReport: unknown case(s) %s; the cases are %s" % (", ".join(unknown),
                                                                                    ", ".join(CASES)))
    table8_summary = None
    if table8:
        if not os.path.exists(table8):
            raise ValueError("validationReport: --table8 %s: no such file (cases/couette/table8.py --out writes it)"
                             % table8)
        with open(table8) as f:
            table8_summary = json.load(f)
    figures_dir = os.path.splitext(out)[0]
    if os.path.isdir(figures_dir):
        for f in os.listdir(figures_dir):
            if f.endswith(".png"):
                os.remove(os.path.join(figures_dir, f))
    os.makedirs(figures_dir, exist_ok=True)
    t0 = time.time()
    results: List[CaseResult] = []
    for i, key in enumerate(keys):
        case = CASES[key]
        if report_only:
            folder = os.path.join(workdir, key)
            results.append(read_case(key, case, folder))
        else:
            elapsed = time.time() - t0
            print("[%d/%d] %s (%.0f s so far)" % (i + 1, len(keys), key, elapsed), flush=True)
            results.append(run_case(key, case, full, os.path.join(workdir, key)))
            print("      %s in %.0f s%s" % (results[-1].status, results[-1].wall_seconds or 0,
                                           (": " + results[-1].message) if results[-1].message else ""), flush=True)
    info = dict(command=shown_command(command), date=time.strftime("%Y-%m-%d %H:%M"), commit=git_commit(),
                workdir=shown_path(workdir),
                size="--full sizes" if full else "default sizes", wall_seconds=time.time() - t0,
                cases_wall_seconds=sum(r.wall_seconds or 0.0 for r in results),
                table8=os.path.relpath(table8, PROJECT) if table8 else None)
    calibration_rows = squeeze_calibration_rows() if os.path.exists(SQUEEZE_CALIBRATION) else None
    text = markdown(results, table8_summary, info, figures_dir, out, calibration_rows)
    with open(out, "w") as f:
        f.write(text)
    summary = dict(info, cases=[dict(key=r.key, section=r.case.section, status=r.status, command=r.command,
                                     provenance=r.provenance, wall_seconds=r.wall_seconds, message=r.message,
                                     rows=[asdict(row) for row in r.rows]) for r in results])
    if calibration_rows is not None:
        summary["squeeze_calibration_rows"] = [asdict(row) for row in calibration_rows]
    if table8_summary is not None:
        summary["table8_rows"] = [asdict(row) for row in table8_rows(table8_summary)]
    with open(os.path.splitext(out)[0] + ".json", "w") as f:
        json.dump(summary, f, indent=1)
    return summary
