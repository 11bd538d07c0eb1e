"""Bad input gets a clear error naming the file, the particle or the value, and no code hangs.

Each test runs the real fdmFoam and fdmDEM on a tiny mesh through fdmRun and checks the exit
status, the message and that both codes stopped within seconds."""
import os
import re
import signal
import subprocess
import time
import warnings

import pytest

from fdmsubgrid import case, output

PROJECT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FDMRUN = os.path.join(PROJECT, "scripts", "fdmRun")


GRAD_P0 = (-0.01, 0, 0)


def make_case(tmp_path, spheres=((2.0, 2.0, 2.0, 0.5),), box=None, dem_box=None, n_particles=-1,
              fdm_edit=None, fix_options="move no", runs=("run 2",), pair_style="none", dt=1.0, connect_timeout=20,
              held=True):
    # connect_timeout: short, so that a case where one code never starts fails quickly, but not so short
    # that a loaded machine's start-up of the other code exceeds it (5 s did, beside two other jobs).
    # held: the particles carry V0 grad P0 (fix addforce), which balances the mean pressure gradient
    # (Eq. 43): the fully periodic box then has a steady flow (move no fixes places, not velocities)
    box = box or case.Box((0, 0, 0), (4, 4, 4), 0.5)
    root = str(tmp_path / "case")
    fluid = os.path.join(root, "fluid")
    case.write_fluid_case(fluid, box, grad_p0=GRAD_P0, tol_lambda=1e-3, n_max=50,
                          n_particles=n_particles)
    props = os.path.join(fluid, "constant", "fdmProperties")
    text = open(props).read().replace("connectTimeout 60", "connectTimeout %d" % connect_timeout)
    if fdm_edit:
        text = fdm_edit(text)
    open(props, "w").write(text)
    case.write_dem_input(os.path.join(root, "dem"), dem_box or box, list(spheres),
                         fix_options="connect_timeout %d " % connect_timeout + fix_options, runs=runs,
                         pair_style=pair_style, dt=dt,
                         before_run=case.balancing_force_line(box, GRAD_P0, max(len(spheres), 1)) if held else "")
    return root


def run_fdm(root, env, timeout=60):
    t0 = time.time()
    proc = subprocess.run([FDMRUN, "--quiet", root], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, errors="replace",
                          text=True, env=env, timeout=timeout)
    return proc.returncode, proc.stdout, time.time() - t0


def run_refused(root, env, pattern):
    """Runs the case, which must stop with a message matching the regular expression pattern;
    returns the logs and the wall time"""
    status, out, wall = run_fdm(root, env)
    assert status != 0
    text = logs(root)
    assert re.search(pattern, text), text[-2000:]
    return text, wall


def logs(root):
    return "".join(open(os.path.join(root, f), errors="replace").read() for f in ("log.fluid", "log.dem")
                   if os.path.exists(os.path.join(root, f)))


def test_reference_run_succeeds(tmp_path, env):
    """The scene the other tests break: it must run, or their failures would mean nothing."""
    root = make_case(tmp_path)
    status, out, _ = run_fdm(root, env)
    assert status == 0, out


def test_particle_crossing_a_wall(tmp_path, env):
    box = case.Box((0, 0, 0), (4, 4, 4), 0.5, faces=("cyclic", ((0, 0, 0), (0, 0, 0)), "cyclic"))
    root = make_case(tmp_path, spheres=[(2.0, 0.3, 2.0, 0.5)], box=box)
    status, out, wall = run_fdm(root, env)
    assert status != 0
    text = logs(root)
    assert re.search(r"particle 1\b", text), text[-2000:]
    assert "0.3" in text
    assert wall < 30


@pytest.mark.parametrize("fix_options", ["", "move no"])
def test_pressure_gradient_in_a_fully_periodic_box_with_free_particles(tmp_path, env, fix_options):
    """gradP0 in a box periodic in every direction, the sphere force-free: no steady Stokes flow
    exists (Eq. 43; the mean flow grew to 2e12 m/s within the first step before this check).
    fix fdm/couple stops before the first fluid solve, naming the loads, gradP0 and the remedies,
    whether the particles move or stay in place (move no fixes places, not velocities); the held sphere
    of the reference run (test_reference_run_succeeds) carries the force and passes."""
    root = make_case(tmp_path, fix_options=fix_options, runs=("run 3",), held=False)
    text, wall = run_refused(root, env, r"in a box periodic in every direction the loads on the free particles .* "
                             r"sum to \(0 0 0\) N but the fluid's imposed pressure gradient gradP0 = \(-0.01 0 0\) "
                             r"Pa/m needs V0 gradP0 = \(-0.64 0 0\) N")
    assert "constant/fdmProperties" in text and "fix addforce" in text and "move no" in text
    steps = os.path.join(root, "fluid", "postProcessing", "fdm", "steps.dat")
    assert not os.path.exists(steps) or all(line.startswith("#") for line in open(steps))
    assert wall < 30


def test_pressure_gradient_between_slip_walls_with_free_particles(tmp_path, env):
    """Slip walls take no force along gradP0: the box has no steady flow unless the particles carry
    V0 gradP0 (Eq. 43), which fdmFoam checks at a converged step (the particle side does not know the
    walls slip). The plain iteration with a loose velocity tolerance declares the growing mean flow
    converged at its fourth inner iteration: the check stops the run there, naming the remedy."""
    box = case.Box((0, 0, 0), (4, 4, 4), 0.5, faces=("cyclic", "slip", "cyclic"))

    def loose_plain_iteration(text):
        text = re.sub(r"tolLambda\s+[^;]+;", "tolLambda 0;", text)
        text = re.sub(r"tolVelocity\s+[^;]+;", "tolVelocity 0.5;", text)
        return re.sub(r"acceleration\s+\w+;", "acceleration none;", text)

    root = make_case(tmp_path, box=box, held=False, fdm_edit=loose_plain_iteration)
    text, wall = run_refused(root, env, r"gradP0 \(-0.01 0 0\) Pa/m in a box whose faces are periodic or slip \(no "
                             r"wall holds the fluid\) has no steady Stokes flow unless the particles carry its force, "
                             r"V0 gradP0 = \(-0.64 0 0\) N \(Eq. 43\); at time step 1")
    assert "fix addforce" in text
    assert wall < 30


def test_overlapping_particles(tmp_path, env):
    root = make_case(tmp_path, spheres=[(2.0, 2.0, 2.0, 0.5), (2.8, 2.0, 2.0, 0.5)])
    status, out, wall = run_fdm(root, env)
    assert status != 0
    text = logs(root)
    assert "overlap" in text.lower(), text[-2000:]
    assert re.search(r"\b1\b", text) and re.search(r"\b2\b", text)
    assert wall < 30


def test_missing_dictionary_entry(tmp_path, env):
    # neither tolerance of the inner iterations (case.py writes both)
    root = make_case(tmp_path, fdm_edit=lambda t: re.sub(r"\n\s*tol(Lambda|Velocity)[^\n]*", "", t, count=2))
    status, out, wall = run_fdm(root, env)
    assert status != 0
    text = logs(root)
    assert "tolLambda" in text and "fdmProperties" in text, text[-2000:]
    assert wall < 30


def test_inconsistent_dictionary_entry(tmp_path, env):
    root = make_case(tmp_path, fdm_edit=lambda t: t.replace("nMin        1;", "nMin        80;"))
    status, out, wall = run_fdm(root, env)
    assert status != 0
    text = logs(root)
    assert "nMin 80" in text and "fdmProperties" in text, text[-2000:]


def test_particle_count_mismatch(tmp_path, env):
    root = make_case(tmp_path, n_particles=3)
    status, out, wall = run_fdm(root, env)
    assert status != 0
    text = logs(root)
    assert "expects 3 particles" in text and "has 1" in text, text[-2000:]
    assert wall < 30


def test_domain_mismatch(tmp_path, env):
    root = make_case(tmp_path, dem_box=case.Box((0, 0, 0), (5, 4, 4), 0.5))
    status, out, wall = run_fdm(root, env)
    assert status != 0
    text = logs(root)
    assert "x extent" in text and "0 .. 5" in text and "0 .. 4" in text, text[-2000:]
    assert wall < 30


def test_fluid_alone_times_out(tmp_path, env):
    """fdmFoam waits for a particle code that never connects: a clear error within the timeout."""
    root = make_case(tmp_path, connect_timeout=5)
    subprocess.run(["blockMesh", "-case", os.path.join(root, "fluid")], env=env, check=True,
                   stdout=subprocess.DEVNULL)
    t0 = time.time()
    proc = subprocess.run(["fdmFoam", "-case", os.path.join(root, "fluid")], env=env, text=True, errors="replace",
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=60)
    assert proc.returncode != 0
    assert re.search(r"no peer|never connected|within", proc.stdout), proc.stdout[-2000:]
    assert time.time() - t0 < 20


def test_dem_alone_times_out(tmp_path, env):
    """fdmDEM waits for a fluid solver that never starts: a clear error within the timeout."""
    root = make_case(tmp_path, connect_timeout=5)
    t0 = time.time()
    proc = subprocess.run(["fdmDEM", "-in", "in.dem"], cwd=os.path.join(root, "dem"), env=env, text=True, errors="replace",
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=60)
    assert proc.returncode != 0
    assert re.search(r"coupling\.port|connect", proc.stdout), proc.stdout[-2000:]
    assert time.time() - t0 < 20


def test_peer_dies_mid_run(tmp_path, env):
    """The particle code is killed while the fluid waits on it: fdmFoam ends within seconds."""
    root = make_case(tmp_path, runs=("run 100000",))
    fluid = os.path.join(root, "fluid")
    subprocess.run(["blockMesh", "-case", fluid], env=env, check=True, stdout=subprocess.DEVNULL)
    with open(os.path.join(root, "log.fluid"), "w") as lf, open(os.path.join(root, "log.dem"), "w") as ld:
        pf = subprocess.Popen(["fdmFoam", "-case", fluid], env=env, stdout=lf, stderr=subprocess.STDOUT)
        pd = subprocess.Popen(["fdmDEM", "-in", "in.dem"], cwd=os.path.join(root, "dem"), env=env,
                              stdout=ld, stderr=subprocess.STDOUT)
        # wait until the coupled run is stepping
        deadline = time.time() + 60
        while time.time() < deadline and "Step " not in open(os.path.join(root, "log.fluid")).read():
            time.sleep(0.2)
        assert "Step " in open(os.path.join(root, "log.fluid")).read(), logs(root)[-2000:]
        pd.send_signal(signal.SIGKILL)
        t0 = time.time()
        status = pf.wait(timeout=30)
        stopped = time.time() - t0
    assert status != 0
    assert stopped < 10
    assert re.search(r"closed the connection|connection", open(os.path.join(root, "log.fluid")).read())


def fluid_alone(root, env):
    """fdmFoam alone on the case (meshed first): for errors it finds before waiting for fdmDEM."""
    fluid = os.path.join(root, "fluid")
    subprocess.run(["blockMesh", "-case", fluid], env=env, check=True, stdout=subprocess.DEVNULL)
    proc = subprocess.run(["fdmFoam", "-case", fluid], env=env, text=True, errors="replace",
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=60)
    return proc.returncode, proc.stdout


@pytest.mark.parametrize("where,good,bad,key,valid", [
    ("constant/fdmProperties", "gradP0  ", "gradPO  ", "gradPO", "indicator alphaLambda pseudoTimeFactor"),
    ("indicator", "{ b ", "{ bb ", "bb", "b c"),
    ("innerIterations", "tolLambda   ", "tolLamda   ", "tolLamda",
     "tolLambda tolVelocity nMax nMin firstStep acceleration depth meanFlowCorrection meanFlowDamping report"),
    ("innerIterations/firstStep", "innerIterations\n{", "innerIterations\n{\n    firstStep { nmax 10; }", "nmax",
     "tolLambda tolVelocity nMax"),
    ("output", "coupling\n{", "output { particleEvery 2; }\ncoupling\n{", "particleEvery", "particlesEvery"),
    ("coupling", "connectTimeout 20", "conectTimeout 20", "conectTimeout",
     "transport host port portFile directory record"),
])
def test_unknown_dictionary_entry(tmp_path, env, where, good, bad, key, valid):
    """A misspelt entry would silently take its default: it is refused, with the valid ones."""
    def misspell(text):
        assert good in text, good
        return text.replace(good, bad, 1)
    root = make_case(tmp_path, fdm_edit=misspell)
    status, out = fluid_alone(root, env)
    assert status != 0
    assert "unknown entry %s in %s; valid: %s" % (key, where, valid) in out, out[-2000:]
    assert "fdmProperties" in out


def test_used_case_folder_needs_overwrite(tmp_path, env):
    """A second run in the same folder would mix the old fluid state and records with fresh
    particles: refused; --overwrite deletes the outputs only and runs afresh."""
    root = make_case(tmp_path)
    status, out, _ = run_fdm(root, env)
    assert status == 0, out
    inputs = {}
    for rel in ("fluid/0/U", "fluid/system/controlDict", "fluid/constant/fdmProperties", "dem/in.dem",
                "dem/spheres.data"):
        inputs[rel] = open(os.path.join(root, rel)).read()
    fluid = os.path.join(root, "fluid")
    first = output.steps(fluid)["step"]

    status, out, _ = run_fdm(root, env)
    assert status == 2
    assert "holds a previous run" in out and "--overwrite" in out and "fluid/2" in out, out
    proc = subprocess.run([FDMRUN, "--resume", root], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          text=True, env=env)
    # a run without checkpoints (no 'checkpoint N' in fix fdm/couple) cannot be resumed: said so,
    # and nothing is touched (test_resume.py resumes runs that have them)
    assert proc.returncode == 2 and "has no checkpoint that both codes completed" in proc.stdout \
        and "checkpoint N" in proc.stdout, proc.stdout
    assert list(output.steps(fluid)["step"]) == list(first)

    proc = subprocess.run([FDMRUN, "--quiet", "--overwrite", root], stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, text=True, env=env, timeout=60)
    assert proc.returncode == 0, proc.stdout
    for rel, text in inputs.items():
        assert open(os.path.join(root, rel)).read() == text, rel
    # the records of the second run alone, from step 1, not appended to the first run's
    assert list(output.steps(fluid)["step"]) == list(first)
    assert "Starting time loop" in open(os.path.join(root, "log.fluid")).read()


def test_disk_full_stops_both_codes(tmp_path, env):
    """The records' disk fills up mid-run (a 8 kB tmpfs on postProcessing/fdm): fdmFoam stops with
    the file it could not write, fdmDEM is told and stops, and the records already written read
    back whole (the reader drops only an unfinished last line)."""
    spheres = [(x, y, z, 0.5) for x in (1.0, 3.0) for y in (1.0, 3.0) for z in (1.0, 3.0)]
    root = make_case(tmp_path, spheres=spheres, runs=("run 1000",),
                     fdm_edit=lambda t: re.sub(r"nMax\s+\d+;", "nMax 2;", t))
    records = os.path.join(root, "fluid", "postProcessing", "fdm")
    os.makedirs(records)
    if os.geteuid() != 0 or subprocess.run(["mount", "-t", "tmpfs", "-o", "size=8k", "tmpfs", records],
                                           stderr=subprocess.DEVNULL).returncode != 0:
        pytest.skip("cannot mount a tmpfs here (needs root)")
    try:
        status, out, wall = run_fdm(root, env, timeout=120)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # an unfinished last line is expected here
            steps = output.steps(os.path.join(root, "fluid"))
            parts = output.particles(os.path.join(root, "fluid"))
    finally:
        subprocess.run(["umount", records])
    assert status != 0
    text = logs(root)
    assert re.search(r"could not write .*(steps|particles)\.dat \(disk full", text), text[-3000:]
    assert "fdmFoam: could not write" in open(os.path.join(root, "log.dem"), errors="replace").read()
    assert wall < 60
    # every step recorded before the failure is there, once, in order
    n = len(steps["step"])
    assert n >= 2 and list(steps["step"]) == list(range(1, n + 1))
    complete = [s for s in range(1, n + 1) if (parts["step"] == s).sum() == len(spheres)]
    assert complete == list(range(1, len(complete) + 1)) and len(complete) >= n - 1


# Two spheres of radius 1 at a gap of 0.05 in a periodic 6 x 4 x 4 box, Delta = 0.5 (a/Delta = 2),
# viscosity 1 Pa s, contact at h_r = 0.01 m, kt = 0: the normal spring of the pair limits the step,
# zeta = 3 pi eta a + the sub-grid squeeze resistance, from ~480 N s/m at h_r to ~5e5 at zero gap.
# a/Delta = 2: outside the calibration table, so the scenes below ask for the cut-off model
PAIR = [(1.5, 2.0, 2.0, 1.0), (3.55, 2.0, 2.0, 1.0)]
PAIR_BOX = case.Box((0, 0, 0), (6, 4, 4), 0.5)


def pair_scene_log(tmp_path, env, pair_style):
    """fdmDEM's log of one step of the two spheres PAIR with this pair style, which must run."""
    root = make_case(tmp_path, spheres=PAIR, box=PAIR_BOX, pair_style=pair_style, runs=("run 1",))
    status, out, wall = run_fdm(root, env)
    assert status == 0, out
    return open(os.path.join(root, "log.dem"), errors="replace").read()


def test_time_step_beyond_contact_stability_at_every_gap(tmp_path, env):
    """Explicit springs, kn = 1e6 N/m, dt = 1 s: beyond dt k/zeta < 1 (ab2) even with the largest resistance a contact
    can have: an error at the start, with the limit and how it was computed; both codes stop."""
    root = make_case(tmp_path, spheres=PAIR, box=PAIR_BOX, pair_style="fdm/subgrid model cutoff contact 1e6 0 0.5 0.01 contact_integration explicit")
    status, out, wall = run_fdm(root, env)
    assert status != 0
    dem = open(os.path.join(root, "log.dem"), errors="replace").read()
    m = re.search(r"ERROR: pair_style fdm/subgrid: time step 1 s is beyond the stability limit of the contact "
                  r"springs at every gap: the normal spring of two spheres \(k 1e\+06 N/m\) needs dt < (\S+) s even at "
                  r"zero gap .* and dt < (\S+) s at the contact gap h_r = 0.01 m .*dt k/zeta < 1 with integrator ab2",
                  dem)
    assert m, dem[-3000:]
    assert 0.1 < float(m.group(1)) < 1 and 1e-4 < float(m.group(2)) < 1e-3
    assert "pair_style fdm/subgrid: time step 1 s" in open(os.path.join(root, "log.fluid")).read()
    assert wall < 30


def test_time_step_beyond_contact_stability_at_the_contact_gap(tmp_path, env):
    """Explicit springs, kn = 1e4 N/m, dt = 1 s: beyond the limit at h_r (~0.05 s), within it for contacts pressed
    deeper (~50 s at zero gap): a warning, and the run goes on."""
    dem = pair_scene_log(tmp_path, env, "fdm/subgrid model cutoff contact 1e4 0 0.5 0.01 contact_integration explicit")
    m = re.search(r"WARNING: pair_style fdm/subgrid: time step 1 s is beyond the stability limit (\S+) s of the normal "
                  r"spring of two spheres .* at the contact gap h_r = 0.01 m", dem)
    assert m and 0.01 < float(m.group(1)) < 0.1, dem[-3000:]


def test_spheres_pressed_through_each_other_stop_the_run(tmp_path, env):
    """Two free spheres pushed together (1 N each) against a spring far too soft for the load
    (k_n = 1 N/m) and no lubrication: once they overlap by more than 0.05 of a radius (what the fluid
    accepts of a sphere in a wall) the run stops naming both and the overlap, instead of going on
    with interpenetrating spheres (dense scenes reached 0.2 a1: docs/benchmarks.md 'Stability map')."""
    root = make_case(tmp_path, spheres=PAIR, box=PAIR_BOX, fix_options="",
                     pair_style="fdm/subgrid lubrication no contact 1 0 0 0.01",
                     fdm_edit=lambda text: text.replace("(-0.01 0 0)", "(0 0 0)"),
                     runs=("variable push atom 1-2*(id-1)", "fix push all addforce v_push 0 0", "run 20"))
    status, out, wall = run_fdm(root, env)
    assert status != 0
    text = logs(root)
    m = re.search(r"particles 1 and 2 overlap by (\S+) m \((\S+) of the smaller radius\) at step (\d+), more than "
                  r"the 0.05 the fluid accepts", text)
    assert m, text[-3000:]
    assert 0.05 < float(m.group(2)) < 1 and float(m.group(1)) == pytest.approx(float(m.group(2)), rel=1e-6)
    assert wall < 60


def test_particles_too_small_for_the_mesh(tmp_path, env):
    """a/Delta = 1: below the range of the cut-off sub-grid model (a/Delta >= 2), reported."""
    root = make_case(tmp_path, pair_style="fdm/subgrid", runs=("run 1",))
    status, out, wall = run_fdm(root, env)
    assert status == 0, out
    dem = open(os.path.join(root, "log.dem"), errors="replace").read()
    assert re.search(r"WARNING: pair_style fdm/subgrid: particle radius over mesh size a/Delta from 1 to 1 \(radii "
                     r"0.5 .. 0.5 m, Delta 0.5 m\) is outside the range the cut-off sub-grid model covers, a/Delta "
                     r"2 .. 20", dem), dem[-3000:]


def test_time_step_beyond_explicit_limit_with_implicit_springs(tmp_path, env):
    """The same kn = 1e6 N/m, dt = 1 s with the implicit springs (the default): no error, a note of
    how far beyond the explicit springs' limit the step is, and the run goes on."""
    dem = pair_scene_log(tmp_path, env, "fdm/subgrid model cutoff contact 1e6 0 0.5 0.01")
    m = re.search(r"pair fdm/subgrid: time step 1 s is (\S+) times the explicit springs' stability limit (\S+) s \(the "
                  r"normal spring of two spheres at the contact gap h_r\): stable with the implicit springs", dem)
    assert m and float(m.group(1)) > 1000 and 1e-4 < float(m.group(2)) < 1e-3, dem[-3000:]
    assert "ERROR" not in dem and "WARNING: pair_style fdm/subgrid: time step" not in dem


def test_pressure_gradient_along_a_wall_normal(tmp_path, env):
    """gradP0 along x in a box with walls normal to x: the walls would hold it as a hydrostatic
    pressure and nothing flows (issue 12). fdmFoam refuses it at start, naming the entry, the value
    and the direction."""
    box = case.Box((0, 0, 0), (4, 4, 4), 0.5, faces=(((0, 0, 0), (0, 0, 0)), "cyclic", "cyclic"))
    root = make_case(tmp_path, box=box)
    status, out, wall = run_fdm(root, env)
    assert status != 0
    text = logs(root)
    assert re.search(r"gradP0 \(-0.01 0 0\) Pa/m has a component along x, which is not periodic", text), text[-2000:]
    assert "fdmProperties" in text
    assert wall < 30
