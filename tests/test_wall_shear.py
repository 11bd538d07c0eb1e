"""cases/wallShear (paper 5.2.1): a free sphere in simple shear next to one wall, held in place but free
in force and torque. The reference first (no solver, about a second): the free-sphere velocities from
the wall resistance functions (freeSphereWall.py) in their far-field and lubrication limits, two
independent sources compared, the interpolation of Goldman, Cox & Brenner's shear factors, the two
branches of Eq. (46). Then one small coupled scene run by the real fdmFoam and fdmDEM (eps = 1, 0.1,
0.01 at two offsets, with and without the sub-grid wall correction, 12^3 a, a/Delta = 3: about 70 s):
the mirror symmetry, the slowing toward the wall, the agreement where the code is good, issue 14 (the
correction over-corrects the tangential wall functions) as a strict xfail, bad options refused by name."""
import math

import numpy as np
import pytest

from conftest import assert_refused, load_case_module


@pytest.fixture(scope="module")
def wall_shear():
    return load_case_module("wallShear")


@pytest.fixture(scope="module")
def ref(wall_shear):
    return wall_shear.freeSphereWall


# ------------------------------------------------------------------------------------------------
# The reference (no solver)
# ------------------------------------------------------------------------------------------------

def test_far_field_limits(ref):
    # far from the wall every factor tends to its unbounded value: U -> gamma_dot d, Omega_z -> -gamma_dot/2,
    # S* -> 1, with the method of reflections' (5/16)(a/d)^3 for U, Omega and Eq. (46)'s 15/(16 Y^3) for S*
    assert ref.free_sphere(5.0, 1.0, 0.0, 0.0, 1.0, 1.0, 1.0) == (1.0, 1.0)
    for eps in (3.0, 10.0, 100.0, 1e4):
        r = ref.reference(eps)
        x3 = (1.0 + eps) ** -3
        assert 0 < 1.0 - r["Ux_norm"] <= 5.0 / 16.0 * x3 + 2e-4, eps
        assert 0 < r["Wz_norm"] + 1.0 <= 5.0 / 16.0 * x3 + 2e-4, eps      # Wz_norm -> -1 from above
        assert r["S_star"] - 1.0 == pytest.approx(15.0 / 16.0 * x3, abs=1.1 * x3 / (1 + eps) ** 2 + 1e-12), eps
    # the exact table's end (eps = 3) meets the far-field form: measured 1.5e-4 (6.3e-4 at eps = 2)
    for entry in ref.compare_sources()["far_field"]:
        bound = {1.0: 5e-3, 2.0: 1e-3, 3.0: 2e-4}[entry["eps"]]
        assert abs(entry["u"] - entry["u_far"]) < bound and abs(entry["w"] - entry["w_far"]) < bound


def test_two_sources_agree(ref):
    # u = U/(gamma d), w = -Omega_z/(gamma/2) at GCB's gaps from the exact bipolar table and from GCB's own
    # translation and rotation factors (GCB's Fs, Ts in both: no interpolation). Measured: within 5.4e-5
    # (eps = 0.0032 ... 2.76) and the far-field form 7.1e-5 from GCB at eps = 9.07
    checks = ref.compare_sources()
    assert len(checks["gcb_gaps"]) == 8
    for entry in checks["gcb_gaps"]:
        assert abs(entry["u_diff"]) < 1e-4 and abs(entry["w_diff"]) < 1e-4, entry
    # the exact table against Chaoui & Feuillebois' small-gap forms, eps = 1e-3 ... 1: measured within 3e-8
    for entry in checks["small_gap"]:
        assert abs(entry["u_diff"]) < 1e-6 and abs(entry["w_diff"]) < 1e-6, entry
    # the resistance matrix is symmetric: 6 pi eta a^2 Fr = 8 pi eta a^2 Tt in GCB's own (independent) numbers
    for row in ref.data()["gcb1967_all_factors"]["rows"]:
        assert row[3] == pytest.approx(4.0 / 3.0 * row[2], rel=1e-3)


def test_shear_factor_interpolation_error(ref):
    # each of GCB's interior gaps interpolated from the others: the misses bound the interpolation error
    # used in uncertainty() (measured 3.8e-4 in Fs at eps = 0.045, 2.2e-4 in Ts at eps = 2.76)
    misses = ref.fs_ts_leave_one_out()
    fs_max = max(abs(e["Fs_miss"]) for e in misses)
    ts_max = max(abs(e["Ts_miss"]) for e in misses)
    assert fs_max <= ref.FS_TS_LOO_BOUND[0] * 1.05 and ts_max <= ref.FS_TS_LOO_BOUND[1] * 1.05
    assert fs_max >= ref.FS_TS_LOO_BOUND[0] * 0.9 and ts_max >= ref.FS_TS_LOO_BOUND[1] * 0.9
    # the spline passes through GCB's points and the contact limit
    for h, fs, ts in ref.data()["gcb1967_fixed_sphere_in_shear"]["rows"]:
        assert ref.shear_factors(h - 1.0) == pytest.approx((fs, ts), abs=1e-12)
    # the resulting uncertainty of the reference stays below 5e-4 over the case's range
    for eps in (1e-3, 0.01, 0.1, 1.0, 3.0):
        assert max(ref.uncertainty(eps)) < 5e-4


def test_lubrication_limits(ref):
    # At contact Ft ~ (8/15) L, Tt ~ L/10, Fr ~ (2/15) L, Tr ~ (2/5) L (L = ln(1/eps)) and Fs, Ts reach GCB's
    # contact values 1.7005, 0.94399: u L -> 2 (Fs0 + Ts0/6) = 3.7157, w L -> (5/2)(Ts0 + 0.2 * 3.7157) = 4.2178
    u_lead = 2.0 * (1.7005 + 0.94399 / 6.0)
    w_lead = 2.5 * (0.94399 + 0.2 * u_lead)
    # GCB's printed small-gap form 0.7431/(0.6376 - 0.2 ln eps) has the same leading coefficient ...
    assert 0.7431 / 0.2 == pytest.approx(u_lead, rel=2e-4)
    # ... but its constant is off (reference README: about 7 % below their own table): measured -7.3 % at eps = 1e-3
    assert 0.7431 / (0.6376 - 0.2 * math.log(1e-3)) / ref.velocities(1e-3)[0] - 1 == pytest.approx(-0.073, abs=0.01)
    eps = 1e-300
    u, w = ref.lubrication_limit(eps)
    assert u * math.log(1 / eps) == pytest.approx(u_lead, rel=0.01)
    assert w * math.log(1 / eps) == pytest.approx(w_lead, rel=0.01)
    # the reference joins its leading-order form as eps -> 0 (the O(eps ln eps) terms fade): measured
    # -5.8e-4, -5.7e-5, -5.6e-7 in u at eps = 1e-3, 1e-4, 1e-6
    gaps = [ref.velocities(e)[0] / ref.lubrication_limit(e)[0] - 1 for e in (1e-3, 1e-4, 1e-6)]
    assert abs(gaps[2]) < abs(gaps[1]) < abs(gaps[0]) < 2e-3
    assert abs(gaps[2]) < 1e-5


def test_velocities_slow_down_toward_the_wall(ref):
    eps = np.logspace(-5, 1, 61)
    u = [ref.reference(e)["Ux_norm"] for e in eps]
    w = [-ref.reference(e)["Wz_norm"] for e in eps]
    assert np.all(np.diff(u) > 0) and np.all(np.diff(w) > 0)
    assert 0 < u[0] < 0.3 and 0 < w[0] < 0.3 and u[-1] > 0.999 and w[-1] > 0.999


def test_eq46_branches_nearly_meet(ref):
    # Eq. (46) as printed, Y = 1 + eps: the first branch for 1/Y <= 0.85, the lubrication branch closer.
    # Where they join (eps = 1/0.85 - 1 = 0.1765) they differ by 3.05 % (measured): the fit's own spread
    eps_join = 1 / 0.85 - 1
    far, near = ref.stresslet_eq46_branches(eps_join)
    assert far == pytest.approx(1.5161, abs=1e-4) and near == pytest.approx(1.4698, abs=1e-4)
    assert abs(near / far - 1) < 0.035
    assert ref.stresslet_eq46(eps_join * (1 + 1e-9)) == ref.stresslet_eq46_branches(eps_join * (1 + 1e-9))[0]
    assert ref.stresslet_eq46(eps_join * (1 - 1e-9)) == ref.stresslet_eq46_branches(eps_join * (1 - 1e-9))[1]
    # each branch decreases away from the wall in its own range; the lubrication branch grows as ln(1/eps)
    near_range = [ref.stresslet_eq46(e) for e in np.logspace(-6, math.log10(eps_join) - 1e-6, 40)]
    far_range = [ref.stresslet_eq46(e) for e in np.logspace(math.log10(eps_join) + 1e-6, 2, 40)]
    assert np.all(np.diff(near_range) < 0) and np.all(np.diff(far_range) < 0)
    assert ref.stresslet_eq46(1e-12) == pytest.approx((0.847 * 27.631 - 0.41) / (0.2 * 27.631 + 0.6376), rel=1e-4)


def test_cell_offsets(wall_shear):
    # 16 = the paper's 4 x 4 lattice, computed at its 4 points in the quarter [0, 1/2)^2 (the mirrors
    # z -> -z and x -> -x with the flow reversed); 2: two Halton points there
    offsets, represented = wall_shear.cell_offsets(16)
    assert represented == 16 and sorted(offsets) == [(0.125, 0.125), (0.125, 0.375), (0.375, 0.125), (0.375, 0.375)]
    assert wall_shear.cell_offsets(4) == ([(0.25, 0.25)], 4)
    halton, represented = wall_shear.cell_offsets(2)
    assert represented == 2 and len(set(halton)) == 2 and all(0 < o < 0.5 for p in halton for o in p)


# ------------------------------------------------------------------------------------------------
# The coupled scene
# ------------------------------------------------------------------------------------------------

OFFSET_VERTEX, OFFSET_GENERIC = (0.0, 0.0), (0.25, 0.17)


@pytest.fixture(scope="module")
def scene(wall_shear, tmp_path_factory, env):
    # two offsets: the mesh vertex (the mesh has the flow's mirror symmetries there, so U_y, U_z, Omega_x,
    # Omega_y vanish to the solvers' tolerance) and a generic one (the discretisation's drift); the
    # cut-off model (the tests below compare it with the FDM alone and with the calibrated model)
    work = tmp_path_factory.mktemp("wallShear")
    result = wall_shear.main(["--eps", "1", "0.1", "0.01", "--model", "cutoff", "--offset", *map(str, OFFSET_VERTEX),
                              "--offset", *map(str, OFFSET_GENERIC), "--workdir", str(work),
                              "--out", str(work / "results.json")])
    rows = {(r["subgrid"], r["eps"]): r for r in result["rows"]}
    return rows, result, work


def test_every_step_converged_and_rows_complete(scene):
    rows, result, work = scene
    assert sorted(rows) == [(False, 0.01), (False, 0.1), (False, 1.0), (True, 0.01), (True, 0.1), (True, 1.0)]
    for row in rows.values():
        assert row["converged"] and row["positions_computed"] == 2
        for key in ("Ux_norm", "Ux_norm_std", "Wz_norm_std", "S_star_std", "Ux_norm_ref", "S_star_rel_error",
                    "box", "a_over_delta", "n_positions", "wall_seconds", "radius"):
            assert key in row
    assert (work / "results_wallShear.png").stat().st_size > 10000


def test_mirror_symmetry(scene):
    # At the vertex: measured |U_y|, |U_z| / (gamma d), |Omega_x|, |Omega_y| / (gamma/2) below 1.6e-5 (1e-4
    # asserted: the inner iterations' tolerance). At the generic offset the mesh breaks the symmetry by
    # up to 2.0e-2 (measured: Omega_y at eps = 0.01 with the correction, Omega_x 1.8e-2 at eps = 1).
    rows, _, _ = scene
    for row in rows.values():
        for position in row["positions"]:
            worst = max(abs(position[q]) for q in ("Uy_norm", "Uz_norm", "Wx_norm", "Wy_norm"))
            if tuple(position["offset"]) == OFFSET_VERTEX:
                assert worst < 1e-4, (row["subgrid"], row["eps"], worst)
            else:
                assert worst < 0.05, (row["subgrid"], row["eps"], worst)


def test_slower_toward_the_wall(scene):
    rows, _, _ = scene
    for subgrid in (True, False):
        u = [rows[(subgrid, e)]["Ux_norm"] for e in (1.0, 0.1, 0.01)]
        assert u[0] > u[1] > u[2] > 0, (subgrid, u)
    w = [-rows[(True, e)]["Wz_norm"] for e in (1.0, 0.1, 0.01)]
    assert w[0] > w[1] > w[2] > 0, w
    # Omega_z is negative (clockwise seen from +z) at every gap, with and without the correction
    assert all(row["Wz_norm"] < 0 for row in rows.values())


def test_no_wall_block_beyond_the_cutoff(scene):
    # at eps = 1 the gap is beyond the wall cut-off (0.75 Delta/a = 0.25 at a/Delta = 3): with and without
    # the correction the run is the same
    rows, _, _ = scene
    on, off = rows[(True, 1.0)], rows[(False, 1.0)]
    for q in ("Ux_norm", "Wz_norm", "S_star"):
        assert on[q] == pytest.approx(off[q], rel=1e-6)
    assert on["S_subgrid_star"] == 0.0 and rows[(True, 0.1)]["S_subgrid_star"] > 0.1


def test_agreement_where_the_code_is_good(scene):
    # Against the reference (exact wall resistance + GCB; Eq. 46 for S*), mean of the two offsets.
    # eps = 1 (both modes, no block acts): measured U -0.25 %, Omega -1.6 %, S* -3.8 % (S* is 4-6 % low at
    # every gap beyond the cut-off in this mesh, a/Delta = 3). eps = 0.1 without the correction: measured
    # U +1.1 % (+2.7 % with the default offsets; Omega +21 %: the FDM alone under-resolves the gap).
    rows, _, _ = scene
    far = rows[(True, 1.0)]
    assert abs(far["Ux_norm_rel_error"]) < 0.01
    assert abs(far["Wz_norm_rel_error"]) < 0.03
    assert abs(far["S_star_rel_error"]) < 0.08
    assert abs(rows[(False, 0.1)]["Ux_norm_rel_error"]) < 0.04
    # the FDM alone cannot resolve the gap below a mesh cell: U saturates (measured 0.717 at eps = 0.01,
    # the reference 0.524) and the correction brings it closer (measured U -14.7 % against +36.7 %,
    # S* +9.9 % against -31.6 %)
    on, off = rows[(True, 0.01)], rows[(False, 0.01)]
    assert off["Ux_norm_rel_error"] > 0.2
    assert abs(on["Ux_norm_rel_error"]) < abs(off["Ux_norm_rel_error"])
    assert abs(on["S_star_rel_error"]) < abs(off["S_star_rel_error"])


@pytest.mark.xfail(strict=True, reason="the cut-off sub-grid model over-corrects the tangential wall functions: "
                                       "the free sphere is 10-17 % too slow for eps 0.001-0.1 with the correction "
                                       "(measured -13.7 % at eps = 0.1, -14.7 % at eps = 0.01); the calibrated "
                                       "model below fixes it")
def test_cutoff_model_free_sphere_within_two_percent_with_correction(scene):
    rows, _, _ = scene
    for eps in (0.1, 0.01):
        assert abs(rows[(True, eps)]["Ux_norm_rel_error"]) < 0.02, eps


@pytest.fixture(scope="module")
def calibrated(wall_shear, tmp_path_factory, env):
    # the same offsets with pair_style fdm/subgrid's default model, calibrated (the tangential wall functions
    # measured with the solver, docs/resistance.md "Tangential wall calibration"), the correction on only
    work = tmp_path_factory.mktemp("wallShearCalibrated")
    result = wall_shear.main(["--eps", "0.1", "0.01", "--subgrid-only",
                              "--offset", *map(str, OFFSET_VERTEX), "--offset", *map(str, OFFSET_GENERIC),
                              "--workdir", str(work), "--out", str(work / "results.json")])
    return {r["eps"]: r for r in result["rows"]}


def test_calibrated_wall_functions_slide_and_turn_the_free_sphere_at_the_right_speed(calibrated, scene):
    # measured (2 Halton offsets, 12^3 a, a/Delta 3; docs/validation.md): U within -4.4 ... +2.2 % and Omega
    # within -9 ... +5 % at eps 1e-3 ... 0.54, against U -10 ... -17 % with the cut-off model and Omega up
    # to +15 % when the solver's excess coupling Y^B was left in (at eps 0.1: +13 %, now -4.8 %). At the
    # test's offsets: U -5.1 % (eps 0.1; -1.0 % with the excess coupling left in, which made up for the
    # solver's own shear loading), -1.4 % (0.01); Omega -0.3 %, -5.7 %; the 12^3 box slows both by ~1.2 %
    rows, _, _ = scene
    for eps in (0.1, 0.01):
        assert abs(calibrated[eps]["Ux_norm_rel_error"]) < 0.06, (eps, calibrated[eps]["Ux_norm_rel_error"])
        assert abs(calibrated[eps]["Ux_norm_rel_error"]) < abs(rows[(True, eps)]["Ux_norm_rel_error"])
        assert abs(calibrated[eps]["Wz_norm_rel_error"]) < 0.08, (eps, calibrated[eps]["Wz_norm_rel_error"])


@pytest.mark.xfail(strict=True, reason="issue 14: Omega_z is still about 6 % slow near contact with the calibrated "
                                       "model (the solver's Y^C varies by 7-9 % with the position in the cell) and "
                                       "3-9 % off at eps 0.05-0.3; the solver's own shear load, which no correction "
                                       "of R touches, is 3-4 % low near contact at a1/Delta 3 (docs/validation.md)")
def test_issue14_calibrated_rotation_within_two_percent(calibrated):
    for eps in (0.1, 0.01):
        assert abs(calibrated[eps]["Wz_norm_rel_error"]) < 0.02, eps


@pytest.mark.parametrize("options, message", [
    (["--eps", "0"], "eps must be positive"),
    (["--eps", "1", "-0.1"], "eps must be positive"),
    (["--radius", "0"], "must be positive"),
    (["--radius", "0.5"], "mesh cells"),
    (["--size", "12", "5", "12"], "from the moving wall"),
    (["--size", "12.1", "12", "12"], "even number of cells"),
    (["--size", "4", "12", "12"], "periodic images"),
    (["--positions", "0"], "at least 1"),
    (["--offset", "1.2", "0"], "in [0, 1)"),
    (["--a-over-delta", "0"], "must be positive"),
    (["--boxes", "12", "12", "12", "18"], "LX LY LZ per box"),
    (["--wall-cutoff", "-1"], "--wall-cutoff must be positive"),
    (["--no-subgrid", "--subgrid-only"], "not allowed with argument"),
    (["--reference", "--eps", "-1"], "eps must be positive"),
])
def test_bad_options_refused(wall_shear, tmp_path, capsys, options, message):
    assert_refused(wall_shear.main, options, message, tmp_path, capsys)
