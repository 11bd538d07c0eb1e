"""cases/couette (paper 6.1) on a tiny scene: a bidisperse frictional suspension between walls at
-U and +U, run by the real fdmFoam and fdmDEM (about 30 s), and the case's bad input."""
import os

import numpy as np
import pytest

from conftest import load_case_module
from fdm import case, output, packing, profiles

TINY = ["--phi", "0.25", "--size", "7", "11", "7", "--a-over-delta", "3", "--dt", "0.02", "--strain", "0.4",
        "--dump-every", "0.02", "--seed", "3"]


@pytest.fixture(scope="module")
def couette():
    return load_case_module("couette")


@pytest.fixture(scope="module")
def tiny_run(couette, tmp_path_factory, env):
    work = tmp_path_factory.mktemp("couette")
    results = couette.main(TINY + ["--workdir", str(work), "--out", str(work / "results.json")])
    return results


def test_tiny_scene_runs_converged_and_integrates_phi_exactly(couette, tiny_run):
    r = tiny_run
    assert r["n_particles"] >= 15 and r["n_a1"] > 0 and r["n_a2"] > 0
    assert r["unconverged_steps"] == 0
    assert r["steps"] == 20
    snapshots, _ = output.suspension_snapshots(os.path.join(r["run_dir"], "dem", "particles.dump"), r["dt"])
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
