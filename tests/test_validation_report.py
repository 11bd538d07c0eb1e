"""scripts/validationReport (issue 15 item 6): one command runs the validation cases and writes the
report beside the paper's values. Here on the cheapest case, run for real (cases/shearedSphere: one free
sphere in a wide channel, about 30 s): the report carries the case's physics (S* and the rotation of
the dilute limit), reading the results again gives the same rows, and what cannot be read is reported
by name, never silently skipped."""
import json
import os
import subprocess
import sys

import pytest

from conftest import PROJECT

REPORT = os.path.join(PROJECT, "scripts", "validationReport")


def report(args, env):
    return subprocess.run([sys.executable, REPORT] + args, env=env, cwd=PROJECT, capture_output=True, text=True)


@pytest.fixture(scope="module")
def sheared_report(tmp_path_factory, env):
    tmp = tmp_path_factory.mktemp("report")
    out, work = tmp / "report.md", tmp / "work"
    done = report(["--only", "shearedSphere", "--out", str(out), "--workdir", str(work)], env)
    assert done.returncode == 0, done.stdout + done.stderr
    with open(tmp / "report.json") as f:
        return tmp, out, work, json.load(f)


def rows_by_quantity(summary):
    return {row["quantity"]: row for case in summary["cases"] for row in case["rows"]}


def test_report_carries_the_case_physics(sheared_report):
    tmp, out, work, summary = sheared_report
    (case,) = summary["cases"]
    assert case["key"] == "shearedSphere" and case["status"] == "ran" and case["wall_seconds"] > 0
    rows = rows_by_quantity(summary)
    # the dilute limit in a 12 x 20 x 12 a box at a/Delta 3 (measured: S* -1.41 %, rotation -0.30 %)
    s_star = rows["S* (unbounded: 1)"]
    assert s_star["reference"] == 1.0 and abs(s_star["error"]) < 0.03
    assert abs(s_star["value"] - 1.0) == pytest.approx(abs(s_star["error"]))
    assert abs(rows["Ω_z/(−γ̇/2)"]["error"]) < 0.01
    assert rows["momentum balance on the walls (largest)"]["value"] < 0.03
    text = out.read_text()
    assert "## 5.2.2" in text and "cases/shearedSphere" in text and "| S* (unbounded: 1) |" in text
    assert (work / "shearedSphere" / "results.json").exists() and (work / "shearedSphere" / "log").exists()
    # the squeeze calibration at every position, read from the shipped measurements (no run): two rows per
    # calibration (3 resolutions x pair 1, pair 1.4, wall; the pair 1 and the wall at 5.6), the mean's error
    # within the spread's reach
    assert "## Appendix B: the squeeze calibration at every position in the cell" in text
    calibration_rows = summary["squeeze_calibration_rows"]
    assert len(calibration_rows) == 22
    for row in calibration_rows:
        assert row["error"] == pytest.approx((row["value"] - row["reference"]) / row["reference"], rel=1e-9)
        assert abs(row["error"]) < (0.035 if "mean" in row["quantity"] else 0.1)


def test_report_only_reads_the_same_rows(sheared_report, env):
    tmp, out, work, summary = sheared_report
    again = tmp / "again.md"
    done = report(["--only", "shearedSphere", "--report-only", "--out", str(again), "--workdir", str(work)], env)
    assert done.returncode == 0, done.stdout + done.stderr
    with open(tmp / "again.json") as f:
        read = json.load(f)
    assert read["cases"][0]["status"] == "read"
    assert read["cases"][0]["rows"] == summary["cases"][0]["rows"]
    # the command that made the results, and its wall time, come back from the case's run record
    assert read["cases"][0]["command"] == summary["cases"][0]["command"]
    assert read["cases"][0]["wall_seconds"] == pytest.approx(summary["cases"][0]["wall_seconds"])
    assert "at commit" in read["cases"][0]["provenance"]
    assert "Command: `%s`; read (run on " % summary["cases"][0]["command"] in again.read_text()


def test_unreadable_and_missing_results_are_reported(tmp_path, env):
    work = tmp_path / "work"
    (work / "threeSpheres").mkdir(parents=True)
    (work / "threeSpheres" / "results.json").write_text("{ not json")
    done = report(["--only", "threeSpheres", "periodicArray", "--report-only", "--out", str(tmp_path / "r.md"),
                   "--workdir", str(work)], env)
    assert done.returncode == 1
    with open(tmp_path / "r.json") as f:
        cases = {c["key"]: c for c in json.load(f)["cases"]}
    assert cases["threeSpheres"]["status"] == "failed"
    # named relative to the project, as every path of the report (tests/test_docs.py)
    assert os.path.relpath(work / "threeSpheres" / "results.json", PROJECT) in cases["threeSpheres"]["message"]
    assert cases["periodicArray"]["status"] == "missing"
    assert "failed or missing: threeSpheres, periodicArray" in done.stdout


def test_bad_options_are_refused_by_name(tmp_path, env):
    done = report(["--only", "pairSqeeze", "--report-only", "--out", str(tmp_path / "r.md")], env)
    assert done.returncode == 2 and "unknown case(s) pairSqeeze" in done.stderr and "pairSqueeze" in done.stderr
    missing = tmp_path / "table8.json"
    done = report(["--only", "shearedSphere", "--report-only", "--table8", str(missing), "--out",
                   str(tmp_path / "r.md")], env)
    assert done.returncode == 2 and str(missing) in done.stderr


def test_table8_figures_join_the_report(tmp_path, env):
    """--table8 SUMMARY puts the summary's rows and both its figures (Fig. 21, Fig. 22) into the report,
    copied beside it, each row's η_s beside the paper's fit (Eq. 55) at its own φ_core; the summary here is
    table8.py --analyse-only over the rows of a shipped one."""
    from conftest import load_case_module
    table8 = load_case_module("couette", "table8")
    shipped = os.path.join(PROJECT, "docs", "data", "validation_table8_fluidEvery.json")
    summary = table8.main(["--analyse-only", "--phis", "0.58", "--workdir", str(tmp_path / "runs"),
                           "--rows-from", shipped, "--out", str(tmp_path / "t8.json")])
    from fdmsubgrid import rheology, validation
    eta_rows = [row for row in validation.table8_rows(summary) if row.quantity == "η_s"]
    finished = [r for r in summary["rows"] if "eta_s" in r]
    assert len(eta_rows) == len(finished) >= 3
    for row, r in zip(eta_rows, finished):
        paper_fit = rheology.PAPER_MARON_PIERCE[0] / (1 - r["phi_core"] / rheology.PAPER_MARON_PIERCE[1]) ** 2
        assert abs(row.reference / paper_fit - 1) < 1e-12
        assert abs(row.error - (r["eta_s"] / paper_fit - 1)) < 1e-12   # (value - reference)/reference
    out = tmp_path / "report" / "r.md"
    out.parent.mkdir()
    report(["--only", "shearedSphere", "--report-only", "--table8", str(tmp_path / "t8.json"), "--out", str(out),
            "--workdir", str(tmp_path / "work")], env)
    text = out.read_text()
    for key in ("figure", "figure_normal_stresses"):
        name = "table8_" + summary[key]
        assert "![%s](r/%s)" % (name, name) in text
        assert (out.parent / "r" / name).stat().st_size > 0


STORED = os.path.join(PROJECT, "docs", "data", "validation_report")


def table_lines(text):
    """The report's table rows (every line of a Markdown table) and its sections' headings, in order."""
    return [line for line in text.splitlines() if line.startswith("|") or line.startswith("## ")]


def test_report_only_rebuilds_the_stored_report_row_for_row(tmp_path):
    """The stored report (docs/data/validation_report.md, .json) rebuilt with --report-only from results files
    that hold its rows (the one shape, fdmsubgrid.results) and the records of its runs: every case's rows, the
    squeeze calibration's rows (recomputed from the shipped measurements) and Table 8's (recomputed from the
    stored summary) are the stored ones, and so is every table line of the Markdown, row for row. A change to
    the reader, the rows' text or the report's tables shows here. No case runs (the calibration rows' theory
    calls fdmResistance: about a minute at load 11 on 2 cores)."""
    from fdmsubgrid import results, validation
    with open(STORED + ".json") as f:
        stored = json.load(f)
    work = tmp_path / "work"
    for case in stored["cases"]:
        folder = work / case["key"]
        folder.mkdir(parents=True)
        date, commit = case["provenance"].split("run on ", 1)[1].split(", read from")[0].split(" at commit ")
        document = dict(shape=results.SHAPE, case=case["key"], command=case["command"], commit=commit, date=date,
                        wall_seconds=case["wall_seconds"], scene={}, rows=case["rows"], data={})
        (folder / "results.json").write_text(json.dumps(document))
        (folder / validation.RUN_RECORD).write_text(json.dumps(dict(command=case["command"], commit=commit, date=date,
                                                                    wall_seconds=case["wall_seconds"], exit_code=0)))
    out = tmp_path / "report.md"
    env = dict(os.environ, PYTHONPATH=os.path.join(PROJECT, "scripts"))
    done = report(["--report-only", "--workdir", str(work), "--table8", os.path.join(PROJECT, stored["table8"]),
                   "--out", str(out)], env)
    assert done.returncode == 0, done.stdout + done.stderr
    with open(tmp_path / "report.json") as f:
        rebuilt = json.load(f)
    assert [c["key"] for c in rebuilt["cases"]] == [c["key"] for c in stored["cases"]]
    for got, want in zip(rebuilt["cases"], stored["cases"]):
        assert got["status"] == want["status"] == "read" and got["command"] == want["command"], got["key"]
        assert got["rows"] == want["rows"], got["key"]
    assert rebuilt["squeeze_calibration_rows"] == stored["squeeze_calibration_rows"]
    assert rebuilt["table8_rows"] == stored["table8_rows"]
    got_lines, want_lines = table_lines(out.read_text()), table_lines(open(STORED + ".md").read())
    assert len(got_lines) == len(want_lines) > 300
    for got, want in zip(got_lines, want_lines):
        assert got == want
