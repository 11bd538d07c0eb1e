"""cases/couette (paper 6.1) on a tiny scene: a bidisperse frictional suspension between walls at
-U and +U, run by the real fdmFoam and fdmDEM (about 30 s), and the case's bad input."""
import hashlib
import json
import os

import numpy as np
import pytest

from conftest import PROJECT, assert_refused, load_case_module
from fdmsubgrid import case, output, packing, profiles, results

TINY = ["--phi", "0.25", "--size", "7", "11", "7", "--a-over-delta", "3", "--dt", "0.02", "--strain", "0.4",
        "--dump-every", "0.02", "--seed", "3"]
# the binary records are what the analysis reads; the text dump of the same steps is written too,
# to check the records against it; the fluid fields (and the particles' VTK files) every 0.2 strain
OUTPUTS = ["--text-dump", "--write-every", "0.2", "--keep"]


@pytest.fixture(scope="module")
def couette():
    return load_case_module("couette")


@pytest.fixture(scope="module")
def tiny_run(couette, tmp_path_factory, env):
    work = tmp_path_factory.mktemp("couette")
    return couette.main(TINY + OUTPUTS + ["--workdir", str(work), "--out", str(work / "results.json")])


@pytest.fixture(scope="module")
def tiny_run_two_dem_ranks(couette, tmp_path_factory, env):
    """The tiny scene for 8 steps (the fewest the analysis takes) with the particles on 2 MPI ranks,
    and the fluid on 2 (its wall forces are sums over the ranks' patch faces)."""
    work = tmp_path_factory.mktemp("couette2")
    args = TINY[:TINY.index("--strain")] + ["--strain", "0.16"] + TINY[TINY.index("--strain") + 2:]
    return couette.main(args + OUTPUTS + ["--np-dem", "2", "--np-fluid", "2", "--workdir", str(work),
                                          "--out", str(work / "r.json")])


def test_tiny_scene_runs_converged_and_integrates_phi_exactly(couette, tiny_run):
    r = tiny_run
    assert r["n_particles"] >= 15 and r["n_a1"] > 0 and r["n_a2"] > 0
    # each species (atom type) reported: counts and core fractions adding up to the suspension's
    assert [(s["type"], s["radius"], s["n"]) for s in r["species"]] == [(1, 1.0, r["n_a1"]), (2, 1.4, r["n_a2"])]
    assert sum(s["phi_core"] for s in r["species"]) == pytest.approx(r["phi_core"], rel=1e-12)
    # results.json names the calibration table the run started with (fdmRun's record) and its SHA-256
    table = os.path.join(PROJECT, "dem", "resistance", "data", "subgrid_calibration.dat")
    with open(table, "rb") as f:
        digest = hashlib.sha256(f.read()).hexdigest()
    document = results.read_results(os.path.join(os.path.dirname(r["run_dir"]), "results.json"))
    assert document.calibration == [dict(table="dem/resistance/data/subgrid_calibration.dat", sha256=digest)]
    assert r["unconverged_steps"] == 0
    assert r["steps"] == 20
    snapshots, _ = output.record_snapshots(os.path.join(r["run_dir"], "dem", "particles.records"))
    assert len(snapshots) == 20
    channel = profiles.Channel((0, 0, 0), tuple(r["box"]))
    for s in snapshots:
        # Eq. 49 integrated exactly over the gap is phi_bulk (every sphere inside the walls)
        assert abs(profiles.bulk_volume_fraction(s, channel) - r["phi_bulk"]) < 1e-10
        assert set(np.unique(s.types)) == {1, 2}
        assert np.allclose(s.radii[s.types == 2], 1.4) and np.allclose(s.radii[s.types == 1], 1.0)
    for key in ("phi_core", "gamma_core_over_gamma0", "eta_s", "eta_s_err", "N1_hat", "N2_hat", "strain_units",
                "steady_from_strain", "cells", "dt", "wall_seconds", "core_seconds_per_strain_unit",
                "inner_iterations_mean", "inner_iterations_max"):
        assert np.isfinite(r[key]), key
    assert len(r["Sigma_c_hat"]) == 3
    # the position update's counts, read from the run's log.dem: every step and particle, and at this time
    # step (within the measured limit) hardly a gap asked to change by more than a factor e in a step
    from fdmsubgrid import demonly
    pu = r["position_update"]
    assert pu["steps"] == 20 and pu["particles"] == r["n_particles"], pu
    assert pu["limited_per_particle_step"] <= demonly.LIMITED_RATE_LIMIT, pu
    # the particles are sheared the right way round
    assert 0 < r["gamma_core_over_gamma0"] < 1.5


def test_no_contact_deeper_than_the_springs_allow(couette, tiny_run):
    # k_n = 2 F_max / h_r puts a contact under the design load F_max at h = h_r/2; the surfaces
    # themselves touch (h = 0) only under 2 F_max. Bound: no pair or wall gap below
    # h_r - 2 F_max / k_n = 0 in any snapshot, i.e. no surface overlap: a deeper contact means the
    # springs do not hold the load (a time step beyond their stability limit, docs/contact.md 3c).
    r = tiny_run
    s = r["springs"]
    bound = s["h_r"] - 2 * s["design_load"] / s["kn"]
    assert abs(bound) < 1e-12
    assert r["min_pair_gap"] >= bound, r["min_pair_gap"]
    assert r["min_wall_gap"] >= bound, r["min_wall_gap"]


def test_stress_balance_of_the_tiny_scene(tiny_run):
    # The momentum balance (docs/profiles.md "Stress balance"). Exact at every snapshot: the
    # gap-averaged stress eta gamma_0 + sum_p (S^H + S^c)_12 / V equals the mean shear stress of the two
    # walls (fluid + sub-grid + contact) -- measured at most 0.22 % (the inner iterations' tolerance).
    # Statistical: the core stress of Eq. 51 against the walls over the steady part; the tiny scene's
    # core is 1 a1 wide and 0.2 strain long, measured 11 %: bound 25 % (the small scene of ./Allrun,
    # 3 strain units, 2.9 +- 2.1 %; docs/validation.md).
    r = tiny_run
    assert r["stress_gap_snapshots"] == 20
    assert r["stress_gap_rel_error_max"] < 0.01, r["stress_gap_rel_error_max"]
    assert r["stress_balance_rel_error"] < 0.25, r["stress_balance_rel_error"]
    assert r["stress_wall"] > 1.0 and r["stress_core"] > 1.0      # more viscous than the fluid alone
    parts = r["stress_wall_fluid"] + r["stress_wall_subgrid"] + r["stress_wall_contact"]
    assert parts == pytest.approx(r["stress_wall"], rel=1e-12)
    assert r["stress_wall_asymmetry"] < 0.03, r["stress_wall_asymmetry"]   # net force on the walls: measured 0.5 %
    assert r["stress_balance_steps"] >= 8


def test_wall_loads_every_step_and_the_same_on_two_ranks(tiny_run, tiny_run_two_dem_ranks):
    # fdmFoam's walls.dat and fix fdm/couple's walls file hold every step; decomposed (2 fluid and 2
    # particle ranks: sums over the ranks' faces and contacts) the first 8 steps carry the loads of the
    # serial run to the inner iterations' tolerance (tolLambda 1e-3; measured 8e-4 of the largest load:
    # a missing sum over ranks would be a factor of about 2)
    one = output.read_wall_loads(tiny_run["run_dir"])
    two = output.read_wall_loads(tiny_run_two_dem_ranks["run_dir"])
    assert np.array_equal(one.steps, np.arange(1, 21)) and np.array_equal(two.steps, np.arange(1, 9))
    assert one.faces == ("ylo", "yhi") and np.allclose(one.areas, 49.0)
    scale = np.abs(one.fluid_viscous).max()
    for name in ("fluid_viscous", "subgrid", "contact"):
        a, b = getattr(one, name)[:8], getattr(two, name)
        assert np.max(np.abs(a - b)) < 5e-3 * scale, (name, np.max(np.abs(a - b)))


def test_a_couette_run_continues_from_a_compact_snapshot(couette, tiny_run, tmp_path):
    """A long Couette row outlives its machine as a channel run does: the tiny run's compact snapshot (its
    last checkpoint, step 20; the case script recorded the scene's command) continued to strain 0.6 by
    `--from-snapshot` in a new folder starts at step 21, and the rheology of a run whose records begin at
    strain 0.4 is analysed."""
    from fdmsubgrid import checkpoint
    dest = str(tmp_path / "snapshot")
    assert checkpoint.snapshot(tiny_run["run_dir"], dest)["step"] == 20
    scene = open(os.path.join(dest, "scene")).read()
    assert scene.startswith("python3 cases/couette/couette.py --phi 0.25 ") and "--workdir" not in scene, scene
    args = TINY[:TINY.index("--strain")] + ["--strain", "0.6"] + TINY[TINY.index("--strain") + 2:]
    r = couette.main(args + OUTPUTS + ["--from-snapshot", dest, "--workdir", str(tmp_path / "work"),
                                       "--out", str(tmp_path / "r.json")])
    steps = output.steps(os.path.join(r["run_dir"], "fluid"))["step"].astype(int)
    assert list(steps) == list(range(21, 31))
    assert "==== fdmRun --from-snapshot %s: step 20 to 30" % dest in open(os.path.join(r["run_dir"], "log.fluid")).read()
    assert np.isfinite(r["eta_s"]) and r["eta_s"] > 1


def test_phi_too_high_is_refused_by_name(couette, tmp_path):
    with pytest.raises(packing.PackingError) as e:
        couette.main(["--phi", "0.62", "--size", "10", "10", "10", "--workdir", str(tmp_path)])
    text = str(e.value)
    assert "phi = 0.62" in text and "10 x 10 x 10" in text and "3 attempts" in text
    with pytest.raises(ValueError, match="no random packing"):
        packing.channel_packing((10, 10, 10), phi=0.7)
    assert not os.listdir(tmp_path)


def test_box_smaller_than_a_particle_is_refused(couette, tmp_path):
    with pytest.raises(ValueError, match="smaller than a particle"):
        couette.main(["--size", "10", "2", "10", "--workdir", str(tmp_path)])
    with pytest.raises(ValueError, match="smaller than a particle"):
        packing.channel_packing((2, 10, 10), phi=0.1)
    with pytest.raises(ValueError, match="minimum image"):
        packing.channel_packing((5, 10, 10), phi=0.1)


def test_existing_run_folder_is_refused(couette, tmp_path):
    args = ["--table8", "0.27", "--workdir", str(tmp_path), "--out", str(tmp_path / "r.json")]
    couette.main(args)   # written, not run
    with pytest.raises(SystemExit, match="already holds a run"):
        couette.main(args)
    couette.main(args + ["--overwrite"])


def test_table8_scene(couette, tmp_path):
    scene = couette.main(["--table8", "0.47", "--workdir", str(tmp_path), "--out", str(tmp_path / "r.json")])
    assert scene["box"] == [25.0, 25.0, 20.0] and scene["dt"] == 1e-4
    data = packing.read_data(os.path.join(scene["run_dir"], "dem", "spheres.data"), walls=(1,))
    assert data.n == 956 and set(np.unique(data.types)) == {1, 2}
    assert data.min_wall_gap >= 2 * couette.ROUGHNESS * (1 - 1e-12)


def test_fluid_every_puts_every_snapshot_on_a_fluid_step(couette, tmp_path):
    """--fluid-every K: fix fdm/couple gets fluid_every K (with held_drag extrapolated, or as --held-drag says),
    the particle snapshots and the ParaView writes
    fall on multiples of K (steps the fluid solves; fdmFoam's time index is the DEM step, so its
    writeInterval counts DEM steps too); a snapshot between fluid steps is refused."""
    scene = couette.main(TINY + ["--fluid-every", "3", "--write-every", "0.2", "--write-only",
                                 "--workdir", str(tmp_path)])
    assert scene["fluid_every"] == 3 and scene["dump_every"] == 3 and scene["write_every"] == 9
    assert scene["run_dir"].endswith("_fluidEvery3")
    fix = next(l for l in open(os.path.join(scene["run_dir"], "dem", "in.couette")) if "fdm/couple" in l)
    assert fix.split()[-4:] == ["fluid_every", "3", "held_drag", "extrapolated"]   # the scenes' choice
    constant = couette.main(TINY + ["--fluid-every", "3", "--held-drag", "constant", "--write-only",
                                    "--workdir", str(tmp_path / "constant")])
    fix = next(l for l in open(os.path.join(constant["run_dir"], "dem", "in.couette")) if "fdm/couple" in l)
    assert fix.split()[-4:] == ["fluid_every", "3", "held_drag", "constant"] and constant["held_drag"] == "constant"
    # coulomb_solve consistent: written into the fix, the folder named after it; frozen (the default) is not written
    assert "coulomb_solve" not in fix and scene["coulomb_solve"] == "frozen"
    consistent = couette.main(TINY + ["--fluid-every", "3", "--coulomb-solve", "consistent", "--write-only",
                                      "--workdir", str(tmp_path / "consistent")])
    fix = next(l for l in open(os.path.join(consistent["run_dir"], "dem", "in.couette")) if "fdm/couple" in l)
    assert fix.split()[-2:] == ["coulomb_solve", "consistent"] and consistent["run_dir"].endswith("_coulombConsistent")
    control = open(os.path.join(scene["run_dir"], "fluid", "system", "controlDict")).read()
    assert "writeInterval   9;" in control
    pack = packing.read_data(os.path.join(scene["run_dir"], "dem", "packing.data"), walls=(1,))
    springs = couette.choose_springs(pack.phi, 0.02, 1 / 3)
    with pytest.raises(ValueError, match="dump_every = 5 steps is not a multiple of fluid_every = 2"):
        couette.write_case(str(tmp_path / "bad"), pack, springs, 3, 0.02, 0.4, 5, 1e-2, "anderson",
                           write_every=10, fluid_every=2)


@pytest.fixture(scope="module")
def held_drag_runs(tmp_path_factory, env):
    """cases/couette/fluidEvery.py's phi 0.47 scene (98 spheres, 10 x 16 x 8 a1) for 0.2 strain units: the
    particles at 0.005 with the fluid at every step (the reference) and every 4th, the steps between holding
    its force constant or extrapolated (about a minute in all). One workdir: the second call takes the reference
    from the first's kept result (a variant with the fluid at every step holds no drag), as a rerun would."""
    fluid_every = load_case_module("couette", "fluidEvery")
    work = tmp_path_factory.mktemp("heldDrag")
    common = ["--phi", "0.47", "--strain", "0.2", "--window", "0.05", "0.2", "--dump-every", "0.02",
              "--variants", "0.005:1", "0.005:4", "--workdir", str(work)]
    return {held: fluid_every.main(common + ["--held-drag", held, "--out", str(work / (held + ".json"))])
            for held in ("constant", "extrapolated")}


def test_extrapolated_held_drag_follows_the_fluid_closer(held_drag_runs):
    """With the fluid every 4th particle step (a third of the fluid solves per particle step), extrapolating
    the held drag from the last two fluid steps keeps the particles closer to the run that solves the fluid at
    every step than holding it constant: the dense suspension's forces change steadily as the force chains
    build, which a constant drag lags by up to 3 steps. Measured 2026-11-28 at strain 0.2 (docs/benchmarks.md,
    "The held drag extrapolated"): mean position difference 2.2e-3 a1 extrapolated, 9.0e-3 constant; the wall
    stress within 0.4 % rms."""
    constant, extrapolated = (held_drag_runs[h]["runs"] for h in ("constant", "extrapolated"))
    every_step, held = extrapolated
    assert held["fluid_every"] == 4 and held["held_drag"] == "extrapolated"
    assert constant[1]["held_drag"] == "constant"
    assert held["fluid_solves_per_step"] < 0.6 * every_step["fluid_solves_per_step"], (held, every_step)
    moved, moved_constant = held["particles_difference"], constant[1]["particles_difference"]
    print("strain %.2f: mean |dx| %.2e a1 extrapolated, %.2e constant; |dU|/U %.2e, %.2e; stress rms %.2f %%, %.2f %%"
          % (moved["strain"], moved["position"], moved_constant["position"], moved["velocity"],
             moved_constant["velocity"], 100 * held["error_rms"], 100 * constant[1]["error_rms"]))
    assert moved["strain"] == pytest.approx(0.2, abs=0.021)
    assert 0 < moved["position"] < 0.5 * moved_constant["position"]
    assert moved["velocity"] < moved_constant["velocity"]
    assert held["error_rms"] < 0.01


def test_bad_fluid_every_keeps_the_run_folder(couette, tmp_path):
    """--fluid-every 0 is refused before anything is written or replaced: with --overwrite the existing
    run folder stays."""
    scene = couette.main(TINY + ["--write-only", "--workdir", str(tmp_path)])
    with pytest.raises(SystemExit):
        couette.main(TINY + ["--fluid-every", "0", "--overwrite", "--write-only", "--workdir", str(tmp_path)])
    assert os.path.isfile(os.path.join(scene["run_dir"], "dem", "in.couette"))


def test_channel_packing_any_box():
    p = packing.channel_packing((9, 14, 7), phi=0.35, seed=4)
    n1, n2 = np.sum(p.types == 1), np.sum(p.types == 2)
    assert abs(n1 - n2 * 1.4 ** 3) <= 1.4 ** 3       # equal volumes of both sizes, to one sphere
    assert abs(p.phi - 0.35) < 0.02
    assert p.min_gap >= 0.01 and p.min_wall_gap >= 0.01
    assert np.all(p.positions[:, 1] - p.radii > 0) and np.all(p.positions[:, 1] + p.radii < 14)


def test_kdtree_finds_the_cell_list_pairs():
    for walls in ((1,), ()):
        p = packing.random_packing(600, 0.45, bidisperse=True, seed=5, walls=walls)
        a = packing.neighbour_pairs_cells(p.positions, p.box, 3.2, walls)
        b = packing.neighbour_pairs_kdtree(p.positions, p.box, 3.2, walls)
        pairs_a = {(min(i, j), max(i, j)): d for i, j, d in zip(*a)}
        pairs_b = {(min(i, j), max(i, j)): d for i, j, d in zip(*b)}
        assert pairs_a.keys() == pairs_b.keys() and len(pairs_a) > 1000
        assert max(abs(pairs_a[k] - pairs_b[k]) for k in pairs_a) < 1e-12


def test_dem_input_keeps_types(tmp_path):
    box = case.Box((0, 0, 0), (8, 8, 8), 0.5)
    case.write_dem_input(str(tmp_path), box, [(2, 2, 2, 1.0, 1), (5, 5, 5, 1.4, 2), (2, 6, 6, 1.0)])
    lines = open(tmp_path / "spheres.data").read().splitlines()
    assert "2 atom types" in lines
    atoms = [l.split() for l in lines[lines.index("Atoms") + 2:] if l.strip()]
    assert [a[1] for a in atoms] == ["1", "2", "1"]


def test_dump_reader_stresslet_and_truncation(tmp_path):
    names = output.SUSPENSION_DUMP_COLUMNS
    rows = []
    couple = np.arange(1, 26, dtype=float)
    for pid in (2, 1):
        rows.append([pid, pid, 1.0 if pid == 1 else 1.4, pid, 5, 5, 0.1 * pid, 0, 0, 0, 0, -0.5] + list(couple * pid))
    frame = lambda step: ("ITEM: TIMESTEP\n%d\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp ff pp\n0 10\n0 10\n0 10\n"
                          "ITEM: ATOMS %s\n" % (step, " ".join(names))
                          + "".join(" ".join("%.17g" % v for v in r) + "\n" for r in rows))
    path = tmp_path / "particles.dump"
    path.write_text(frame(0) + frame(10) + frame(20)[:-40])      # the last frame cut short
    snaps, forces = output.suspension_snapshots(str(path), dt=0.02)
    assert len(snaps) == 1 and snaps[0].time == pytest.approx(0.2)
    s = snaps[0]
    assert list(s.types) == [1, 2] and list(s.radii) == [1.0, 1.4]      # sorted by id
    # S^H = S^h + s^h delta/3: columns 13-18 plus column 19 / 3 on xx, yy, zz
    expected = couple[12:18].copy()
    expected[[0, 3, 5]] += couple[18] / 3
    assert np.allclose(s.stresslet_h[0], expected) and np.allclose(s.stresslet_h[1], 2 * expected)
    assert np.allclose(s.stresslet_c[0], couple[19:25])
    assert np.allclose(forces[0][0], couple[0:3] + couple[6:9])


# ---- the particle records and the ParaView files (fix fdm/output, docs/dem.md) --------------------

def _records_match_the_dump(r):
    """Every record step holds every particle, by tag, with the values of the LIGGGHTS text dump of
    the same step (full precision): positions (wrapped into the box; image counts the periods),
    radius, type, U, Omega, the fluid + sub-grid forces and the stresslets S^H, S^c."""
    dem = os.path.join(r["run_dir"], "dem")
    rec = output.read_particle_records(os.path.join(dem, "particles.records"))
    frames = [(step, c) for step, c in output.read_dump(os.path.join(dem, "particles.dump")) if step > 0]
    snapshots, forces = output.suspension_snapshots(os.path.join(dem, "particles.dump"), r["dt"])
    n = r["n_particles"]
    assert rec.n_particles == n and rec.dropped_bytes == 0
    assert list(rec.steps) == [step for step, _ in frames] == list(range(1, r["steps"] + 1))
    assert np.allclose(rec.times, rec.steps * r["dt"], rtol=1e-14, atol=0)
    assert np.all(rec["tag"] == np.arange(1, n + 1))                 # every particle, in tag order
    box = np.array(r["box"])
    lo, hi = np.array(rec.header["box_lo"]), np.array(rec.header["box_hi"])
    assert np.allclose(lo, 0) and np.allclose(hi, box) and rec.header["periodic"] == [1, 0, 1]
    x = rec["x"]
    assert np.all(x >= lo) and np.all(x < hi)                      # wrapped into the box
    for k, (step, c) in enumerate(frames):
        s = snapshots[k]
        # the dump holds x as LIGGGHTS does (wrapped only when it re-neighbours): the same point
        # modulo the periods; the unwrapped trajectory x + image L
        d = x[k] - s.positions
        assert np.max(np.abs(d - box * np.round(d / box))) < 1e-12 * box.max()
        assert np.all(rec["image"][k][:, 1] == 0)
        assert np.array_equal(rec["radius"][k], s.radii) and np.array_equal(rec["type"][k], s.types)
        assert np.array_equal(rec["U"][k], s.velocities) and np.array_equal(rec["omega"][k], s.omegas)
        assert np.array_equal(rec["F_fluid"][k] + rec["F_subgrid"][k], forces[k])
        scale = np.abs(s.stresslet_h).max()
        assert np.max(np.abs(rec["S_fluid"][k] + rec["S_subgrid"][k] - s.stresslet_h)) < 1e-13 * scale
        assert np.array_equal(rec["S_contact"][k], s.stresslet_c)
    # the sub-grid part is there: in a suspension at phi = 0.25 some pairs have lubrication blocks
    assert np.abs(rec["S_subgrid"]).max() > 1e-3 * np.abs(rec["S_fluid"]).max()
    return rec


def test_records_hold_every_particle_and_match_the_dump(tiny_run):
    rec = _records_match_the_dump(tiny_run)
    # the size: a header, then one block per record step of 16 + N record_bytes + 8 bytes
    path = rec.path
    assert os.path.getsize(path) == rec.header["header_bytes"] + len(rec) * rec.header["block_bytes"]
    assert rec.header["block_bytes"] == 16 + tiny_run["n_particles"] * rec.header["record_bytes"] + 8


def test_records_of_two_dem_ranks_match_their_dump(tiny_run_two_dem_ranks):
    rec = _records_match_the_dump(tiny_run_two_dem_ranks)
    assert len(rec) == 8


def test_truncated_records_keep_every_complete_block(tiny_run, tmp_path):
    full = output.read_particle_records(os.path.join(tiny_run["run_dir"], "dem", "particles.records"), mmap=False)
    data = open(full.path, "rb").read()
    block = full.header["block_bytes"]
    for cut in (block // 2, 1, 8):        # in the middle of the last block, in its end marker
        path = tmp_path / "cut.records"
        path.write_bytes(data[:len(data) - cut])
        with pytest.warns(UserWarning, match="incomplete block"):
            rec = output.read_particle_records(str(path))
        assert len(rec) == len(full) - 1 and rec.dropped_bytes == block - cut
        assert np.array_equal(rec.blocks, full.blocks[:-1])
    # a crash after the file grew leaves zeros: not a block
    path.write_bytes(data[:len(data) - block] + bytes(block))
    with pytest.warns(UserWarning, match="incomplete block"):
        assert len(output.read_particle_records(str(path))) == len(full) - 1
    path.write_bytes(data[:full.header["header_bytes"] - 5])
    with pytest.raises(ValueError, match="cut short"):
        output.read_particle_records(str(path))
    dump = os.path.join(tiny_run["run_dir"], "dem", "particles.dump")
    with pytest.raises(ValueError, match="not a particle records file"):
        output.read_particle_records(dump)


def _vtk_reads(path):
    """Number of points and arrays of a .vtp read by the real VTK library (Debian's python3-vtk9,
    under the system Python), or None if it is not installed."""
    import shutil
    import subprocess
    system_python = shutil.which("python3", path="/usr/bin")
    if not system_python or subprocess.run([system_python, "-c", "import vtk"], capture_output=True).returncode:
        return None
    script = ("import sys, vtk\nr = vtk.vtkXMLPolyDataReader(); r.SetFileName(sys.argv[1]); r.Update()\n"
              "o = r.GetOutput(); d = o.GetPointData()\n"
              "print(r.GetErrorCode(), o.GetNumberOfPoints(), o.GetNumberOfVerts(), "
              "' '.join(d.GetArrayName(i) for i in range(d.GetNumberOfArrays())))")
    out = subprocess.run([system_python, "-c", script, path], capture_output=True, text=True, check=True).stdout.split()
    return int(out[0]), int(out[1]), int(out[2]), out[3:]


def test_paraview_files_at_the_fluid_write_times(tiny_run):
    r = tiny_run
    run = r["run_dir"]
    assert os.path.isfile(os.path.join(run, "fluid", "fluid.foam"))
    series = output.read_pvd(os.path.join(run, "dem", "vtk", "particles.pvd"))
    # the fluid writes every 0.2 strain (writeInterval 10 steps) and at the end; the particles too
    fluid_times = sorted(float(d) for d in os.listdir(os.path.join(run, "fluid"))
                         if d.replace(".", "").isdigit())
    assert [t for t, _ in series] == fluid_times == [0.0, 0.2, 0.4]
    rec = output.read_particle_records(os.path.join(run, "dem", "particles.records"))
    checked = 0
    for time, path in series:
        v = output.read_vtp(path)
        assert v["Points"].shape == (r["n_particles"], 3)
        assert np.array_equal(v["id"], np.arange(1, r["n_particles"] + 1))
        for name in ("radius", "type", "diameter", "U", "omega", "F_hydro", "F_fluid", "F_subgrid", "F_dem",
                     "T_hydro", "S_hydro", "S_fluid", "S_subgrid", "S_contact"):
            assert name in v, name
        k = np.flatnonzero(np.isclose(rec.times, time, rtol=0, atol=1e-9))
        if len(k):
            k = k[0]
            assert np.array_equal(v["Points"], rec["x"][k]) and np.array_equal(v["U"], rec["U"][k])
            # symmetric tensors in VTK's order xx yy zz xy yz xz
            assert np.allclose(v["S_contact"], rec["S_contact"][k][:, [0, 3, 5, 1, 4, 2]], rtol=0, atol=0)
            checked += 1
        vtk = _vtk_reads(path)
        if vtk is not None:
            assert vtk[:3] == (0, r["n_particles"], r["n_particles"]) and "S_hydro" in vtk[3]
    assert checked == 2


def test_analyse_a_run_folder_as_it_stands(couette, tiny_run, tmp_path):
    # couette --analyse RUN_DIR (what table8.py uses for resumed and running runs): the scene from
    # the folder's own files gives the run's own results; the run time from the step records
    out = str(tmp_path / "again.json")
    again = couette.main(["--analyse", tiny_run["run_dir"], "--out", out])
    for key in ("phi_bulk", "phi_core", "gamma_core_over_gamma0", "eta_s", "eta_s_err", "N1_hat", "N2_hat",
                "stress_balance_rel_error", "stress_gap_rel_error_max", "min_pair_gap", "cells", "dt",
                "strain_units", "unconverged_steps"):
        assert again[key] == tiny_run[key], key
    assert again["Sigma_c_hat"] == tiny_run["Sigma_c_hat"]
    assert again["springs"]["kn"] == pytest.approx(tiny_run["springs"]["kn"], rel=1e-12)
    assert again["steps_planned"] == 20
    # the step records' seconds (solve, particles, exchange) are the run's wall time less start-up
    assert 0.3 * tiny_run["wall_seconds"] < again["wall_seconds"] <= tiny_run["wall_seconds"]
    assert os.path.exists(out) and os.path.exists(str(tmp_path / "again.png"))


def test_fdmProfiles_command_on_a_run_folder(tiny_run, tmp_path, env):
    # the command-line tool of the package (scripts/fdmProfiles, on the PATH of etc/bashrc) reads the
    # folder's own files and gives the case's own numbers; --from-strain moves the averaging window
    import json
    import subprocess
    out = tmp_path / "p.json"
    proc = subprocess.run(["fdmProfiles", tiny_run["run_dir"], "--out", str(out)], env=env, text=True,
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    assert proc.returncode == 0, proc.stdout[-2000:]
    assert "stress_balance_rel_error" in proc.stdout and "eta_s" in proc.stdout
    again = json.loads(out.read_text())
    for key in ("phi_bulk", "phi_core", "eta_s", "eta_s_err", "N2_hat", "steady_from_strain", "strain_units"):
        assert again[key] == tiny_run[key], key
    assert (tmp_path / "p.png").stat().st_size > 1000
    late = tmp_path / "late.json"
    proc = subprocess.run(["fdmProfiles", tiny_run["run_dir"], "--out", str(late), "--from-strain", "0.26", "--core", "4"],
                          env=env, text=True, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    assert proc.returncode == 0, proc.stdout[-2000:]
    late = json.loads(late.read_text())
    assert late["steady_from_strain"] == pytest.approx(0.26, abs=0.01) and late["h_layer"] == 4
    assert late["samples_averaged"] == 8 < again["samples_averaged"]
    # a window too short for a time average: said, with the strain the run reached
    proc = subprocess.run(["fdmProfiles", tiny_run["run_dir"], "--out", str(tmp_path / "x.json"), "--from-strain", "0.35"],
                          env=env, text=True, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    assert proc.returncode == 2 and "from strain 0.35 on there are" in proc.stdout and "Traceback" not in proc.stdout
    # a folder that is not a run: the file it lacks is named, nothing is written
    proc = subprocess.run(["fdmProfiles", str(tmp_path)], env=env, text=True, stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT)
    assert proc.returncode == 2 and "packing.data" in proc.stdout, proc.stdout
    assert not (tmp_path / "profiles.json").exists()


def test_time_step_beyond_the_measured_limit_is_warned(couette):
    # the measured limits (docs/benchmarks.md, "What limits the time step"): phi 0.47 holds up to dt 0.1,
    # but its particle stress is that of smaller steps at 0.01 only (30 % low at 0.02)
    assert couette.time_step_warning(0.47, 0.01) is None
    message = couette.time_step_warning(0.4691, 0.02)          # the small scene of the study at 0.47
    assert "dt = 0.02" in message and "phi_bulk 0.47" in message and "0.01" in message and "viscosity" in message
    assert message.endswith("--dt 0.01 --fluid-every 2"), message   # the same fluid step, good particle steps
    assert couette.time_step_warning(0.2682, 0.04) is None     # the Table 8 row of phi_bulk 0.27
    assert "phi_bulk 0.32" in couette.time_step_warning(0.3032, 0.04)   # the run time against error scene
    message = couette.time_step_warning(0.3687, 0.04)          # the Table 8 row of phi_bulk 0.37 (ran so)
    assert "phi_bulk 0.37" in message and "0.02" in message, message
    # between two measured rows the denser row's limit applies
    assert "phi_bulk 0.32" in couette.time_step_warning(0.29, 0.03)
    assert "phi_bulk 0.42" in couette.time_step_warning(0.42, 0.04) and "0.02" in couette.time_step_warning(0.42, 0.04)
    assert couette.time_step_warning(0.4160, 0.02) is None     # the time-step study's scene at 0.42
    # beyond the densest: the limit scaled by 1/eta_MP(phi), rounded down, said so
    message = couette.time_step_warning(0.54, 0.01)
    assert "denser than any measured" in message and "0.0024" in message, message
    limits = [couette.largest_good_dt(phi) for phi in (0.27, 0.32, 0.37, 0.42, 0.47, 0.52, 0.54)]
    assert limits == sorted(limits, reverse=True) and limits[-2:] == [0.0034, 0.0024]
    from fdmsubgrid import suspension
    assert limits[-1] <= 0.01 * suspension.maron_pierce_viscosity(0.47) / suspension.maron_pierce_viscosity(0.54)
    # the fluid every 0.04 up to 0.42, every 0.02 beyond, where the particle step is smaller
    assert [couette.fluid_dt(phi) for phi in (0.27, 0.42, 0.4691, 0.54)] == [0.04, 0.04, 0.02, 0.02]
    assert [couette.fluid_every(phi) for phi in (0.27, 0.32, 0.42, 0.47, 0.52, 0.54)] == [1, 2, 2, 2, 6, 8]
    assert couette.fluid_every(0.47, dt=0.005) == 4


def test_table8_names_a_run_that_stopped(tmp_path, env):
    """A run that fdmRun stops (here a folder without a case) ends table8.py with a message naming the run
    and its log, not a traceback; the log holds fdmRun's own reason."""
    import argparse
    table8 = load_case_module("couette", "table8")
    run_dir = tmp_path / "table8_phi0.47_broken"
    run_dir.mkdir()
    with pytest.raises(SystemExit) as stopped:
        table8._fdmrun(str(run_dir), argparse.Namespace(np_fluid=1))
    message = str(stopped.value)
    assert "exit code" in message and str(run_dir) in message and str(run_dir) + ".log" in message
    assert "resumes the run from its last checkpoint" in message
    assert "fluid/system not found" in (tmp_path / "table8_phi0.47_broken.log").read_text()


def test_table8_continues_a_new_run_folder_from_its_kept_snapshot(tmp_path, env, capsys):
    """--snapshots DIR: a row whose run folder is new (nothing run, no checkpoint) is continued from the compact
    snapshot kept under the run folder's name in DIR (fdmRun --from-snapshot, on to the step asked), one that is
    not kept starts afresh; fdmRun itself checks the snapshot (here it stops on the folder without a case, and
    table8.py names the run and its log). --save without --snapshots is refused."""
    import argparse
    table8 = load_case_module("couette", "table8")
    run_dir = tmp_path / "runs" / "table8_phi0.47_25x25x20_ad4_dt0.01_seed1_calibrated_fluidEvery2"
    run_dir.mkdir(parents=True)
    kept = tmp_path / "snapshots" / run_dir.name
    kept.mkdir(parents=True)
    (kept / "README").write_text("Compact snapshot\n")
    args = argparse.Namespace(np_fluid=1, snapshots=str(tmp_path / "snapshots"))
    assert table8.snapshot_folder(str(run_dir), args) == str(kept)
    with pytest.raises(SystemExit) as stopped:
        table8._fdmrun(str(run_dir), args, until=2500)
    line = [l for l in capsys.readouterr().out.splitlines() if l.startswith("table8: ")][-1]
    assert "fdmRun -f 1 --from-snapshot %s --until 2500 %s " % (kept, run_dir) in line
    assert str(run_dir) + ".log" in str(stopped.value)
    # another row's folder: no snapshot of its name, a fresh start
    other = tmp_path / "runs" / "table8_phi0.52_broken"
    other.mkdir()
    assert table8.snapshot_folder(str(other), args) is None
    with pytest.raises(SystemExit):
        table8._fdmrun(str(other), args)
    line = [l for l in capsys.readouterr().out.splitlines() if l.startswith("table8: ")][-1]
    assert "--from-snapshot" not in line and line.endswith("fdmRun -f 1 %s (log %s.log)" % (other, other))
    with pytest.raises(SystemExit) as refused:
        table8.main(["--phis", "0.47", "--save", "--workdir", str(tmp_path / "runs"), "--out", str(tmp_path / "t.json")])
    assert refused.value.code == 2
    assert "--save writes into the --snapshots folder" in capsys.readouterr().err


def test_table8_extends_a_run_whose_averaging_window_is_short():
    """table8.py's rule: a finished run averaged over fewer than --min-average strain units after its
    transient is continued by the shortfall, at least a tenth of --min-average (in whole steps), never
    beyond --max-strain."""
    import argparse
    table8 = load_case_module("couette", "table8")
    args = argparse.Namespace(min_average=20.0, max_strain=60.0, dt=None)
    # the rows' time steps: couette.largest_good_dt (0.04 at 0.27, 0.02 from 0.32 to 0.42, 0.01 at 0.47),
    # unless --dt says one
    assert (table8.row_dt(0.27, args), table8.row_dt(0.37, args), table8.row_dt(0.47, args)) == (0.04, 0.02, 0.01)
    assert table8.row_dt(0.32, args) == 0.02     # dt 0.04 is 7 % low there without the fluid (docs/benchmarks.md)
    assert table8.row_dt(0.42, args) == 0.02     # dt 0.04 is 26 % low there (docs/benchmarks.md)
    assert table8.row_dt(0.47, argparse.Namespace(dt=0.02)) == 0.02
    assert table8.row_dt(0.54, args) == 0.0024   # beyond the densest measured: scaled by 1/eta_MP
    # the fluid every 0.04 up to 0.42 (2 particle steps per fluid step at 0.37), 0.02 beyond (2 at 0.47, 8 at
    # 0.54); --dt 0.02 at 0.47: every step
    assert [table8.row_fluid_every(phi, args) for phi in (0.27, 0.37, 0.47, 0.54)] == [1, 2, 2, 8]
    assert table8.row_fluid_every(0.47, argparse.Namespace(dt=0.02, fluid_every=None)) == 1
    assert table8.row_fluid_every(0.47, argparse.Namespace(dt=None, fluid_every=3)) == 3
    # 25 strain units (625 steps), transient to strain 12.1: 12.9 averaged, 7.1 short = 177.5 -> 178 steps
    assert table8.extension(dict(steps_done=625, strain_averaged=12.9), args, 0.04) == 625 + 178
    assert table8.extension(dict(steps_done=625, strain_averaged=20.0), args, 0.04) is None
    assert table8.extension(dict(steps_done=625, strain_averaged=21.3), args, 0.04) is None
    # short by less than a tenth of --min-average: extended by 2 strain units (50 steps), not 0.7
    assert table8.extension(dict(steps_done=880, strain_averaged=19.3), args, 0.04) == 880 + 50
    # capped at --max-strain, and not extended once there
    assert table8.extension(dict(steps_done=1450, strain_averaged=2.0), args, 0.04) == 1500
    assert table8.extension(dict(steps_done=1500, strain_averaged=2.0), args, 0.04) is None
    # a run too short to be analysed yet counts as averaged over nothing
    assert table8.extension(dict(steps_done=25), args, 0.04) == 25 + 500


def test_table8_runs_the_densest_rows_first_and_projects_the_whole_curve(tmp_path, capsys):
    """--paper is the paper's seven rows; rows are launched densest (costliest) first; the summary's budget
    is the rows' wall times run --jobs at a time in that order, each next one on the first free slot."""
    import argparse
    table8 = load_case_module("couette", "table8")
    assert table8.launch_order([0.27, 0.54, 0.37]) == [0.54, 0.37, 0.27]
    # two slots: 10 | 8, then 3 after the 8 (11), 2 after the 10 (12), 1 after the 11 (12)
    assert table8.makespan([10.0, 8.0, 3.0, 2.0, 1.0], 2) == 12.0
    assert table8.makespan([10.0, 8.0, 3.0, 2.0, 1.0], 1) == 24.0      # one at a time: the sum
    assert table8.makespan([10.0, 8.0, 3.0], 7) == 10.0                 # more slots than rows: the longest
    args = argparse.Namespace(a_over_delta=3.0, dt=None, tol_lambda=0.01, strain=25.0, seed=1, jobs=2,
                              np_fluid=1, out=str(tmp_path / "table8.json"))
    rows = [dict(phi_bulk_table8=phi, phi_core=phi + 0.03, eta_s=eta, eta_s_err=0.1, status="finished",
                 window_short=False, wall_seconds=wall)
            for phi, eta, wall in ((0.27, 3.5, 3.0), (0.37, 8.0, 2.0), (0.47, 26.0, 8.0), (0.52, 80.0, 10.0))]
    budget = table8.summarise(rows, args)["budget"]
    assert budget["rows"] == [0.52, 0.47, 0.37, 0.27] and budget["jobs"] == 2
    # launched 0.52 (10) | 0.47 (8), then 0.37 after the 8 (10), then 0.27 after a 10 (13)
    assert budget["wall_seconds_rows"] == 23.0 and budget["projected_wall_seconds"] == 13.0
    assert budget["unfinished"] == []
    rows[3]["status"] = "partial"                  # a row still running counts as it stands, and is named
    assert table8.summarise(rows, args)["budget"]["unfinished"] == [0.52]
    assert_refused(table8.main, ["--paper", "--phis", "0.27"], ["--paper", "--phis"], tmp_path, capsys)


def test_table8_fits_only_finished_rows_with_a_full_window(tmp_path):
    """table8.py's Maron-Pierce fit takes the finished rows whose averaging window holds --min-average
    strain units; a partial run or a short window is plotted and listed as not fitted."""
    import argparse
    table8 = load_case_module("couette", "table8")
    args = argparse.Namespace(a_over_delta=3.0, dt=None, tol_lambda=0.01, strain=25.0, seed=1,
                              out=str(tmp_path / "table8.json"))
    alpha, phi_m = 0.8, 0.6

    def row(phi_bulk, phi_core, status="finished", short=False):
        eta = alpha * (1 - phi_core / phi_m) ** -2
        return dict(phi_bulk_table8=phi_bulk, phi_core=phi_core, eta_s=eta, eta_s_err=0.02 * eta,
                    status=status, window_short=short)

    rows = [row(0.27, 0.31), row(0.32, 0.366), row(0.37, 0.41), row(0.47, 0.50, status="partial", short=True)]
    # the partial row far off the curve: fitted, it would move phi_m
    rows[3]["eta_s"] *= 0.5
    fit = table8.summarise(rows, args)["fit"]
    assert fit["rows"] == [0.27, 0.32, 0.37] and fit["not_fitted"] == [0.47]
    assert abs(fit["alpha"] - alpha) < 1e-6 and abs(fit["phi_m"] - phi_m) < 1e-6
    assert "fit" not in table8.summarise(rows[:2] + rows[3:], args)
    # a finished row whose position update limited too many gap targets (too large a time step, its stress
    # low): listed, not fitted
    # (the counts of the coupled phi 0.47 small scene at dt 0.02 and 0.01, docs/benchmarks.md)
    rows[3].update(status="finished", window_short=False,
                   position_update=dict(steps=400, fallback_steps=333, limited=1050, fallback_fraction=0.8325,
                                        particles=98, limited_per_particle_step=1050 / (400 * 98)))
    summary = table8.summarise(rows, args)
    assert summary["fit"]["not_fitted"] == [0.47]
    rows[3]["position_update"].update(steps=800, fallback_steps=104, limited=212, fallback_fraction=0.13,
                                      limited_per_particle_step=212 / (800 * 98))
    assert table8.summarise(rows, args)["fit"]["rows"] == [0.27, 0.32, 0.37, 0.47]


def test_table8_takes_rows_of_earlier_summaries(tmp_path):
    """--rows-from: rows of earlier summaries (runs made elsewhere, or gone with their machine) join the
    rows run here for the other phi_bulk; a row whose particle step exceeds the largest good one at its
    phi_bulk (0.32 at 0.04) is listed, not fitted; each keeps its own dt and fluid_every."""
    import json
    table8 = load_case_module("couette", "table8")
    alpha, phi_m = 0.8, 0.6

    def row(phi_bulk, phi_core, dt):
        eta = alpha * (1 - phi_core / phi_m) ** -2
        return dict(phi_bulk_table8=phi_bulk, phi_core=phi_core, eta_s=eta, eta_s_err=0.02 * eta, dt=dt,
                    status="finished", window_short=False)

    earlier = tmp_path / "earlier.json"
    earlier.write_text(json.dumps(dict(rows=[row(0.27, 0.31, 0.04), row(0.32, 0.366, 0.04), row(0.37, 0.41, 0.02),
                                             row(0.47, 0.50, 0.02)])))
    summary = table8.main(["--analyse-only", "--phis", "0.42", "0.47", "--workdir", str(tmp_path),
                           "--out", str(tmp_path / "t.json"), "--rows-from", str(earlier)])
    assert [r["phi_bulk_table8"] for r in summary["rows"]] == [0.27, 0.32, 0.37, 0.42, 0.47]
    assert [r["status"] for r in summary["rows"]][3:] == ["not started"] * 2   # run here: none yet
    assert summary["dt"]["0.32"] == 0.04 and summary["fluid_every"]["0.32"] == 1
    assert summary["dt"]["0.47"] == 0.01 and summary["fluid_every"]["0.47"] == 2   # the rule, run here
    assert "fit" not in summary                                 # two rows fitted: 0.32 is beyond its good step
    earlier.write_text(json.dumps(dict(rows=[row(0.27, 0.31, 0.04), row(0.32, 0.366, 0.04), row(0.37, 0.41, 0.02),
                                             row(0.42, 0.455, 0.02)])))
    fit = table8.main(["--analyse-only", "--phis", "0.47", "--workdir", str(tmp_path), "--out",
                       str(tmp_path / "t.json"), "--rows-from", str(earlier)])["fit"]
    assert fit["rows"] == [0.27, 0.37, 0.42] and fit["not_fitted"] == [0.32]
    assert abs(fit["alpha"] - alpha) < 1e-6 and abs(fit["phi_m"] - phi_m) < 1e-6
    bad = tmp_path / "bad.json"
    bad.write_text("{}")
    with pytest.raises(SystemExit, match="bad.json is not a table8.py summary"):
        table8.main(["--analyse-only", "--phis", "0.47", "--workdir", str(tmp_path), "--out", str(tmp_path / "t.json"),
                     "--rows-from", str(bad)])


def test_table8_finds_the_run_of_its_fluid_every(tmp_path):
    """A row's run folder is the one of its particle step and fluid_every: the run with the fluid at every
    step (no suffix) and the one with particle steps between fluid steps are different rows."""
    table8 = load_case_module("couette", "table8")
    base = "table8_phi0.47_25x25x20_ad3_dt0.01_seed1_calibrated"
    for name in (base, base + "_fluidEvery2"):
        (tmp_path / name).mkdir()
    assert table8.find_run(str(tmp_path), 0.47, 3, 0.01, 1, "calibrated") == str(tmp_path / base)
    assert table8.find_run(str(tmp_path), 0.47, 3, 0.01, 1, "calibrated", 2) == str(tmp_path / (base + "_fluidEvery2"))
    assert table8.find_run(str(tmp_path), 0.47, 3, 0.01, 1, "calibrated", 4) is None
    # and the run with coulomb_solve consistent is another row again
    assert table8.find_run(str(tmp_path), 0.47, 3, 0.01, 1, "calibrated", 2, "consistent") is None
    (tmp_path / (base + "_fluidEvery2_coulombConsistent")).mkdir()
    assert table8.find_run(str(tmp_path), 0.47, 3, 0.01, 1, "calibrated", 2) == str(tmp_path / (base + "_fluidEvery2"))
    assert (table8.find_run(str(tmp_path), 0.47, 3, 0.01, 1, "calibrated", 2, "consistent")
            == str(tmp_path / (base + "_fluidEvery2_coulombConsistent")))


def test_table8_runs_rows_at_once_and_names_a_stopped_one(tmp_path, monkeypatch):
    """--jobs 2: the two densest rows run at the same time and the third waits for one of them; a row whose run
    fdmRun stops (run_row's SystemExit) lets the others finish, the summary is written, and table8.py
    then ends naming it. The rows' runs are replaced by a pause here: this is the scheduling alone."""
    import json
    import time
    table8 = load_case_module("couette", "table8")
    spans = {}

    def run_row(phi, args):
        begin = time.monotonic()
        time.sleep(0.5)
        spans[phi] = (begin, time.monotonic())
        if phi == 0.32:
            raise SystemExit("table8: fdmRun stopped with exit code 1 on the row 0.32")
        return None

    monkeypatch.setattr(table8, "run_row", run_row)
    out = tmp_path / "table8.json"
    with pytest.raises(SystemExit, match="row 0.32"):
        table8.main(["--phis", "0.27", "0.32", "0.37", "--jobs", "2", "--workdir", str(tmp_path), "--out", str(out)])
    assert set(spans) == {0.27, 0.32, 0.37}
    # launched densest first: 0.37 and 0.32 at once, 0.27 when a worker was free
    (a0, a1), (b0, b1), (c0, _) = spans[0.37], spans[0.32], spans[0.27]
    assert b0 < a1 and a0 < b1                  # the first two at once
    assert c0 >= min(a1, b1) - 0.05             # the third when a worker was free
    assert [r["status"] for r in json.loads(out.read_text())["rows"]] == ["not started"] * 3
    assert table8.default_jobs(1) >= table8.default_jobs(2) >= 1


def test_particle_side_alone_from_a_written_scene(tmp_path, env):
    """timeStepWithoutFluid.py --phi: the scene written by couette.py --write-only (not run), then its particle
    side alone in the background shear; the bulk particle stress holds at least the spheres' own stresslets
    (eta_r >= 1 + 2.5 phi: lubrication and contacts only add), and the row has the position update's counts."""
    tool = load_case_module("couette", "timeStepWithoutFluid")
    out = tmp_path / "t.json"
    summary = tool.main(["--phi", "0.3", "--size", "8", "12", "7", "--dts", "0.04", "--strain", "4", "--from-strain",
                         "1", "--workdir", str(tmp_path / "w"), "--out", str(out)])
    scene = os.path.join(summary["run"], "dem")
    assert os.path.isfile(os.path.join(scene, "in.couette")) and not os.path.exists(os.path.join(summary["run"], "log.dem"))
    row = summary["rows"][0]
    phi = float(os.path.basename(summary["run"]).split("_")[0][3:])
    assert 0.28 < phi < 0.32
    assert row["eta_r"] >= 1 + 2.5 * phi, row
    assert row["position_update"]["steps"] == 100, row["position_update"]
    assert json.loads(out.read_text())["rows"][0]["dt"] == 0.04


def test_table8_progress_lines_read_the_runs_own_log(tiny_run, tmp_path):
    """table8.py's progress line reads fdmFoam's last 'Step N ... | ETA S s' line of a row's log (the tiny
    run's real log here, copied as table8 names a row's log): the last step done, its strain against the
    target, the rows still waiting; nothing once no row runs or waits."""
    table8 = load_case_module("couette", "table8")
    log = os.path.join(tiny_run["run_dir"], "log.fluid")
    step, eta = table8.last_progress(log)
    assert step == tiny_run["steps"] and eta >= 0
    assert table8.last_progress(str(tmp_path / "missing.log")) is None
    run_dir = str(tmp_path / "table8_phi0.25_tiny")
    with open(log) as src, open(run_dir + ".log", "w") as dst:
        dst.write(src.read())
    with table8.running(run_dir, 0.25, tiny_run["dt"], 2 * tiny_run["steps"]):
        line = table8.progress_report([0.54, 0.52])
        assert "phi_bulk 0.25 at strain %.1f of %.1f, ETA" % (0.4, 0.8) in line
        assert line.endswith("waiting: 0.52, 0.54")
        with table8.running(str(tmp_path / "not_started"), 0.3, 0.02, 100):
            assert "phi_bulk 0.3 starting" in table8.progress_report([])
    assert table8.progress_report([]) is None


def test_table8_summary_draws_fig21_and_fig22_from_earlier_rows(tmp_path):
    """table8.py --analyse-only with the rows of a shipped summary (docs/data/validation_table8_fluidEvery.json:
    all seven of the paper's) and one row not run (0.58, outside the shipped ones: a listed row replaces the
    shipped row of its phi) writes the summary with both figures, Fig. 21 and Fig. 22 (normal stresses), and
    refits the same Maron-Pierce parameters from the same rows; --out may name a folder not made yet."""
    table8 = load_case_module("couette", "table8")
    shipped = os.path.join(PROJECT, "docs", "data", "validation_table8_fluidEvery.json")
    out = tmp_path / "report" / "t8.json"
    summary = table8.main(["--analyse-only", "--phis", "0.58", "--workdir", str(tmp_path / "runs"),
                           "--rows-from", shipped, "--out", str(out)])
    assert (out.parent / summary["figure"]).stat().st_size > 0
    assert summary["figure_normal_stresses"] == "t8_normal_stresses.png"
    assert (out.parent / summary["figure_normal_stresses"]).stat().st_size > 0
    assert json.loads(out.read_text())["rows"] == summary["rows"]
    with open(shipped) as f:
        fit = json.load(f)["fit"]
    assert abs(summary["fit"]["alpha"] - fit["alpha"]) < 1e-6 and abs(summary["fit"]["phi_m"] - fit["phi_m"]) < 1e-6
