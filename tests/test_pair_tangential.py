"""The tangential pair measurement (scripts/fdmsubgrid/pairtangential.py, issue 14): the internal-mode
decomposition it relies on, its theory side, and one small coupled run."""
import json
import os

import numpy as np
import pytest

from conftest import PROJECT
from fdmsubgrid import calibration, pairtangential as pt, squeeze

SHIPPED = os.path.join(PROJECT, "dem", "resistance", "data", "pair_tangential_calibration.json")


@pytest.mark.parametrize("ratio", [1.0, 1.4, 1 / 1.4])
@pytest.mark.parametrize("xi", [0.1, 0.01, 1e-3])
def test_subgrid_block_acts_on_the_internal_modes_only(env, ratio, xi):
    # Appendix C.2's block is P^T K P with the six internal modes of the module docstring, to rounding,
    # for equal and unequal spheres: so K = M_th^-1 - M_FDM^-1 on these modes is the whole correction
    k, residual = pt.model_correction(ratio, xi, 1 / 3)
    assert residual < 1e-12, (ratio, xi, residual)
    assert k[0] > 0 and k[3] > 0                  # the cut-off model adds sliding and twist resistance


@pytest.mark.parametrize("ratio", [1.0, 1.4])
def test_theory_mobility_is_symmetric_positive_and_singular_at_contact(env, ratio):
    near, far = pt.theory_mobility(ratio, 1e-3), pt.theory_mobility(ratio, 1.0)
    for m in (near, far):
        assert m[1] == pytest.approx(m[2], abs=1e-10 * np.sqrt(m[0] * m[3]))      # reciprocity
        assert m[0] > 0 and m[3] > 0 and m[4] > 0 and m[0] * m[3] > m[1] * m[2]
    # sliding (q1) is resisted by lubrication, ln(1/xi): its mobility falls toward contact; the twist only
    # weakly (X^C ~ xi ln(1/xi))
    assert near[0] < 0.5 * far[0]
    assert near[4] == pytest.approx(far[4], rel=0.3)
    assert np.allclose(pt.correction(near, near), 0, atol=1e-12)


def test_loaded_pair_decouples_and_resolves_a_wide_gap(env, tmp_path):
    # a1/Delta 3, xi = 1 (one a1 between the surfaces, three cells), L = 8: the solver resolves the gap, so its
    # internal mobilities are the theory's up to the box (about 3 %, measured) and the mesh; the loads along
    # y, z and x barely reach the squeeze, and the measured 2 x 2 is nearly symmetric
    res = pt.run_loaded_pair(str(tmp_path), 1.0, [1.0], 3.0, 8.0, pt.OFFSETS[0])
    assert res["converged"]
    m = pt.internal_mobility(res, 1.0)[0]
    th = pt.theory_mobility(1.0, 1.0)
    for k in (0, 3, 4):
        assert m[k] == pytest.approx(th[k], rel=0.05), (k, m[k], th[k])
    assert abs(m[1] - m[2]) < 0.02 * np.sqrt(m[0] * m[3])
    squeeze = abs(res["U1"][0][0] - res["U2"][0][0])
    assert squeeze < 0.05 * abs(res["U1"][0][1] - res["U2"][0][1])
    # kept: the same scene again is read, not run (a killed measurement resumes)
    assert pt.run_loaded_pair(str(tmp_path), 1.0, [1.0], 3.0, 8.0, pt.OFFSETS[0]) == json.loads(json.dumps(res))


@pytest.fixture(scope="module")
def shipped():
    with open(SHIPPED) as f:
        return json.load(f)


def test_shipped_measurements_reanalyse_to_their_corrections(env, shipped):
    # a1/Delta 3 (the suspension runs) and the size ratios of the bidisperse suspension are measured; the
    # kept raw responses give the same corrections again
    assert {(3.0, 1.0), (3.0, 1.4), (4.0, 1.0), (4.0, 1.4)} <= {(s["a_over_delta"], s["ratio"]) for s in shipped}
    for s in shipped[:1]:
        again = pt.summarize(s["ratio"], s["a_over_delta"], s["gaps"], s["boxes"], s["offsets"], s["raw"],
                             s["wall_seconds"])
        assert np.allclose(again["correction"], s["correction"], rtol=1e-9, atol=1e-12)


def test_solver_resolves_the_twist_and_more_sliding_than_the_cutoff_model_assumes(shipped):
    """What the measurement shows (docs/resistance.md, "Tangential pair measurement"): the solver's twist
    mobility is the theory's within 3 % at every gap (the cut-off model adds up to 1.1-1.8 eta a1^3 of
    twist resistance), and near contact the sliding correction it needs is below the cut-off model's by a
    constant (it resolves sliding down to a smaller gap), while the rolling one is near the cut-off model's
    (within 2 % at a1/Delta 3 and 4, 3-14 % below it at 5)."""
    for s in shipped:
        xi = np.array(s["gaps"])
        fdm, th = np.array(s["mobility_fdm"]), np.array(s["mobility_theory"])
        assert np.all(np.abs(fdm[:, 4] / th[:, 4] - 1) < 0.03), (s["a_over_delta"], s["ratio"])
        k, cut = np.array(s["correction"]), np.array(s["cutoff_correction"])
        near = xi <= 1e-2
        assert np.all(cut[near, 0] - k[near, 0] > 1.0), (s["a_over_delta"], s["ratio"])
        assert np.all(np.abs(k[near, 2] - cut[near, 2]) < 0.15 * cut[near, 2]), (s["a_over_delta"], s["ratio"])


def test_shipped_fits_follow_the_seen_gap_and_reproduce_the_measurements(shipped):
    """The seen-gap fits R_FDM(xi) = R_th((xi^p + xi_c^p)^(1/p)) of the sliding and rolling resistance:
    within 3 % of the measured values at every gap (relative to the theory's scale), and the surface gap
    the solver stops seeing is 0.3-0.4 cell at every a1/Delta and both size ratios."""
    assert {(3.0, 1.0), (3.0, 1.4), (4.0, 1.0), (4.0, 1.4), (5.0, 1.0), (5.0, 1.4)} <= {
        (s["a_over_delta"], s["ratio"]) for s in shipped}
    for s in shipped:
        fits = {f["element"]: f for f in s["fits"]}
        for name in pt.ELEMENTS:
            assert fits[name]["rms"] < 0.02 and fits[name]["max"] < 0.03, (s["a_over_delta"], s["ratio"], name)
        for name in ("K11", "K22"):
            cells = fits[name]["xi_c"] * (1 + s["ratio"]) / 2 * s["a_over_delta"]     # surface gap / Delta
            assert 0.25 < cells < 0.45, (s["a_over_delta"], s["ratio"], name, cells)
        assert s["clipped_rows"] == 0
        if s["ratio"] == 1:
            assert fits["K12"].get("symmetric_zero")


def test_shipped_table_holds_the_measured_corrections(shipped):
    # the C++ model reads these rows (linear in ln xi of xi K): at the measured gaps below the taper they
    # give the measured K within 4 % of the theory's internal resistance (sqrt(R11 R22) for K12)
    blocks = calibration.read_table(os.path.join(PROJECT, "dem", "resistance", "data", "subgrid_calibration.dat"))
    for s in shipped:
        xi = np.array(s["gaps"])
        use = xi <= 0.3
        measured = np.array(s["correction"])[use]
        th = pt.internal_resistance(np.array(s["mobility_theory"]))[use]
        scale = np.column_stack([th[:, 0], np.sqrt(th[:, 0] * th[:, 2]), th[:, 2], th[:, 3]])
        for j, name in enumerate(pt.ELEMENTS):
            rows = blocks[("pair_" + name, s["a_over_delta"], s["ratio"])][1]
            table = np.interp(np.log(xi[use]), np.log(rows[:, 0]), rows[:, 1]) / xi[use]
            err = np.abs(table - measured[:, j]) / scale[:, j]
            assert np.all(err < 0.04), (s["a_over_delta"], s["ratio"], name, err.max())


def test_dissipation_rule_keeps_what_the_theory_allows_and_clips_beyond():
    r_th = np.array([10.0, -2.0, 12.0, 1.0])
    kept, changed = pt.dissipative(np.array([-3.0, 1.0, 2.0, -0.5]), r_th)     # indefinite alone, allowed
    assert not changed and np.allclose(kept, [-3.0, 1.0, 2.0, -0.5])
    clipped, changed = pt.dissipative(np.array([-12.0, 30.0, 2.0, -2.0]), r_th)
    assert changed
    total = np.array([[r_th[0] + clipped[0], r_th[1] + clipped[1]], [r_th[1] + clipped[1], r_th[2] + clipped[2]]])
    assert np.linalg.eigvalsh(total).min() > -1e-12 and r_th[3] + clipped[3] >= 0
    assert r_th[1] + clipped[1] >= 0        # the coupling's sign kept


def test_calibrated_model_brings_sliding_and_twist_to_the_theory(env, tmp_path, shipped):
    """The coupled solver with `model calibrated` against the theory, at a position in the cell the
    calibration did not use (a2/a1 = 1.4, a1/Delta 3, L = 8 a1 with the shipped box correction): sliding,
    rolling and twist mobilities within 4.5 % at xi = 0.05, 0.01, 1e-3 (measured: 3.0 %), where the cut-off
    model leaves sliding 7-10 % and the twist 5-8 % too slow (docs/validation.md, "Tangential pair
    calibration")."""
    gaps, offset, ratio = [0.05, 0.01, 1e-3], (0.23, 0.57, 0.71), 1.4
    s = next(x for x in shipped if x["a_over_delta"] == 3.0 and x["ratio"] == ratio)
    rows = [s["gaps"].index(g) for g in gaps]
    first = {L: pt.internal_mobility(s["raw"][L][0], ratio) for L in ("8", "12")}
    box = (squeeze.extrapolate_box(first["8"], first["12"], 8.0, 12.0) - first["8"])[rows]   # M_inf - M(L = 8)
    th = np.array([pt.theory_mobility(ratio, xi) for xi in gaps])
    errors = {}
    for model in ("calibrated", "cutoff"):
        res = pt.run_loaded_pair(str(tmp_path), ratio, gaps, 3.0, 8.0, offset, model=model)
        assert res["converged"]
        m = pt.internal_mobility(res, ratio) + box
        errors[model] = m[:, [0, 3, 4]] / th[:, [0, 3, 4]] - 1
    assert np.all(np.abs(errors["calibrated"]) < 0.045), errors["calibrated"]
    assert np.all(errors["cutoff"][:, 0] < -0.06) and np.all(errors["cutoff"][:, 2] < -0.04), errors["cutoff"]
