"""Checkpoint and resume of a coupled run (issue 16 item 1; docs/coupling.md "Checkpoint and resume").

The scene: three spheres (a = 1) in plane Couette flow between walls moving at -/+1.5 along x
(shear rate 0.5), x and z periodic, a/Delta = 2: two of them are brought into frictional contact by
the shear (tangential springs: contact history) and one sits near a wall (wall lubrication and the
log-gap position update); Adams-Bashforth 2 (U_{n-1}, x_{n-1}: the position update's history). 50
steps, a checkpoint every 5.

test_killed_run_resumes_to_the_same_trajectory: the run is killed (SIGKILL, of fdmFoam and of fdmDEM
in turn) at a random step, resumed with fdmRun --resume, and gives the uninterrupted run's particle
trajectories (positions of every frame to 1e-8 of the box, in practice to rounding) and records with
every step once. 2 trials (FDM_FULL=1: 10). The faults: a truncated checkpoint falls back to the
previous one, one of another scene is refused by name, a peer killed during its checkpoint leaves
the previous one to resume from.

fix fdm/couple ... fluid_every 2 (docs/dem.md, "Particle steps between fluid steps"): the fluid solves
the first step, every second one and the checkpoints' steps; at unchanged positions (move no) a step
between fluid steps gives the velocities of the fluid step before it; with moving particles the
trajectory stays close to the one with the fluid at every step; killed and resumed, it is the
uninterrupted run's.
"""
import json
import os
import random
import re
import shutil
import signal
import subprocess
import time

import numpy as np
import pytest

from conftest import FULL, PROJECT
from fdmsubgrid import case, checkpoint, output

STEPS = 50
EVERY = 5
FDMRUN = os.path.join(PROJECT, "scripts", "fdmRun")


def make_scene(root, steps=STEPS, every=EVERY, spheres=None, fix_extra="", fluid_write=100000, linear_solver=None):
    """fluid/ and dem/ of the small Couette scene in root; fix_extra: more keywords of fix fdm/couple;
    fluid_write: the fluid fields' writeInterval (steps); linear_solver: write_fluid_case's (None: the
    cases' default)."""
    U = 3.0
    box = case.Box((0, 0, 0), (8.0, 6.0, 6.0), 0.5, faces=("cyclic", ((-U, 0, 0), (U, 0, 0)), "cyclic"))
    if spheres is None:
        # 1 (below the mid-plane, carried to -x) and 2 (above, to +x) meet; 3 is near the lower wall
        spheres = [(5.0, 2.55, 3.0, 1.0), (3.0, 3.45, 3.0, 1.0), (1.0, 1.15, 1.2, 1.0)]
    case.write_fluid_case(os.path.join(root, "fluid"), box, nu=1.0, rho=1.0, tol_lambda=1e-4, n_max=60,
                          first_step=(1e-5, 300), n_particles=len(spheres), tol_u=1e-7, tol_p=1e-6,
                          write_interval=fluid_write, linear_solver=linear_solver)
    # a mesh coarser than the calibration table (a/Delta 2): the cut-off model, asked for
    pair = "fdm/subgrid model cutoff contact 400 200 0.5 0.05 wall ylo %r 0 0 wall yhi %r 0 0" % (-U, U)
    runs = output.dump_custom_command("particles", 1, "particles.dump") + [
        "thermo_style    custom step f_couple[1] f_couple[6] f_couple[7] f_couple[8]",  # contacts: column 5
        "thermo          1",
        "fix             out all fdm/output records 1 particles.records",
        "run             %d upto" % steps]
    case.write_dem_input(os.path.join(root, "dem"), box, spheres, dt=0.05, pair_style=pair,
                         fix_options=("stresslets yes checkpoint %d " % every + fix_extra).strip(), runs=runs,
                         name="in.couette")
    return root


def fdm_run(root, env, *options, timeout=300):
    return subprocess.run([FDMRUN, "--quiet"] + list(options) + [root], env=env, stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, text=True, errors="replace", timeout=timeout)


def dump_frames(root, columns):
    """{step: the columns (N, len(columns)) by id} of the DEM dump, and the list of steps in file order."""
    frames = output.read_dump(os.path.join(root, "dem", "particles.dump"))
    return ({s: np.column_stack([c[k] for k in columns])[np.argsort(c["id"])] for s, c in frames},
            [s for s, _ in frames])


def trajectory(root):
    """{step: positions (N, 3)} of the DEM dump, and the list of steps in file order."""
    return dump_frames(root, ("x", "y", "z"))


def largest_difference(root, reference):
    """The largest position difference between the DEM dumps of two runs, over root's frames."""
    got, order = trajectory(root)
    ref, _ = trajectory(reference)
    return max(float(np.max(np.abs(got[s] - ref[s]))) for s in order)


def records_once(root):
    """The fluid's records hold each step once, in order: steps 1..STEPS, and one particle record
    per step and particle."""
    steps = output.steps(os.path.join(root, "fluid"))["step"].astype(int)
    assert list(steps) == list(range(1, STEPS + 1)), steps
    parts = output.particles(os.path.join(root, "fluid"))
    pairs = list(zip(parts["step"].astype(int), parts["tag"].astype(int)))
    assert len(pairs) == len(set(pairs)) == 3 * STEPS


def find_pid(root, who):
    """The process id of fdmFoam or fdmDEM of the run in root (from /proc), or None."""
    for pid in os.listdir("/proc"):
        if not pid.isdigit():
            continue
        try:
            cmd = open("/proc/%s/cmdline" % pid, "rb").read().split(b"\0")
            cwd = os.readlink("/proc/%s/cwd" % pid)
        except OSError:
            continue
        if not cmd or os.path.basename(cmd[0].decode()) != who:
            continue
        if who == "fdmFoam" and os.path.join(root, "fluid").encode() in cmd:
            return int(pid)
        if who == "fdmDEM" and cwd == os.path.join(root, "dem"):
            return int(pid)
    return None


def steps_done(root):
    path = os.path.join(root, "fluid", "postProcessing", "fdm", "steps.dat")
    try:
        with open(path) as f:
            return sum(1 for line in f if line.strip() and not line.startswith("#"))
    except OSError:
        return 0


def run_and_kill(root, env, who, at_step, *options):
    """fdmRun [options] in root, SIGKILL of `who` once `at_step` steps are recorded; returns fdmRun's exit code."""
    proc = subprocess.Popen([FDMRUN, "--quiet"] + list(options) + [root], env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, errors="replace",
                            text=True)
    deadline = time.time() + 240
    while steps_done(root) < at_step and proc.poll() is None and time.time() < deadline:
        time.sleep(0.01)
    pid = find_pid(root, who)
    assert pid, "%s of %s not found (fdmRun: %s)" % (who, root, proc.poll())
    os.kill(pid, signal.SIGKILL)
    proc.communicate(timeout=60)
    return proc.returncode


@pytest.fixture(scope="module")
def reference(tmp_path_factory, env):
    root = str(tmp_path_factory.mktemp("reference"))
    make_scene(root)
    t0 = time.time()
    r = fdm_run(root, env)
    assert r.returncode == 0, r.stdout
    wall = time.time() - t0
    log = open(os.path.join(root, "log.fluid")).read()
    print("reference run: %.1f s wall; %s" % (wall, [l for l in log.splitlines() if "checkpoints" in l]))
    records_once(root)
    return root


def assert_same_records(root, reference):
    """fix fdm/output's binary records of a resumed run: every step once, as in the uninterrupted
    run (the resumed fdmDEM appends after the checkpoint step, whatever the input's append says)."""
    got = output.read_particle_records(os.path.join(root, "dem", "particles.records"), mmap=False)
    ref = output.read_particle_records(os.path.join(reference, "dem", "particles.records"), mmap=False)
    assert list(got.steps) == list(ref.steps) == list(range(1, STEPS + 1)), got.steps
    assert np.array_equal(got["x"], ref["x"])


def assert_same_trajectory(root, reference):
    got, order = trajectory(root)
    ref, ref_order = trajectory(reference)
    assert order == ref_order == list(range(0, STEPS + 1)), order   # every frame once, in order
    worst = largest_difference(root, reference)
    final = float(np.max(np.abs(got[STEPS] - ref[STEPS]) / np.abs(ref[STEPS])))
    print("largest position difference over the trajectory %.3g (box 8 x 6 x 6), relative at step %d %.3g"
          % (worst, STEPS, final))
    assert final < 1e-8 and worst < 1e-8 * 8
    return worst


def assert_same_run(root, reference):
    """A resumed (or extended) run holds each step once and is the uninterrupted reference run."""
    records_once(root)
    assert_same_trajectory(root, reference)
    assert_same_records(root, reference)


def test_checkpoint_interval_and_contact(reference):
    """The scene exercises what a checkpoint must carry: contacts (history) and the AB2 plan."""
    names = sorted(os.listdir(os.path.join(reference, "dem", "checkpoint")))
    assert names == ["dem.45", "dem.50"], names   # every 5 steps and at the end, the two newest kept
    markers = sorted(os.listdir(os.path.join(reference, "fluid", "checkpoint")))
    assert markers == ["fluid.45", "fluid.50"], markers
    log = open(os.path.join(reference, "log.dem")).read()
    contacts = [float(l.split()[4]) for l in log.splitlines() if l.strip() and l.split()[0].isdigit()
                and len(l.split()) == 5]
    assert max(contacts, default=0) >= 1, "no contact in the scene: its history would not be tested"


@pytest.mark.parametrize("trial", range(10 if FULL else 2))
def test_killed_run_resumes_to_the_same_trajectory(tmp_path, env, reference, trial):
    rng = random.Random(16 + trial)
    who = ("fdmFoam", "fdmDEM")[trial % 2]
    at_step = rng.randint(3, STEPS - 3)
    root = make_scene(str(tmp_path))
    code = run_and_kill(root, env, who, at_step)
    assert code != 0
    done = steps_done(root)
    t0 = time.time()
    r = fdm_run(root, env, "--resume")
    assert r.returncode == 0, r.stdout
    print("trial %d: %s killed after %d steps recorded; resumed in %.1f s" % (trial, who, done, time.time() - t0))
    assert_same_run(root, reference)


def test_truncated_checkpoint_falls_back_to_the_previous_one(tmp_path, env, reference):
    root = str(tmp_path / "run")
    shutil.copytree(reference, root)
    newest = os.path.join(root, "dem", "checkpoint", "dem.50")
    size = os.path.getsize(newest)
    with open(newest, "r+b") as f:
        f.truncate(size // 2)
    r = fdm_run(root, env, "--resume")   # the run ended at 50: resuming at 45 repeats 46..50
    assert r.returncode == 0, r.stdout
    log = open(os.path.join(root, "log.fluid")).read()
    assert "Resuming from" in log and "fluid.45" in log
    records_once(root)
    assert_same_trajectory(root, reference)
    # the reason is said
    r = subprocess.run(["python3", "-m", "fdmsubgrid.checkpoint", "select", root], env=dict(
        env, PYTHONPATH=os.path.join(PROJECT, "scripts")), stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, errors="replace")
    assert r.returncode == 0


def test_truncated_checkpoint_is_named(tmp_path, env, reference):
    root = str(tmp_path / "run")
    shutil.copytree(reference, root)
    for step in (45, 50):
        path = os.path.join(root, "dem", "checkpoint", "dem.%d" % step)
        with open(path, "r+b") as f:
            f.truncate(os.path.getsize(path) - 100)
    r = fdm_run(root, env, "--resume")
    assert r.returncode != 0
    assert "dem/checkpoint/dem.50 is truncated" in r.stdout and "has no checkpoint that both codes completed" \
        in r.stdout, r.stdout


def test_checkpoint_of_another_scene_is_refused(tmp_path, env, reference):
    root = str(tmp_path / "run")
    shutil.copytree(reference, root)
    # the input now has 2 particles: the checkpoint holds 3
    make_scene(str(tmp_path / "other"), spheres=[(5.0, 2.55, 3.0, 1.0), (2.6, 3.45, 3.0, 1.0)])
    shutil.copy(str(tmp_path / "other" / "dem" / "spheres.data"), os.path.join(root, "dem", "spheres.data"))
    r = fdm_run(root, env, "--resume")
    assert r.returncode != 0
    assert "dem.50 is from another scene: it holds 3 particles, the LIGGGHTS input has 2" in r.stdout, r.stdout


def test_peer_killed_during_its_checkpoint_resumes_from_the_previous(tmp_path, env, reference):
    """fdmDEM killed while writing its checkpoint of step 50 (fdmFoam had written its own): the
    temporary file is left, the fluid's checkpoint 50 has no partner, so the run resumes from 45."""
    root = str(tmp_path / "run")
    shutil.copytree(reference, root)
    ckpt = os.path.join(root, "dem", "checkpoint")
    with open(os.path.join(ckpt, "dem.50"), "rb") as f:
        head = f.read(1000)
    os.remove(os.path.join(ckpt, "dem.50"))
    with open(os.path.join(ckpt, "dem.50.tmp"), "wb") as f:
        f.write(head)
    r = fdm_run(root, env, "--resume")
    assert r.returncode == 0, r.stdout
    assert "fluid.45" in open(os.path.join(root, "log.fluid")).read()
    assert not os.path.exists(os.path.join(ckpt, "dem.50.tmp"))
    records_once(root)
    assert_same_trajectory(root, reference)


def test_resume_step_mismatch_at_the_handshake(tmp_path, env, reference):
    """Both codes started by hand on different checkpoints: the handshake refuses."""
    root = str(tmp_path / "run")
    shutil.copytree(reference, root)
    os.remove(os.path.join(root, "fluid", "coupling.port")) if os.path.exists(
        os.path.join(root, "fluid", "coupling.port")) else None
    fluid = subprocess.Popen(["fdmFoam", "-case", os.path.join(root, "fluid"), "-resume", "45"], env=env,
                             stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, errors="replace")
    dem = subprocess.run(["fdmDEM", "-in", "in.couette", "-resume", "checkpoint/dem.50"], cwd=os.path.join(root, "dem"),
                         env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, errors="replace", timeout=120)
    out, _ = fluid.communicate(timeout=60)
    assert fluid.returncode != 0 and dem.returncode != 0
    message = "fdmFoam resumes from its checkpoint of step 45 (checkpoint/fluid.45) but fdmDEM from step 50"
    assert message in out and message in dem.stdout, out[-2000:] + dem.stdout[-2000:]


def test_finished_run_extended_with_until_gives_the_longer_run(tmp_path, env, reference):
    """A run planned to 32 steps, finished, then continued with `fdmRun --resume --until 50` (from the
    checkpoint written at its last step): the 50-step run's trajectory and records, bit for bit, every
    step once, and the input now says `run 50 upto`. Step 32 is one where the force evaluation of a
    resumed run's setup, had it re-applied the contact law to the restored tangential spring, would
    have moved it by an ulp (the records then left the uninterrupted run's by 4e-13 of the positions)."""
    root = make_scene(str(tmp_path), steps=32)
    env = dict(env, FDM_LOAD_EVERY="1")
    started = time.time()
    r = fdm_run(root, env)
    assert r.returncode == 0, r.stdout
    assert steps_done(root) == 32
    # an extension killed before its first checkpoint leaves the input at 50 and the newest checkpoint
    # of the 32-step run: a plain resume is refused with the advice, --until (table8.py passes it) goes on
    assert checkpoint.set_last_step(os.path.join(root, "dem", "in.couette"), STEPS, 32) == 32
    r = fdm_run(root, env, "--resume")
    assert r.returncode != 0 and "fdmRun --resume --until L extends it to L" in r.stdout, r.stdout
    r = fdm_run(root, env, "--resume", "--until", str(STEPS))
    assert r.returncode == 0, r.stdout
    assert "run             %d upto" % STEPS in open(os.path.join(root, "dem", "in.couette")).read()
    assert "resume from step 32, to step 50 (--until; the input ran to 50)" in open(os.path.join(root, "log.fluid")).read()
    assert_same_run(root, reference)
    # log.load: one segment per fdmRun, the refused resume one without steps, each sampled while it ran
    segments = output.run_segments(root)
    assert [(s.kind, s.first_step, s.last_step) for s in segments] == [("start", 0, 32), ("resume", 32, 32),
                                                                       ("resume", 32, 50)]
    # (log.load's times are whole seconds: date +%s)
    assert all(int(started) <= s.start <= s.end <= time.time() for s in segments)
    assert sum(s.wall_seconds for s in segments) <= time.time() - started + len(segments)
    assert segments[0].samples >= 2 and all(s.load_mean >= 0 for s in segments)
    assert "3 segments, 50 particle steps" in output.segments_table(segments)
    kept = output.keep_segments(segments, str(tmp_path / "kept"))
    assert os.path.basename(kept) == "wall_0.json"
    record = json.load(open(kept))
    assert record["wall_seconds"] == pytest.approx(sum(s.wall_seconds for s in segments))
    assert [(r["first_step"], r["last_step"]) for r in record["segments"]] == [(0, 32), (32, 32), (32, 50)]
    # the same segments from log.fluid's ETA alone (a run made before log.load): the same steps, each wall
    # time within its start-up and last sample of log.load's
    from_eta = output.segments_from_fluid_log(root, 32)
    assert [(s.kind, s.first_step, s.last_step) for s in from_eta] == [(s.kind, s.first_step, s.last_step)
                                                                      for s in segments]
    for eta, load in zip(from_eta, segments):
        assert eta.from_eta and 0 <= eta.wall_seconds <= load.wall_seconds + 1.0
    assert from_eta[0].wall_seconds > 0.3 * segments[0].wall_seconds and from_eta[1].wall_seconds == 0
    os.remove(os.path.join(root, "log.load"))
    older = output.measured_segments(root, 32)
    assert [(s.first_step, s.last_step, s.wall_seconds) for s in older] == [(s.first_step, s.last_step, s.wall_seconds)
                                                                            for s in from_eta]
    assert "(*: 3 segments made before log.load" in output.segments_table(older)


def test_bad_load_sampling_interval_is_refused_before_anything_runs(tmp_path, env):
    root = make_scene(str(tmp_path))
    r = fdm_run(root, dict(env, FDM_LOAD_EVERY="0"))
    assert r.returncode == 2 and "FDM_LOAD_EVERY takes a positive number of seconds, got '0'" in r.stdout, r.stdout
    assert not os.path.exists(os.path.join(root, "log.fluid")) and not os.path.exists(os.path.join(root, "log.load"))


def test_resumed_on_another_number_of_fluid_ranks_continues_the_run(tmp_path, env, reference):
    """A run made serially to step 20, resumed on 2 fluid ranks to step 35 (`fdmRun --resume -f 2`: the
    checkpoint's fields decomposed first), then serially again to 50 (gathered back with reconstructPar):
    every step once, and the uninterrupted serial run's trajectory within the decomposed direct solve's
    round-off (FFTBox on 2 ranks gives the serial answer to ~1e-13; docs/fluid.md); each marker says on how
    many ranks its fields are."""
    root = make_scene(str(tmp_path), steps=20)
    r = fdm_run(root, env)
    assert r.returncode == 0, r.stdout
    r = fdm_run(root, env, "--resume", "-f", "2", "--until", "35")
    assert r.returncode == 0, r.stdout
    assert os.path.isfile(os.path.join(root, "log.decomposePar"))     # step 20's fields split first
    assert checkpoint.marker_processors(root, 35)[0] == 2               # written by the run on 2 ranks
    assert "walls across y, decomposed over 2 processors" in open(os.path.join(root, "log.fluid")).read()
    r = fdm_run(root, env, "--resume", "--until", str(STEPS))
    assert r.returncode == 0, r.stdout
    assert os.path.isfile(os.path.join(root, "log.reconstructPar"))   # step 35's fields gathered first
    assert checkpoint.marker_processors(root, STEPS)[0] == 1
    records_once(root)
    ref, _ = trajectory(reference)
    got, order = trajectory(root)
    assert order == list(range(0, STEPS + 1)), order
    worst = max(float(np.max(np.abs(got[s] - ref[s]))) for s in order)
    print("largest position difference from the serial run: %.3g (box 8 x 6 x 6)" % worst)
    assert worst < 1e-6, worst
    # steps 1-20 were made serially: bit for bit the reference's
    assert max(float(np.max(np.abs(got[s] - ref[s]))) for s in range(0, 21)) == 0.0


def test_until_that_cannot_be_done_leaves_the_run_as_it_was(tmp_path, env, reference):
    root = str(tmp_path / "run")
    shutil.copytree(reference, root)
    demInput = os.path.join(root, "dem", "in.couette")
    stepsFile = os.path.join(root, "fluid", "postProcessing", "fdm", "steps.dat")
    before = open(demInput).read(), open(stepsFile).read()
    cases = [(("--resume", "--until", "50"), "the run resumes from step 50, so it cannot end at step 50"),
             (("--resume", "--until", "4O"), "--until takes a step number, got '4O'"),
             (("--until", "60"), "--until 60 goes with --resume")]
    for options, message in cases:
        r = fdm_run(root, env, *options)
        assert r.returncode != 0 and message in r.stdout, (options, r.stdout)
        assert (open(demInput).read(), open(stepsFile).read()) == before
    with open(demInput, "w") as f:
        f.write(before[0].replace("run             50 upto", "run             50"))
    r = fdm_run(root, env, "--resume", "--until", "60")
    assert r.returncode != 0 and "its run command 'run             50' is not 'run N upto'" in r.stdout, r.stdout
    assert open(stepsFile).read() == before[1]


def test_set_last_step_rewrites_only_the_run_command(tmp_path):
    """checkpoint.set_last_step on input text (no codes run): the one `run N upto` line changes, its
    trailing keywords and every other line stay; two run commands are refused."""
    path = str(tmp_path / "in.scene")
    text = "# run 10 upto in a comment\nrun_style verlet\nfix out all print 1 \"run\"\n  run 625 upto every 0 NULL\n"
    with open(path, "w") as f:
        f.write(text)
    assert checkpoint.set_last_step(path, 830, 625) == 625
    assert open(path).read() == text.replace("run 625 upto", "run 830 upto")
    with open(path, "a") as f:
        f.write("run 5\n")
    with pytest.raises(checkpoint.CheckpointError, match="has 2 run commands"):
        checkpoint.set_last_step(path, 900, 830)


def test_marker_rewritten_for_redistributed_fields_keeps_the_rest(tmp_path):
    """After fdmRun --resume -f N has redistributed a checkpoint's fields, its marker says N ranks and
    nothing else changes (the time, the step count, the scene's cells and particles)."""
    (tmp_path / "fluid" / "checkpoint").mkdir(parents=True)
    marker = tmp_path / "fluid" / "checkpoint" / "fluid.20"
    marker.write_text("# fdmFoam checkpoint: U p lambda phi of this step in 1/ (binary; processor*/1/ in parallel)\n"
                      "step 20\ntime 1.0000000000000002\ntimeIndex 20\ntimeName 1\nstepsDone 20\ncells 2304\n"
                      "processors 1\nparticles 3\nregularOutput 0\nfromRest 0\nend\n")
    before = checkpoint.read_fluid_marker(str(marker))
    assert checkpoint.marker_processors(str(tmp_path), 20) == (1, "1")
    checkpoint.set_marker_processors(str(tmp_path), 20, 4)
    after = checkpoint.read_fluid_marker(str(marker))
    assert after == dict(before, processors="4")
    assert checkpoint.marker_processors(str(tmp_path), 20) == (4, "1")
    assert "redistributed from 1 to 4 fluid ranks" in marker.read_text()


def test_calibration_table_the_input_reads(tmp_path, monkeypatch):
    """checkpoint.calibration_table on input text (no codes run): the shipped table by default, the input's
    own `calibration FILE` (relative to the input), none with the cut-off model or the lubrication off."""
    monkeypatch.setenv("FDM_ROOT", "/somewhere")
    path = str(tmp_path / "in.scene")

    def table(pair_style):
        with open(path, "w") as f:
            f.write("units si\n# pair_style fdm/subgrid calibration commented.dat\n" + pair_style + "\nrun 5 upto\n")
        return checkpoint.calibration_table(path)
    shipped = "/somewhere/dem/resistance/data/subgrid_calibration.dat"
    assert table("pair_style      fdm/subgrid contact 1 1 0.5 0.005 wall ylo 0 0 0") == shipped
    assert table("pair_style fdm/subgrid model calibrated") == shipped
    assert table("pair_style fdm/subgrid model cutoff contact 1 1 0.5 0.005") is None
    assert table("pair_style fdm/subgrid lubrication no") is None
    assert table("pair_style fdm/subgrid &\n  calibration my.dat cutoff 0.5") == str(tmp_path / "my.dat")
    assert table("pair_style gran model hertz tangential history") is None


def test_changed_calibration_table_refuses_a_resume(tmp_path):
    """A run records its table when it starts (checkpoint.stamp); a resume whose table changed since is
    refused naming the table and the record, and goes on only with accept_new (fdmRun --new-calibration),
    which records the new one; a run started before the record existed gets it at its resume."""
    case_dir = tmp_path / "run"
    (case_dir / "dem").mkdir(parents=True)
    dem_input = str(case_dir / "dem" / "in.scene")
    with open(dem_input, "w") as f:
        f.write("pair_style fdm/subgrid calibration table.dat contact 1 1 0.5 0.005\n")
    table = case_dir / "dem" / "table.dat"
    table.write_text("# squeeze table\n1 2 3\n")
    assert "no record" in checkpoint.check_stamp(str(case_dir), dem_input)      # an older run: recorded now
    assert checkpoint.check_stamp(str(case_dir), dem_input) == "the same calibration table as at the start"
    table.write_text("# squeeze table, refitted\n1 2 4\n")
    with pytest.raises(checkpoint.CheckpointError) as e:
        checkpoint.check_stamp(str(case_dir), dem_input)
    message = str(e.value)
    assert str(table) in message and checkpoint.CALIBRATION_STAMP in message and "--new-calibration" in message
    assert "--new-calibration: continues with" in checkpoint.check_stamp(str(case_dir), dem_input, accept_new=True)
    assert checkpoint.check_stamp(str(case_dir), dem_input) == "the same calibration table as at the start"
    table.unlink()
    with pytest.raises(checkpoint.CheckpointError, match="table.dat .*is missing"):
        checkpoint.check_stamp(str(case_dir), dem_input)


# the table the shipped one replaced, kept beside it by the first 8 hex digits of its SHA-256: the paper
# channel's committed snapshot (cases/poiseuille/paper/snapshot) and Table 8's shipped rows ran with it
PREVIOUS_TABLE = os.path.join(PROJECT, "dem", "resistance", "data", "subgrid_calibration_b6ffff38.dat")
PAPER_SNAPSHOT = os.path.join(PROJECT, "cases", "poiseuille", "paper", "snapshot")


def test_the_previous_table_is_found_by_its_hash():
    """checkpoint.table_by_hash: the kept previous table by the SHA-256 a run or snapshot recorded, the shipped
    one by its own, nothing for a hash no table of the project has."""
    previous = json.load(open(os.path.join(PAPER_SNAPSHOT, checkpoint.SNAPSHOT_CALIBRATION)))["sha256"]
    assert os.path.basename(PREVIOUS_TABLE) == "subgrid_calibration_%s.dat" % previous[:8]
    assert checkpoint.table_by_hash(previous) == PREVIOUS_TABLE
    shipped = os.path.join(PROJECT, "dem", "resistance", "data", "subgrid_calibration.dat")
    digest = checkpoint._table_identity(shipped)["sha256"]
    assert digest != previous
    assert checkpoint.table_by_hash(digest) == shipped
    assert checkpoint.table_by_hash("0" * 64) is None and checkpoint.table_by_hash(None) is None


def scene_input(snapshot_dir) -> str:
    """The LIGGGHTS input the scene command writes for a snapshot's run: the snapshot's own, less the `calibration
    FILE` that fdmRun --resume gives the pair style of a run that goes on with the table it started with."""
    text = open(os.path.join(snapshot_dir, "in.poiseuille")).read()
    return re.sub(r"(pair_style[ \t]+fdm/subgrid)[ \t]+calibration[ \t]+\S+", r"\1", text, count=1)


def test_committed_paper_snapshot_continues_with_the_table_it_ran_with(tmp_path, monkeypatch):
    """The paper channel's committed snapshot ran with the previous table; a case of its scene reads the
    shipped one. snapshot_check accepts it (the project keeps the previous table), snapshot_table names that
    table, and use_table (what snapshot_install does) points the input at a copy of it beside the input, so
    that the run reads the bytes the snapshot's run read; with a hash no table of the project has, the check
    refuses, naming the snapshot's record and the hash. (The case here is the snapshot's input alone: no data
    file, no mesh.)"""
    monkeypatch.setenv("FDM_ROOT", PROJECT)
    case_dir = tmp_path / "case"
    (case_dir / "dem").mkdir(parents=True)
    dem_input = str(case_dir / "dem" / "in.poiseuille")
    (case_dir / "dem" / "in.poiseuille").write_text(scene_input(PAPER_SNAPSHOT))
    snap = checkpoint.check_snapshot(PAPER_SNAPSHOT)
    assert checkpoint.calibration_table(dem_input) == os.path.join(PROJECT, "dem", "resistance", "data",
                                                                   "subgrid_calibration.dat")
    step, last = checkpoint.snapshot_check(PAPER_SNAPSHOT, str(case_dir), dem_input)
    assert step == snap["step"] and last > step   # the newest committed step
    assert checkpoint.snapshot_table(snap, PAPER_SNAPSHOT, dem_input) == PREVIOUS_TABLE
    copy = checkpoint.use_table(dem_input, PREVIOUS_TABLE)
    assert copy == str(case_dir / "dem" / os.path.basename(PREVIOUS_TABLE))
    assert checkpoint.calibration_table(dem_input) == copy
    assert checkpoint._table_identity(copy)["sha256"] == snap["calibration"]["sha256"]
    assert checkpoint.snapshot_table(snap, PAPER_SNAPSHOT, dem_input) is None
    # only the pair style's line changed
    before = scene_input(PAPER_SNAPSHOT).split("\n")
    after = open(dem_input).read().split("\n")
    changed = [(a, b) for a, b in zip(before, after) if a != b]
    assert len(before) == len(after) and len(changed) == 1
    assert changed[0][1] == changed[0][0].replace("fdm/subgrid ", "fdm/subgrid calibration %s "
                                                  % os.path.basename(PREVIOUS_TABLE), 1)
    # a second use_table replaces the keyword instead of adding another
    checkpoint.use_table(dem_input, PREVIOUS_TABLE)
    assert open(dem_input).read().count("calibration ") == 1
    # a snapshot naming a hash the project does not keep
    bogus = tmp_path / "bogus"
    shutil.copytree(PAPER_SNAPSHOT, bogus)
    record = bogus / checkpoint.SNAPSHOT_CALIBRATION
    record.write_text(json.dumps(dict(table="dem/resistance/data/subgrid_calibration.dat", sha256="ab" * 32)))
    (case_dir / "dem" / "in.poiseuille").write_text(scene_input(PAPER_SNAPSHOT))
    with pytest.raises(checkpoint.CheckpointError) as e:
        checkpoint.snapshot_check(str(bogus), str(case_dir), dem_input)
    message = str(e.value)
    assert str(record) in message and "ab" * 32 in message, message
    assert "no table of the project (dem/resistance/data/subgrid_calibration*.dat) has sha256" in message


def test_resume_finds_the_table_the_run_started_with(tmp_path, monkeypatch):
    """A run started with the previous shipped table (its record names it by path and hash) and resumed where the
    shipped table is the new one: check_stamp points the input at a copy of the previous table and records it; a
    further resume finds the same table; a record with a hash the project does not keep is refused, naming it."""
    monkeypatch.setenv("FDM_ROOT", PROJECT)
    case_dir = tmp_path / "run"
    (case_dir / "dem").mkdir(parents=True)
    dem_input = str(case_dir / "dem" / "in.scene")
    with open(dem_input, "w") as f:
        f.write("pair_style fdm/subgrid model calibrated contact 1 1 0.5 0.005 # the shipped table\nrun 10 upto\n")
    stamp = case_dir / checkpoint.CALIBRATION_STAMP
    previous = checkpoint._table_identity(PREVIOUS_TABLE)["sha256"]
    stamp.write_text(json.dumps(dict(table="/elsewhere/dem/resistance/data/subgrid_calibration.dat",
                                     sha256=previous)))
    line = checkpoint.check_stamp(str(case_dir), dem_input)
    assert line.startswith("continues with the calibration table it started with (sha256 %s)" % previous[:12]), line
    copy = str(case_dir / "dem" / os.path.basename(PREVIOUS_TABLE))
    assert checkpoint.calibration_table(dem_input) == copy
    assert json.load(open(stamp)) == dict(table=copy, sha256=previous)
    assert checkpoint.check_stamp(str(case_dir), dem_input) == "the same calibration table as at the start"
    stamp.write_text(json.dumps(dict(table=copy, sha256="cd" * 32)))
    with pytest.raises(checkpoint.CheckpointError) as e:
        checkpoint.check_stamp(str(case_dir), dem_input)
    assert "cd" * 32 in str(e.value) and str(stamp) in str(e.value)


def test_fdmRun_refuses_a_resume_whose_table_changed_and_loses_nothing(tmp_path, env, reference):
    """fdmRun --resume on a run whose record names another table than the input reads: refused before the
    records are cut (every file as it was); with --new-calibration it resumes (here the cut-off model reads no
    table, so the run is the reference's)."""
    root = str(tmp_path / "run")
    shutil.copytree(reference, root)
    stamp = os.path.join(root, checkpoint.CALIBRATION_STAMP)
    assert json.load(open(stamp)) == {"table": None, "sha256": None}        # written when the reference started
    with open(stamp, "w") as f:
        json.dump({"table": "/elsewhere/subgrid_calibration.dat", "sha256": "0" * 64}, f)
    before = {os.path.join(d, p): os.path.getsize(os.path.join(d, p)) for d, _, files in os.walk(root) for p in files}
    r = fdm_run(root, env, "--resume")
    assert r.returncode != 0 and "the sub-grid calibration table changed since this run started" in r.stdout, r.stdout
    assert "/elsewhere/subgrid_calibration.dat" in r.stdout
    after = {os.path.join(d, p): os.path.getsize(os.path.join(d, p)) for d, _, files in os.walk(root) for p in files}
    assert after == before
    r = fdm_run(root, env, "--resume", "--new-calibration")
    assert r.returncode == 0, r.stdout
    assert json.load(open(stamp)) == {"table": None, "sha256": None}
    assert_same_trajectory(root, reference)


def test_fdmRun_edited_in_place_during_a_run_ends_it_normally(tmp_path, env):
    """A copy of fdmRun (beside an etc/bashrc that sources the project's) runs the small scene; while it
    runs, its file is rewritten in place with 40 comment lines more at the top (an editor saving it, a
    careless update): bash reads a script at byte offsets as it goes, so without fdmRun's { ... } group
    the running fdmRun would read shifted text at its end (seen 2026-11-28: 'syntax error near unexpected
    token' after a Table 8 row had finished). It must end normally, with its summary."""
    tools = tmp_path / "tools"
    (tools / "scripts").mkdir(parents=True)
    (tools / "etc").mkdir()
    (tools / "etc" / "bashrc").write_text(". '%s/etc/bashrc'\n" % PROJECT)
    os.symlink(os.path.join(PROJECT, "scripts", "fdmsubgrid"), str(tools / "scripts" / "fdmsubgrid"))
    copy = tools / "scripts" / "fdmRun"
    shutil.copy(FDMRUN, str(copy))
    root = make_scene(str(tmp_path / "run"), steps=30)
    proc = subprocess.Popen([str(copy), root], env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            errors="replace")
    deadline = time.time() + 120
    while steps_done(root) < 3 and proc.poll() is None and time.time() < deadline:
        time.sleep(0.2)
    assert proc.poll() is None, "fdmRun ended before the edit: " + proc.communicate()[0][-2000:]
    text = open(FDMRUN).read()
    with open(str(copy), "r+") as f:          # in place: the same file, the running bash's offsets now shifted
        f.seek(0)
        f.write("".join("# an edit made while a run was going, line %d\n" % k for k in range(40)) + text)
        f.truncate()
    out, _ = proc.communicate(timeout=300)
    assert proc.returncode == 0, out[-3000:]
    assert "syntax error" not in out and "fdm/couple timing" in out, out[-3000:]
    assert steps_done(root) == 30


# ------------------------------------------------------------------------------------------------
# fluid_every K: particle steps between fluid steps
# ------------------------------------------------------------------------------------------------

def fluid_steps(root):
    return list(output.steps(os.path.join(root, "fluid"))["step"].astype(int))


@pytest.fixture(scope="module")
def reference_every2(tmp_path_factory, env):
    root = str(tmp_path_factory.mktemp("every2"))
    make_scene(root, fix_extra="fluid_every 2", fluid_write=10)
    r = fdm_run(root, env)
    assert r.returncode == 0, r.stdout
    return root


def test_step_records_hold_the_runs_time(reference_every2):
    """steps.dat's seconds of each fluid step (fluid solve, particle forcing, exchange) sum to the run's: a
    step's exchange holds the wait for its particles, the particle steps between fluid steps included, so
    that a run's wall time and a budget can be read from the records (fdmsubgrid.shear.run_seconds,
    poiseuille.budget). Against fdmFoam's own breakdown at the end of the run."""
    steps = output.steps(os.path.join(reference_every2, "fluid"))
    parts = output.fluid_time_breakdown(open(os.path.join(reference_every2, "log.fluid")).read())
    wall = parts["wall"]
    exchange = float(np.sum(steps["exchangeSeconds"]))
    # every wait for the particle code but the last (its end of run) is some step's
    assert abs(exchange - parts["exchange_dem"]) < 0.01 * wall + 0.02, (exchange, parts)
    recorded = float(np.sum(steps["fluidSeconds"]) + np.sum(steps["particleSeconds"])) + exchange
    unrecorded = parts["output"] + parts["checkpoints"]
    print("wall %.3f s; steps.dat exchange %.3f s against the breakdown's %.3f s; recorded %.3f s + output and "
          "checkpoints %.3f s" % (wall, exchange, parts["exchange_dem"], recorded, unrecorded))
    assert recorded + unrecorded > 0.95 * wall, (recorded, unrecorded, wall)


def test_fluid_every_solves_the_fluid_on_its_steps(reference_every2, reference):
    """The fluid solves step 1 (nothing to hold yet), every second step and the checkpoints' steps
    (multiples of 5, and the last): 30 of 50; the trajectory stays within 3e-2 a of the run that
    solves the fluid at every step (measured 1.15e-2 a, where the spheres travel up to 3.75 a: the held
    drag is first order in the steps it spans, and the frictional contact of the scene amplifies)."""
    expected = sorted({1} | set(range(2, STEPS + 1, 2)) | set(range(EVERY, STEPS + 1, EVERY)))
    assert fluid_steps(reference_every2) == expected
    # the fluid's time index is the DEM step: writeInterval 10 writes at the DEM steps 10, 20, ... (time =
    # step x 0.05), not at its own 10th, 20th, ... step (beside them: the checkpoint of step 45)
    times = sorted(float(d) for d in os.listdir(os.path.join(reference_every2, "fluid"))
                   if d.replace(".", "").isdigit() and float(d) > 0)
    assert times == pytest.approx(sorted([0.05 * s for s in range(10, STEPS + 1, 10)] + [0.05 * 45])), times
    log = open(os.path.join(reference_every2, "log.dem")).read()
    assert "fluid_every 2: the fluid solved in %d of the steps" % len(expected) in log
    assert trajectory(reference_every2)[1] == list(range(0, STEPS + 1))
    worst = largest_difference(reference_every2, reference)
    print("fluid_every 2 against every step: largest position difference %.3g a over %d steps" % (worst, STEPS))
    assert 0 < worst < 3e-2


def test_held_drag_gives_the_fluid_steps_velocities_at_unchanged_positions(tmp_path, env):
    """move no: the positions never change, so a step between fluid steps must give the velocities the
    fluid gave at the step before it (U_b = U + F^FDM/(6 pi eta a) makes Eq. 31 give U back), to the inner
    iteration's tolerance (F^FDM is the fluid's force after its last lambda correction, U the solve before
    it: measured 2e-7 of the largest velocity at tolLambda 1e-4), as the fluid's own steps agree."""
    root = make_scene(str(tmp_path), steps=8, every=100, fix_extra="move no fluid_every 2")
    r = fdm_run(root, env)
    assert r.returncode == 0, r.stdout
    assert fluid_steps(root) == [1, 2, 4, 6, 8]
    u, _ = dump_frames(root, ("vx", "vy", "vz", "omegax", "omegay", "omegaz"))
    scale = float(np.max(np.abs(u[2])))
    assert scale > 0.1   # the shear moves them (wall speed 3)
    for held, fluid in ((3, 2), (5, 4), (7, 6)):
        assert float(np.max(np.abs(u[held] - u[fluid]))) < 1e-5 * scale, (held, u[held] - u[fluid])
    print("fluid steps 2 and 4 differ by %.3g, held step 3 and fluid step 2 by %.3g of the largest velocity"
          % (np.max(np.abs(u[4] - u[2])) / scale, np.max(np.abs(u[3] - u[2])) / scale))
    assert float(np.max(np.abs(u[4] - u[2]))) < 1e-3 * scale


def test_fluid_every_killed_run_resumes_to_the_same_trajectory(tmp_path, env, reference_every2):
    """fdmDEM killed once the fluid has recorded 9 steps (it solved step 14), resumed from the
    checkpoint of step 10: its first step, 11, is a held one, whose U_b comes from the checkpoint's U
    and F^FDM."""
    root = make_scene(str(tmp_path), fix_extra="fluid_every 2")
    code = run_and_kill(root, env, "fdmDEM", 9)
    assert code != 0
    r = fdm_run(root, env, "--resume")
    assert r.returncode == 0, r.stdout
    assert fluid_steps(root) == fluid_steps(reference_every2)
    assert trajectory(root)[1] == trajectory(reference_every2)[1]
    worst = largest_difference(root, reference_every2)
    assert worst < 1e-8 * 8, worst


# ------------------------------------------------------------------------------------------------
# held_drag extrapolated: the held steps' drag target extrapolated from the last two fluid steps
# ------------------------------------------------------------------------------------------------

EXTRAPOLATED = "fluid_every 2 held_drag extrapolated"


@pytest.fixture(scope="module")
def reference_extrapolated(tmp_path_factory, env):
    root = str(tmp_path_factory.mktemp("every2extrapolated"))
    make_scene(root, fix_extra=EXTRAPOLATED)
    r = fdm_run(root, env)
    assert r.returncode == 0, r.stdout
    return root


def test_extrapolated_held_drag_solves_the_fluid_on_the_same_steps(reference_extrapolated, reference_every2, reference):
    """The same 50 steps with the fluid every second step, the held drag extrapolated from the last two fluid
    steps: the fluid solves the same steps, the log says how the drag was held, and the trajectory stays within
    the bound of the constant held drag's test above from the run that solves the fluid at every step. In this
    three-sphere scene extrapolating gains nothing (measured 2026-11-28: 1.28e-2 a against 1.15e-2 a constant;
    with checkpoints every 100 steps 1.08e-2 against 0.82e-2, and at fluid_every 4 2.28e-2 against 2.84e-2):
    where it does, in a dense suspension, is tests/test_couette.py's
    test_extrapolated_held_drag_follows_the_fluid_closer."""
    extrapolated = largest_difference(reference_extrapolated, reference)
    constant = largest_difference(reference_every2, reference)
    print("fluid_every 2 against every step: largest position difference %.3g a extrapolated, %.3g a constant"
          % (extrapolated, constant))
    log = open(os.path.join(reference_extrapolated, "log.dem")).read()
    assert "the held drag extrapolated" in log
    assert fluid_steps(reference_extrapolated) == fluid_steps(reference_every2)
    assert 0 < extrapolated < 3e-2


def test_extrapolated_held_drag_killed_run_resumes_to_the_same_trajectory(tmp_path, env, reference_extrapolated):
    """Killed once the fluid has recorded 9 steps, resumed from the checkpoint of step 10: the checkpoint
    carries the last two fluid steps' drag targets, so the resumed run extrapolates as the uninterrupted one
    (without them its first held steps would hold the drag constant and the trajectories would part)."""
    root = make_scene(str(tmp_path), fix_extra=EXTRAPOLATED)
    assert run_and_kill(root, env, "fdmDEM", 9) != 0
    r = fdm_run(root, env, "--resume")
    assert r.returncode == 0, r.stdout
    assert fluid_steps(root) == fluid_steps(reference_extrapolated)
    assert largest_difference(root, reference_extrapolated) < 1e-8 * 8


def refused_resume_loses_nothing(root, env, change, message):
    """The input of a killed run changed by `change` (text -> text): its resume is refused with `message`, the
    checkpoints stay, and the run resumes once the input is as it was."""
    path = os.path.join(root, "dem", "in.couette")
    text = open(path).read()
    with open(path, "w") as f:
        f.write(change(text))
    checkpoints = sorted(os.listdir(os.path.join(root, "dem", "checkpoint")))
    r = fdm_run(root, env, "--resume")
    assert r.returncode != 0
    assert message in r.stdout, r.stdout[-3000:]
    assert sorted(os.listdir(os.path.join(root, "dem", "checkpoint"))) == checkpoints
    with open(path, "w") as f:
        f.write(text)
    r = fdm_run(root, env, "--resume")
    assert r.returncode == 0, r.stdout


def test_resume_with_another_held_drag_is_refused_and_loses_nothing(tmp_path, env):
    """A run killed with the drag held constant, its input then changed to held_drag extrapolated: the resume
    is refused naming both, and the checkpoints stay for a resume with the input as it was."""
    root = make_scene(str(tmp_path), fix_extra="fluid_every 2")
    assert run_and_kill(root, env, "fdmDEM", 9) != 0
    refused_resume_loses_nothing(root, env, lambda text: text.replace("fluid_every 2", EXTRAPOLATED),
                                 "was written with held_drag constant but the input has held_drag extrapolated")


def test_resume_with_another_coulomb_solve_is_refused_and_loses_nothing(tmp_path, env):
    """A run killed with the frozen slides (the default), its input then changed to coulomb_solve consistent:
    the resume is refused naming both (the checkpoint records how the contacts slid), and the checkpoints stay
    for a resume with the input as it was."""
    root = make_scene(str(tmp_path))
    assert run_and_kill(root, env, "fdmDEM", 9) != 0
    refused_resume_loses_nothing(
        root, env,
        lambda text: re.sub(r"(fix\s+\S+\s+all\s+fdm/couple[^\n]*)", r"\1 coulomb_solve consistent", text, count=1),
        "was written with coulomb_solve frozen but the input has coulomb_solve consistent")


# ------------------------------------------------------------------------------------------------
# compact snapshot: the particles of a checkpoint in a few plain files, continued in a fresh case
# with the fluid from rest (fdmRun --from-snapshot; docs/coupling.md "Compact snapshot")
# ------------------------------------------------------------------------------------------------

SNAPSHOT_STEP = 20
SCENE = "tests/test_resume.py make_scene(root, fix_extra='%s')" % EXTRAPOLATED
# the largest position difference from the uninterrupted run over the first 1, 5 and 30 steps after the
# snapshot (a): measured 5.3e-9 (step 21 holds the drag: the snapshot's state alone, its velocities and
# drags rounded to single precision; 0 with the checkpoint's own doubles), 4.8e-6 and 4.8e-6 (the inner
# iteration's tolerance, tolLambda 1e-4, from two starting points); bounds 10 times that
SNAPSHOT_BOUND = {1: 5e-8, 5: 5e-5, 30: 5e-5}


@pytest.fixture(scope="module")
def snapshot_dir(tmp_path_factory, env):
    """The extrapolated-held-drag scene run to step 20 (a run of its own, ended there: checkpoints 15
    and 20), and its compact snapshot."""
    root = str(tmp_path_factory.mktemp("to20"))
    make_scene(root, steps=SNAPSHOT_STEP, fix_extra=EXTRAPOLATED)
    r = fdm_run(root, env)
    assert r.returncode == 0, r.stdout
    dest = str(tmp_path_factory.mktemp("snapshot") / "snapshot")
    done = checkpoint.snapshot(root, dest, scene=SCENE)
    assert done["step"] == SNAPSHOT_STEP
    return root, dest


def snapshot_case(path):
    """A case folder freshly written by the scene's command (the 50-step run)."""
    return make_scene(str(path), fix_extra=EXTRAPOLATED)


def test_snapshot_is_complete_and_compact(snapshot_dir, env):
    """The snapshot is the newest checkpoint's DEM file compacted (positions, velocities, contact history, the
    position update's history, the extrapolated held drag's last two fluid steps; the exact arrays as fdmDEM
    wrote them, the velocity-like ones to single precision, the outputs every step recomputes zero, xz), the
    fluid marker, the input, the calibration record, the scene command and a README: 6 plain files, a few kB
    for 3 spheres. A second snapshot replaces the first."""
    root, dest = snapshot_dir
    assert sorted(os.listdir(dest)) == ["README", "calibration.json", "dem.20.xz", "fluid.20", "in.couette", "scene"]
    header, arrays = checkpoint.read_dem_checkpoint(os.path.join(dest, "dem.20.xz"))
    _, written = checkpoint.read_dem_checkpoint(checkpoint.dem_file(root, 20))
    assert sorted(arrays) == sorted(written)
    for name, values in written.items():
        if name in checkpoint.SNAPSHOT_RECOMPUTED:
            assert arrays[name] == [0.0] * len(values), name
        elif name in checkpoint.SNAPSHOT_SINGLE:
            assert np.allclose(arrays[name], values, rtol=1e-7, atol=0), name
        else:
            assert arrays[name] == values, name
    assert header["step"] == 20 and header["natoms"] == 3
    assert len(arrays["atoms"]) == 14 * 3
    assert arrays["heldDrag"][0] == 1 and len(arrays["heldDragLast"]) == len(arrays["heldDragBefore"]) == 6 * 3
    assert arrays["heldDrag"][1] > arrays["heldDrag"][2] > 0     # the steps of the two fluid steps' targets
    assert len(arrays["currentVelocity"]) == len(arrays["previousVelocity"]) == 6 * 3 and arrays["moveRate"]
    assert sum(arrays["contactHistoryLength"]) > 0      # the frictional contact's spring
    marker = checkpoint.read_fluid_marker(os.path.join(dest, "fluid.20"))
    # stepsDone: the fluid's steps (1, the even ones, the checkpoints' 5 and 15), the count particlesEvery goes on with
    assert (marker["step"], marker["stepsDone"], marker["timeIndex"]) == ("20", "13", "20")
    assert open(os.path.join(dest, "scene")).read() == SCENE + "\n"
    size = sum(os.path.getsize(os.path.join(dest, n)) for n in os.listdir(dest))
    print("snapshot of 3 spheres: %d bytes (%s)" % (size, ", ".join(
        "%s %d" % (n, os.path.getsize(os.path.join(dest, n))) for n in sorted(os.listdir(dest)))))
    assert size < 16000
    # taken again from an earlier checkpoint (the newer one truncated): the folder holds that one only
    other = os.path.join(os.path.dirname(dest), "again")
    shutil.copytree(dest, other)
    copy = os.path.join(os.path.dirname(dest), "run-copy")
    shutil.copytree(root, copy)
    with open(checkpoint.dem_file(copy, 20), "r+b") as f:
        f.truncate(100)
    assert checkpoint.snapshot(copy, other, scene=SCENE)["step"] == 15
    assert sorted(n for n in os.listdir(other) if n[0] in "df") == ["dem.15.xz", "fluid.15"]


def test_snapshot_continues_close_to_the_uninterrupted_run(snapshot_dir, tmp_path, env, reference_extrapolated):
    """The 50-step scene written afresh and continued from the snapshot of step 20 (fdmRun --from-snapshot):
    the fluid restarts from rest at its first step, 22 (the first step's tolerances, tolLambda 1e-5 against 1e-4), the
    particles from the snapshot; the records start at step 21 (the DEM dump at 20), the fluid solves the
    uninterrupted run's steps, and the trajectory stays within SNAPSHOT_BOUND of it: not bit-exact, since
    the inner iteration starts from rest instead of the previous step's fields."""
    _, dest = snapshot_dir
    root = snapshot_case(tmp_path / "case")
    r = fdm_run(root, env, "--from-snapshot", dest)
    assert r.returncode == 0, r.stdout
    log = open(os.path.join(root, "log.fluid")).read()
    assert "==== fdmRun --from-snapshot %s: step 20 to 50" % dest in log
    assert "from a compact snapshot: the fluid from rest" in log
    steps = fluid_steps(root)
    assert steps == [s for s in fluid_steps(reference_extrapolated) if s > SNAPSHOT_STEP], steps
    # the first fluid step after the snapshot, 22 (21 holds the drag of 20 and 18): from rest, to the first
    # step's tolerance
    inner = dict(zip(steps, output.steps(os.path.join(root, "fluid"))["innerIterations"]))
    ref = output.steps(os.path.join(reference_extrapolated, "fluid"))
    ref_inner = dict(zip(ref["step"].astype(int), ref["innerIterations"]))
    print("inner iterations at step 22: %d from rest, %d uninterrupted" % (inner[22], ref_inner[22]))
    assert steps[0] == 22 and inner[22] > ref_inner[22]
    got, order = trajectory(root)
    ref, _ = trajectory(reference_extrapolated)
    assert order == list(range(SNAPSHOT_STEP, STEPS + 1)), order
    assert float(np.max(np.abs(got[SNAPSHOT_STEP] - ref[SNAPSHOT_STEP]))) == 0    # the snapshot's positions
    records = output.read_particle_records(os.path.join(root, "dem", "particles.records"), mmap=False)
    assert list(records.steps) == list(range(SNAPSHOT_STEP + 1, STEPS + 1))
    worst = {}
    for after, bound in SNAPSHOT_BOUND.items():
        worst[after] = max(float(np.max(np.abs(got[s] - ref[s]))) for s in range(SNAPSHOT_STEP + 1, SNAPSHOT_STEP + after + 1))
    print("largest position difference from the uninterrupted run over the first 1, 5, 30 steps: %s (a)"
          % ", ".join("%.3g" % worst[k] for k in sorted(worst)))
    for after, bound in SNAPSHOT_BOUND.items():
        assert worst[after] <= bound, (after, worst)
    # the run's own checkpoints replaced the installed one (and the copy of 0/ at its time)
    assert sorted(os.listdir(os.path.join(root, "fluid", "checkpoint"))) == ["fluid.45", "fluid.50"]
    assert not os.path.exists(os.path.join(root, "fluid", "1"))


def test_snapshot_run_killed_before_its_first_checkpoint_resumes_from_the_snapshot(snapshot_dir, tmp_path, env,
                                                                                  reference_extrapolated):
    """A continued run killed (fdmDEM, SIGKILL) after its first fluid step, before its own first checkpoint (25):
    `fdmRun --resume` takes the installed snapshot (step 20, the fluid again from rest), and the run ends
    within the same bound of the uninterrupted one, each step recorded once."""
    _, dest = snapshot_dir
    root = snapshot_case(tmp_path / "case")
    assert run_and_kill(root, env, "fdmDEM", 1, "--from-snapshot", dest) != 0
    r = fdm_run(root, env, "--resume")
    assert r.returncode == 0, r.stdout
    log = open(os.path.join(root, "log.fluid")).read()
    assert "==== fdmRun --resume from step 20" in log and log.count("from a compact snapshot: the fluid from rest") == 2
    assert fluid_steps(root) == [s for s in fluid_steps(reference_extrapolated) if s > SNAPSHOT_STEP]
    got, order = trajectory(root)
    ref, _ = trajectory(reference_extrapolated)
    assert order == list(range(SNAPSHOT_STEP, STEPS + 1)), order
    worst = max(float(np.max(np.abs(got[s] - ref[s]))) for s in order)
    print("killed and resumed from the installed snapshot: largest position difference %.3g a" % worst)
    assert worst <= SNAPSHOT_BOUND[30]


def test_snapshot_of_another_scene_is_refused(snapshot_dir, tmp_path, env):
    """fdmRun --from-snapshot refuses, naming the file and the value, before the case changes: a case that
    holds a run, another input, another particle count, a changed calibration table, an incomplete snapshot,
    another mesh."""
    _, dest = snapshot_dir

    def refused(root, message, snapshot=dest):
        before = sorted(os.path.relpath(os.path.join(d, n), root) for d, _, files in os.walk(root) for n in files)
        r = fdm_run(root, env, "--from-snapshot", snapshot)
        assert r.returncode != 0 and message in r.stdout, (message, r.stdout[-3000:])
        after = sorted(os.path.relpath(os.path.join(d, n), root) for d, _, files in os.walk(root) for n in files
                       if "polyMesh" not in d and n != "log.blockMesh")
        assert after == [p for p in before if "polyMesh" not in p], "the case changed"

    # another input: the spring's stiffness
    root = snapshot_case(tmp_path / "input")
    path = os.path.join(root, "dem", "in.couette")
    text = open(path).read()
    with open(path, "w") as f:
        f.write(text.replace("contact 400 200", "contact 500 200"))
    refused(root, "in.couette is not the input of the snapshot's run %s/in.couette: line 8 is 'pair_style      "
            "fdm/subgrid model cutoff contact 400 200 0.5 0.05" % dest)
    # another particle count (the data file)
    root = make_scene(str(tmp_path / "natoms"), fix_extra=EXTRAPOLATED, spheres=[(5.0, 2.55, 3.0, 1.0), (3.0, 3.45, 3.0, 1.0)])
    refused(root, "spheres.data has 2 particles, the snapshot %s/dem.20.xz holds 3" % dest)
    # a calibration record of another table
    changed = str(tmp_path / "changed")
    shutil.copytree(dest, changed)
    with open(os.path.join(changed, "calibration.json"), "w") as f:
        json.dump({"table": "/elsewhere/subgrid_calibration.dat", "sha256": "0" * 64}, f)
    refused(snapshot_case(tmp_path / "calibration"), "the sub-grid calibration table differs from the run's: the "
            "snapshot's run used /elsewhere/subgrid_calibration.dat", changed)
    # an incomplete snapshot
    incomplete = str(tmp_path / "incomplete")
    shutil.copytree(dest, incomplete)
    os.remove(os.path.join(incomplete, "fluid.20"))
    refused(snapshot_case(tmp_path / "incomplete-case"), "is not a complete snapshot: it needs one dem.STEP.xz (or "
            "dem.STEP) and the fluid.STEP", incomplete)
    # another mesh (cells of 0.4 instead of 0.5: the same input)
    root = snapshot_case(tmp_path / "mesh")
    path = os.path.join(root, "fluid", "system", "blockMeshDict")
    text = open(path).read()
    with open(path, "w") as f:
        f.write(text.replace("(16 12 12)", "(20 15 15)"))
    assert open(path).read() != text
    r = fdm_run(root, env, "--from-snapshot", dest)
    assert r.returncode != 0 and "has 4500 cells, the snapshot's run had 2304" in r.stdout, r.stdout[-3000:]
    # a case that holds a run
    root = snapshot_case(tmp_path / "ran")
    assert fdm_run(root, env, "--from-snapshot", dest).returncode == 0
    r = fdm_run(root, env, "--from-snapshot", dest)
    assert r.returncode != 0 and "--from-snapshot: %s holds a run" % root in r.stdout, r.stdout


def test_a_snapshot_of_a_run_resumed_with_its_table_continues_in_a_fresh_scene(tmp_path, monkeypatch):
    """fdmRun --resume names the table a run started with in its input (`pair_style fdm/subgrid calibration
    FILE ...`); a snapshot of that run still continues in a scene written afresh, whose input has no such
    keyword (the table is checked by its hash), while any other changed line is refused."""
    monkeypatch.setenv("FDM_ROOT", PROJECT)
    snap = tmp_path / "snapshot"
    shutil.copytree(PAPER_SNAPSHOT, snap)
    text = scene_input(PAPER_SNAPSHOT)
    assert "fdm/subgrid calibration" not in text
    (snap / "in.poiseuille").write_text(text.replace("fdm/subgrid ", "fdm/subgrid calibration %s "
                                                     % os.path.basename(PREVIOUS_TABLE), 1))
    case_dir = tmp_path / "case"
    (case_dir / "dem").mkdir(parents=True)
    dem_input = str(case_dir / "dem" / "in.poiseuille")
    (case_dir / "dem" / "in.poiseuille").write_text(text)
    step, last = checkpoint.snapshot_check(str(snap), str(case_dir), dem_input)
    assert step == checkpoint.check_snapshot(str(snap))["step"] and last > step
    (case_dir / "dem" / "in.poiseuille").write_text(text.replace("model calibrated", "model cutoff", 1))
    with pytest.raises(checkpoint.CheckpointError, match="is not the input of the snapshot's run"):
        checkpoint.snapshot_check(str(snap), str(case_dir), dem_input)
