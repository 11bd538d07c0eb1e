"""The calibration table a scene runs with (fdmsubgrid.deminput.scene_calibration, issue 50 item 2): the
shipped table where it covers the scene; where every pair and wall it lacks is interpolated within 2 % as
measured on held-back blocks, the shipped table with those blocks written into the run's dem/, the pair
style pointed at it, one line saying so, and the table's SHA-256 in fdmRun's record and results.json;
otherwise a refusal, one line per refused pair or wall with the command that measures it
(docs/resistance.md, "Sizes and resolutions outside the table"). Scenes are written, not run (the coupled
run of such a scene is in docs/cases/couette.md)."""
import hashlib
import json
import math
import os
import subprocess
import time

import numpy as np
import pytest

from conftest import PROJECT, assert_refused, load_case_module
from fdmsubgrid import calibration, case, checkpoint, couettescene, deminput, packing, results, subgridinterp

SHIPPED = os.path.join(PROJECT, "dem", "resistance", "data", "subgrid_calibration.dat")
# one sphere of radius 1 in a Couette cell at a1/Delta 6: no pair, and its wall (a/Delta 6) a little above the
# table's walls (3-5.6), interpolated: the one kind of scene the table lacks only a wall for (every wall the
# table's pairs bring, a/Delta 4.2 and 5.6 of the 1.4 sphere at a1/Delta 3 and 4, lies between its walls)
LONE_SPHERE = packing.SizeDistribution.of([1.0], [1.0])


def covered(env, root, *args) -> dict:
    """fdmResistance coverage with the table root/dem/resistance/data/subgrid_calibration.dat (FDM_ROOT)."""
    done = subprocess.run(["fdmResistance", "coverage"] + [str(a) for a in args], env=dict(env, FDM_ROOT=str(root)),
                          check=True, capture_output=True, text=True)
    return json.loads(done.stdout)


def test_a_scene_needing_only_an_interpolated_wall_runs_with_its_own_table(env, tmp_path, capsys):
    """A lone sphere in 6^3 a1 at a1/Delta 6 is written, not refused: dem/subgrid_calibration.dat is the shipped
    table with the one wall block it lacks (a/Delta 6, measured error 0.6 %), the pair style reads it, the
    resistance library covers the scene with it (and not with the shipped one), one line says so, and fdmRun's
    record and results.json name that file and its SHA-256."""
    written = couettescene.write_run(str(tmp_path), (6, 6, 6), dt=0.02, strain=0.04, n_particles=1,
                                     a_over_delta=6.0, sizes=LONE_SPHERE)
    pack, run_dir = written["pack"], written["run_dir"]
    assert list(pack.radii) == [1.0]     # the scene meant
    out = capsys.readouterr().out
    line = [l for l in out.splitlines() if "interpolated" in l]
    assert line == ["couette: the run reads dem/subgrid_calibration.dat, the shipped table with the squeeze "
                    "interpolated for radius 1 at a wall (a/Delta 6, error 0.6 %) (measured on held-back blocks, "
                    "within 2 %; the tangential functions there from the cut-off model: docs/resistance.md)"]
    table = os.path.join(run_dir, "dem", "subgrid_calibration.dat")
    dem_input = os.path.join(run_dir, "dem", "in.couette")
    pair_style = [l for l in open(dem_input) if l.startswith("pair_style")]
    assert len(pair_style) == 1 and " model calibrated calibration subgrid_calibration.dat contact " in pair_style[0]
    # the shipped table unchanged, one block added
    shipped_text = open(SHIPPED).read()
    assert open(table).read().startswith(shipped_text)
    added = set(calibration.read_table(table)) - set(calibration.read_table(SHIPPED))
    assert added == {("wall", 6.0, 1.0)}
    [entry] = written["scene"]["calibration_interpolated"]
    assert entry["kind"] == "wall" and entry["radii"] == [1.0] and entry["a_over_delta"] == 6.0
    assert 0 < entry["error"] <= subgridinterp.TOLERANCE
    # the resistance library reads it as the pair style does: the wall at Delta 1/6 covered with it only
    root = tmp_path / "root"
    (root / "dem" / "resistance" / "data").mkdir(parents=True)
    (root / "dem" / "resistance" / "data" / "subgrid_calibration.dat").write_text(open(table).read())
    assert covered(env, root, "--a1", 1.0, "--delta", 1 / 6, "--wall")["wall"]
    assert not covered(env, PROJECT, "--a1", 1.0, "--delta", 1 / 6, "--wall")["wall"]
    # the record fdmRun makes at the start, and results.json
    checkpoint.stamp(run_dir, dem_input)
    digest = hashlib.sha256(open(table, "rb").read()).hexdigest()
    assert json.load(open(os.path.join(run_dir, checkpoint.CALIBRATION_STAMP))) == dict(table=table, sha256=digest)
    out = os.path.join(run_dir, "results.json")
    script = os.path.join(PROJECT, "cases", "couette", "couette.py")
    results.write_results(out, script, [], {}, [], dict(run_dir=run_dir), time.time())
    assert json.load(open(out))["calibration"] == [dict(table=os.path.relpath(table, PROJECT), sha256=digest)]
    assert digest != hashlib.sha256(open(SHIPPED, "rb").read()).hexdigest()


def test_a_pair_beyond_the_interpolation_is_refused_one_line(tmp_path, capsys):
    """Spheres of radii 1 and 2 at a1/Delta 3 (pairs 1-2 at a2/a1 2 and 2-2 at a1/Delta 6, interpolated to
    3.0 % > 2 % at worst): refused before anything is written, one line per pair with the command that
    measures it into the folder later scenes read, the interpolable wall named as such."""
    with pytest.raises(deminput.UncalibratedScene) as refused:
        deminput.scene_calibration("couette", [1.0] * 5 + [2.0] * 2, 1 / 3, walls=True)
    lines = str(refused.value).splitlines()
    assert lines[0] == ("couette: the sub-grid calibration (model calibrated) lacks 2 of this scene's pairs and walls "
                        "beyond what the interpolation reaches within 2 %:")
    assert lines[1].startswith("  the pair of radii 1 and 2 at a1/Delta 3 (a2/a1 2): not calibrated, "
                               "interpolation error 3.0 % > 2 %; measure it (about ")
    assert lines[1].endswith("core-seconds): python3 -m fdmsubgrid.calibration --a-over-delta 3 --ratios 2 "
                             "--no-wall --boxes 12 16 --cache")
    assert lines[2].startswith("  the pair of radii 2 and 2 at a1/Delta 6 (a2/a1 1): not calibrated, "
                               "interpolation error 3.0 % > 2 %; measure it (about ")
    assert lines[2].endswith("core-seconds): python3 -m fdmsubgrid.calibration --a-over-delta 6 --ratios 1 "
                             "--no-wall --boxes 8 12 --cache")
    assert lines[3] == "  interpolated within 2 %: radius 2 at a wall (a/Delta 6, error 0.6 %)"
    assert lines[4].startswith("  dem/resistance/data/subgrid_calibration.dat has pairs")
    assert lines[5].startswith("  or --model cutoff")
    assert len(lines) == 6
    # the case script: refused with that message, no run folder
    couette = load_case_module("couette")
    with pytest.raises(SystemExit) as stopped:
        couette.main(["--radii", "1", "2", "--volume-fractions", "0.8", "0.2", "--phi", "0.2", "--size", "12", "12",
                      "12", "--write-only", "--workdir", str(tmp_path)])
    assert "the pair of radii 2 and 2 at a1/Delta 6 (a2/a1 1): not calibrated" in str(stopped.value)
    assert os.listdir(tmp_path) == []


def test_the_decision_for_walls_alone_and_for_the_shipped_table(tmp_path, capsys):
    """A free sphere against the walls (pairs=False): at a/Delta 4 the shipped table (nothing written, no
    keyword), at 6 the interpolated wall (0.6 %), at 7 (farther above 3-5.6 than any held-back wall) refused
    with the command; the cut-off model needs no table. wallShear refuses a/Delta 7 as argparse does."""
    shipped = case.scene_calibration("wallShear", [1.0], 1 / 4, walls=True, pairs=False)
    assert shipped.table() is None and shipped.line() is None and shipped.write(str(tmp_path / "a")) is None
    assert not (tmp_path / "a").exists()
    assert case.subgrid_pair_style(calibration=shipped.table()) == "fdm/subgrid"
    finer = case.scene_calibration("wallShear", [1.0], 1 / 6, walls=True, pairs=False)
    assert [(e.kind, e.a_over_delta, e.status) for e in finer.interpolated] == [("wall", 6.0, "interpolated")]
    assert finer.interpolated[0].error == pytest.approx(0.006, abs=5e-4)
    path = finer.write(str(tmp_path / "b" / "dem"))
    assert set(calibration.read_table(path)) - set(calibration.read_table(SHIPPED)) == {("wall", 6.0, 1.0)}
    assert case.subgrid_pair_style((("ylo", (0, 0, 0)),), calibration=finer.table()) == \
        "fdm/subgrid calibration subgrid_calibration.dat wall ylo 0.0 0.0 0.0"
    # without the correction the table does not enter the line
    assert case.subgrid_pair_style(subgrid=False, calibration=finer.table()) == "fdm/subgrid lubrication no"
    with pytest.raises(case.UncalibratedScene, match=r"radius 1 against a wall at a/Delta 7: not calibrated, no "
                       r"held-back test .* --a-over-delta 7 --no-pairs --cache"):
        case.scene_calibration("wallShear", [1.0], 1 / 7, walls=True, pairs=False)
    assert case.scene_calibration("wallShear", [1.0], 1 / 7, walls=True, pairs=False, model="cutoff").table() is None
    wall_shear = load_case_module("wallShear")
    assert_refused(wall_shear.main, ["--a-over-delta", "7", "--subgrid-only"],
                   ["wallShear: the sub-grid calibration (model calibrated) lacks 1 of this scene's pairs and walls",
                    "radius 1 against a wall at a/Delta 7"], tmp_path, capsys)


def write_measured(folder, summary: dict) -> str:
    """A table as `calibration --cache` leaves it (FOLDER/<name>/subgrid_calibration.dat), for the held-back
    direct calibration `summary`: its own header (fit) with the rows the interpolation gives there (the rows of
    the real command need some 90 s of theory calls; the plumbing is the same)."""
    block = subgridinterp.CollapsedBlock.from_summary(summary)
    rows = subgridinterp.interpolated_rows(subgridinterp.load_blocks(), block.kind, block.a_over_delta, block.ratio)
    name = subgridinterp.measured_name([(block.kind, block.a_over_delta, block.ratio)])
    os.makedirs(os.path.join(folder, name))
    path = os.path.join(folder, name, subgridinterp.MEASURED_TABLE)
    with open(path, "w") as f:
        f.write("# measured on demand\n")
        calibration.write_block(f, block.calibration(), summary["fit"], rows)
    return path


def test_a_pair_measured_on_demand_is_found_by_later_scenes(env, tmp_path, monkeypatch, capsys):
    """Issue 50 item 2, measured on demand: one sphere of radius 2 among spheres of radius 1 at a1/Delta 3
    between walls is refused for its pair 1-2 (a2/a1 2: 3.0 % > 2 %) with the one command that measures it
    into the folder later scenes read (`--cache`); with that table there (FDM_CALIBRATIONS), the same scene
    is written with the shipped table plus the measured block and the interpolated wall of radius 2
    (a/Delta 6), one line naming both, the resistance library covering the pair with it; the same block
    measured twice with other values is refused naming both files; --cache does not measure over a kept one."""
    folder = tmp_path / "calibrations"
    monkeypatch.setenv(subgridinterp.MEASURED_ENV, str(folder))
    radii = [1.0] * 6 + [2.0]
    with pytest.raises(deminput.UncalibratedScene) as refused:
        deminput.scene_calibration("couette", radii, 1 / 3, walls=True)
    [line] = [l for l in str(refused.value).splitlines() if "radii 1 and 2" in l]
    assert "interpolation error 3.0 % > 2 %" in line
    assert line.endswith("python3 -m fdmsubgrid.calibration --a-over-delta 3 --ratios 2 --no-wall --boxes 12 16 "
                         "--cache")
    with open(os.path.join(PROJECT, subgridinterp.HELD_BACK_JSON[0])) as f:
        [summary] = json.load(f)["calibrations"]
    assert (summary["kind"], summary["a_over_delta"], summary["ratio"]) == ("pair", 3.0, 2.0)
    path = write_measured(str(folder), summary)
    assert os.path.dirname(path) == str(folder / "pair_ad3_ratio2")
    # found: the scene runs with the shipped table, the measured block and the interpolated wall
    scene = deminput.scene_calibration("couette", radii, 1 / 3, walls=True)
    assert [(e.kind, e.a_over_delta, e.ratio, e.status) for e in scene.measured] == [("pair", 3.0, 2.0, "measured")]
    assert [(e.kind, e.a_over_delta, e.status) for e in scene.interpolated] == [("wall", 6.0, "interpolated")]
    assert scene.tables == [os.path.realpath(path)]
    assert scene.line() == ("couette: the run reads dem/subgrid_calibration.dat, the shipped table with the "
                            "calibration measured on demand for radii 1 and 2 (a1/Delta 3, a2/a1 2) (%s) and the "
                            "squeeze interpolated for radius 2 at a wall (a/Delta 6, error 0.6 %%) (measured on held-back "
                            "blocks, within 2 %%; the tangential functions there from the cut-off model: "
                            "docs/resistance.md)" % os.path.realpath(path))
    table = scene.write(str(tmp_path / "run" / "dem"))
    assert open(table).read().startswith(open(SHIPPED).read())
    blocks = calibration.read_table(table)
    assert set(blocks) - set(calibration.read_table(SHIPPED)) == {("pair", 3.0, 2.0), ("wall", 6.0, 1.0)}
    assert np.array_equal(blocks[("pair", 3.0, 2.0)][1], calibration.read_table(path)[("pair", 3.0, 2.0)][1])
    assert blocks[("pair", 3.0, 2.0)][0] != []          # a measured block's header keeps its fit
    root = tmp_path / "root"
    (root / "dem" / "resistance" / "data").mkdir(parents=True)
    (root / "dem" / "resistance" / "data" / "subgrid_calibration.dat").write_text(open(table).read())
    assert covered(env, root, "--a1", 1, "--a2", 2, "--delta", 1 / 3)["pair"]
    assert not covered(env, PROJECT, "--a1", 1, "--a2", 2, "--delta", 1 / 3)["pair"]
    # the couette writer takes it (nothing run)
    couette = load_case_module("couette")
    couette.main(["--radii", "1", "2", "--volume-fractions", "0.9", "0.1", "--phi", "0.1", "--size", "12", "12",
                  "12", "--write-only", "--workdir", str(tmp_path / "couette")])
    assert "the calibration measured on demand for radii 1 and 2" in capsys.readouterr().out
    # a second measurement of the same block with other values: refused, both files named
    other = dict(summary, fit=dict(summary["fit"], r_0=summary["fit"]["r_0"] * 1.01))
    second = os.path.join(str(folder), "again", subgridinterp.MEASURED_TABLE)
    os.makedirs(os.path.dirname(second))
    with open(second, "w") as f:
        calibration.write_block(f, subgridinterp.CollapsedBlock.from_summary(other).calibration(), other["fit"],
                                subgridinterp.interpolated_rows(subgridinterp.load_blocks(), "pair", 3.0, 2.0))
    with pytest.raises(ValueError, match="pair a/Delta 3 ratio 2 is in .* and, with other values, in .*: remove one "
                                         "of them") as twice:
        subgridinterp.measured_blocks()
    assert path in str(twice.value) and second in str(twice.value)
    # --cache refuses to measure over the kept table
    with pytest.raises(SystemExit):
        calibration.main(["--a-over-delta", "3", "--ratios", "2", "--no-wall", "--cache"])
    assert "holds this measurement already" in capsys.readouterr().err
