"""fix fdm/couple transport none with background_shear G (docs/dem.md): the particle side of a sheared
suspension without the fluid solver, each sphere's isolated drag taken relative to the simple shear
u = G (y - y_centre) e_x. Checked against Stokes flow: an isolated sphere follows the flow (Faxen: U =
u(x_p), Omega = -G/2 e_z) and carries the stresslet (20/3) pi eta a^3 E; a close pair across the
flow keeps the point symmetry of the shear and is slowed by its sub-grid lubrication. fdmDEM alone,
a second each."""
import math

import numpy as np
import pytest

from fdmsubgrid import demonly, output, packing

ETA, DELTA, G = 2.0, 1.0 / 3.0, 1.5


def run(tmp_path, positions, radii, steps=1, logs=None):
    p = packing.Packing(positions, radii, [1 if a == 1.0 else 2 for a in radii], [12.0] * 3)
    scene = demonly.Scene(p, solver="ldlt", steps=steps, dt=1e-3, eta=ETA, delta=DELTA, contact=None,
                          extra_fix="background_shear %r stresslets yes" % G, records_every=1)
    r = demonly.run(scene, str(tmp_path))
    assert r["ok"] and r["completed"], r["log"]
    if logs is not None:
        logs.append(r["log"])
    return output.read_particle_records(str(tmp_path / "particles.records"))


def test_isolated_spheres_follow_the_shear(tmp_path):
    # y_centre = 6: spheres 4 and 5 radii apart in x and y, far beyond any sub-grid range
    radii = [1.0, 1.4]
    rec = run(tmp_path, [[2.0, 2.5, 6.0], [8.0, 9.0, 6.0]], radii)
    U, W, S = rec["U"][-1], rec["omega"][-1], rec["S_fluid"][-1]
    for p, (y, a) in enumerate(zip((2.5, 9.0), radii)):
        assert U[p] == pytest.approx([G * (y - 6.0), 0.0, 0.0], abs=1e-10)
        assert W[p] == pytest.approx([0.0, 0.0, -G / 2], abs=1e-10)
        # Kim & Karrila's S = (20/3) pi eta a^3 E, E_xy = G/2; order xx xy xz yy yz zz
        assert S[p] == pytest.approx([0, 10 / 3 * math.pi * ETA * a ** 3 * G, 0, 0, 0, 0], abs=1e-9)
        assert np.all(rec["S_subgrid"][-1][p] == 0)
        # the fluid's force on a sphere moving with the flow is zero
        assert rec["F_fluid"][-1][p] == pytest.approx([0, 0, 0], abs=1e-9)


def test_close_pair_across_the_shear_is_symmetric_and_slowed(tmp_path):
    # equal spheres on the line x = 6 through the box centre, one above the other, gap 0.05 a: the
    # flow slides them past each other at G (2 a + h); point symmetry about the centre gives U2 = -U1,
    # Omega1 = Omega2; the sub-grid sliding resistance slows the slide
    h = 0.05
    rec = run(tmp_path, [[6.0, 6.0 - 1 - h / 2, 6.0], [6.0, 6.0 + 1 + h / 2, 6.0]], [1.0, 1.0])
    U, W = rec["U"][-1], rec["omega"][-1]
    assert U[1] == pytest.approx(-U[0], abs=1e-10)
    assert W[1] == pytest.approx(W[0], abs=1e-10)
    free = G * (1 + h / 2)
    assert 0 < U[1][0] < 0.99 * free
    assert abs(U[0][1]) < 1e-10 and abs(U[0][2]) < 1e-10
    assert np.any(rec["S_subgrid"][-1] != 0)


def test_position_update_counts_are_read_from_the_log(tmp_path):
    # the run-end line's log-gap counts (demonly.position_update_counts, which the Couette report, table8.py
    # and timeStepWithoutFluid.py use): a close pair sliding in the shear has a log-gap target every step
    # and, alone, no contradictory or limited targets
    logs = []
    run(tmp_path, [[6.0, 6.0 - 1.05, 6.0], [6.0, 6.0 + 1.05, 6.0]], [1.0, 1.0], steps=20, logs=logs)
    counts = demonly.position_update_counts(logs[0])
    assert counts == dict(steps=20, fallback_steps=0, limited=0, fallback_fraction=0.0, particles=2,
                          limited_per_particle_step=0.0), counts
    assert demonly.time_step_too_large(counts) is None
    # beyond the limit: the coupled phi 0.47 small scene at dt 0.02 (1050 limited targets in 400 steps of 98)
    too_large = dict(counts, steps=400, fallback_steps=333, limited=1050, particles=98,
                     limited_per_particle_step=1050 / (400 * 98))
    message = demonly.time_step_too_large(too_large)
    assert "0.0268 gap targets per particle and step" in message and "333 of 400 steps" in message, message


def test_fluid_every_without_the_fluid_is_refused(tmp_path):
    """fluid_every K goes with the fluid solver: transport none has no fluid step to space out."""
    p = packing.Packing([[2.0, 2.5, 6.0]], [1.0], [1], [12.0] * 3)
    scene = demonly.Scene(p, solver="ldlt", steps=1, dt=1e-3, eta=ETA, delta=DELTA, contact=None,
                          extra_fix="background_shear %r fluid_every 2" % G)
    r = demonly.run(scene, str(tmp_path))
    assert not r["ok"]
    assert "fix fdm/couple: fluid_every goes with the fluid solver (transport none has no fluid step)" in r["log"], \
        r["log"][-2000:]
