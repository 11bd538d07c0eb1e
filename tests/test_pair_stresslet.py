"""fdmsubgrid.pairstresslet, the probe of the solver's own squeeze stresslet (docs/resistance.md): its
algebra on a synthetic response, no solver run (the measurement itself is in the docs)."""
import numpy as np
import pytest

from fdmsubgrid import pairstresslet as ps


def fluid_stresslet(kim_karrila_xg_times_u: np.ndarray, trace: float) -> np.ndarray:
    """S_fluid (xx xy xz yy yz zz) whose Kim-Karrila traceless part along x is X^G U, plus any trace."""
    s = -np.asarray(kim_karrila_xg_times_u)       # the fluid's stresslet is the opposite of Kim-Karrila's
    out = np.zeros((len(s), 6))
    out[:, 0], out[:, 3], out[:, 5] = 2 * s / 3 + trace / 3, -s / 3 + trace / 3, -s / 3 + trace / 3
    return out


@pytest.mark.parametrize("ratio", [1.0, 1.4])
def test_solver_x11g_recovers_a_known_response(env, ratio):
    # a solver that resolves a fraction of the theory's X^G_11 of each labelling, with the theory's response to
    # a rigid translation, at unequal velocities (a rigid translation on top of the squeeze)
    gaps = [0.2, 0.02]
    u1, u2 = np.array([0.31, 0.12]), np.array([-0.17, -0.05])
    fraction = np.array([0.7, 0.1])
    s1, s2 = [], []
    for k, xi in enumerate(gaps):
        x11, x12, x21, x22 = ps.theory_xg(1.0, ratio, xi)
        g11 = fraction[k] * x11
        s1.append(g11 * u1[k] + (x11 + x12 - g11) * u2[k])
        # sphere 2 seen as the first of the relabelled pair: its X11G is -X^G_22 here (X^G is odd in d)
        g22 = -fraction[k] * ps.theory_xg(ratio, 1.0, xi)[0]
        s2.append((x21 + x22 - g22) * u1[k] + g22 * u2[k])
    run = dict(U1=u1, U2=u2, S1=fluid_stresslet(s1, trace=-3.0), S2=fluid_stresslet(s2, trace=5.0))
    g1, g2 = ps.solver_x11g(run, ratio, gaps)
    assert g1 == pytest.approx([f * ps.theory_xg(1.0, ratio, x)[0] for f, x in zip(fraction, gaps)], rel=1e-12)
    assert g2 == pytest.approx([f * ps.theory_xg(ratio, 1.0, x)[0] for f, x in zip(fraction, gaps)], rel=1e-12)


@pytest.mark.parametrize("model", ps.MODELS)
@pytest.mark.parametrize("ratio", [1.0, 1.4])
def test_the_applied_squeeze_stresslets_add_up_to_the_dipole_of_the_squeeze_force(env, model, ratio):
    # Appendix C.2 (X^G_21 = -X^G_11 - r X^A_21) and the average over the labellings: whatever the base
    # function X11G, the two spheres' sub-grid squeeze stresslets add up to r times the sub-grid squeeze
    # force, X^G_11(a1, a2) + X^G_11(a2, a1) = -r X^A_21, and equal spheres take half each
    delta = 1.0 / 3
    for xi in (0.01, 0.1, 0.2, 0.3, 0.5):
        r = (1 + ratio) / 2 * (2 + xi)
        xa21 = ps.theory.resistance("pair", "--a1", 1.0, "--a2", ratio, "--xi", xi, "--subgrid", "--delta", delta,
                                    *ps.theory.subgrid_options(model))["dimensional_over_eta"]["XA21"]
        xg1, xg2 = ps.applied_x11g(1.0, ratio, xi, delta, model), ps.applied_x11g(ratio, 1.0, xi, delta, model)
        assert xg1 + xg2 == pytest.approx(-r * xa21, rel=1e-9, abs=1e-12)
        if ratio == 1.0:
            assert xg1 == pytest.approx(-r * xa21 / 2, rel=1e-9, abs=1e-12)
    # beyond the cut-off model's range only the calibrated squeeze force acts, and with it the stresslet
    if model == "calibrated":
        assert ps.applied_x11g(1.0, ratio, 0.3, delta, model) > 0
    else:
        assert ps.applied_x11g(1.0, ratio, 0.3, delta, model) == 0


def test_analyse_predicts_no_error_for_a_solver_that_misses_what_the_model_applies(env):
    # a synthetic solver-alone result whose X11G is the theory minus what the calibrated model applies
    delta, ratio = 1.0 / 3, 1.4
    rows = []
    for xi in (0.05, 0.3):
        th = [ps.theory_xg(1.0, ratio, xi)[0], ps.theory_xg(ratio, 1.0, xi)[0]]
        applied = [ps.applied_x11g(1.0, ratio, xi, delta, "calibrated"),
                   ps.applied_x11g(ratio, 1.0, xi, delta, "calibrated")]
        rows.append(dict(xi=xi, measured=[th[0] - applied[0], th[1] - applied[1]], measured_spread=[0, 0]))
    result = ps.analyse(dict(ratio=ratio, a_over_delta=3.0, model=None, rows=rows))
    for r in result["rows"]:
        assert r["predicted_error"]["calibrated"] == pytest.approx([0, 0], abs=1e-12)
        assert r["needed"] == pytest.approx(r["applied"]["calibrated"], rel=1e-12)
