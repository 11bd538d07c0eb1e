"""Suspensions of any size distribution (docs/cases/couette.md, "Any size distribution"): the distribution
writer (each species' share of the particle volume within the rounding of its count, no overlap, one atom
type per radius in the LIGGGHTS input), the paper's suspension unchanged, the errors for bad input, the
refusal of an uncalibrated scene (one line per missing pair, with the command that measures it), the
calibration table each results.json records, and the per-species profiles. No coupled run here: the scenes
are written, not run (the end-to-end run is in docs/cases/couette.md)."""
import hashlib
import json
import math
import os
import time

import numpy as np
import pytest

from conftest import PROJECT, assert_refused, load_case_module
from fdmsubgrid import checkpoint, couettescene, packing, profiles, results, suspension

THREE = packing.SizeDistribution.of([1.0, 1.2, 1.4], [0.4, 0.3, 0.3])
TABLE = os.path.join(PROJECT, "dem", "resistance", "data", "subgrid_calibration.dat")


@pytest.fixture(scope="module")
def couette():
    return load_case_module("couette")


def pair_gaps(pack):
    """Every pair's surface gap by brute force (minimum image along the periodic axes), independent of the
    packing's neighbour search."""
    x, a, box = pack.positions, pack.radii, pack.box
    i, j = np.triu_indices(pack.n, 1)
    d = x[i] - x[j]
    for axis in (k for k in range(3) if k not in pack.walls):
        d[:, axis] -= box[axis] * np.round(d[:, axis] / box[axis])
    return np.linalg.norm(d, axis=1) - a[i] - a[j]


def read_atoms(path):
    """(type, radius) of every atom of a LIGGGHTS data file (atom_style sphere: id type diameter density x y z)
    and its declared number of atom types."""
    lines = open(path).read().splitlines()
    ntypes = next(int(line.split()[0]) for line in lines if line.endswith("atom types"))
    start = lines.index("Atoms") + 2
    atoms = [line.split() for line in lines[start:] if line.strip()]
    return [(int(w[1]), 0.5 * float(w[2])) for w in atoms], ntypes


def test_a_distribution_packs_with_its_volume_fractions_and_no_overlap():
    box = (12.0, 12.0, 10.0)
    pack = packing.channel_packing(box, phi=0.35, seed=3, min_gap=0.01, wall_gap=0.01, sizes=THREE)
    shares = {t: share for t, _, _, share in pack.species()}
    tolerance = THREE.volume_tolerance(float(np.prod(box)), pack.phi)
    for k, (radius, fraction) in enumerate(zip(THREE.radii, THREE.volume_fractions)):
        mask = pack.types == k + 1
        assert np.all(pack.radii[mask] == radius)                     # one radius per atom type
        assert abs(shares[k + 1] - fraction) <= tolerance[k] * 1.05, (k, shares[k + 1], fraction, tolerance[k])
    assert pair_gaps(pack).min() >= 0.01 and pack.min_wall_gap >= 0.01
    assert np.all(pack.positions[:, 1] - pack.radii >= 0.01)
    assert np.all(box[1] - pack.positions[:, 1] - pack.radii >= 0.01)
    # the periodic cube of python3 -m fdmsubgrid.packing too
    cube = packing.random_packing(200, 0.4, seed=1, sizes=THREE)
    assert pair_gaps(cube).min() >= 1e-4 * (1 - 1e-9)
    assert {t: r for t, r, _, _ in cube.species()} == {1: 1.0, 2: 1.2, 3: 1.4}
    # a count of spheres (Table 8's N_P) is split by volume too
    numbers = THREE.counts_for_number(500)
    assert sum(numbers) == 500
    volumes = np.array(numbers) * np.array(THREE.radii) ** 3
    assert np.allclose(volumes / volumes.sum(), THREE.volume_fractions, atol=0.01)


def test_lognormal_distribution():
    d = packing.SizeDistribution.lognormal(1.2, 0.2, 5)
    assert d.n_species == 5 and abs(sum(d.volume_fractions) - 1) < 1e-12
    assert math.isclose(d.radii[2], 1.2) and math.isclose(d.radii[0] * d.radii[4], 1.2 ** 2)
    assert list(d.radii) == sorted(d.radii)
    # the volume weighting shifts the shares towards the large spheres
    assert d.volume_fractions[3] > d.volume_fractions[1]


def test_the_scene_writes_each_species_as_an_atom_type(env, tmp_path):
    written = couettescene.write_run(str(tmp_path), (10, 12, 8), dt=0.02, strain=1.0, phi=0.3, sizes=THREE)
    pack = written["pack"]
    atoms, ntypes = read_atoms(os.path.join(written["run_dir"], "dem", "spheres.data"))
    assert ntypes == 3 and len(atoms) == pack.n
    assert {t: r for t, r in atoms} == {1: 1.0, 2: 1.2, 3: 1.4}
    assert sorted(t for t, _ in atoms) == sorted(pack.types.tolist())
    dem = open(os.path.join(written["run_dir"], "dem", "in.couette")).read()
    assert "pair_coeff      * *" in dem
    assert written["name"].endswith("_r1-1.2-1.4_f0.4-0.3-0.3")
    # the springs: the design load of the largest sphere (6 pi a_max^2 tau), the resistances of the smallest pair
    tau = couettescene.ETA * couettescene.SHEAR_RATE * suspension.maron_pierce_viscosity(pack.phi)
    assert math.isclose(written["springs"].design_load, 6 * math.pi * 1.4 ** 2 * tau, rel_tol=1e-12)


def test_the_springs_and_time_step_follow_the_sizes(env):
    delta = 1 / 3
    wide = packing.SizeDistribution.of([1.0, 2.0], [0.5, 0.5])
    small = packing.SizeDistribution.of([0.7, 1.0], [0.5, 0.5])
    paper = suspension.choose_springs(1.0, 0.02, delta)
    assert suspension.choose_springs(1.0, 0.02, delta, sizes=packing.PAPER_SUSPENSION) == paper
    assert math.isclose(suspension.choose_springs(1.0, 0.02, delta, sizes=wide).design_load,
                        paper.design_load * (2.0 / 1.4) ** 2, rel_tol=1e-12)
    # the smallest pair's resistance: a pair of radius 0.7 resists less than a pair of a1 (both in the cut-off
    # model: the shipped calibration has no pair at a/Delta 2.1, and a scene with one is refused before its springs)
    assert (suspension.choose_springs(1.0, 0.02, delta, sizes=small, model="cutoff").zeta_n
            < suspension.choose_springs(1.0, 0.02, delta, model="cutoff").zeta_n)
    # the time step: unchanged for the paper's ratio 1.4 and below, shortened as (a_min/a_max)^2 beyond
    assert suspension.time_step_factor(packing.PAPER_SUSPENSION) == 1.0
    assert suspension.time_step_factor(THREE) == 1.0
    assert math.isclose(suspension.time_step_factor(wide), (0.5 / (1 / 1.4)) ** 2)
    assert couettescene.largest_good_dt(0.3, wide) == 0.0098   # 0.02 x 0.49, two digits
    assert couettescene.largest_good_dt(0.3, packing.PAPER_SUSPENSION) == couettescene.largest_good_dt(0.3)
    assert "time_step_factor" in couettescene.time_step_warning(0.3, 0.02, wide)


def test_the_paper_suspension_is_unchanged(couette, env, tmp_path):
    """The default scene is the paper's (docs/cases/couette.md: 47 spheres, 34 a1 and 13 a2, phi_bulk 0.3040),
    and giving its radii and fractions explicitly writes the same bytes."""
    default = couette.main(["--write-only", "--workdir", str(tmp_path / "default")])
    explicit = couette.main(["--write-only", "--workdir", str(tmp_path / "explicit"), "--radii", "1", "1.4",
                             "--volume-fractions", "0.5", "0.5"])
    assert os.path.basename(default["run_dir"]) == os.path.basename(explicit["run_dir"]) == \
        "phi0.304001_10x12x8_ad3_dt0.02_seed1_calibrated"
    for folder in ("dem", "fluid/system", "fluid/constant"):
        a, b = os.path.join(default["run_dir"], folder), os.path.join(explicit["run_dir"], folder)
        for name in sorted(os.listdir(a)):
            if os.path.isfile(os.path.join(a, name)):
                assert open(os.path.join(a, name), "rb").read() == open(os.path.join(b, name), "rb").read(), name
    atoms, ntypes = read_atoms(os.path.join(default["run_dir"], "dem", "spheres.data"))
    assert ntypes == 2 and sum(t == 1 for t, _ in atoms) == 34 and sum(t == 2 for t, _ in atoms) == 13
    assert {t: r for t, r in atoms} == {1: 1.0, 2: 1.4}
    assert default["dt"] == 0.02
    # the counts of the former bidisperse rule
    assert packing.PAPER_SUSPENSION.counts_for_number(956) == list(packing.counts(956, True))


def test_bad_sizes_are_refused_by_value(couette, tmp_path, capsys):
    with pytest.raises(packing.SizeDistributionError, match="sum to 1.1"):
        packing.SizeDistribution.of([1, 1.4], [0.5, 0.6])
    with pytest.raises(packing.SizeDistributionError, match="2 radii .* but 3 volume fractions"):
        packing.SizeDistribution.of([1, 1.4], [0.2, 0.3, 0.5])
    with pytest.raises(packing.SizeDistributionError, match="radius -1 is not a positive"):
        packing.SizeDistribution.of([-1, 1.4])
    with pytest.raises(packing.SizeDistributionError, match="radius 1.4 is given twice"):
        packing.SizeDistribution.of([1.4, 1, 1.4])
    assert_refused(couette.main, ["--radii", "1", "1.4", "--volume-fractions", "0.5", "0.6"], "sum to 1.1",
                   tmp_path, capsys)
    # the smallest sphere sets the mesh: 0.5 a1 at a1/Delta 3 is 1.5 cells
    assert_refused(couette.main, ["--radii", "0.5", "1"], ["radius 0.5 a1 is 1.5 mesh cells",
                                                           "--a-over-delta 4 or more"], tmp_path, capsys)
    assert_refused(couette.main, ["--distribution", "gamma", "1", "1", "3"], "lognormal MEDIAN SIGMA N",
                   tmp_path, capsys)
    with pytest.raises(ValueError, match="no random packing"):
        packing.channel_packing((10, 10, 10), phi=0.66, sizes=THREE)
    with pytest.raises(ValueError, match="radius 2 a1 gets no sphere"):
        packing.channel_packing((10, 10, 10), phi=0.1, sizes=packing.SizeDistribution.of([1, 2], [0.99, 0.01]))


def test_an_uncalibrated_scene_is_refused_one_line_per_pair(couette, env, tmp_path):
    """issue 50's example: phi 0.4 in 12^3 a1 at a1/Delta 6. Each (a1/Delta, a2/a1) pair or wall a/Delta that
    neither the table nor the interpolation within 2 % covers gets one line naming the command that measures it
    (deminput.scene_calibration, subgridinterp.refusal); the wall of radius 1 at a/Delta 6, interpolated within
    0.6 %, is named as such; then the table's line and the cut-off alternative. Nothing is written."""
    with pytest.raises(SystemExit) as refused:
        couette.main(["--phi", "0.4", "--size", "12", "12", "12", "--a-over-delta", "6", "--write-only",
                      "--workdir", str(tmp_path)])
    lines = str(refused.value).splitlines()
    assert lines[0] == ("couette: the sub-grid calibration (model calibrated) lacks 4 of this scene's pairs and walls "
                        "beyond what the interpolation reaches within 2 %:")
    missing = lines[1:5]
    assert all("python3 -m fdmsubgrid.calibration --a-over-delta" in line for line in missing)
    [one] = [line for line in missing if "radii 1 and 1 " in line]
    assert one.startswith("  the pair of radii 1 and 1 at a1/Delta 6 (a2/a1 1): not calibrated, interpolation error "
                          "3.0 % > 2 %; measure it (about ")
    assert one.endswith(" core-seconds): python3 -m fdmsubgrid.calibration --a-over-delta 6 --ratios 1 --no-wall "
                        "--boxes 8 12 --cache")
    assert {line.split(":")[0].strip() for line in missing} == {
        "the pair of radii 1 and 1 at a1/Delta 6 (a2/a1 1)", "the pair of radii 1 and 1.4 at a1/Delta 6 (a2/a1 1.4)",
        "the pair of radii 1.4 and 1.4 at a1/Delta 8.4 (a2/a1 1)", "radius 1.4 against a wall at a/Delta 8.4"}
    assert lines[5] == "  interpolated within 2 %: radius 1 at a wall (a/Delta 6, error 0.6 %)"
    assert lines[-2] == ("  dem/resistance/data/subgrid_calibration.dat has pairs a1/Delta 3, 4, 5 x a2/a1 1, 1.4; "
                         "5.6 x 1; walls a/Delta 3, 4, 5, 5.6 (interpolated between)")
    assert lines[-1].startswith("  or --model cutoff (squeeze up to 16 % off")
    assert len(lines) == 8
    assert os.listdir(tmp_path) == []


def test_results_record_the_calibration_table(env, tmp_path):
    """results.json names the table the run started with (fdmRun's record) and its SHA-256; a run of the
    cut-off model reads none."""
    calibrated = couettescene.write_run(str(tmp_path), (10, 12, 8), dt=0.02, strain=0.1, phi=0.2)["run_dir"]
    cutoff = couettescene.write_run(str(tmp_path), (10, 12, 8), dt=0.02, strain=0.1, phi=0.2, model="cutoff")["run_dir"]
    script = os.path.join(PROJECT, "cases", "couette", "couette.py")
    digest = hashlib.sha256(open(TABLE, "rb").read()).hexdigest()
    for run_dir, expected in ((calibrated, dict(table="dem/resistance/data/subgrid_calibration.dat", sha256=digest)),
                              (cutoff, dict(table=None, sha256=None))):
        checkpoint.stamp(run_dir, os.path.join(run_dir, "dem", "in.couette"))     # as fdmRun does at the start
        out = os.path.join(run_dir, "results.json")
        results.write_results(out, script, [], {}, [], dict(run_dir=run_dir), time.time())
        assert json.load(open(out))["calibration"] == [expected]
        assert results.read_results(out).calibration == [expected]
    # a run folder without fdmRun's record (an older run): nothing claimed
    bare = tmp_path / "bare"
    bare.mkdir()
    results.write_results(str(bare / "results.json"), script, [], {}, [], dict(run_dir=str(bare)), time.time())
    assert results.read_results(str(bare / "results.json")).calibration == []


def test_per_species_profiles_of_a_synthetic_record():
    """Two species in layers: the small spheres low in the channel, the large high. Each species' phi(y) is its
    own spheres' (zero where none reaches), the species add up to the total bin by bin, and each integrates to
    its own volume; the core volume fractions add up to the whole suspension's."""
    rng = np.random.default_rng(7)
    channel = profiles.Channel.centred((8.0, 12.0, 8.0))
    box_lo = channel.y_lo
    snapshots = []
    for k in range(16):
        small = np.column_stack([rng.uniform(0, 8, 6), box_lo + rng.uniform(1.0, 4.0, 6), rng.uniform(0, 8, 6)])
        large = np.column_stack([rng.uniform(0, 8, 4), box_lo + rng.uniform(8.0, 10.6, 4), rng.uniform(0, 8, 4)])
        x = np.vstack([small, large])
        radii = np.r_[np.full(6, 1.0), np.full(4, 1.4)]
        types = np.r_[np.ones(6, dtype=int), np.full(4, 2)]
        snapshots.append(profiles.Snapshot(x, radii, velocities=np.tile([1.0, 0, 0], (10, 1)), types=types,
                                           time=0.1 * k))
    total = profiles.average_profiles(snapshots, channel)
    species = profiles.species_profiles(snapshots, channel, h_layer=2.0)
    assert [(sp.type, sp.radius, sp.n) for sp in species] == [(1, 1.0, 6), (2, 1.4, 4)]
    assert np.allclose(species[0].average.phi + species[1].average.phi, total.phi, rtol=0, atol=1e-12)
    width = np.diff(total.edges)
    area = channel.area
    for sp in species:
        volume = sp.n * 4 / 3 * math.pi * sp.radius ** 3
        assert math.isclose(np.sum(sp.average.phi * width) * area, volume, rel_tol=1e-12)
    low = total.y - box_lo
    assert np.all(species[0].average.phi[low > 5.5] == 0) and np.all(species[1].average.phi[low < 6.5] == 0)
    core = profiles.core_series(snapshots, channel, h_layer=2.0).phi.mean()
    assert math.isclose(species[0].phi_core + species[1].phi_core, core, rel_tol=1e-12)
    summary = profiles.species_summary(species, channel.volume)
    assert [round(s["phi_bulk"], 12) for s in summary] == [round(6 * 4 / 3 * math.pi / channel.volume, 12),
                                                         round(4 * 4 / 3 * math.pi * 1.4 ** 3 / channel.volume, 12)]
    assert json.loads(json.dumps(summary)) == summary
