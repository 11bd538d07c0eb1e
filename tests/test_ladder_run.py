"""cases/poiseuille/ladderRun, the ladder of channel sizes run in segments (and cases/poiseuille/paperRun, its
paper rung): each rung's scene writes the run folder the script continues and saves from, paperRun is the
ladder's paper rung with its own command line, and bad input is refused by name. Scenes are written
(poiseuille.py --write-only, a few seconds); one test runs --until-steady's loop on L20 for two short chunks
(about a minute)."""
import os
import re
import subprocess

import numpy as np
import pytest

from conftest import PROJECT, load_case_module

CASE = os.path.join(PROJECT, "cases", "poiseuille")
LADDER = os.path.join(CASE, "ladderRun")
PAPER = os.path.join(CASE, "paperRun")


def run(cmd, env):
    return subprocess.run(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def scene(script, rung, workdir, env):
    """The rung's poiseuille.py options and its run folder, as the script prints them."""
    out = run([script] + ([rung] if rung else []) + ["--scene", "--workdir", str(workdir)], env)
    assert out.returncode == 0, out.stderr
    options, folder = out.stdout.splitlines()
    return options.split(), folder


@pytest.mark.parametrize("rung, size, spheres", [("L12", [12.0, 12.0, 8.0], 85), ("L20", [20.0, 20.0, 10.0], 293)])
def test_each_rung_continues_the_run_folder_its_scene_writes(rung, size, spheres, tmp_path, env):
    """The folder ladderRun resumes, saves and analyses is the one poiseuille.py writes from the rung's options:
    the channel of the rung at phi_bulk 0.45 (seed 1: the same spheres every time), the particles at dt 0.05,
    the fluid every 8th step."""
    options, folder = scene(LADDER, rung, tmp_path, env)
    assert os.path.dirname(folder) == str(tmp_path)
    written = load_case_module("poiseuille").main(options + ["--write-only", "--workdir", str(tmp_path),
                                                             "--out", str(tmp_path / "r.json")])
    assert written["run_dir"] == folder and os.path.isdir(os.path.join(folder, "fluid"))
    with open(os.path.join(folder, "dem", "in.poiseuille")) as f:
        data = f.read()
    assert "fluid_every 8" in data
    assert options[options.index("--size") + 1:options.index("--size") + 4] == ["%g" % v for v in size]
    assert os.path.basename(folder).startswith("phi0.45_%gx%gx%g_ad3_dt0.05_seed1" % tuple(size))
    with open(os.path.join(folder, "dem", "packing.data")) as f:
        assert "\n%d atoms\n" % spheres in f.read()


def test_the_paper_rung_started_near_its_steady_state_is_a_scene_of_its_own(tmp_path, env):
    """ladderRun paper-sbm: the paper's channel with --start sbm, in a run folder (and kept folder) of its own,
    the same spheres as the paper rung spread with the SBM's profile."""
    options, folder = scene(LADDER, "paper-sbm", tmp_path, env)
    paper, paper_folder = scene(LADDER, "paper", tmp_path, env)
    assert options[options.index("--start") + 1] == "sbm" and folder != paper_folder
    assert [o for o in options if o not in ("--start", "sbm")] == paper
    written = load_case_module("poiseuille").main(options + ["--write-only", "--workdir", str(tmp_path),
                                                             "--out", str(tmp_path / "r.json")])
    assert written["run_dir"] == folder and folder.endswith("_seed1_startSbm_calibrated_fluidEvery8")
    with open(os.path.join(folder, "dem", "packing.data")) as f:
        assert "\n2345 atoms\n" in f.read()


def test_paper_run_is_the_ladders_paper_rung(tmp_path, env):
    """paperRun keeps its command line: the same scene and run folder as `ladderRun paper`, the options of
    the committed paper snapshot's scene command, its own help and its own name in a refusal."""
    paper = scene(PAPER, None, tmp_path, env)
    assert paper == scene(LADDER, "paper", tmp_path, env)
    assert paper[1] == str(tmp_path / "phi0.45_40x40x20_ad3_dt0.05_seed1_calibrated_fluidEvery8")
    with open(os.path.join(CASE, "paper", "snapshot", "scene")) as f:
        committed = f.read().split()
    assert committed[2:2 + len(paper[0])] == paper[0]
    helped = run([PAPER, "--help"], env)
    assert helped.returncode == 0 and helped.stdout.startswith("The paper's channel")
    refused = run([PAPER, "--bogus"], env)
    assert refused.returncode == 2 and "paperRun: unknown option --bogus" in refused.stderr


def test_bad_rung_and_options_are_refused(tmp_path, env):
    refused = run([LADDER, "L7"], env)
    assert refused.returncode == 2 and "not 'L7'" in refused.stderr and "L12, L20, paper or paper-sbm" in refused.stderr
    refused = run([LADDER, "L20", "--save", "--workdir", str(tmp_path)], env)
    assert refused.returncode == 2 and "no run in %s" % tmp_path in refused.stderr
    refused = run([LADDER, "L12", "--until", "100", "--workdir", str(tmp_path)], env)
    assert refused.returncode == 2 and "--until continues a run folder's own checkpoint or the committed " \
        "snapshot" in refused.stderr
    # the committed snapshot of L20 is continued by --until, but only past its own step
    refused = run([LADDER, "L20", "--until", "100", "--workdir", str(tmp_path)], env)
    assert refused.returncode == 2 and "--until 100: the committed snapshot" in refused.stderr
    assert "already" in refused.stderr
    # --until-steady continues a run; its chunks are 200 steps at least (the 8 records of an analysis)
    refused = run([LADDER, "L12", "--until-steady", "--workdir", str(tmp_path)], env)
    assert refused.returncode == 2 and "--until-steady continues a run" in refused.stderr
    for bad in ("0", "100", "x"):
        refused = run([LADDER, "L20", "--until-steady", "--check-every", bad, "--workdir", str(tmp_path)], env)
        assert refused.returncode == 2 and "--check-every takes at least 200 steps" in refused.stderr
        assert "got '%s'" % bad in refused.stderr
    assert not os.listdir(tmp_path)


def test_until_steady_stops_at_its_end_without_running(tmp_path, env):
    """ladderRun --until-steady goes on in chunks to the rung's T or to --until: from the committed snapshot of
    L20 (step 40000) an end before it is reached already, said so, and nothing is run or written."""
    out = run([LADDER, "L20", "--until-steady", "--until", "39000", "--workdir", str(tmp_path)], env)
    assert out.returncode == 0, out.stderr
    assert "step 40000, the end (39000), reached before the run was steady" in out.stdout
    assert not os.listdir(tmp_path)


def test_until_steady_runs_chunks_from_the_snapshot_then_its_own_checkpoint(tmp_path, env):
    """--until-steady's loop end to end on L20, two chunks of 200 steps: the first continues the committed
    snapshot (step 40000), the steady check answers 'not yet' (L20's centre falls over its window) and the
    progress line names the step, the chunk's time and the time to the end; the second continues the run
    folder's own checkpoint and the run stops at --until. The records run on without a step twice or a gap
    between the chunks."""
    from fdmsubgrid import output
    out = run([LADDER, "L20", "--until-steady", "--until", "40400", "--check-every", "200",
               "--workdir", str(tmp_path)], env)
    assert out.returncode == 0, out.stderr[-2000:]
    lines = [line for line in out.stdout.splitlines() if line.startswith("ladderRun L20:")]
    assert "continuing from the snapshot" in lines[0]
    assert re.match(r"ladderRun L20: step 40200 of at most 40400; the chunk took \d+ (s|min) for 200 steps: "
                    r"the end in about \d+ (s|min) at this rate", lines[1]), lines[1]
    assert "from its own checkpoint to step 40400" in lines[2]
    assert lines[3] == "ladderRun L20: step 40400, the end (40400), reached before the run was steady"
    _, folder = scene(LADDER, "L20", tmp_path, env)
    records = output.read_particle_records(os.path.join(folder, "dem", "particles.records"))
    every = int(records.header["every"])
    assert records.steps[0] == 40000 + every and records.steps[-1] == 40400
    assert np.all(np.diff(records.steps) == every)
    for code, prefix in (("dem", "dem."), ("fluid", "fluid.")):
        assert prefix + "40400" in os.listdir(os.path.join(folder, code, "checkpoint"))
