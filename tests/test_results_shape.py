"""The one shape of a case's results file (fdmsubgrid.results, docs/running.md "Results files"): the
writer stamps the document, the reader gives it back, every case script writes through it and turns
its own numbers into rows, and the validation report builds its tables from those rows with one
reader. No solver runs here: each case's rows come from a small record of its own shape."""
import ast
import glob
import json
import os

import pytest

from conftest import PROJECT, load_case_module
from fdmsubgrid import results, validation
from fdmsubgrid.results import Row

# Every script that writes a case's results file, and the ones whose rows the validation report shows
WRITERS = sorted(os.path.relpath(p, PROJECT) for p in glob.glob(os.path.join(PROJECT, "cases", "*", "*.py"))
                 if os.path.basename(os.path.dirname(p)) == os.path.splitext(os.path.basename(p))[0])
REPORTED = sorted({case.name for case in validation.CASES.values()})


def test_write_then_read_gives_the_document_back(tmp_path):
    script = os.path.join(PROJECT, "cases", "periodicArray", "periodicArray.py")
    out = tmp_path / "deeper" / "results.json"
    rows = [Row("K (Eq. 40)", "L/a 8", 1.5335, 1.5321, error=results.relative(1.5335, 1.5321), spread=0.002),
            Row("minimum gap / a1", "no contact", 0.31)]
    data = dict(case="periodicArray", runs=[dict(K=1.5335)], profile=[0.0, 0.5, 1.0])
    returned = results.write_results(str(out), script, ["--L-over-a", "8", "--workdir", str(tmp_path / "runs")],
                                     dict(L_over_a=[8.0], workdir=str(tmp_path / "runs"), out=str(out),
                                          keep=False, table=os.path.join(PROJECT, "cases", "t.csv")),
                                     rows, data, started=0.0)
    assert returned is data and data["wall_seconds"] > 0 and len(data["date"]) == 10
    document = json.loads(out.read_text())
    assert list(document) == list(results.DOCUMENT_KEYS)
    assert document["shape"] == results.SHAPE and document["case"] == "periodicArray"
    # the command and the scene name no absolute folder of the machine, only paths relative to the project
    # (tests/test_docs.py)
    assert document["command"].startswith(os.path.join("cases", "periodicArray", "periodicArray.py") + " --L-over-a 8")
    assert not any(token.startswith(os.sep) for token in document["command"].split())
    assert os.path.relpath(tmp_path / "runs", PROJECT) in document["command"]
    assert document["scene"] == dict(L_over_a=[8.0], table=os.path.join("cases", "t.csv"))
    assert document["commit"] and "wall_seconds" not in document["data"]
    read = results.read_results(str(out))
    assert not read.legacy and read.rows == rows and read.data["profile"] == [0.0, 0.5, 1.0]
    assert read.rows[0].error_text() == "+0.09 %" and read.rows[1].error_text() == "—"
    # read_data: the record as the case's main() returned it
    assert results.read_data(str(out)) == json.loads(json.dumps(data))


def test_numpy_values_are_written_as_numbers(tmp_path):
    np = pytest.importorskip("numpy")
    out = tmp_path / "results.json"
    results.write_results(str(out), os.path.join(PROJECT, "cases", "couette", "couette.py"), [], {},
                          [Row("η_s", "φ 0.4", float(np.float64(2.5)))], dict(profile=np.arange(3.0)), 0.0)
    assert results.read_results(str(out)).data["profile"] == [0.0, 1.0, 2.0]


def test_older_files_and_other_shapes(tmp_path):
    old = tmp_path / "old.json"
    old.write_text(json.dumps(dict(case="shearedSphere", averages=[], wall_seconds=3.0)))
    read = results.read_results(str(old))
    assert read.legacy and read.rows == [] and read.data["averages"] == []
    assert results.read_data(str(old)) == dict(case="shearedSphere", averages=[], wall_seconds=3.0)
    other = tmp_path / "other.json"
    other.write_text(json.dumps(dict(shape="fdmsubgrid.results/99", rows=[])))
    with pytest.raises(ValueError, match="results/99"):
        results.read_results(str(other))
    bad_row = tmp_path / "bad_row.json"
    document = dict(shape=results.SHAPE, case="x", command="", commit="", date="", wall_seconds=1.0, scene={},
                    rows=[dict(quantity="q", configuration="c", value=1.0, tolerance=0.1)], data={})
    bad_row.write_text(json.dumps(document))
    with pytest.raises(KeyError, match="tolerance"):
        results.read_results(str(bad_row))


@pytest.mark.parametrize("script", WRITERS)
def test_every_case_writes_through_the_one_writer(script):
    """Each case's script calls fdmsubgrid.results.write_results and dumps no JSON of its own."""
    tree = ast.parse(open(os.path.join(PROJECT, script)).read())
    called = {node.func.attr if isinstance(node.func, ast.Attribute) else getattr(node.func, "id", None)
              for node in ast.walk(tree) if isinstance(node, ast.Call)}
    assert "write_results" in called, script
    assert "dump" not in called and "write_json" not in called, script


# A small record of each reported case's own shape (the keys its main() writes), and the rows it must give:
# (quantity, value, reference) of the first row, and the number of rows
RECORDS = {
    "periodicArray": (dict(runs=[dict(L_over_a=8.0, a_over_delta=5.0, c=0.3, n_positions=64, K=1.533, K_hasimoto=1.532,
                                      sigma_K=0.002)]),
                      ("K (Eq. 40)", 1.533, 1.532), 1),
    "shearedSphere": (dict(averages=[dict(size=[12, 20, 12], a_over_delta=3.0, positions=1, S_star=0.986, S_star_std=0.0,
                                          omega_z_over_minus_half_gamma=0.997, wall_balance_rel_error_max=1e-5)]),
                      ("S* (unbounded: 1)", 0.986, 1.0), 3),
    "pairSqueeze": (dict(a_over_delta=4.0, L_over_a=8.0, box_extrapolated_with=12.0,
                         cases=[{"lambda": 1.0, "xi": [1.0, 0.1], "theory": [0.5, 0.1],
                                 "subgrid": dict(velocity=[0.49, 0.101]), "nosubgrid": dict(velocity=[0.49, 0.3])}]),
                    ("closing velocity, with the sub-grid correction", 0.49, 0.5), 4),
    "wallSqueeze": (dict(a_over_delta=4.0, L_over_a=8.0, eps=[1.0, 0.1], theory=[0.4, 0.09],
                         subgrid=dict(velocity=[0.41, 0.09])),
                    ("closing velocity, with the sub-grid correction", 0.41, 0.4), 2),
    "pairShear": (dict(summaries=[dict(r_y_start=0.5, min_gap_over_a1=0.3, fore_aft_asymmetry=0.01, r_y_end=0.505),
                                  dict(r_y_start=0.93, min_gap_over_a1=0.001, contact_r_x_from=-1.3,
                                       contact_r_x_to=None)],
                       trajectories=[dict(ratio=1.0, contact=None), dict(ratio=1.4, contact=[1, 2, 3, 0.005])]),
                  ("minimum gap / a1", 0.3, None), 5),
    "wallShear": (dict(model="calibrated", rows=[dict(
        radius=1.0, eps=0.1, subgrid=True, box=[12, 12, 12], a_over_delta=3.0, n_positions=2,
        **{q + suffix: v for q in ("Ux_norm", "Wz_norm", "S_star")
           for suffix, v in (("", 0.8), ("_ref", 0.79), ("_rel_error", 0.8 / 0.79 - 1), ("_std", 0.01))})]),
        ("U_x/(γ̇d)", 0.8, 0.79), 3),
    "channelShear": (dict(rows=[dict(radius=1.0, H_over_a=20.0, subgrid=True, box=[12, 20, 12], a_over_delta_sphere=3.0,
                                     n_positions=16, Wz_norm=0.99, Wz_norm_std=0.01, S_star=1.02, S_star_std=0.0)]),
                     ("Ω_z/(−γ̇/2) (unbounded: 1)", 0.99, 1.0), 2),
    "poiseuilleSphere": (dict(rows=[dict(radius=1.0, two_a_over_H=0.4, d_over_a=3.0, centre_plane=False, a_over_delta=3.0,
                                         box=[12, 12], n_positions=2, faxen_wall_applies=True,
                                         faxen_wall=dict(Ux_norm=0.8, Wz_norm=0.1, S_star=0.5), staben_Ux_norm=None,
                                         Ux_norm=0.81, Ux_norm_std=0.0, Wz_norm=0.1, Wz_norm_std=0.0, S_star=0.52,
                                         S_star_std=0.01)]),
                         ("U_x/U_c (Faxén + walls)", 0.81, 0.8), 3),
    "pairPoiseuille": (dict(d2_over_a=1.33, a_over_delta=3.0, box=[16, 8], n_positions=4,
                            scenes=[dict(subgrid=True, single=dict(Ux2=0.6)), dict(subgrid=False, single=dict(Ux2=0.6))],
                            summary=dict(subgrid=dict(Uy1_sign_change_rho_over_H=[0.6], nearest=dict(xi=1e-5, Un_ratio=0.01),
                                                      farthest=dict(rho_over_H=1.5, Ux2_minus_single=0.001)),
                                         no_subgrid=dict(Uy1_sign_change_rho_over_H=[], nearest=dict(xi=1e-5, Un_ratio=0.5),
                                                         farthest=dict(rho_over_H=1.5, Ux2_minus_single=0.001)))),
                       ("ρ12/H where U_y1 changes sign", 0.6, None), 4),
    "threeSpheres": (dict(far_field=[dict(r=6.0, reference=dict(U1x=1.0, U23x=0.3, dU=0.7, U23y=0.05, W23z=0.01))],
                          rows=[dict(r=6.0, box=[16, 16, 12], a_over_delta=3.0, n_positions=8, U1x=0.95, U23x=0.29,
                                     dU=0.66, U23y=0.05, W23z=0.01, U1x_std=0.001, unbounded_estimate=dict(U1x=0.99))]),
                     ("U1x (box removed)", 0.99, 1.0), 5),
}


def test_every_reported_case_has_a_record_here():
    assert sorted(RECORDS) == REPORTED


@pytest.mark.parametrize("name", sorted(RECORDS))
def test_each_case_turns_its_record_into_rows(name, tmp_path):
    """The case's validation_rows on a small record of its shape: rows of the documented shape, the error
    (value - reference)/|reference| wherever a relative error is given, and through write_results the
    validation report reads them back unchanged with its one reader."""
    module = load_case_module(name)
    record, (quantity, value, reference), count = RECORDS[name]
    rows = module.validation_rows(record)
    assert len(rows) == count and all(isinstance(r, Row) for r in rows)
    assert (rows[0].quantity, rows[0].value, rows[0].reference) == (quantity, value, reference)
    for row in rows:
        assert isinstance(row.quantity, str) and isinstance(row.configuration, str)
        if row.error is not None and row.error_unit == "%" and row.reference:
            assert row.error == pytest.approx((row.value - row.reference) / abs(row.reference))
    folder = tmp_path / "work" / name
    results.write_results(str(folder / "results.json"), module.__file__, ["--quick"], {}, rows, record, 0.0)
    read = validation.read_case(name, validation.CASES[name], str(folder))
    assert read.status == "read" and read.rows == rows
    # without a run record the command and the commit come from the results file
    assert read.command == os.path.join("cases", name, name + ".py") + " --quick" and "at commit" in read.provenance


def test_pair_shear_without_touching_reports_no_window():
    """A contact run in which the spheres never come within h_r: the window's rows have no value (the
    report shows a dash), rather than the case failing to write its results."""
    module = load_case_module("pairShear")
    record = dict(summaries=[dict(r_y_start=0.93, min_gap_over_a1=0.1, contact_r_x_from=None, contact_r_x_to=None)],
                  trajectories=[dict(ratio=1.4, contact=[1, 2, 3, 0.005])])
    window = [r for r in module.validation_rows(record) if r.quantity.startswith("contact window")]
    assert len(window) == 2 and all(r.value is None and r.error is None for r in window)


def test_report_builds_its_tables_from_the_rows_and_names_older_files(tmp_path):
    """validation.run_report --report-only over a current results file and an older one: the rows of the
    first in the report as written, the second reported as failed, naming the shape it lacks."""
    work = tmp_path / "work"
    module = load_case_module("periodicArray")
    record = RECORDS["periodicArray"][0]
    rows = module.validation_rows(record)
    results.write_results(str(work / "periodicArray" / "results.json"), module.__file__, [], {}, rows, record, 0.0)
    (work / "shearedSphere").mkdir(parents=True)
    (work / "shearedSphere" / "results.json").write_text(json.dumps(RECORDS["shearedSphere"][0]))
    summary = validation.run_report(["periodicArray", "shearedSphere"], report_only=True, out=str(tmp_path / "r.md"),
                                    workdir=str(work))
    cases = {c["key"]: c for c in summary["cases"]}
    assert cases["periodicArray"]["status"] == "read"
    assert [Row(**r) for r in cases["periodicArray"]["rows"]] == rows
    assert cases["shearedSphere"]["status"] == "failed" and results.SHAPE in cases["shearedSphere"]["message"]
    text = (tmp_path / "r.md").read_text()
    assert "| K (Eq. 40) | L/a 8, a/Δ 5, c 0.3, 64 positions | 1.532059 (+0.11 %) | 1.533 ± 0.002 | 1.532 | +0.07 % |" \
        in text


def test_the_suspension_cases_rows_from_shipped_runs():
    """cases/couette and cases/poiseuille turn a run's record into rows: read from the shipped results of
    older runs (an older file reads as its data), couette's rows beside the paper's fit of Fig. 21 at the
    run's own φ_core, poiseuille's the channel's measures."""
    couette = load_case_module("couette")
    record = results.read_data(os.path.join(PROJECT, "docs", "data", "validation_table8_phi0.27.json"))["mser_window"]
    rows = {row.quantity: row for row in couette.validation_rows(record)}
    assert rows["η_s"].value == record["eta_s"] and rows["η_s"].error == pytest.approx(
        record["eta_s"] / rows["η_s"].reference - 1)
    assert rows["stress balance (core against walls)"].percent
    poiseuille = load_case_module("poiseuille")
    record = results.read_data(os.path.join(PROJECT, "docs", "data", "validation_poiseuille_L12.json"))
    rows = {row.quantity: row for row in poiseuille.validation_rows(record)}
    # an older record: the rows of the measures it holds
    assert len(rows) == sum(m[0] in record for m in poiseuille.MEASURES) >= 6
    assert rows["φ at the centre plane"].value == record["phi_center"]
    # the steady-state analysis: every measure with a value, with its error bar; no plateau above 0.6 at L_y 12 a1
    record = results.read_data(os.path.join(PROJECT, "docs", "data", "validation_poiseuille_L12_fluidEvery4.json"))
    rows = {row.quantity: row for row in poiseuille.validation_rows(record)}
    assert len(rows) == len(poiseuille.MEASURES) - 1 and "central plateau's φ" not in rows
    assert rows["migration time (φ_center's exponential approach)"].spread == record["migration_time_err"]
    assert rows["φ at the centre plane"].configuration.endswith("(not steady)")


def test_contact_tuning_rows():
    """cases/contactTuning: the stability limits against their estimates; no rows from a partial run."""
    module = load_case_module("contactTuning")
    assert module.validation_rows(dict(integrator="ab2", normal={})) == []
    figures = dict(stability_limits={"pair, lubrication, ab2": dict(dt_measured=0.03, dt_estimate=0.025),
                                     "wall, lubrication, euler": dict(dt_measured=None, dt_estimate=0.02)},
                   normal_gap_error=1e-4, normal_force_balance=None)
    rows = module.validation_rows(dict(integrator="ab2", figures=figures))
    assert [(r.quantity, r.configuration) for r in rows] == [("stability limit Δt", "pair, lubrication, ab2"),
                                                             ("normal load: gap error / (F/k_n) (largest)",
                                                              "integrator ab2")]
    assert rows[0].error == pytest.approx(0.2)


def test_a_record_without_rows_still_writes_its_file(tmp_path, capsys):
    """A case's rows function that cannot read its record (a partial run) costs the rows, not the file."""
    out = tmp_path / "results.json"

    def rows_of(record):
        return [Row("K", "c", record["K"])]

    data = results.write_results(str(out), os.path.join(PROJECT, "cases", "periodicArray", "periodicArray.py"), [],
                                 {}, rows_of, dict(runs=[]), 0.0)
    read = results.read_results(str(out))
    assert read.rows == [] and read.data == dict(runs=[]) and data["wall_seconds"] > 0
    assert "periodicArray.py: no rows from this record (KeyError: 'K')" in capsys.readouterr().err
    results.write_results(str(out), os.path.join(PROJECT, "cases", "periodicArray", "periodicArray.py"), [], {},
                          rows_of, dict(K=1.5), 0.0)
    assert results.read_results(str(out)).rows == [Row("K", "c", 1.5)]
