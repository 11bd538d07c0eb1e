"""cases/poiseuilleSphere (paper 5.2.3, Eqs. 47-48, Fig. 12): a free sphere held in plane Poiseuille flow
between walls at rest, periodic in x and z. The references first (no solver, under a second): Faxen's
laws for the quadratic flow against finite differences of u0, their centre-plane limit, the leading wall
reflections, the Staben et al. (2003) value kept in the case folder, the solver's discrete undisturbed
profile. Then one small coupled run by the real fdmFoam and fdmDEM (2a/H = 0.2 and 0.6 in an 8 a x 8 a
box, a/Delta = 3, three offsets of the centre in the cell: about 40 s): symmetries, the lag behind the
flow, the ordering with the distance to the wall, Faxen's limit and Staben's centre-line value. Bad
options refused by name."""
import json
import math

import numpy as np
import pytest

from conftest import assert_refused, load_case_module
from fdmsubgrid import results


@pytest.fixture(scope="module")
def ps():
    return load_case_module("poiseuilleSphere")


# ------------------------------------------------------------------------------------------------
# The references (no solver)
# ------------------------------------------------------------------------------------------------

def test_faxen_centre_plane_limit(ps):
    # On the centre plane u0 = U_c and (a^2/6) lap u0 = (a^2/6)(-8 U_c/H^2): U = U_c - 4 a^2 U_c/(3 H^2)
    # = U_c (1 - (2a/H)^2/3); no rotation, no stresslet (E = 0 there).
    for t in (0.1, 0.3, 0.6, 0.7):
        a, H = 1.0, 2.0 / t
        f = ps.faxen(t, 1.0 / t)
        assert f["u0_norm"] == pytest.approx(1.0, abs=1e-14)
        assert f["Ux_norm"] == pytest.approx(1.0 - 4.0 * a ** 2 / (3.0 * H ** 2), abs=1e-14)
        assert f["Ux_norm"] == pytest.approx(1.0 - t ** 2 / 3.0, abs=1e-14)
        assert f["Wz_norm"] == pytest.approx(0.0, abs=1e-14)
        assert f["S_star"] == pytest.approx(0.0, abs=1e-13)
    assert ps.faxen(0.6, 1.0 / 0.6)["Ux_norm"] == pytest.approx(0.88, abs=1e-12)


def test_faxen_against_finite_differences_of_u0(ps):
    # Faxen's laws evaluated independently from u0(y) of Eq. (47) by central differences (a = 1, U_c = 1,
    # eta = 1): U = u0 + (a^2/6) u0'', Omega_z = -(1/2) u0' (half the vorticity), S_xy = (20/3) pi a^3
    # (1/2) u0' (E_xy; lap E = 0 for a quadratic flow), S* = S_xy H/4.
    h = 1e-4
    for t in (0.1, 0.4, 0.7):
        H = 2.0 / t

        def u0(y):
            return 1.0 - (2.0 * (y - H / 2) / H) ** 2

        for d in (1.05, 1.5, 0.25 / t + 0.5, 1.0 / t):
            du = (u0(d + h) - u0(d - h)) / (2 * h)
            d2u = (u0(d + h) - 2 * u0(d) + u0(d - h)) / h ** 2
            f = ps.faxen(t, d)
            assert f["u0_norm"] == pytest.approx(u0(d), abs=1e-12)
            assert f["Ux_norm"] == pytest.approx(u0(d) + d2u / 6.0, abs=1e-6)
            assert f["Wz_norm"] == pytest.approx(-0.5 * du, abs=1e-8)
            assert f["Wz_H"] == pytest.approx(-0.5 * du * H, abs=1e-7)
            assert f["S_star"] == pytest.approx(20.0 / 3.0 * math.pi * 0.5 * du * H / 4.0, abs=1e-7)
            if d < 1.0 / t - 1e-9:
                # below the centre plane the shear is positive: the sphere turns clockwise, S_xy > 0
                assert f["Wz_norm"] < 0 and f["S_star"] > 0


def test_wall_estimate_orders(ps):
    # The leading wall reflections vanish on the centre plane (no shear there: the next term is
    # O((a/H)^5)) and scale as (a/H)^3 at a fixed y'/H: halving 2a/H at d = H/4 divides every correction
    # by 8. They slow the sphere and its rotation and raise the stresslet.
    for t in (0.2, 0.6):
        f, w = ps.faxen(t, 1.0 / t), ps.wall_estimate(t, 1.0 / t)
        for q in ("Ux_norm", "Wz_norm", "S_star"):
            assert w[q] == pytest.approx(f[q], abs=1e-14)
    corrections = {}
    for t in (0.1, 0.2, 0.4):
        d = 0.5 / t
        f, w = ps.faxen(t, d), ps.wall_estimate(t, d)
        corrections[t] = (w["Ux_norm"] - f["Ux_norm"], w["Wz_norm"] / f["Wz_norm"] - 1, w["S_star"] / f["S_star"] - 1)
        assert corrections[t][0] < 0 and corrections[t][1] < 0 and corrections[t][2] > 0
    for k in range(3):
        assert corrections[0.2][k] / corrections[0.1][k] == pytest.approx(8.0, rel=1e-9)
        assert corrections[0.4][k] / corrections[0.2][k] == pytest.approx(8.0, rel=1e-9)
    # one wall far away, the other at h = 10 a in a wide channel: Goldman, Cox & Brenner's
    # U = gamma h (1 - (5/16)(a/h)^3) with gamma = du0/dy at the centre, the far wall negligible
    t, d = 0.001, 10.0
    H = 2.0 / t
    gamma = 8.0 * (H / 2 - d) / H ** 2
    w = ps.wall_estimate(t, d)
    assert w["Ux_norm"] - ps.faxen(t, d)["Ux_norm"] == pytest.approx(-5.0 / 16.0 * gamma / d ** 2, rel=1e-3)


def test_wall_estimate_is_a_reference_two_radii_from_both_walls(ps):
    # wall_estimate()'s one-wall forms, U = gamma h (1 - (5/16)(a/h)^3), Omega = -(gamma/2)(1 - (5/16)(a/h)^3),
    # S = S_inf (1 + (15/16)(a/h)^3), against the exact free sphere in simple shear next to one wall
    # (the bipolar tables, GCB's fixed sphere and Eq. 46: cases/wallShear/freeSphereWall.py): within 2 % from
    # h = 2 a on, S* off by more than 4 % at h = 1.5 a. Hence WALL_ESTIMATE_MIN_H = 2 for the report's rows.
    exact = load_case_module("wallShear", "freeSphereWall")

    def worst(h):
        r, velocity, stresslet = exact.reference(h - 1.0), 1 - 5.0 / 16.0 / h ** 3, 1 + 15.0 / 16.0 / h ** 3
        return max(abs(velocity / r["Ux_norm"] - 1), abs(-velocity / r["Wz_norm"] - 1), abs(stresslet / r["S_star"] - 1))

    assert ps.WALL_ESTIMATE_MIN_H == 2.0
    for h in (2.0, 2.5, 3.0, 4.0):
        assert worst(h) < 0.02
    assert worst(1.5) > 0.04
    # both walls count: 2a/H 0.1 (H = 20 a) at d/a 3, and the centre plane of H = 5 a, are far enough;
    # d/a 1.5, and d/a 1.5 of H = 3.33 a (1.83 a from the upper wall) are not
    assert ps.wall_estimate_applies(0.1, 3.0) and ps.wall_estimate_applies(0.4, 2.5)
    assert not ps.wall_estimate_applies(0.1, 1.5) and not ps.wall_estimate_applies(0.6, 1.5)
    assert not ps.wall_estimate_applies(0.4, 1.25)


def test_staben_reference_in_the_case_folder(ps):
    # staben_2003.csv (Staben, Zinchenko & Davis 2003, Table 1): 2a/H = 0.6 on the centre plane, 0.871
    table = ps.read_staben()
    assert len(table) == 1
    assert ps.staben_at(0.6, 1.0 / 0.6, table) == pytest.approx(0.871, abs=1e-12)
    assert ps.staben_at(0.6, 1.5, table) is None
    assert ps.staben_at(0.4, 2.5, table) is None
    # the walls slow the centre-line sphere below Faxen's unbounded value, by about 1 %
    assert 0.0 < ps.faxen(0.6, 1.0 / 0.6)["Ux_norm"] - 0.871 < 0.015


def test_discrete_profile_is_the_solvers_steady_profile(ps):
    # fdmFoam's finite-volume Laplacian with the wall half a cell from the first centre
    # (docs/fluid.md, channelProfile.H: (nu/Delta^2)(3 u_0 - u_1) at the wall cell): its steady profile
    # under dP0/dx = -8 eta U_c/H^2, solved here directly, is the parabola plus U_c (Delta/H)^2
    for t, ad in ((0.6, 3.0), (0.2, 3.0), (0.7, 5.0)):
        scene = ps.Scene(1.0, t, ad, (8.0, 8.0))
        n, delta = scene.ny, scene.delta
        A = 2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1)
        A[0, 0] = A[-1, -1] = 3
        u = np.linalg.solve(A, np.full(n, -scene.grad_p0 * delta ** 2 / ps.ETA))
        y = (np.arange(n) + 0.5) * delta
        assert np.allclose(u, scene.discrete_profile(y), atol=1e-12)
        assert scene.discrete_profile(np.array([scene.H / 2]))[0] == pytest.approx(1.0 + (delta / scene.H) ** 2)


def test_scene_mesh_and_positions(ps):
    # H must be whole cells: 2a/H = 0.6 at a1/Delta = 3 is exact (10 cells); 0.7 gives 9 cells and
    # a/Delta = 3.15; the paper's a2 = 1.4 at 2a/H = 0.7 is H = 4 a1, 12 cells at a1/Delta = 3
    s = ps.Scene(1.0, 0.6, 3.0, (12.0, 12.0))
    assert (s.ny, s.nx, s.nz) == (10, 36, 36) and s.a_over_delta == pytest.approx(3.0)
    s = ps.Scene(1.0, 0.7, 3.0, (12.0, 12.0))
    assert s.ny == 9 and s.a_over_delta == pytest.approx(3.15)
    s = ps.Scene(1.4, 0.7, 3.0, (12.0, 12.0))
    assert s.ny == 12 and s.H == pytest.approx(4.0) and s.a_over_delta == pytest.approx(4.2)
    # the paper's 16 positions: the 4 x 4 lattice, computed at its 4 points in the quarter cell whose
    # mirror images (o -> 1 - o in x and z) give the whole lattice
    offsets, represented = ps.cell_offsets(16)
    assert represented == 16 and len(offsets) == 4
    images = {(round(x, 9), round(z, 9)) for ox, oz in offsets for x in (ox, 1 - ox) for z in (oz, 1 - oz)}
    assert images == {(round((i + 0.5) / 4, 9), round((k + 0.5) / 4, 9)) for i in range(4) for k in range(4)}
    offsets, _ = ps.cell_offsets(2)
    assert len(offsets) == 2 and all(0 <= v < 0.5 for o in offsets for v in o)
    with pytest.raises(ValueError, match="--positions"):
        ps.cell_offsets(0)
    # d/a: the centre plane and d = H/4 by name, values above the centre plane skipped
    kept, skipped = ps.d_values(0.4, ps.parse_d_over_a(["1.1", "quarter", "centre", "3"]))
    assert kept == pytest.approx([2.5, 1.25, 1.1]) and skipped == [3.0]
    kept, skipped = ps.d_values(0.6, ps.parse_d_over_a(["quarter", "centre"]))
    assert kept == pytest.approx([1.0 / 0.6]) and skipped == pytest.approx([0.5 / 0.6])


def test_stencil_ties(ps):
    # cells exactly on fdmFoam's stencil reach a + 0.3 Delta (once kept or dropped by the floating-point
    # distance's last bit, breaking the mirror symmetries): at 2a/H = 0.2, d/a = 2.5 (a cell centre in y), a/Delta = 3, the
    # offset (0.3, 0) has (i + 0.5 - 0.3)^2 + 2^2 + 2.5^2 = 3.3^2 for i = -1: four such cells
    s = ps.Scene(1.0, 0.2, 3.0, (8.0, 8.0))
    assert ps.stencil_ties(s, s.centre(2.5, (0.3, 0.0))) == 4
    assert ps.stencil_ties(s, s.centre(2.5, (0.7, 0.0))) == 4
    for d in (5.0, 2.5, 1.3, 1.1):
        for o in ((0.0, 0.0), (0.35, 0.0), (0.65, 0.0)):
            assert ps.stencil_ties(s, s.centre(d, o)) == 0


def test_stencil_ties_keep_the_mirror_symmetry(ps, tmp_path, env):
    # The tie offsets of test_stencil_ties, run: fdmFoam leaves out every cell within 1e-9 Delta of the
    # reach, so the z mirror holds (U_z, Omega_x, Omega_y = 0) and the two mirror offsets give the same U_x.
    # Measured: out of plane 3.6e-8, U_x 6.5e-7 apart (before, when the last bit decided: 6e-4 and 5e-4).
    out = ps.main(["--two-a-over-H", "0.2", "--d-over-a", "2.5", "--offset", "0.3", "0", "--offset", "0.7", "0",
                   "--size", "8", "8", "--workdir", str(tmp_path), "--out", str(tmp_path / "r.json"), "--no-plot"])
    (row,) = out["rows"]
    assert row["stencil_ties"] == [4, 4] and row["converged"]
    assert row["out_of_plane_max"] < 1e-6
    u = row["per_position"]["Ux_norm"]
    assert abs(u[0] - u[1]) < 1e-5


@pytest.mark.parametrize("argv, named", [
    (["--d-over-a", "0.9"], "0.9"),
    (["--d-over-a", "wall"], "wall"),
    (["--two-a-over-H", "1.2"], "1.2"),
    (["--two-a-over-H", "0.6", "--d-over-a", "3"], "0.6"),
    (["--positions", "0"], "--positions"),
    (["--offset", "1.5", "0"], "--offset 1.5 0"),
    (["--size", "0.5", "8"], "L_x"),
])
def test_bad_options_refused_by_name(ps, argv, named, tmp_path, capsys):
    assert_refused(ps.main, argv, named, tmp_path, capsys)


# ------------------------------------------------------------------------------------------------
# One coupled run
# ------------------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def coupled(ps, tmp_path_factory, env):
    """2a/H = 0.2 (d/a = 1.1, 1.3, 2.5 = H/4, 5 = centre) and 0.6 (1.1, 1.3, centre), box 8 a x 8 a,
    a/Delta = 3, the centre at three offsets (o_x, o_z) = (0, 0) (the mesh mirror-symmetric in x and z about
    the sphere), (0.35, 0) and (0.65, 0) (mirror images of each other; the mesh mirror-symmetric in z).
    (0.3 and 0.7 put cells exactly on the stencil's reach at d/a = 2.5: test_stencil_ties_keep_the_mirror_symmetry.)"""
    tmp = tmp_path_factory.mktemp("poiseuilleSphere")
    out = ps.main(["--two-a-over-H", "0.2", "0.6", "--d-over-a", "centre", "quarter", "1.3", "1.1",
                   "--offset", "0", "0", "--offset", "0.35", "0", "--offset", "0.65", "0",
                   "--size", "8", "8", "--workdir", str(tmp), "--out", str(tmp / "results.json"), "--no-plot"])
    # the results file (fdmsubgrid.results): the case's record under data, its rows those of validation_rows
    written = results.read_results(str(tmp / "results.json"))
    assert written.data["rows"] == json.loads(json.dumps(out["rows"]))
    assert written.rows == ps.validation_rows(out) and written.rows
    return out


def _row(out, t, d):
    rows = [r for r in out["rows"] if r["two_a_over_H"] == t and abs(r["d_over_a"] - d) < 1e-9]
    assert len(rows) == 1
    return rows[0]


def test_coupled_converged_and_complete(coupled):
    assert len(coupled["rows"]) == 7
    for r in coupled["rows"]:
        assert r["converged"], r
        assert r["positions_computed"] == 3 and r["n_positions"] == 3
        assert r["stencil_ties"] == [0, 0, 0]
        # U_z, Omega_x, Omega_y: zero by the z mirror of the scene and of the mesh (o_z = 0)
        assert r["out_of_plane_max"] < 1e-6


def test_centre_plane_symmetry(coupled):
    # y' -> -y' (scene and mesh symmetric about y = H/2): Omega_z = 0, S_xy = 0 to the solver's
    # tolerance. Measured: |Omega_z a/U_c| <= 4e-8, |S*| <= 4.4e-7, against 0.1 and 5 off the centre plane.
    for t in (0.2, 0.6):
        r = _row(coupled, t, 1.0 / t)
        assert r["centre_plane"]
        assert max(abs(v) for v in r["per_position"]["Wz_norm"]) < 1e-5
        assert max(abs(v) for v in r["per_position"]["S_star"]) < 1e-4


def test_no_lateral_velocity(coupled):
    # Stokes flow: U_y = 0 for a free sphere at any d (reversibility + the x mirror). With the mesh
    # mirror-symmetric about the sphere (o_x = 0) to the inner iterations' tolerance; at o_x = 0.35 and
    # 0.65 the mesh breaks the mirror: U_y is the discretisation's, equal and opposite at the mirror
    # offsets, while U_x, Omega_z and S_xy are equal there. Measured (tolLambda 1e-4): |U_y| <= 9.5e-6 U_c
    # at o_x = 0 (1e-6 or less where no wall block acts), up to 4.2e-3 U_c at o_x = 0.35; the mirror
    # pairs agree to 2e-5 U_c in U_y, 7e-6 in U_x, 1.5e-6 in Omega_z a, 4e-5 relative in S*.
    for r in coupled["rows"]:
        per = r["per_position"]
        uy = per["Uy_norm"]
        assert abs(uy[0]) < 5e-5, r["d_over_a"]
        assert max(abs(v) for v in uy) < 1e-2
        assert uy[1] == pytest.approx(-uy[2], abs=1e-4)
        assert per["Ux_norm"][1] == pytest.approx(per["Ux_norm"][2], abs=5e-5)
        assert per["Wz_norm"][1] == pytest.approx(per["Wz_norm"][2], abs=5e-5)
        assert per["S_star"][1] == pytest.approx(per["S_star"][2], rel=2e-4, abs=1e-5)


def test_lag_rotation_and_ordering_with_the_wall(coupled):
    # The sphere lags the undisturbed flow at its centre (Faxen's (a^2/6) lap u0 < 0 and the walls);
    # below the centre plane it turns clockwise and S_xy > 0; U_x grows with the distance to the wall.
    for t in (0.2, 0.6):
        rows = sorted((r for r in coupled["rows"] if r["two_a_over_H"] == t), key=lambda r: r["d_over_a"])
        for r in rows:
            assert r["Ux_norm"] < r["u0_norm"], r["d_over_a"]
            if not r["centre_plane"]:
                assert r["Wz_norm"] < 0 and r["S_star"] > 0
        ux = [r["Ux_norm"] for r in rows]
        assert all(b > a for a, b in zip(ux, ux[1:])), ux
        # the nearest to the wall lags the most (relative to u0): the wall's lubrication drag
        lag = [r["Ux_norm"] / r["u0_norm"] for r in rows]
        assert lag[0] == min(lag)


def test_faxen_limit_far_from_the_walls(coupled):
    # 2a/H = 0.2, 8 a x 8 a box, a/Delta = 3, three offsets. Measured: centre plane U_x/U_c = 0.98778, less
    # the solver's offset (Delta/H)^2 = 0.00111: 0.98667 against Faxen's 0.98667 (-1e-6 relative; the
    # default run, 12 a x 12 a and 2 other positions: +0.07 %); at d = H/4 (d/a = 2.5) against Faxen + the
    # leading wall reflections: U_x -0.7 %, Omega_z -0.8 %, S* -0.8 % (Faxen alone: U_x -1.9 %; S* spreads
    # by +-5 % with the position at a/Delta = 3).
    c = _row(coupled, 0.2, 5.0)
    assert c["Ux_norm_shifted"] == pytest.approx(c["faxen"]["Ux_norm"], rel=3e-3)
    q = _row(coupled, 0.2, 2.5)
    assert q["Ux_norm"] == pytest.approx(q["faxen_wall"]["Ux_norm"], rel=1.5e-2)
    assert q["Wz_norm"] == pytest.approx(q["faxen_wall"]["Wz_norm"], rel=0.05)
    assert q["S_star"] == pytest.approx(q["faxen_wall"]["S_star"], rel=0.1)


def test_staben_centre_line(coupled):
    # Staben, Zinchenko & Davis (2003): U/U_c = 0.871 at 2a/H = 0.6 on the centre plane. Measured here
    # (8 a x 8 a, a/Delta = 3, the 3 offsets): U_x/U_c = 0.8826 (+1.3 %), less the solver's undisturbed-flow
    # offset (Delta/H)^2 = 0.01: 0.8726 (+0.2 %). (12 a x 12 a, 16 positions: 0.8867, +1.8 %, less the
    # offset +0.7 %; the box extrapolated to infinity adds +0.0017; a/Delta = 6, 16 positions: 0.8737,
    # +0.3 %, less the offset +0.02 %.)
    r = _row(coupled, 0.6, 1.0 / 0.6)
    assert r["staben_Ux_norm"] == pytest.approx(0.871)
    assert abs(r["Ux_rel_error_staben"]) < 0.03
    assert abs(r["Ux_shifted_rel_error_staben"]) < 0.015
