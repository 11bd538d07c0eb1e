"""Parallel runs give the serial answers: the fluid on N MPI ranks (fdmRun -f N, the mesh split by
scripts/fdmsubgrid/decomposition.py for any N the mesh allows) and the particles on N ranks (fdmRun -d N).

The scene: six spheres (a/Delta = 2) in a shear cell of 16 x 12 x 12 cells, periodic in x and z,
walls moving at -/+0.5 in y, with sub-grid lubrication (two close pairs, one sphere near a wall),
contact (both pairs inside h_r) and stresslets. Sphere 1 straddles the periodic face x = 0, the
pairs 3-4 and 4-6 straddle x = 2 and x = 2.67 (LIGGGHTS's cuts on 2 and 3 ranks), spheres 2, 3, 4
and 6 the fluid's cuts (test_scene_straddles_the_cuts). The solver tolerances are tight
(relTol 0) and tolLambda 0 runs a fixed number of inner iterations, so that serial and parallel
runs differ by round-off only, not by where an iteration stopped: measured at most 1e-10 relative
(the stresslets; displacements 2e-12) on 3 and 4 fluid ranks, bit for bit on 2 and 3 particle ranks."""
import os
import subprocess

import numpy as np
import pytest

from fdmsubgrid import case, decomposition

DELTA = 0.25
BOX = case.Box((0, 0, 0), (4.0, 3.0, 3.0), DELTA, faces=("cyclic", ((-0.5, 0, 0), (0.5, 0, 0)), "cyclic"))
CELLS, PERIODIC = (16, 12, 12), (True, False, True)
SPHERES = [(0.1, 1.5, 2.4, 0.5), (1.45, 1.0, 2.9, 0.5), (1.48, 1.6, 1.2, 0.5), (2.49, 1.75, 1.2, 0.5),
           (3.0, 0.56, 2.0, 0.5), (3.50, 1.70, 1.2, 0.5)]
STENCIL_C = 0.3       # indicator c of write_fluid_case: the stencil reaches a + c Delta
STEPS = 2
# dumped per particle: id, x(3), v(3), omega(3), then fix fdm/couple's 25 per-atom columns
COLUMNS = "id x y z vx vy vz omegax omegay omegaz " + " ".join("f_couple[%d]" % i for i in range(1, 26))
GROUPS = {"displacement": slice(1, 4), "velocity": slice(4, 7), "angular velocity": slice(7, 10),
          "fluid force and torque": slice(10, 16), "sub-grid force and torque": slice(16, 22),
          "stresslet": slice(22, 29), "contact stresslet": slice(29, 35)}
TOLERANCE = 1e-6


def write_scene(root):
    fluid = os.path.join(root, "fluid")
    case.write_fluid_case(fluid, BOX, tol_lambda=0, n_max=10, tol_u=1e-12, tol_p=1e-11, n_particles=len(SPHERES))
    path = os.path.join(fluid, "system", "fvSolution")
    with open(path) as f:
        text = f.read()
    with open(path, "w") as f:
        f.write(text.replace("relTol          0.01;", "relTol          0;"))
    dump = ("dump            d all custom 1 dump.particles " + COLUMNS,
            'dump_modify     d sort id format "%d' + " %.17g" * (len(COLUMNS.split()) - 1) + '"')
    case.write_dem_input(os.path.join(root, "dem"), BOX, SPHERES, dt=0.05, fix_options="stresslets yes",
                         # a/Delta = 2: outside the calibration table of the default model; the ranks must agree with either
                         pair_style="fdm/subgrid model cutoff contact 50 20 0.5 0.03 wall ylo -0.5 0 0 wall yhi 0.5 0 0",
                         runs=dump + ("run %d" % STEPS,))
    return root


def run_scene(root, np_fluid=1, np_dem=1):
    write_scene(root)
    case.run(root, np_fluid=np_fluid, np_dem=np_dem)
    return read_dump(os.path.join(root, "dem", "dump.particles"))


def read_dump(path):
    """The dumped frames as an array (frame, particle by id, column)."""
    frames = []
    with open(path) as f:
        lines = f.read().splitlines()
    for i, line in enumerate(lines):
        if line.startswith("ITEM: NUMBER OF ATOMS"):
            n = int(lines[i + 1])
            start = next(j for j in range(i, len(lines)) if lines[j].startswith("ITEM: ATOMS")) + 1
            assert lines[start - 1].split()[2:] == COLUMNS.split(), lines[start - 1]
            frames.append(np.loadtxt(lines[start:start + n], ndmin=2))
    return np.array(frames)


def last_contacts(root):
    """The contact count of fix fdm/couple's timing line (last step of the run)."""
    with open(os.path.join(root, "log.dem")) as f:
        line = next(l for l in f if "fdm/couple timing of this run" in l)
    return int(line.split(" contacts")[0].rsplit(" ", 1)[1])


def assert_same(reference, frames, what):
    assert frames.shape == reference.shape, (what, frames.shape, reference.shape)
    assert (frames[:, :, 0] == reference[:, :, 0]).all()
    for name, columns in GROUPS.items():
        a, b = reference[:, :, columns], frames[:, :, columns]
        if name == "displacement":  # from the first frame: the motion, not the position in the box
            a, b = a - reference[:1, :, columns], b - reference[:1, :, columns]
        scale = np.abs(a).max()
        assert scale > 0, name  # every quantity is exercised
        error = np.abs(a - b).max() / scale
        assert error < TOLERANCE, "%s: %s differs from serial by %.2e relative" % (what, name, error)


@pytest.fixture(scope="module")
def serial(tmp_path_factory, env):
    root = str(tmp_path_factory.mktemp("serial"))
    return root, run_scene(root)


# ---- the split ---------------------------------------------------------------------------------

def test_split_has_the_fewest_processor_faces():
    # the scene's mesh: a cut across the walled direction y costs one plane, across a periodic
    # one two (the cyclic faces join two ranks too)
    assert decomposition.choose_split(CELLS, PERIODIC, 2) == (1, 2, 1)
    assert decomposition.choose_split(CELLS, PERIODIC, 3) == (1, 3, 1)
    assert decomposition.choose_split(CELLS, PERIODIC, 4) == (2, 2, 1)
    assert decomposition.choose_split(CELLS, PERIODIC, 7) == (7, 1, 1)   # 7 > 12: only x can take it
    assert decomposition.choose_split((100, 100, 100), (True,) * 3, 2) == (2, 1, 1)
    assert decomposition.choose_split((100, 100, 100), (True,) * 3, 8) == (2, 2, 2)
    # the fewest faces first, even if a split does not divide the cells (the hierarchical method
    # balances the cell counts either way)
    assert decomposition.choose_split((101, 10, 10), (False,) * 3, 2) == (2, 1, 1)
    assert decomposition.choose_split((30, 30, 100), (False,) * 3, 4) == (1, 1, 4)


@pytest.mark.parametrize("cells, n, why", [((16, 12, 12), 17, "no split n_x n_y n_z = 17 has n_x <= 16"),
                                            ((4, 4, 4), 65, "more ranks than the 64 cells")])
def test_split_refuses_what_the_mesh_cannot_take(cells, n, why):
    with pytest.raises(decomposition.DecompositionError) as error:
        decomposition.choose_split(cells, (True,) * 3, n)
    message = str(error.value)
    assert "%d x %d x %d mesh cannot be split into %d sub-domains" % (cells + (n,)) in message, message
    assert why in message, message


def test_mesh_layout_binary_and_ascii(tmp_path, env):
    for fmt in ("binary", "ascii"):
        root = write_scene(str(tmp_path / fmt))
        fluid = os.path.join(root, "fluid")
        control = os.path.join(fluid, "system", "controlDict")
        with open(control) as f:
            text = f.read()
        with open(control, "w") as f:
            f.write(text.replace("writeFormat     binary", "writeFormat     " + fmt))
        subprocess.run(["blockMesh", "-case", fluid], env=env, check=True, stdout=subprocess.DEVNULL,
                       stderr=subprocess.STDOUT)
        assert decomposition.mesh_layout(fluid) == (CELLS, PERIODIC), fmt


def test_case_own_decomposition_is_kept_or_refused(tmp_path):
    system = tmp_path / "fluid" / "system"
    system.mkdir(parents=True)
    own = system / "decomposeParDict"
    own.write_text("FoamFile { version 2.0; format ascii; class dictionary; object decomposeParDict; }\n"
                   "numberOfSubdomains 4;\nmethod simple;\nsimpleCoeffs { n (1 1 4); delta 0.001; }\n")
    fluid = str(tmp_path / "fluid")
    assert "the case's own decomposition" in decomposition.prepare(fluid, 4)
    with pytest.raises(decomposition.DecompositionError, match="numberOfSubdomains 4, method simple"):
        decomposition.prepare(fluid, 3)
    assert "numberOfSubdomains 4" in own.read_text()  # never overwritten
    own.write_text(own.read_text().replace("method simple", "method scotch"))
    with pytest.raises(decomposition.DecompositionError, match="scotch, a dummy library"):
        decomposition.prepare(fluid, 4)


def test_rank_count_the_mesh_cannot_take(tmp_path, env):
    root = write_scene(str(tmp_path / "bad"))
    proc = subprocess.run([os.path.join(env["FDM_ROOT"], "scripts", "fdmRun"), "-f", "17", root], env=env,
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=120)
    assert proc.returncode == 2, proc.stdout
    assert ("fdmRun: --np-fluid 17: the 16 x 12 x 12 mesh cannot be split into 17 sub-domains"
            in proc.stdout), proc.stdout
    assert not os.path.exists(os.path.join(root, "log.fluid"))  # stopped before starting anything


# ---- the answers -------------------------------------------------------------------------------

def stencil_subdomains(sphere, split):
    """Sub-domains holding the stencil cells of a sphere (cell centres within a + c Delta) for a
    split that divides the cells, and whether the stencil wraps a periodic face."""
    x, a = np.array(sphere[:3]), sphere[3]
    reach = a + STENCIL_C * DELTA
    ranges = [np.arange(int(np.floor((x[d] - reach) / DELTA)), int(np.floor((x[d] + reach) / DELTA)) + 1)
              for d in range(3)]
    subdomains, wraps = set(), False
    for i, j, k in ((i, j, k) for i in ranges[0] for j in ranges[1] for k in ranges[2]):
        index = np.array([i, j, k])
        if np.linalg.norm((index + 0.5) * DELTA - x) > reach:
            continue
        if ((index < 0) | (index >= CELLS)).any():
            wraps = True
        wrapped = index % CELLS
        subdomains.add(tuple(wrapped // (np.array(CELLS) // split)))
    return subdomains, wraps


@pytest.mark.parametrize("n", [3, 4])
def test_scene_straddles_the_cuts(n):
    split = decomposition.choose_split(CELLS, PERIODIC, n)
    assert all(c % s == 0 for c, s in zip(CELLS, split))
    shared = [stencil_subdomains(s, split) for s in SPHERES]
    assert sum(len(sub) > 1 for sub, _ in shared) >= 4, shared
    assert any(wraps for _, wraps in shared)
    if n == 4:  # sphere 1 across the periodic face x = 0, which joins two ranks in (2 2 1)
        assert len(shared[0][0]) > 1 and shared[0][1], shared[0]


@pytest.mark.parametrize("n", [3, 4])
def test_fluid_ranks_agree_with_serial(tmp_path, serial, n):
    root = str(tmp_path / ("fluid%d" % n))
    frames = run_scene(root, np_fluid=n)
    with open(os.path.join(root, "fluid", "system", "decomposeParDict")) as f:
        assert "n (%d %d %d)" % decomposition.choose_split(CELLS, PERIODIC, n) in f.read()
    assert_same(serial[1], frames, "fdmRun -f %d" % n)


@pytest.mark.parametrize("n", [2, 3])
def test_particle_ranks_agree_with_serial(tmp_path, serial, n):
    root = str(tmp_path / ("dem%d" % n))
    frames = run_scene(root, np_dem=n)
    with open(os.path.join(root, "log.dem")) as f:
        assert "%d by 1 by 1 MPI processor grid" % n in f.read()
    assert_same(serial[1], frames, "fdmRun -d %d" % n)
    # both contacts counted once, also where a pair is split between two ranks
    assert last_contacts(root) == last_contacts(serial[0]) == 2
