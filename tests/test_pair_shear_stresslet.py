"""fdmsubgrid.pairshearstresslet (issue 14): the theory's stresslets of two spheres for any motion, built from the
library's full-range X^G, Y^G, Y^H, checked without the solver: Faxen's law in the far field (which fixes the
sign the records are compared with), the symmetries of equal spheres, and the reading of a loaded-pair run.
Then one small coupled run: with the calibrated model the rolling mode's stresslet stays within the cut-off
model's accuracy (docs/resistance.md, "The pair's shear-mode stresslets")."""
import math

import numpy as np
import pytest

from fdmsubgrid import pairshearstresslet as pss


def _strain_rate(velocity, x, h=1e-5):
    grad = np.zeros((3, 3))
    for k in range(3):
        dx = np.zeros(3)
        dx[k] = h
        grad[:, k] = (velocity(x + dx) - velocity(x - dx)) / (2 * h)
    return 0.5 * (grad + grad.T)


def test_far_field_is_faxen_for_a_sphere_held_near_a_moving_one():
    # Sphere 1 held (U1 = W1 = 0) at r = 51 a1 from sphere 2 (a2 = 1.4): its stresslet is Faxen's
    # (20/3) pi eta a1^3 E(x1), E the strain rate of sphere 2's far field at x1 (a Stokeslet of force
    # 6 pi eta a2 U2 for a translation, a rotlet of torque 8 pi eta a2^3 W2 for a rotation), to O(r^-4)
    ratio, xi = 1.4, 40.0
    r = (1 + ratio) / 2 * (2 + xi)
    x1 = np.array([-r, 0.0, 0.0])           # sphere 2 at the origin, d = e_x from 1 to 2
    for u2 in (np.array([1.0, 0, 0]), np.array([0.3, -0.5, 0.8])):
        force = 6 * math.pi * ratio * u2
        def stokeslet(y, f=force):
            rho = np.linalg.norm(y)
            return (f / rho + y * (y @ f) / rho ** 3) / (8 * math.pi)
        expected = 20.0 / 3.0 * math.pi * _strain_rate(stokeslet, x1)
        got = pss.theory_stresslet(ratio, xi, dict(U1=np.zeros(3), W1=np.zeros(3), U2=u2, W2=np.zeros(3)))[0]
        assert np.abs(got - expected).max() < 2e-3 * np.abs(expected).max()
    torque = 8 * math.pi * ratio ** 3 * np.array([0.0, 0.0, 1.0])
    def rotlet(y):
        return np.cross(torque, y) / (8 * math.pi * np.linalg.norm(y) ** 3)
    expected = 20.0 / 3.0 * math.pi * _strain_rate(rotlet, x1)
    got = pss.theory_stresslet(ratio, xi, dict(U1=np.zeros(3), W1=np.zeros(3), U2=np.zeros(3),
                                               W2=np.array([0.0, 0.0, 1.0])))[0]
    assert expected[0, 1] != 0
    assert np.abs(got - expected).max() < 2e-3 * abs(expected[0, 1])


def test_equal_spheres_sliding_and_rolling_symmetries():
    # Equal spheres: swapping them (d -> -d) maps sliding (U1 = -U2 across d) onto itself with the same
    # S_xy on both, and rolling (W1 = -W2 about n) onto itself with opposite S_xz; stresslets are traceless
    # and symmetric; a twist about d makes none
    z = np.zeros(3)
    for xi in (1e-3, 0.1, 1.0):
        sliding = pss.theory_stresslet(1.0, xi, dict(U1=np.array([0, 1.0, 0]), W1=z, U2=np.array([0, -1.0, 0]), W2=z))
        assert sliding[0][0, 1] == pytest.approx(sliding[1][0, 1], rel=1e-9)
        rolling = pss.theory_stresslet(1.0, xi, dict(U1=z, W1=np.array([0, 1.0, 0]), U2=z, W2=np.array([0, -1.0, 0])))
        assert rolling[0][0, 2] == pytest.approx(-rolling[1][0, 2], rel=1e-9)
        for s in np.concatenate([sliding, rolling]):
            assert np.allclose(s, s.T) and abs(np.trace(s)) < 1e-12 * np.abs(s).max()
        twist = pss.theory_stresslet(1.0, xi, dict(U1=z, W1=np.array([1.0, 0, 0]), U2=z, W2=np.array([-1.0, 0, 0])))
        assert np.abs(twist).max() == 0
    # near contact the lubrication stresslets grow like ln(1/xi)
    s3, s4 = (abs(pss.theory_stresslet(1.0, xi, dict(U1=np.array([0, 1.0, 0]), W1=z, U2=np.array([0, -1.0, 0]),
                                                     W2=z))[0][0, 1]) for xi in (1e-3, 1e-4))
    assert s4 > s3


def test_components_of_a_run_record():
    # stresslet_components reads S1, S2 (xx xy xz yy yz zz) per gap: measured xy, xz beside the theory's
    xi = 0.05
    v = dict(U1=[0.1, 0.4, -0.2], W1=[0.3, -0.6, 0.5], U2=[0.0, -0.4, 0.1], W2=[-0.2, 0.7, 0.4])
    th = pss.theory_stresslet(1.4, xi, {k: np.array(x) for k, x in v.items()})
    record = dict(gaps=[xi], **{k: [x] for k, x in v.items()},
                  S1=[[th[0][0, 0], th[0][0, 1], th[0][0, 2], th[0][1, 1], th[0][1, 2], th[0][2, 2]]],
                  S2=[[th[1][0, 0], 2 * th[1][0, 1], th[1][0, 2], th[1][1, 1], th[1][1, 2], th[1][2, 2]]])
    measured, theory = pss.stresslet_components(record, 1.4)
    assert measured.shape == theory.shape == (1, 2, 2)
    assert np.allclose(measured[0, 0], theory[0, 0], rtol=1e-12)
    assert measured[0, 1, 0] == pytest.approx(2 * theory[0, 1, 0], rel=1e-12)
    assert measured[0, 1, 1] == pytest.approx(theory[0, 1, 1], rel=1e-12)


def test_coupled_rolling_stresslet_of_the_calibrated_model(env, tmp_path):
    # Equal spheres, a1/Delta 3, boxes 8 and 10 a1, one offset, xi 0.1 and 0.01 (about a minute): with the
    # calibrated model the rolling mode's stresslet is within 6 % of the theory (measured 0.4-2.8 %; before
    # the Y21H rule of CalibratedSubgridModel::pair +51-70 %), the sliding mode's within 12 % (3.7-8.7 %)
    result = pss.measure(1.0, 3.0, str(tmp_path), "calibrated", gaps=[0.1, 0.01], boxes=[8.0, 10.0],
                         offsets=pss.OFFSETS[:1])
    for row in result["rows"]:
        sliding = [row["relative"][s][0] for s in range(2)]
        rolling = [row["relative"][s][1] for s in range(2)]
        assert max(abs(v) for v in rolling) < 0.06, row
        assert max(abs(v) for v in sliding) < 0.12, row
