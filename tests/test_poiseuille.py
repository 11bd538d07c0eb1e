"""cases/poiseuille (paper 6.2) on a small channel: a bidisperse frictional suspension at phi_bulk 0.45
driven by a pressure gradient between walls at rest, run by the real fdmFoam and fdmDEM for a few
steps (about 30 s); the exact checks of the analysis (the phi integral, the walls' force balance, the
linear shear stress in the core) and the case's bad input. The SBM's own tests: test_sbm.py."""
import json
import os
import subprocess
import sys

import numpy as np
import pytest

from conftest import load_case_module
from fdmsubgrid import checkpoint, contacts, output, packing, poiseuille, sbm, shear

SMALL = ["--size", "8", "12", "8", "--duration", "2", "--dump-every", "0.1", "--seed", "2", "--fluid-every", "1"]


@pytest.fixture(scope="module")
def case_module():
    return load_case_module("poiseuille")


@pytest.fixture(scope="module")
def small_run(case_module, tmp_path_factory, env):
    work = tmp_path_factory.mktemp("poiseuille")
    return case_module.main(SMALL + ["--workdir", str(work), "--out", str(work / "results.json")])


def test_small_channel_runs_converged_with_the_results_keys(small_run):
    r = small_run
    assert r["unconverged_steps"] == 0 and r["steps"] == 40
    for key in ("phi_bulk", "L", "time", "steady_from", "phi_center", "phi_wall_layer", "jammed_width_over_a1",
                "u_center_star", "shear_stress_linearity_rel_error", "sbm_phi_rms_diff", "sbm_u_rms_diff",
                "cells", "n_particles", "wall_seconds", "core_seconds"):
        assert key in r, key
    assert r["L"] == [8.0, 12.0, 8.0] and r["time"] == pytest.approx(2.0)
    assert abs(r["phi_bulk"] - 0.45) < 0.01 and r["n_particles"] > 40
    # the scales of Eq. 58 with U_c = L_y/4: tau_w = 1, the time unit L_y/(2U_c) = 2 s
    assert r["tau_w"] == pytest.approx(1.0) and r["time_unit"] == pytest.approx(2.0)
    assert os.path.isfile(os.path.join(os.path.dirname(r["run_dir"]), r["figure"]))


def test_phi_integral_is_exact(small_run):
    """Eq. 49 integrated over the channel is phi_bulk at every snapshot (the spheres stay between the walls)."""
    assert small_run["phi_bulk_integral_max_error"] < 1e-10


def test_each_species_is_reported(small_run):
    """The paper's two species (atom types 1 and 2, radii 1 and 1.4): their counts, bulk fractions and central
    fractions add up to the suspension's (the same band and snapshots), and each phi(y) has one value per bin."""
    r = small_run
    species = r["species"]
    assert [(s["type"], s["radius"]) for s in species] == [(1, 1.0), (2, 1.4)]
    assert sum(s["n"] for s in species) == r["n_particles"]
    assert sum(s["phi_bulk"] for s in species) == pytest.approx(r["phi_bulk"], rel=1e-12)
    assert sum(s["phi_center"] for s in species) == pytest.approx(r["phi_center"], rel=1e-12)
    assert all(len(s["phi_profile"]) == len(r["species_profile_y"]) for s in species)


def test_migration_series_of_a_segment_is_the_analysis_series(small_run, tmp_path):
    """The series kept beside a compact snapshot (cases/poiseuille/paperRun --save) is the run's own: the
    same times and phi at the centre as the analysis, phi(y) in bins of a1 integrating to phi_bulk."""
    from fdmsubgrid import poiseuille
    path = poiseuille.write_segment(small_run["run_dir"], str(tmp_path))
    with open(path) as f:
        series = json.load(f)
    assert os.path.basename(path) == "segment_%g_%g.json" % (series["time"][0], series["time"][-1])
    assert series["time"] == pytest.approx(small_run["series"]["time"], abs=1e-6)
    assert series["phi_center"] == pytest.approx(small_run["series"]["phi_center"], abs=1e-5)
    assert np.allclose(np.diff(series["y"]), 1.0)
    for profile in series["phi_profile"]:
        assert np.mean(profile) == pytest.approx(small_run["phi_bulk"], abs=2e-4)
    # written again after the run went on: the segment of the same start is replaced, not added to
    poiseuille.write_segment(small_run["run_dir"], str(tmp_path))
    assert len(os.listdir(tmp_path)) == 1


def test_momentum_balance(small_run):
    """The walls carry the pressure gradient's whole force, tau_lo - tau_hi = |dP0/dx| L_y, to the
    solver's tolerance; and the shear stress of Eqs. 51-53 on the cell faces (fluid eta d<u>/dy from
    fdmFoam's plane averages plus the particles' stresslets) follows the exact line in the core within
    a loose bound (a short, unsteady run: the paper's 5 % is for time averages in the steady state)."""
    r = small_run
    assert r["wall_force_balance_rel_error"] < 0.01
    assert r["shear_stress_linearity_rel_error"] < 0.2
    # the flow goes down the gradient, slower than the Newtonian parabola's centre (0.5)
    assert 0 < r["u_center_star"] < 0.5


def test_channel_profile_record_is_the_mean_velocity(small_run):
    """fdmFoam's channelProfile.dat: one line per step, the plane averages of U; at rest walls and a
    flow along x only: u_y averages to zero on every plane (continuity, to the pressure solver's
    tolerance 1e-3 and the forcing inside the particles: 1.5e-3 of u_x measured), u_x > 0."""
    prof = output.channel_profile(os.path.join(small_run["run_dir"], "fluid"))
    assert len(prof["step"]) == 40 and prof["u"].shape[1] == 36
    assert np.max(np.abs(prof["u"][:, :, 1])) < 1e-2 * np.max(np.abs(prof["u"][:, :, 0]))
    assert np.all(prof["u"][:, :, 0] > 0)


def test_analysis_refuses_a_couette_run(tmp_path):
    """A run folder whose walls move and whose fluid has no pressure gradient is not a pressure-driven
    channel: the analysis says so and names the file."""
    couette = load_case_module("couette")
    out = couette.main(["--table8", "0.27", "--workdir", str(tmp_path), "--dt", "0.04"])
    with pytest.raises(poiseuille.PoiseuilleRunError, match=r"fdmProperties: gradP0 = \(0 0 0\)"):
        poiseuille.scales(shear.read_run(out["run_dir"]))


def test_bad_options_are_refused(case_module, tmp_path):
    with pytest.raises(SystemExit):
        case_module.main(["--size", "8", "12.1", "8", "--workdir", str(tmp_path)])
    with pytest.raises(SystemExit):
        case_module.main(["--phi", "0.7", "--workdir", str(tmp_path)])
    # --until continues a snapshot past the scene's end; a new run ends at its --duration
    with pytest.raises(SystemExit) as refused:
        case_module.main(["--until", "100", "--workdir", str(tmp_path)])
    assert refused.value.code == 2 and not os.listdir(tmp_path)


def test_steady_state_keys_of_a_short_run(small_run):
    """The steady-state analysis on the real records of a 2-time-unit run (20 snapshots): the window found
    from the data says not steady, with its reason; the walls carry the pressure gradient's force within
    1 %; the stresses across the channel in the 12 bins of a1 (contact yy compressive where spheres touch);
    the SBM fitted to this project's Table 8 rows with their phi_m (the Maron-Pierce fit, 0.593)."""
    r = small_run
    assert r["steady_detected"] is False and r["steady_reason"] and r["steady_method"] == "fit"
    assert r["wall_force_balance_within_1pct"] is True
    sp = r["stress_profile"]
    assert all(len(sp[k]) == 12 for k in ("y_star", "sigma_h_xy", "sigma_c_xy", "sigma_c_yy", "total_xy", "exact_line"))
    assert sp["exact_line"][0] == pytest.approx(-sp["exact_line"][-1]) and sp["exact_line"][0] == pytest.approx(11 / 12)
    assert r["plateau_threshold"] == 0.6 and r["plateau_width_over_a1"] >= 0
    assert r["sbm_table8_phi_m"] == pytest.approx(0.5934, abs=2e-4)
    assert r["sbm_table8_material"]["fitted_from"] == ["docs/data/validation_table8_fluidEvery.json"]
    assert 0 <= r["sbm_table8_phi_rms_diff"] < 0.2


def test_steady_check_of_a_run_is_the_analysis_window(small_run, tmp_path, env):
    """python3 -m fdmsubgrid.poiseuille steady, what ladderRun --until-steady asks between its chunks: on the
    real records of the short run it finds the analysis's own window and verdict (not steady, the same reason)
    and says so with exit status 1; its kept segments before the folder's first record are taken in; a run
    folder without records is an error (status 2) that names it."""
    from fdmsubgrid import poiseuille
    w = poiseuille.steady_check(small_run["run_dir"])
    assert w.steady is False and w.reason == small_run["steady_reason"]
    assert w.start_time == pytest.approx(small_run["steady_from"], abs=1e-6)
    assert w.end_time == pytest.approx(small_run["time"], abs=1e-6)
    out = subprocess.run([sys.executable, "-m", "fdmsubgrid.poiseuille", "steady", small_run["run_dir"]], env=env,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert out.returncode == 1 and "not steady: " + w.reason in out.stdout
    # a kept segment of the same records: the folder's own are not counted twice
    poiseuille.write_segment(small_run["run_dir"], str(tmp_path / "segments"))
    again = poiseuille.steady_check(small_run["run_dir"], poiseuille.read_segments(str(tmp_path / "segments")))
    assert again.start_time == w.start_time and again.reason == w.reason
    out = subprocess.run([sys.executable, "-m", "fdmsubgrid.poiseuille", "steady", str(tmp_path / "none")], env=env,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert out.returncode == 2 and str(tmp_path / "none") in out.stderr


def test_fluid_shear_stress_of_the_newtonian_parabola():
    """The Newtonian channel u = 4 U_c y (L - y)/L^2 sampled at 36 cell centres: eta du/dy on the faces
    and averaged over bins of a1 equals the exact (dP0/dx)(y - L/2) (to O(Delta^2) at the walls,
    exact inside: a parabola's centred difference is exact)."""
    L, n, eta, u_c = 12.0, 36, 1.0, 3.0
    d = L / n
    centres = d * (np.arange(n) + 0.5)
    u = 4 * u_c * centres * (L - centres) / L ** 2
    grad = -8 * eta * u_c / L ** 2
    faces, tau = poiseuille.fluid_shear_stress(u, d, eta)
    exact = grad * (faces - L / 2)
    assert np.max(np.abs(tau[1:-1] - exact[1:-1])) < 1e-12
    assert np.max(np.abs(tau[[0, -1]] - exact[[0, -1]])) < 0.06 * abs(exact[0])
    edges = np.linspace(0, L, 13)
    binned = poiseuille.fluid_shear_stress_in_bins(u, d, eta, edges)
    exact_bins = grad * (0.5 * (edges[1:] + edges[:-1]) - L / 2)
    assert np.max(np.abs(binned[1:-1] - exact_bins[1:-1])) < 1e-12
    assert np.max(np.abs(binned - exact_bins)) < 0.05 * abs(grad * L / 2)


def test_two_fluid_ranks_give_the_serial_profile(case_module, small_run, tmp_path_factory, env):
    """The same channel with the fluid on 2 MPI ranks (fdmRun -f 2) for its first 4 steps: the plane
    averages of channelProfile.dat (reduced over the ranks) are the serial
    run's to the inner iteration's tolerances (the decomposed linear solves differ, so the two stop at
    different iterations): the first step to its tolLambda 1e-3 (2.6e-4 measured), the next ones to
    tolLambda 1e-2 (4e-3). A reduction over one
    rank's planes only would be off by tens of per cent."""
    work = tmp_path_factory.mktemp("poiseuille2")
    args = SMALL[:SMALL.index("--duration")] + ["--duration", "0.2"] + SMALL[SMALL.index("--duration") + 2:]
    with pytest.raises(ValueError, match="too few"):    # 4 steps: too short for the analysis, run all the same
        case_module.main(args + ["--np-fluid", "2", "--workdir", str(work), "--out", str(work / "r.json")])
    run2 = os.path.join(str(work), os.path.basename(small_run["run_dir"]))
    serial = output.channel_profile(os.path.join(small_run["run_dir"], "fluid"))
    parallel = output.channel_profile(os.path.join(run2, "fluid"))
    assert len(parallel["step"]) == 4
    scale = np.max(np.abs(serial["u"][:4, :, 0]))
    difference = np.abs(parallel["u"][:, :, 0] - serial["u"][:4, :, 0])
    assert np.max(difference[0]) < 1e-3 * scale
    assert np.max(difference) < 1e-2 * scale


def test_default_channel_holds_its_contacts_into_the_dense_core(case_module, tmp_path_factory, env):
    """The README's channel at its defaults (seed 1, dt 0.05) past step 220, where a pair of its
    migrating core used to be pushed into contact 0.0017 a1 per step beyond the step its springs
    assumed, until fdmDEM stopped the run at an overlap of 0.05 a1 (the position update's compromise
    between contradictory gap targets, now held to the fallback's bounds: docs/dem.md, "Position
    update"). Every recorded pair stays within the roughness layer h_r = 0.005 a1 (about 3.5 minutes)."""
    work = tmp_path_factory.mktemp("poiseuilleDense")
    r = case_module.main(["--duration", "11.5", "--dump-every", "0.05", "--fluid-every", "1", "--workdir", str(work),
                          "--out", str(work / "results.json")])
    assert r["steps"] == 230 and r["unconverged_steps"] == 0
    gaps = contacts.smallest_gaps(os.path.join(r["run_dir"], "dem", "particles.records"))
    assert len(gaps) == 230 and gaps.min() > -0.005, gaps.min()


def test_a_channel_starts_from_the_last_record_of_another(case_module, small_run, tmp_path):
    """--from-records: the packing is the last record's particles (by tag), in the same box with its walls;
    a records file of another box is refused with its name and both boxes."""
    path = os.path.join(small_run["run_dir"], "dem", "particles.records")
    records = output.read_particle_records(path)
    pack = poiseuille.packing_from_records(path, [8, 12, 8])
    last = records.blocks[-1]["particles"]
    order = np.argsort(last["tag"])
    assert pack.n == records.n_particles and pack.walls == (1,) and pack.boundary == "p f p"
    assert np.array_equal(pack.positions, last["x"][order]) and np.array_equal(pack.radii, last["radius"][order])
    assert pack.phi == pytest.approx(small_run["phi_bulk"], rel=1e-12)
    with pytest.raises(ValueError, match=r"particles\.records: box .* not the channel \[0, \[8, 16, 8\]\]"):
        poiseuille.packing_from_records(path, [8, 16, 8])
    with pytest.raises(SystemExit):
        case_module.main(["--from-records", path, "--size", "8", "16", "8", "--workdir", str(tmp_path)])


def test_a_channel_continues_from_a_compact_snapshot_and_is_analysed(case_module, small_run, tmp_path):
    """The small run's compact snapshot (its last checkpoint, step 40: the case script recorded the scene's
    command, without where it was written) continued past the scene's end to step 60 (t = 3) by
    `--from-snapshot --until` in a new folder: the run starts at step 41, its records after step 40, and the
    analysis of a run that starts at t = 2 works. With the small run's kept segment (`--segments`, as
    ladderRun keeps them) the analysis covers the whole migration: the segment's 20 records before the new
    folder's 10, the series and phi_center's start the small run's own."""
    dest = str(tmp_path / "snapshot")
    assert checkpoint.snapshot(small_run["run_dir"], dest)["step"] == 40
    scene = open(os.path.join(dest, "scene")).read()
    assert scene == "python3 cases/poiseuille/poiseuille.py %s\n" % " ".join(SMALL), scene
    r = case_module.main(SMALL + ["--from-snapshot", dest, "--until", "60", "--workdir", str(tmp_path / "work"),
                                  "--out", str(tmp_path / "r.json")])
    steps = output.steps(os.path.join(r["run_dir"], "fluid"))["step"].astype(int)
    assert list(steps) == list(range(41, 61))
    records = output.read_particle_records(os.path.join(r["run_dir"], "dem", "particles.records"), mmap=False)
    assert list(records.steps) == list(range(42, 61, 2))
    assert r["time"] == pytest.approx(3.0) and r["steps"] == 20 and r["unconverged_steps"] == 0
    assert r["wall_force_balance_rel_error"] < 0.01
    assert r["records_from_segments"] == 0 and len(r["series"]["time"]) == 10
    # the continued run's scene is the snapshot's: how far it went is not part of it
    assert open(os.path.join(r["run_dir"], "scene")).read() == scene
    assert "==== fdmRun --from-snapshot %s: step 40 to 60" % dest in open(os.path.join(r["run_dir"], "log.fluid")).read()
    # the whole history: the small run's segment before the new folder's records
    poiseuille.write_segment(small_run["run_dir"], str(tmp_path / "segments"))
    whole = case_module.main(["--analyse", r["run_dir"], "--segments", str(tmp_path / "segments"),
                              "--out", str(tmp_path / "whole.json")])
    assert whole["records_from_segments"] == 20 and whole["snapshots_averaged"] <= 10
    assert whole["series"]["time"] == pytest.approx(small_run["series"]["time"] + r["series"]["time"])
    assert whole["series"]["phi_center"][:20] == pytest.approx(small_run["series"]["phi_center"], abs=1e-5)
    assert whole["series"]["phi_center"][20:] == pytest.approx(r["series"]["phi_center"], abs=1e-12)
    assert whole["phi_center_initial"] == pytest.approx(small_run["phi_center_initial"], abs=1e-5)
    assert whole["profiles_from"] >= 2.0
    # a segment of another channel (profiles in other bins) is refused by name
    other = dict(json.load(open(next((tmp_path / "segments").iterdir()))), y=[0.5] * 7)
    with pytest.raises(poiseuille.PoiseuilleRunError, match="bins"):
        poiseuille.analyse(r["run_dir"], segments=[dict(other, time=[t - 5 for t in other["time"]])])


def test_required_duration_scales_the_ladders_migration_time(case_module, capsys):
    """--required-duration: tau = c L_y^2 through the ladder's analysed rungs (docs/data), weighted by their
    errors (the 12 a1 rung's 73 +- 116 hardly counts, the 20 a1 rung's 206 +- 27 sets c), so the 20 a1 channel
    gets its own tau back and the paper's 40 a1 four times it; the duration is the analysis's 3 tau before its
    window plus 3 tau in it. No rung with a migration time: refused."""
    data = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "docs", "data")
    rungs = [json.load(open(os.path.join(data, "validation_poiseuille_ladder%d.json" % n)))["data"] for n in (12, 20)]
    twenty = poiseuille.required_duration(rungs, 20.0)
    assert twenty["migration_time"] == pytest.approx(rungs[1]["migration_time"], rel=0.01)
    paper = poiseuille.required_duration(rungs, 40.0)
    assert paper["migration_time"] == pytest.approx(4 * twenty["migration_time"])
    assert paper["migration_time_err"] / paper["migration_time"] == pytest.approx(
        rungs[1]["migration_time_err"] / rungs[1]["migration_time"], rel=0.02)
    assert paper["steady_from"] == pytest.approx(3 * paper["migration_time"])
    assert paper["duration"] == pytest.approx(6 * paper["migration_time"])
    assert poiseuille.required_duration(rungs, 40.0, window_taus=1.0)["duration"] == pytest.approx(
        4 * paper["migration_time"])
    with pytest.raises(ValueError, match="no rung with a measured migration time"):
        poiseuille.required_duration([dict(L=[12, 12, 8], migration_time=None)], 40.0)
    out = case_module.main(["--paper", "--required-duration"] + [
        os.path.join(data, "validation_poiseuille_ladder%d.json" % n) for n in (12, 20)])
    assert out["duration"] == pytest.approx(paper["duration"])
    assert "a channel of L_y = 40 a1 needs about" in capsys.readouterr().out


def test_ladder_sets_the_rungs_side_by_side(case_module, tmp_path, capsys):
    """--ladder: the analysed rungs (docs/data) sorted by L_y, each as its results say it (phi_center, the
    plateau, the migration time with their error bars), the run started near the SBM's profile told apart by
    its folder's name; the figure written beside --out; a results file without the ladder's keys refused."""
    data = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "docs", "data")
    paths = [os.path.join(data, "validation_poiseuille_%s.json" % n) for n in ("ladder20_startSbm", "ladder20", "ladder12")]
    out = case_module.main(["--ladder"] + paths + ["--out", str(tmp_path / "results.json")])
    rows = out["rows"]
    assert [(r["width"], r["start"]) for r in rows] == [(12.0, "uniform"), (20.0, "sbm"), (20.0, "uniform")]
    for row, path in zip(rows, [paths[2], paths[0], paths[1]]):
        r = json.load(open(path))["data"]
        assert row["phi_center"] == r["phi_center"] and row["phi_center_err"] == r["phi_center_err"]
        assert row["plateau_width"] == r["plateau_width_over_a1"] and row["migration_time"] == r["migration_time"]
        assert row["steady"] == r["steady_detected"] and row["time"] == r["time"]
    assert os.path.getsize(out["figure"]) > 10000 and os.path.dirname(out["figure"]) == str(tmp_path)
    assert "20x20x10   sbm" in capsys.readouterr().out
    with pytest.raises(poiseuille.PoiseuilleRunError, match="lack migration_time"):
        poiseuille.ladder_table([dict(L=[12, 12, 8], phi_center=0.5, plateau_width_over_a1=0, time=10)])


def test_budget_predicts_the_run_it_was_measured_on(case_module, small_run):
    """--budget: the fluid steps a duration needs at the run's own fluid step, and its wall time from the
    median step after the cold first one; predicted for the small run's own duration, it is that run's
    summed step seconds within the steps' scatter; a run without two fluid steps is refused."""
    b = poiseuille.budget(small_run["run_dir"], 2.0)
    steps = output.steps(os.path.join(small_run["run_dir"], "fluid"))
    assert b["fluid_dt"] == pytest.approx(0.05) and b["fluid_steps"] == 40 and b["measured_fluid_steps"] == 40
    actual = sum(float(np.sum(steps[k])) for k in ("fluidSeconds", "particleSeconds", "exchangeSeconds"))
    assert b["predicted_seconds"] == pytest.approx(actual, rel=0.3)
    assert case_module.main(["--budget", small_run["run_dir"], "--duration", "20"])["fluid_steps"] == 400


def test_channel_at_its_defaults_migrates_and_balances(case_module, tmp_path_factory, env):
    """The README's channel at its defaults (the particles at dt 0.05, the fluid every 4th step with the
    held drag extrapolated) for 11.5 time units: the walls carry the pressure gradient's force at every
    fluid step (1 %), the spheres migrate toward the centre (phi_center up from its start, the wall
    layers down) and no pair goes deeper than the roughness layer (about 20 s)."""
    work = tmp_path_factory.mktemp("poiseuilleDefaults")
    r = case_module.main(["--duration", "11.5", "--dump-every", "0.2", "--workdir", str(work),
                          "--out", str(work / "results.json")])
    assert 230 / 4 <= r["steps"] <= 230 / 4 + 2 and r["unconverged_steps"] == 0   # fluid steps: every 4th, and the first
    assert r["wall_force_balance_rel_error"] < 0.01
    assert r["phi_center"] > r["phi_center_initial"] + 0.01
    gaps = contacts.smallest_gaps(os.path.join(r["run_dir"], "dem", "particles.records"))
    assert gaps.min() > -0.005, gaps.min()


def test_how_a_run_ended_is_read_from_its_logs_and_records(small_run, tmp_path):
    """case.last_error and case.records_finite (the stability maps' reading of a run): the small run wrote
    no error and finite records; an error appended to a copy of its logs is the line returned (fdmDEM's
    `ERROR` as written, OpenFOAM's `FOAM FATAL` by the two lines after it, the last one of either log)."""
    from fdmsubgrid import case
    run_dir = small_run["run_dir"]
    assert case.last_error(run_dir) is None and case.records_finite(run_dir) is True
    copy = tmp_path / "run"
    (copy / "dem").mkdir(parents=True)
    assert case.last_error(str(copy)) is None and case.records_finite(str(copy)) is None
    dem = open(os.path.join(run_dir, "log.dem")).read()
    message = ("ERROR on proc 0: particles 39 and 50 overlap by 0.0512 m (0.0512 of the smaller radius) at step 223, "
               "more than the 0.05 the fluid accepts")
    (copy / "log.dem").write_text(dem + "ERROR: an earlier one\n" + message + "\nLast command: run 800 upto\n")
    assert case.last_error(str(copy)) == message
    (copy / "log.dem").write_text(dem)
    (copy / "log.fluid").write_text("--> FOAM FATAL ERROR:\n    Cannot find patch wall\n\n    From function x\n")
    assert case.last_error(str(copy)) == "Cannot find patch wall"


def test_time_step_variants_take_a_spring_factor():
    """timeStep.py's variants DT:K[:S] (the channel's stability map): S scales the recipe's k_n = k_t of the
    channel's wall shear stress tau_w = 1 (2 F_max/h_r with F_max = 6 pi a2^2 tau_w, a2 = 1.4 a1); bad ones
    are refused by value."""
    import argparse
    time_step = load_case_module("poiseuille", "timeStep")
    assert time_step.parse_variant("0.05:8") == (0.05, 8, 1.0, "frozen")
    assert time_step.parse_variant("0.1:4:10") == (0.1, 4, 10.0, "frozen")
    assert time_step.parse_variant("0.05:4:consistent") == (0.05, 4, 1.0, "consistent")
    assert time_step.parse_variant("0.1:4:10:consistent") == (0.1, 4, 10.0, "consistent")
    assert time_step.variant_name(0.1, 4, 10.0) == "dt0.1_K4_k10" and time_step.variant_name(0.05, 8) == "dt0.05_K8"
    assert time_step.variant_name(0.05, 4, 1.0, "consistent") == "dt0.05_K4_consistent"
    assert time_step.spring_options(1.0, [8.0, 12.0, 8.0]) == []
    kn = 2 * 6 * np.pi * 1.4 ** 2 * 1.0 / 0.005
    options = time_step.spring_options(10.0, [8.0, 12.0, 8.0])
    assert options[0] == "--kn" and options[2] == "--kt"
    assert float(options[1]) == pytest.approx(10 * kn, rel=1e-12) and float(options[3]) == float(options[1])
    for bad in ("0.05", "0.05:0", "-0.1:4", "0.1:4:0", "0.1:4:10:2", "a:b", "0.05:4:sticky", "0.05:consistent"):
        with pytest.raises(argparse.ArgumentTypeError, match=bad.replace(".", r"\.")):
            time_step.parse_variant(bad)


def test_a_time_step_variant_too_short_for_the_analysis_still_compares(small_run, tmp_path):
    """A coarse variant over a short --duration runs to its end with too few records for the channel's time
    averages: timeStep.py keeps its flow-rate curve, compares it with the reference's and says why the
    analysis was left out, instead of stopping with the analysis's error."""
    time_step = load_case_module("poiseuille", "timeStep")
    start = os.path.join(small_run["run_dir"], "dem", "particles.records")
    out = time_step.main(["--start", start, "--variants", "0.4:1", "0.8:1", "--duration", "4",
                          "--workdir", str(tmp_path), "--out", str(tmp_path / "timeStep.json")])
    coarse = out["variants"][1]
    assert coarse["error"] is None and "too few for time averages" in coarse["analysis"]
    assert coarse["fluid_steps"] == 5 and np.isfinite(coarse["rms_difference"])


def test_time_step_warning_cites_the_measured_steps_and_the_stability_map():
    """No warning at the measured steps and springs (the defaults, the fluid every 8th step of the ladder); the
    accuracy limits (particle step 0.05, fluid step 0.4) cite "The channel's time step", a particle step beyond
    the stability map's 0.4 or springs outside its 0.1-10 times the recipe's cite "The channel's stability map";
    the limits carry over to other sizes by suspension.time_step_factor."""
    from fdmsubgrid import packing
    assert poiseuille.time_step_warning(0.05, 4) is None and poiseuille.time_step_warning(0.05, 8) is None
    assert poiseuille.time_step_warning(0.05, 8, spring_factors=(0.1, 10.0)) is None
    accuracy = poiseuille.time_step_warning(0.1, 4)
    assert "the particle step 0.1 above 0.05" in accuracy and "stability map" not in accuracy
    assert "The channel's time step" in accuracy
    assert "the fluid's step 0.8" in poiseuille.time_step_warning(0.05, 16)
    beyond = poiseuille.time_step_warning(0.5, 1)
    assert "beyond the stability map's 0.4" in beyond and "The channel's stability map" in beyond
    assert poiseuille.time_step_warning(0.4, 1).count("stability map") == 0
    springs = poiseuille.time_step_warning(0.05, 4, spring_factors=(20.0, 1.0))
    assert "the springs 20 times the recipe's, outside the stability map's 0.1 to 10" in springs
    assert "0.05 the springs" not in springs and "above 0.05" not in springs
    # the paper's radii: the limits as measured; a wider distribution scales both particle limits
    assert poiseuille.time_step_warning(0.05, 4, packing.PAPER_SUSPENSION) is None


def band_phi(pack, lo, hi):
    """The packing's volume fraction between the planes y = lo and hi."""
    return float(packing.slab_volume_fractions(pack, [lo, hi])[0])


def test_a_channel_starts_near_the_sbm_profile(case_module, tmp_path):
    """--start sbm spreads the same spheres (same seed, count and sizes) with the SBM's steady phi(y) at phi_bulk
    (sbm.solve, the paper's material functions): denser at the centre and thinner at the walls than the uniform
    start, no overlap, its own run folder; --start with --from-records, or sbm-table8 without Table 8 rows,
    is refused."""
    common = ["--size", "12", "16", "8", "--duration", "1", "--write-only", "--workdir", str(tmp_path)]
    packs = {}
    for start in ("uniform", "sbm"):
        out = case_module.main(common + ["--start", start])
        assert out["run_dir"].endswith("_seed1_calibrated_fluidEvery4" if start == "uniform"
                                       else "_seed1_startSbm_calibrated_fluidEvery4"), out["run_dir"]
        packs[start] = packing.read_data(os.path.join(out["run_dir"], "dem", "packing.data"), walls=(1,))
    uniform, near = packs["uniform"], packs["sbm"]
    assert near.n == uniform.n and sorted(near.radii) == sorted(uniform.radii)
    assert near.min_gap >= 0.01 - 1e-12 and near.min_wall_gap >= 0.01 - 1e-12
    model = sbm.solve(sbm.MaterialFunctions.maron_pierce_power_law(), near.phi, y_edge=0.5)
    centre, walls = (6.0, 10.0), [(0.0, 2.0), (14.0, 16.0)]
    assert model.at([0.0])[0][0] > 0.55                       # what the start aims at: the centre jammed
    assert band_phi(near, *centre) > band_phi(uniform, *centre) + 0.03
    assert np.mean([band_phi(near, *w) for w in walls]) < np.mean([band_phi(uniform, *w) for w in walls])
    with pytest.raises(SystemExit):
        case_module.main(common + ["--start", "sbm-table8", "--table8", "none"])
    with pytest.raises(SystemExit):
        case_module.main(common + ["--start", "sbm", "--from-records", "x.records", "--overwrite"])


def test_a_profiled_packing_follows_its_target_at_the_papers_size():
    """packing.profiled_channel_packing in the paper's channel (2345 spheres, 40 x 40 x 20 a1) with the SBM's
    profile: the corrections bring the packed phi in slabs of a1 (those 2 a1 or more from the walls) nearer the
    target than the first draw (rms 0.026 against 0.034), the central 2 a1 within 0.02 of the model's 0.592
    (0.591; the first draw 0.587), and the packing keeps its gaps and its phi_bulk."""
    model = sbm.solve(sbm.MaterialFunctions.maron_pierce_power_law(), 0.45, y_edge=0.5)
    target = lambda y: np.nan_to_num(model.at((np.asarray(y) - 20.0) / 40.0)[0])
    options = dict(seed=1, min_gap=0.01, wall_gap=0.01)
    first = packing.profiled_channel_packing((40, 40, 20), target, 0.45, iterations=0, **options)
    corrected = packing.profiled_channel_packing((40, 40, 20), target, 0.45, **options)
    assert corrected.info["profile_rms"] < first.info["profile_rms"]
    centre = [packing.slab_volume_fractions(p, [19.0, 21.0])[0] for p in (first, corrected)]
    assert abs(centre[1] - target(20.0)) < 0.02 and centre[0] < centre[1]
    assert corrected.n == 2345 and corrected.phi == pytest.approx(first.phi)
    assert corrected.min_gap >= 0.01 - 1e-12 and corrected.min_wall_gap >= 0.01 - 1e-12
    # the slabs add up to the whole channel's phi (each sphere's volume counted once)
    edges = np.linspace(0.0, 40.0, 41)
    assert packing.slab_volume_fractions(corrected, edges).mean() == pytest.approx(corrected.phi, rel=1e-12)


def test_arrival_of_the_centre_from_two_starts(tmp_path, env):
    """poiseuille.arrival on exponential approaches phi(t) = 0.62 - d exp(-t/150) sampled every time unit: the
    +-25 average reaches a level at the time the exponential does (to the window's curvature, a unit or two),
    the nearer start (d 0.07) sooner than the farther (d 0.14) by tau ln 2; a level never reached is None. The
    command reads a segments folder as it reads an analysed run."""
    t = np.arange(0.0, 1000.0)
    first = {}
    for d in (0.14, 0.07):
        found = poiseuille.arrival(t, 0.62 - d * np.exp(-t / 150.0), levels=[0.6, 0.63], at=[500.0])
        exact = 150.0 * np.log(d / 0.02)
        assert found["first"][0.6] == pytest.approx(exact, abs=3.0)
        assert found["first"][0.63] is None
        assert found["at"][500.0] == pytest.approx(0.62 - d * np.exp(-500 / 150.0), abs=1e-4)
        first[d] = found["first"][0.6]
    assert first[0.14] - first[0.07] == pytest.approx(150.0 * np.log(2.0), abs=3.0)
    folder = tmp_path / "segments"
    folder.mkdir()
    phi = 0.62 - 0.14 * np.exp(-t / 150.0)
    (folder / "segment_0_999.json").write_text(json.dumps(dict(
        time=t.tolist(), phi_center=phi.tolist(), phi_wall_layer=[0.3] * len(t), y=[0.5],
        phi_profile=[[0.45]] * len(t))))
    done = subprocess.run([sys.executable, "-m", "fdmsubgrid.poiseuille", "arrival", "0.6", "500", str(folder)],
                          capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stderr
    assert "first reaching 0.6 at t %g" % first[0.14] in done.stdout
