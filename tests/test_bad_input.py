"""Bad input gets a clear error naming the file, the particle or the value, and no code hangs.

Each test runs the real fdmFoam and fdmDEM on a tiny mesh through fdmRun and checks the exit
status, the message and that both codes stopped within seconds."""
import os
import re
import signal
import subprocess
import time

import pytest

from fdm import case

PROJECT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FDMRUN = os.path.join(PROJECT, "scripts", "fdmRun")


def make_case(tmp_path, spheres=((2.0, 2.0, 2.0, 0.5),), box=None, dem_box=None, n_particles=-1,
              fdm_edit=None, fix_options="move no", runs=("run 2",)):
    box = box or case.Box((0, 0, 0), (4, 4, 4), 0.5)
    root = str(tmp_path / "case")
    fluid = os.path.join(root, "fluid")
    case.write_fluid_case(fluid, box, grad_p0=(-0.01, 0, 0), tol_lambda=1e-3, n_max=50,
                          n_particles=n_particles)
    props = os.path.join(fluid, "constant", "fdmProperties")
    text = open(props).read().replace("connectTimeout 60", "connectTimeout 5")
    if fdm_edit:
        text = fdm_edit(text)
    open(props, "w").write(text)
    case.write_dem_input(os.path.join(root, "dem"), dem_box or box, list(spheres),
                         fix_options="connect_timeout 5 " + fix_options, runs=runs)
    return root


def run_fdm(root, env, timeout=60):
    t0 = time.time()
    proc = subprocess.run([FDMRUN, "--quiet", root], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, errors="replace",
                          text=True, env=env, timeout=timeout)
    return proc.returncode, proc.stdout, time.time() - t0


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


def test_overlapping_particles(tmp_path, env):
    root = make_case(tmp_path, spheres=[(2.0, 2.0, 2.0, 0.5), (2.8, 2.0, 2.0, 0.5)])
    status, out, wall = run_fdm(root, env)
    assert status != 0
    text = logs(root)
    assert "overlap" in text.lower(), text[-2000:]
    assert re.search(r"\b1\b", text) and re.search(r"\b2\b", text)
    assert wall < 30


def test_missing_dictionary_entry(tmp_path, env):
    root = make_case(tmp_path, fdm_edit=lambda t: re.sub(r"\n\s*tolLambda[^\n]*", "", t, count=1))
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
    root = make_case(tmp_path)
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
    root = make_case(tmp_path)
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
