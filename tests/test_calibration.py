"""The squeeze calibration of Appendix B (scripts/fdmsubgrid/calibration.py and the table shipped in
dem/resistance/data): the box extrapolation and the fit on synthetic data, the shipped fits against
their own measurements, the table's layout, and the calibrated model in the coupled solver
(pair_style fdm/subgrid model calibrated) against the two-sphere and sphere-wall theory."""
import json
import os

import numpy as np
import pytest

from conftest import PROJECT, load_case_module
from fdmsubgrid import calibration, squeeze, theory

DATA = os.path.join(PROJECT, "dem", "resistance", "data")
TABLE = os.path.join(DATA, "subgrid_calibration.dat")


def test_box_extrapolation_removes_dipole_images():
    v_inf = np.array([0.9, 0.5, 0.3])
    c = np.array([40.0, -3.0, 10.0])
    at = {L: v_inf + c / L ** 3 for L in (8.0, 12.0)}
    assert np.allclose(squeeze.extrapolate_box(at[8.0], at[12.0], 8.0, 12.0), v_inf, rtol=0, atol=1e-14)


def test_fit_recovers_a_logistic_resistance():
    """A solver resistance that is the logistic curve itself, at the gaps where the table's correction is the
    fit's untapered (xi <= TAPER_START): the fit gives back its parameters and leaves no velocity error."""
    gaps = [g for g in calibration.GAPS if g <= calibration.TAPER_START]
    truth = dict(r_0=2.7, r_inf=0.6, xi_1=0.3, p=1.25)
    r = calibration.fitted_resistance(np.array(gaps), **truth)
    cal = calibration.SqueezeCalibration("pair", 3.0, 1.0, gaps, [8.0, 12.0],
                                         {"8": [list(1 / r)], "12": [list(1 / r)]})
    fit = cal.fit()
    for k, v in truth.items():
        assert fit[k] == pytest.approx(v, rel=1e-4), k
    assert fit["max_rel"] < 1e-6 and fit["velocity_max"] < 1e-6


def test_taper_is_continuous_and_ends_the_correction():
    assert calibration.taper(calibration.TAPER_START) == 1.0
    assert calibration.taper(calibration.TAPER_END) == 0.0
    mid = np.sqrt(calibration.TAPER_START * calibration.TAPER_END)
    assert calibration.taper(mid) == pytest.approx(0.5, abs=1e-12)


def test_shipped_table_covers_the_suspension_runs_and_is_well_formed():
    blocks = calibration.read_table(TABLE)
    for ad in (3.0, 4.0, 5.0):
        for key in (("pair", ad, 1.0), ("pair", ad, 1.4), ("wall", ad, 1.0)):
            assert key in blocks, key
            _, rows = blocks[key]
            assert np.all(np.diff(np.log(rows[:, 0])) > 0), key
            assert rows[0, 0] == pytest.approx(calibration.TABLE_MIN_GAP)
            assert rows[-1, 1] == 0.0 and rows[-1, 0] <= calibration.TAPER_END * (1 + 1e-9), key
            assert np.all(rows[:-1, 1] > 0), key


def test_shipped_fits_reproduce_their_measurements():
    """Each fit through the box-extrapolated, position-averaged resistances: within 3 % rms and 7 % at
    any gap (the spread over positions in the cell, reported beside it, is of the same size)."""
    with open(os.path.join(DATA, "squeeze_calibration.json")) as f:
        summaries = json.load(f)
    assert len(summaries) >= 9
    for s in summaries:
        cal = calibration.SqueezeCalibration(s["kind"], s["a_over_delta"], s["ratio"], s["gaps"], s["boxes"],
                                             s["velocities"])
        fit = cal.fit()
        label = "%s a/Delta %g ratio %g" % (s["kind"], s["a_over_delta"], s["ratio"])
        assert fit["rms_rel"] < 0.03, label
        assert fit["max_rel"] < 0.07, label
        # the json is what the table was made from: the same curve (not the same digits of each parameter,
        # which are only as sharp as the optimizer's stopping rule and a machine's rounding)
        xi = np.geomspace(1e-4, 1, 41)
        shipped_curve = calibration.fitted_curve(xi, s["fit"])
        assert np.max(np.abs(calibration.fitted_curve(xi, fit) / shipped_curve - 1)) < 1e-5, label
        assert fit["rms_rel"] == pytest.approx(s["fit"]["rms_rel"], abs=1e-7), label


def test_position_floor_is_the_best_any_gap_only_correction_can_do():
    """Two positions whose solver resistances differ: no common correction s does better at the worse of
    the two than the floor, and the floor's s makes both equally wrong; one position: no floor."""
    r_th, r = 2.0, np.array([1.2, 1.5])
    cal = calibration.SqueezeCalibration("pair", 3.0, 1.0, [0.1], [8.0, 12.0],
                                         {"8": [[1 / r[0]], [1 / r[1]]], "12": [[1 / r[0]], [1 / r[1]]]})
    cal.theory = lambda: np.array([1 / r_th])          # a synthetic theory for the one gap
    floor = cal.position_floor()[0]
    scan = np.linspace(0.0, 1.5, 30001)
    worst = np.max(np.abs(r_th / (r[:, None] + scan[None, :]) - 1), axis=0)
    assert floor == pytest.approx(worst.min(), rel=1e-4)   # the scan's step
    assert floor > 0.5 * (r[1] - r[0]) / r_th * 0.9
    one = calibration.SqueezeCalibration("pair", 3.0, 1.0, [0.1], [8.0, 12.0], {"8": [[0.7]], "12": [[0.7]]})
    one.theory = lambda: np.array([0.5])
    assert one.position_floor()[0] == pytest.approx(0.0, abs=1e-12)


def test_no_position_beats_the_floor_and_the_mean_holds():
    """The shipped calibrations at their own 4 positions: the model, a correction of the gap alone, is nowhere
    better at its worst position than the floor; averaged over the positions it is within the fit's bound at
    every gap (calibration.FIT_VELOCITY_BOUND, 1.8 %), and near contact, where the correction carries the
    resistance, the worst position is within 1 % (xi <= 1e-3)."""
    for e in calibration.position_errors(os.path.join(DATA, "squeeze_calibration.json")):
        label = "%s a/Delta %g ratio %g" % (e["kind"], e["a_over_delta"], e["ratio"])
        assert e["positions"] == 4, label
        for g, worst, floor, mean in zip(e["gaps"], e["worst"], e["floor"], e["mean"]):
            assert abs(worst) >= floor - 1e-12, (label, g)
            assert abs(mean) <= calibration.FIT_VELOCITY_BOUND + 1e-6, (label, g)
            if g <= 1e-3:
                assert abs(worst) < 0.01, (label, g)


def table_s_hat(rows: np.ndarray, xi: float) -> float:
    """s_hat of a table block's rows as the resistance library reads them (SubgridCalibration::Block::sHatAt):
    xi * s_hat linear in ln xi, 0 from the last row on."""
    t = np.log(xi)
    if t >= np.log(rows[-1, 0]):
        return 0.0
    return float(np.interp(t, np.log(rows[:, 0]), rows[:, 1])) / xi


def test_shipped_table_within_2_percent_at_every_gap():
    """The issue's criterion, as the paper judges it: the closing velocity the shipped table's correction gives,
    averaged over the calibration's 4 positions in the cell, within 2 % of the theory at every measured gap
    (xi or eps 1e-4 ... 1) for every shipped (a1/Delta, a2/a1, wall): 11 blocks x 15 gaps. The correction is
    the table's rows as the resistance library interpolates them, the solver's resistance at each position
    the stored measurement (the resistances add: exact, no run)."""
    blocks = calibration.read_table(TABLE)
    with open(os.path.join(DATA, "squeeze_calibration.json")) as f:
        summaries = json.load(f)
    kinds, points, worst = set(), 0, 0.0
    for s in summaries:
        cal = calibration.SqueezeCalibration(s["kind"], s["a_over_delta"], s["ratio"], s["gaps"], s["boxes"],
                                             s["velocities"])
        _, rows = blocks[(s["kind"], float(s["a_over_delta"]), float(s["ratio"]))]
        s_hat = np.array([table_s_hat(rows, g) for g in cal.gaps])
        mean = (cal.theory() ** -1 / (1 / cal.velocity_by_position() + s_hat) - 1).mean(axis=0)
        label = "%s a1/Delta %g a2/a1 %g" % (s["kind"], s["a_over_delta"], s["ratio"])
        for g, e in zip(cal.gaps, mean):
            assert abs(e) < 0.02, (label, g, e)
        # the table holds the fit's correction: the errors the calibration module reports from the fit, but for the
        # linear interpolation between the table's rows (20 per decade; measured at most 0.04 %)
        assert np.allclose(mean, cal.corrected_errors(s["fit"]).mean(axis=0), rtol=0, atol=5e-4), label
        kinds.add((s["kind"], s["a_over_delta"], s["ratio"]))
        points += len(mean)
        worst = max(worst, float(np.max(np.abs(mean))))
    assert kinds == {(k, ad, r) for ad in (3.0, 4.0, 5.0) for k, r in (("pair", 1.0), ("pair", 1.4), ("wall", 1.0))} | {
        ("pair", 5.6, 1.0), ("wall", 5.6, 1.0)}
    assert points == 165
    print("squeeze calibration: 165 position-averaged points, worst %.2f %%" % (100 * worst))


def test_cpp_reads_the_shipped_correction_python_computes(env):
    """fdmResistance (the resistance library pair_style fdm/subgrid uses, `--calibrated`: the shipped table) gives
    X21A = -6 pi a1 s_hat (pairs) and X^A = 6 pi a s_hat (walls) with s_hat the table's rows interpolated in ln xi
    (to 1e-6), and that is the calibration module's correction from its fit, kept where positive and tapered
    (within 0.1 % of the resistance the corrected model gives), at every measured gap of every shipped block."""
    import subprocess
    blocks = calibration.read_table(TABLE)
    with open(os.path.join(DATA, "squeeze_calibration.json")) as f:
        summaries = json.load(f)

    def resistance(*args):
        done = subprocess.run(["fdmResistance"] + [str(a) for a in args], env=env, check=True, capture_output=True,
                              text=True)
        return json.loads(done.stdout)
    for s in summaries:
        cal = calibration.SqueezeCalibration(s["kind"], s["a_over_delta"], s["ratio"], s["gaps"], s["boxes"],
                                             s["velocities"])
        _, rows = blocks[(s["kind"], float(s["a_over_delta"]), float(s["ratio"]))]
        delta = 1 / s["a_over_delta"]
        for g in cal.gaps:
            if s["kind"] == "pair":
                out = resistance("pair", "--a1", 1, "--a2", s["ratio"], "--xi", g, "--subgrid", "--calibrated",
                                 "--delta", delta)
                cpp = -out["base"]["X21A"] / (6 * np.pi)
            else:
                out = resistance("wall", "--a", 1, "--eps", g, "--delta", delta, "--calibrated")
                cpp = out["subgrid_dimensional_over_eta"]["XA"] / (6 * np.pi)
            label = (s["kind"], s["a_over_delta"], s["ratio"], g)
            assert cpp == pytest.approx(table_s_hat(rows, g), rel=1e-6, abs=1e-9), label
            python = max(cal.correction(g, s["fit"]), 0.0) * calibration.taper(g)
            r_th = 1 / calibration.theory_velocity(s["kind"], s["ratio"], g)
            assert abs(cpp - python) < 1e-3 * r_th, label


def test_position_errors_predict_the_coupled_solver(tmp_path, env):
    """The calibrated model's error at one of the calibration's positions, predicted from the solver's own
    measurements alone (the squeeze resistances add), against the coupled run there (a1/Delta 3,
    a2/a1 1.4, the worst of the 4 positions at xi 0.1; box extrapolated from 8 and 12 a1 as the
    calibration was): the same within 0.3 %. So the spread the table docs/validation.md shows over
    positions is what the pair style does."""
    with open(os.path.join(DATA, "squeeze_calibration.json")) as f:
        s = next(c for c in json.load(f) if (c["kind"], c["a_over_delta"], c["ratio"]) == ("pair", 3.0, 1.4))
    cal = calibration.SqueezeCalibration(s["kind"], s["a_over_delta"], s["ratio"], s["gaps"], s["boxes"],
                                         s["velocities"])
    predicted = cal.corrected_errors(s["fit"])
    position, xis = 3, [0.1, 0.05]
    runs = [squeeze.run_pair(str(tmp_path), 1.4, xis, True, a_over_delta=3.0, L_over_a=L, tol_lambda=1e-5,
                             offset=calibration.OFFSETS[position]) for L in s["boxes"]]
    r = squeeze.box_extrapolated(runs[0], runs[1], *s["boxes"])
    assert r["converged"]
    measured = theory.relative_errors(r["velocity"], [theory.pair_squeeze_velocity(1.0, 1.4, xi) for xi in xis])
    for xi, e in zip(xis, measured):
        assert e == pytest.approx(predicted[position, s["gaps"].index(xi)], abs=3e-3), xi
    # and that position is off by more than the 2 %, which the floor says no gap-only correction mends
    assert abs(measured[0]) > 0.04
    assert cal.position_floor()[s["gaps"].index(0.1)] > 0.04


@pytest.mark.parametrize("ratio", [1.0, 1.4])
def test_calibrated_pair_squeeze_against_theory(tmp_path, env, ratio):
    """pair_style fdm/subgrid model calibrated at a1/Delta = 3 (the suspension resolution): the
    closing velocity, box effect extrapolated away, against Jeffrey & Onishi."""
    xis = [0.3, 0.1, 0.03, 1e-3]
    ref = [theory.pair_squeeze_velocity(1.0, ratio, xi) for xi in xis]
    runs = [squeeze.run_pair(str(tmp_path), ratio, xis, True, a_over_delta=3.0, L_over_a=L, tol_lambda=1e-5,
                             pair_options="model calibrated") for L in (8.0, 12.0)]
    r = squeeze.box_extrapolated(runs[0], runs[1], 8.0, 12.0)
    assert r["converged"]
    errors = theory.relative_errors(r["velocity"], ref)
    assert max(abs(e) for e in errors) < 0.05, errors


def test_calibrated_model_refuses_an_uncovered_resolution(tmp_path, env):
    """a/Delta = 2 is not in the table: a run with the pair style's default model (calibrated, nothing
    asked) stops and names the radii, the mesh and the way out; asked for, the cut-off model runs."""
    with pytest.raises(RuntimeError) as failure:
        squeeze.run_pair(str(tmp_path / "default"), 1.0, [0.01], True, a_over_delta=2.0, L_over_a=8.0,
                         tol_lambda=1e-3)
    message = str(failure.value)
    assert "no squeeze calibration for radii 1 and 1" in message
    assert "model cutoff" in message
    run = squeeze.run_pair(str(tmp_path / "cutoff"), 1.0, [0.01], True, a_over_delta=2.0, L_over_a=8.0,
                           tol_lambda=1e-3, pair_options="model cutoff")
    assert np.isfinite(run["velocity"]).all() and run["velocity"][0] > 0


def test_scenes_outside_the_table_are_refused_before_they_run(tmp_path, env):
    """`fdmResistance coverage` makes the pair style's test; the suspension cases ask it before they
    write anything: radii 1 and 2 at a1/Delta 3 between walls have no wall calibration for a/Delta 6 (the
    interpolation gives one within 2 %) and no pairs 1-2 and 2-2 (it does not)."""
    from fdmsubgrid import case
    covered = theory.resistance("coverage", "--a1", 1, "--a2", 1.4, "--delta", 1 / 3, "--wall")
    assert covered["pair"] and covered["pair_tangential"] and covered["wall"]
    assert not theory.resistance("coverage", "--a1", 1.4, "--delta", 0.2, "--wall")["wall"]
    assert not theory.resistance("coverage", "--a1", 1, "--a2", 2, "--delta", 0.25)["pair"]
    assert case.uncalibrated([1.0, 1.0, 1.4], 1 / 3, walls=True) == []
    assert case.uncalibrated([1.0, 2.0], 0.25) != []
    assert case.uncalibrated([1.0, 2.0], 0.25, model="cutoff") == []
    # one sphere per scene (wallShear, channelShear): only each radius against the walls
    alone = case.uncalibrated([1.0, 1.4], 0.2, walls=True, pairs=False)
    assert alone[0].startswith("radius 1.4 at a wall (a/Delta 7): python3 -m fdmsubgrid.calibration "
                               "--a-over-delta 7 --no-pairs") and len(alone) == 3
    # one sphere of a radius has no pair with itself: a2/Delta = 7 alone is fine without walls, two are not
    assert case.uncalibrated([1.0, 1.0, 1.4], 0.2) == []
    assert "pair of radii 1.4 and 1.4" in case.uncalibrated([1.0, 1.4, 1.4], 0.2)[0]
    couette = load_case_module("couette")
    with pytest.raises(SystemExit) as refused:
        couette.main(["--radii", "1", "2", "--size", "12", "12", "12", "--workdir", str(tmp_path), "--out",
                      str(tmp_path / "r.json")])
    # the pairs 1-2 (a2/a1 2) and 2-2 (a1/Delta 6) lie beyond the interpolation's 2 %; the wall of 2 does not
    assert "the pair of radii 1 and 2 at a1/Delta 3 (a2/a1 2): not calibrated" in str(refused.value)
    assert "the pair of radii 2 and 2 at a1/Delta 6 (a2/a1 1): not calibrated" in str(refused.value)
    assert "interpolated within 2 %: radius 2 at a wall (a/Delta 6, error 0.6 %)" in str(refused.value)
    assert "--model cutoff" in str(refused.value)
    assert os.listdir(tmp_path) == []
