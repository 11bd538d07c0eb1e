"""cases/shearedSphere: the dilute limit of the stresslet (issue 11 item 4) and the momentum balance
of the fluid on the walls, a free sphere at the centre of a channel H = 20 a in simple shear, run by
the real fdmFoam and fdmDEM (one time step from the linear profile)."""
import pytest

from conftest import load_case_module


@pytest.fixture(scope="module")
def sheared_sphere():
    return load_case_module("shearedSphere")


def test_dilute_stresslet_and_wall_balance(sheared_sphere, tmp_path, env):
    # CI size: L = 12 a (x, z periodic), H = 20 a, a/Delta = 3, the centre on a mesh vertex, about 10 s.
    # Measured: S* = 0.9859 (L = 8: 0.9753, 16: 0.9885, 20: 0.9895; H = 30 at L = 12: 0.9847); the
    # position in the cell moves S* by up to +-5 % at a/Delta = 3 (8-position mean at L = 8: 0.961,
    # docs/validation.md), which the FULL test averages. The fluid's shear force on the walls equals
    # eta gamma_dot A + S_xy A / V (the momentum balance): measured to 3e-7.
    r = sheared_sphere.main(["--size", "12", "20", "12", "--workdir", str(tmp_path), "--out",
                             str(tmp_path / "r.json")])["runs"][0]
    assert r["converged"]
    assert r["S_star"] == pytest.approx(1.0, abs=0.02)
    assert r["omega_z_over_minus_half_gamma"] == pytest.approx(1.0, abs=0.01)
    assert max(abs(v) for v in r["velocity"]) < 1e-3
    assert r["wall_balance_rel_error"] < 1e-4
    # both walls carry the same shear stress, and its excess over eta gamma_dot is the stresslet's
    assert r["wall_stress_lo"] == pytest.approx(r["wall_stress_hi"], rel=1e-4)
    assert r["wall_excess_over_eta_gamma"] == pytest.approx(r["stresslet_excess"], rel=0.02)


@pytest.mark.full
def test_dilute_stresslet_averaged_over_cell_positions(sheared_sphere, tmp_path, env):
    # The paper's way (5.2.2: 16 positions in a cell): 8 positions (2^3 midpoints of the cell modulo
    # its mirror symmetries), a/Delta = 4, L = 12 a, H = 20 a. Measured at L = 8: mean S* 0.983
    # (a/Delta = 4), 0.980 (5), 0.961 (3); L = 8 -> 12 adds about 1 %. Measured here: 0.9936
    # (0.954 ... 1.033), 197 s.
    res = sheared_sphere.main(["--size", "12", "20", "12", "--a-over-delta", "4", "--positions", "2",
                               "--workdir", str(tmp_path), "--out", str(tmp_path / "r.json")])
    avg = res["averages"][0]
    assert avg["positions"] == 8
    assert avg["S_star"] == pytest.approx(1.0, abs=0.02)
    assert avg["wall_balance_rel_error_max"] < 1e-3
