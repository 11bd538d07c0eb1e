"""cases/channelShear (paper 5.2.2, Fig. 10): a free sphere at the centre of a channel sheared by both
walls, run by the real fdmFoam and fdmDEM: one small scene (a1 = 1, walls 12a x 12a, a1/Delta = 3,
the paper's 16 positions in the cell (4 computed), H/a = 7/3 with and without the sub-grid
correction, 8/3 and 10; about 45 s), and bad options refused by name (no solver)."""
import pytest

from conftest import assert_refused, load_case_module


@pytest.fixture(scope="module")
def channel_shear():
    return load_case_module("channelShear")


def test_confined_and_wide_channel(channel_shear, tmp_path, env):
    # Measured (2026-11-26, tolLambda 1e-5, mean +- standard deviation over the 16 positions; 45 s on
    # 2 shared cores), Wz = Omega_z/(-gamma_dot/2), with the default (calibrated) sub-grid model:
    #   H/a = 7/3, sub-grid:  Wz = 0.765 +- 0.064  S* = 2.663 +- 0.156 (sub-grid part 0.424)
    #   H/a = 7/3, FDM alone: Wz = 0.989 +- 0.063  S* = 2.241 +- 0.145
    #   H/a = 8/3:            Wz = 0.782 +- 0.029  S* = 1.622 +- 0.040 (sub-grid part 0.052)
    #   H/a = 10:             Wz = 0.972 +- 0.027  S* = 0.973 +- 0.026
    # (the cut-off model, --model cutoff: Wz 0.936, 0.816, 0.976 and S* 3.085 (sub-grid part 0.844), 1.575, 0.973)
    #   |Ux|, |Uz| < 1.1e-8, |Uy| <= 0.014 gamma_dot a (the offsets break the mesh's symmetry about the centre)
    res = channel_shear.main(["--H-over-a", "2.3333333333", "2.6666666667", "10", "--positions", "16",
                              "--workdir", str(tmp_path), "--out", str(tmp_path / "r.json")])
    rows = {(round(r["H_over_a"], 3), r["subgrid"]): r for r in res["rows"]}
    assert sorted(rows) == [(2.333, False), (2.333, True), (2.667, True), (10.0, True)]
    for r in rows.values():
        assert r["converged"]
        assert r["n_positions"] == 16 and r["n_computed"] == 4
        # no translation: x and z by the symmetry of the scene (the mesh included), y up to the
        # discretisation (the offset makes the mesh asymmetric under the half-turn about z)
        assert max(r["Ux_max"], r["Uz_max"]) < 1e-6
        assert r["Uy_max"] < 0.03
    confined, no_subgrid = rows[(2.333, True)], rows[(2.333, False)]
    next_gap, wide = rows[(2.667, True)], rows[(10.0, True)]
    # eps = 1/6 and 1/3 are inside the calibrated wall range (eps < 1): the wall block acts, adds to S*
    # and slows the rotation (lubrication: the sliding walls resist the spin, Eq. D.6); at eps = 4 it does not
    assert confined["wall_block_acts"] and next_gap["wall_block_acts"] and not wide["wall_block_acts"]
    assert confined["S_star_subgrid"] > 0.3 and next_gap["S_star_subgrid"] > 0.0
    assert no_subgrid["S_star_subgrid"] == 0.0 and wide["S_star_subgrid"] == 0.0
    assert confined["S_star"] > no_subgrid["S_star"] + 0.3
    assert confined["Wz_norm"] < no_subgrid["Wz_norm"] - 0.1
    # confinement: the stresslet grows and the rotation slows as H -> 2a
    assert confined["S_star"] > next_gap["S_star"] + 0.8
    assert next_gap["S_star"] > wide["S_star"] + 0.4
    assert next_gap["S_star"] > 1.3
    assert next_gap["Wz_norm"] < 0.9 and confined["Wz_norm"] < 1.0
    assert next_gap["Wz_norm"] < wide["Wz_norm"] - 0.1
    # the unbounded limits at H = 10a: Omega_z = -gamma_dot/2 and S* = 1 within the position spread of
    # a/Delta = 3 (+-3 % over the 16 positions at H = 10 and 20, docs) and the walls' remaining effect
    assert wide["Wz_norm"] == pytest.approx(1.0, abs=0.05)
    assert wide["S_star"] == pytest.approx(1.0, abs=0.06)


@pytest.mark.parametrize("args, words", [
    (["--H-over-a", "1.9"], ["--H-over-a 1.9", "exceed 2 a"]),
    (["--H-over-a", "2.2"], ["--H-over-a 2.2", "whole number of cells", "2.333333333"]),
    (["--radius", "1.4", "--H-over-a", "3"], ["--H-over-a 3", "radius 1.4"]),
    (["--positions", "8"], ["--positions 8", "4 K^2"]),
    (["--size", "1", "12"], ["--size 1", "no room"]),
])
def test_bad_options_refused_by_name(channel_shear, tmp_path, capsys, args, words):
    assert_refused(channel_shear.main, args, words, tmp_path, capsys)
