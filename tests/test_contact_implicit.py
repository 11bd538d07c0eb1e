"""Implicit contact springs (pair_style fdm/subgrid contact_integration implicit, the default;
docs/contact.md 2b, 3c): stable far beyond the explicit springs' limit with the steady gap
h_r - F/k_n exact, the same trajectories as the explicit springs at small dt, and the fluid's
answer to a sphere pressed a little into a wall (accepted, warned once) or escaping through it
(fatal, naming the particle). DEM-only scenes of cases/contactTuning (SI at the 1 m scale) and two
small coupled runs; about 30 s."""
import os
import re
import subprocess

import pytest

from fdmsubgrid import case, contactstability, output

from test_bad_input import FDMRUN, make_case, run_fdm, logs



@pytest.mark.parametrize("name, geometry, integrator", [
    ("pair, lubrication", "pair", "ab2"),
    ("pair, lubrication", "pair", "euler"),
    ("wall, lubrication", "wall", "ab2"),
    ("tangential (two walls), lubrication", "tangential", "ab2"),
])
def test_stable_at_ten_times_the_explicit_limit(tmp_path, env, ct, res, name, geometry, integrator):
    # the perturbed steady contact at 10 dt_explicit: explicit springs chatter, implicit ones
    # converge at the factor of Eq. (C4), (1 + r/2)/(1 + 3r/2) (ab2) or 1/(1 + r) (euler)
    implicit = ct.StabilityConfig(res, name, geometry, True, integrator, cint="implicit")
    r = implicit.run(str(tmp_path), 10 * implicit.dt_estimate, 400)
    assert r["ok"] and r["stable"] and r["label"] == "converged", r
    if r["factor_measured"]:
        assert abs(r["factor_measured"] - contactstability.implicit_growth_factor(r["r"], integrator)) < 1e-3, r
    explicit = ct.StabilityConfig(res, name, geometry, True, integrator, cint="explicit")
    e = explicit.run(str(tmp_path), 10 * explicit.dt_estimate, 400)
    assert e["ok"] and not e["stable"], e


def test_steady_gap_far_beyond_the_explicit_limit(tmp_path, env, ct, res):
    # pair and wall at 10 times the explicit limit, an overlap (F > k_n h_r) with the frozen
    # lubrication at 10 x 707 s, a spring 100 times stiffer at the soft one's limit: the steady gap
    # is h_r - F/k_n to 1e-6 of F/k_n, the contact force the load, F1 + F2 = 0 at every step
    runs = ct.implicit_equilibrium(res, str(tmp_path), 2)
    assert len(runs) == 5
    for r in runs:
        assert r["ok"], r.get("log")
        assert r["dt"] >= 10 * r["dt_explicit_limit"] * (1 - 1e-12), r
        assert abs(r["gap_error"]) < 1e-6, r
        assert abs(r["normal_force_error"]) < 1e-6, r
        assert r["settled_step"] is not None and r["settled_step"] < 60, r
        if r["geometry"] == "pair":
            assert r["force_balance"] < 1e-9, r


def test_same_trajectory_at_small_time_steps(tmp_path, env, ct):
    # a pair pressed from inside the roughness layer: both laws converge to the same gap history,
    # explicit at second order, implicit at first (the spring force is that of the step's end)
    c = ct.implicit_convergence(None, str(tmp_path), 2, dts=(0.05, 0.025, 0.0125), dt_ref=0.001)
    err = {(x["cint"], x["dt"]): x["error"] for x in c["runs"]}
    assert err[("explicit", 0.0125)] < 0.005 and err[("implicit", 0.0125)] < 0.02, c
    assert 1.8 < c["order_explicit"] < 2.2, c
    assert 0.85 < c["order_implicit"] < 1.15, c


def test_stuck_and_sliding_with_implicit_springs(tmp_path, env, ct, res):
    # at 10 times the tangential limit: stuck below mu_s F_n with the displacement F_t/k_t, sliding
    # above it with exactly mu_s F_n and the theory's speed
    stuck = ct.sliding_run(res, str(tmp_path), 0.5, cint="implicit", r_target=10.0)
    assert stuck["ok"] and stuck["stuck"], stuck
    assert abs(stuck["ft_over_Ft"] - 1) < 1e-6 and abs(stuck["displacement_over_spring"] - 1) < 1e-6, stuck
    slide = ct.sliding_run(res, str(tmp_path), 1.5, cint="implicit", r_target=10.0)
    assert slide["ok"] and not slide["stuck"], slide
    assert abs(slide["ft_over_muFn"] - 1) < 1e-9, slide
    assert abs(slide["U_end"] / slide["sliding_speed_theory"] - 1) < 1e-6, slide


# A sphere (a = 0.5, Delta = 0.25) on the wall y = 0 of a box periodic in x and z, in contact from
# the start (gap 0.002 < h_r = 0.0025), pushed down by its buoyant weight (rho_p = 2000, rho_f = 1,
# g = 0.01: 0.5 * 2000 * (4/3 pi 0.125) * 0.01 = 5.24 N; no lubrication: the resolved flow only).
WALL_BOX = case.Box((0, 0, 0), (4, 4, 4), 0.25, faces=("cyclic", ((0, 0, 0), (0, 0, 0)), "cyclic"))


def _wall_case(tmp_path, kn, steps, checkpoint=0):
    weight = 0.5 * 2000 * 4.0 / 3.0 * 3.141592653589793 * 0.125 * 0.01
    root = make_case(tmp_path, spheres=[(2.0, 0.502, 2.0, 0.5)], box=WALL_BOX,
                     fix_options="gravity 0 -0.01 0" + (" checkpoint %d" % checkpoint if checkpoint else ""),
                     runs=("run %d upto" % steps,), dt=0.1,
                     pair_style="fdm/subgrid lubrication no contact %g 0 0.5 0.0025 wall ylo 0 0 0 wall yhi 0 0 0" % kn)
    # the write_dem_input spheres have density 1000: make them 2000
    data = os.path.join(root, "dem", "spheres.data")
    text = open(data).read().replace(" 1000 2 0.502 2", " 2000 2 0.502 2")
    open(data, "w").write(text)
    return root, weight


def test_fluid_accepts_a_sphere_pressed_into_a_wall(tmp_path, env):
    # k_n = 698 N/m: the steady overlap F/k_n - h_r = 0.005 = 0.01 a, reached in a few steps at
    # dt = 0.1 s (beyond the explicit limit); fdmFoam warns once and runs on
    root, weight = _wall_case(tmp_path, 698.0, 12)
    status, out, wall = run_fdm(root, env, timeout=120)
    assert status == 0, out + logs(root)[-3000:]
    fluid = open(os.path.join(root, "log.fluid"), errors="replace").read()
    warnings = re.findall(r"fdmFoam: particle 1 at .* overlaps the wall y = 0 by (\S+) \((\S+) radii\): accepted", fluid)
    assert len(warnings) == 1, fluid[-3000:]
    assert 0 < float(warnings[0][1]) <= 0.05
    dem = open(os.path.join(root, "log.dem"), errors="replace").read()
    assert "stable with the implicit springs" in dem


def test_a_run_with_a_sphere_pressed_into_a_wall_resumes(tmp_path, env):
    # the same sphere, checkpointed while pressed 0.01 a into the wall: both codes accept the
    # resumed configuration as they accepted it at every step (a configuration the input gives must
    # be clear of the walls: test_particle_crossing_a_wall), and the run extends to step 16
    root, weight = _wall_case(tmp_path, 698.0, 12, checkpoint=4)
    status, out, wall = run_fdm(root, env, timeout=120)
    assert status == 0, out + logs(root)[-3000:]
    proc = subprocess.run([FDMRUN, "--quiet", "--resume", "--until", "16", root], stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, errors="replace", text=True, env=env, timeout=120)
    assert proc.returncode == 0, proc.stdout + logs(root)[-3000:]
    dem = open(os.path.join(root, "log.dem"), errors="replace").read()
    assert "resuming from checkpoint/dem.12" in dem, dem[-3000:]
    steps = output.steps(os.path.join(root, "fluid"))["step"].astype(int)
    assert list(steps) == list(range(1, 17)), steps
    y = output.particles(os.path.join(root, "fluid"))["y"]
    assert 0.5 - 0.05 * 0.5 < y[-1] < 0.5, y    # still pressed in, less than the accepted 0.05 radii


def test_fluid_stops_a_sphere_escaping_through_a_wall(tmp_path, env):
    # k_n = 1 N/m cannot hold 5.24 N: the sphere sinks through the wall; fdmFoam stops the run once
    # it crosses the wall by more than 0.05 radii, naming the particle, its position and the overlap
    root, weight = _wall_case(tmp_path, 1.0, 40)
    status, out, wall = run_fdm(root, env, timeout=120)
    assert status != 0
    text = logs(root)
    m = re.search(r"particle 1 at \(.*\) with radius 0.5 lies outside the OpenFOAM mesh .* in y: the mesh spans 0 "
                  r"\.\. 4 \(walls\): it crosses the wall y = 0 by (\S+) \((\S+) radii, more than the 0.05 radii "
                  r"accepted for a contact pressed into a wall\): it escapes through the wall", text)
    assert m and float(m.group(2)) > 0.05, text[-3000:]


def _dem_shear(tmp_path, env, *variants):
    """cases/couette/demShear.py (phi 0.47 between walls, no fluid, 200 steps) for the named variants;
    its rows by variant name."""
    import json
    import subprocess
    import sys
    project = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    script = os.path.join(project, "cases", "couette", "demShear.py")
    out = tmp_path / "dem.json"
    proc = subprocess.run([sys.executable, script, "--variant", *variants, "--steps", "200", "--workdir", str(tmp_path),
                           "--out", str(out)], env=env, text=True, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          timeout=900)
    assert proc.returncode == 0, proc.stdout[-3000:]
    return {r["variant"]: r for r in json.loads(out.read_text())["rows"]}


def test_dense_sheared_packing_keeps_contacts_shallow(tmp_path, env):
    # phi 0.47 between walls at -U and +U without the fluid (cases/couette/demShear.py, the case's
    # former springs at dt 0.02, k_t = 485 N/m): with the contact gaps held during the log-gap correction (the default)
    # no pair overlaps by more than 0.02 a1 and no sphere reaches into a wall; left free, the
    # corrections of the particles' lubrication gaps pushed them into their contacts (0.09 a1 and
    # walls crossed by 0.07 a1 in 200 steps, docs/benchmarks.md "Stability map")
    rows = _dem_shear(tmp_path, env, "hold:kt=485.1", "free:kt=485.1:fix=contact_gaps+free")
    hold, free = rows["hold"], rows["free"]
    assert hold["completed"] and free["completed"]
    assert hold["min_pair_gap"] > -0.02 and hold["min_wall_gap"] > 0, hold
    assert "held contact gaps per step" in hold["position_update"]
    assert free["min_pair_gap"] < 2 * hold["min_pair_gap"], (hold, free)


def test_stiff_friction_in_a_dense_sheared_packing_holds(tmp_path, env):
    # phi 0.47 between walls without the fluid, k_t = k_n (k_t dt/zeta_t ~ 320 at dt 0.02), with and
    # without the log-gap correction: Coulomb's law at the end of the step (docs/contact.md 2c)
    # keeps every particle slow and every overlap shallow. Before it, the run without the correction
    # reached 896 a1 gamma_dot_0 and overlaps of 2 a1 at step 150, and mu_s = 5 blew up within 25
    # steps (docs/benchmarks.md, "Coulomb's law at the end of the step")
    rows = _dem_shear(tmp_path, env, "stiff:kt=kn", "stiff_no_gap_update:kt=kn:fix=gap_update+none")
    for name, deepest in (("stiff", -0.02), ("stiff_no_gap_update", -0.1)):
        row = rows[name]
        assert row["completed"] and row["steps"] >= 200, row
        assert row["max_speed"] < 20, row          # the walls move at 6 a1 gamma_dot_0 (L_y = 12)
        assert row["min_pair_gap"] > deepest, row
