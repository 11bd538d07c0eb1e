"""The Suspension Balance Model of a pressure-driven channel (scripts/fdmsubgrid/sbm.py, Eqs. 62a, 62b,
63): its closed-form cases (a Newtonian liquid's parabola; a power-law contact stress, whose first
integral gives the volume fraction in closed form up to the jammed width), the volume constraint, the
plug in the jammed zone, the fit from Couette results, and the errors on input it cannot solve."""
import math
import os

import numpy as np
import pytest
from scipy.integrate import trapezoid
from scipy.optimize import brentq

from conftest import PROJECT
from fdmsubgrid import sbm


def power_law_reference(phi_mean: float, phi_m: float, n: float, y_edge: float):
    """phi_r(y) = min(1, (y_j/|y|)^(1/n)) (the first integral Sigma_hat |y| = K y_j with Sigma_hat =
    -K phi_r^n), y_j from Eq. (63) by a root find on the closed-form integral."""
    target = phi_mean / phi_m

    def mean(y_j: float) -> float:
        tail = y_j ** (1 / n) * (y_edge ** (1 - 1 / n) - y_j ** (1 - 1 / n)) / (1 - 1 / n)
        return (y_j + tail) / y_edge

    y_j = brentq(lambda s: mean(s) - target, 1e-14, y_edge)
    return y_j, (lambda y: np.minimum(1.0, (y_j / np.maximum(np.abs(y), 1e-300)) ** (1 / n)))


@pytest.mark.parametrize("n, y_edge", [(2.0, 0.5), (3.0, 0.4375), (1.5, 0.45)])
def test_power_law_contact_stress_matches_the_closed_form(n, y_edge):
    material = sbm.MaterialFunctions.maron_pierce_power_law(0.8, 0.6, 0.7, n)
    prof = sbm.solve(material, 0.45, y_edge=y_edge)
    y_j, phi_r = power_law_reference(0.45, 0.6, n, y_edge)
    assert prof.y_jammed == pytest.approx(y_j, rel=1e-6)
    outside = np.abs(prof.y) > 1.001 * y_j
    assert np.max(np.abs(prof.phi_r - phi_r(prof.y))) < 1e-6
    # the first integral of Eq. (62b): Sigma_hat_22(phi_r) |y| is uniform outside the jammed zone
    first_integral = -material.sigma22(prof.phi_r[outside]) * np.abs(prof.y[outside])
    assert np.ptp(first_integral) < 1e-6 * first_integral.mean()
    assert first_integral.mean() == pytest.approx(prof.invariant, rel=1e-6)


@pytest.mark.parametrize("phi_mean", [0.2, 0.45, 0.55])
def test_the_particle_volume_is_conserved(phi_mean):
    material = sbm.MaterialFunctions.maron_pierce_power_law()
    prof = sbm.solve(material, phi_mean, y_edge=0.4)
    assert trapezoid(prof.phi, prof.y) / (2 * prof.y_edge) == pytest.approx(phi_mean, rel=2e-5)
    assert np.all(prof.phi <= material.phi_m * (1 + 1e-12))
    # phi rises toward the centre: migration
    half = prof.y >= 0
    assert np.all(np.diff(prof.phi[half]) <= 1e-12)


def newtonian(phi_m: float = 0.6) -> sbm.MaterialFunctions:
    base = sbm.MaterialFunctions.maron_pierce_power_law(phi_m=phi_m)
    return sbm.MaterialFunctions(phi_m=phi_m, eta_s=lambda r: np.ones_like(np.asarray(r, dtype=float)),
                                 sigma22=base.sigma22, dsigma22=base.dsigma22)


def test_a_newtonian_liquid_gives_the_parabola():
    """eta_s = 1 everywhere: Eq. (62a) is the plane Poiseuille profile u* = (1 - 4 y*^2)/2."""
    prof = sbm.solve(newtonian(), 0.3, y_edge=0.5, u_edge=0.0)
    assert np.max(np.abs(prof.u - (1 - 4 * prof.y ** 2) / 2)) < 1e-9
    # and with a slip velocity at the edge of a smaller region, shifted by it
    prof = sbm.solve(newtonian(), 0.3, y_edge=0.4, u_edge=0.05)
    assert np.max(np.abs(prof.u - (0.05 + 2 * (0.4 ** 2 - prof.y ** 2)))) < 1e-9


def test_velocity_against_quadrature_and_the_plug():
    """Eq. (62a) with Maron-Pierce against scipy's quad of the closed-form profile; u* is flat in the
    jammed zone (eta_s infinite) and blunted against the parabola of the same wall shear stress."""
    from scipy.integrate import quad
    material = sbm.MaterialFunctions.maron_pierce_power_law(0.803, 0.592, 0.8, 2.0)
    prof = sbm.solve(material, 0.45, y_edge=0.5)
    y_j, phi_r = power_law_reference(0.45, 0.592, 2.0, 0.5)

    def slope(s: float) -> float:
        r = float(phi_r(s))
        return 0.0 if r >= 1 else 4 * s * (1 - r) ** 2 / 0.803

    for y in (0.45, 0.3, 0.2, y_j * 1.01):
        exact = quad(slope, y, 0.5, points=[y_j], limit=200, epsabs=1e-13)[0]
        assert float(prof.at(y)[1]) == pytest.approx(exact, rel=2e-4, abs=1e-7)
    plug = np.abs(prof.y) <= y_j
    assert np.ptp(prof.u[plug]) < 1e-12
    assert prof.y_jammed > 0.05
    newton = (1 - 4 * prof.y ** 2) / 2
    assert float(prof.at(0.0)[1]) < 0.5 * float(newton.max())


def test_fit_from_couette_results():
    """The material functions from the shipped Table 8 phi_bulk 0.27 results: one row fits alpha (phi_m
    held at the paper's 0.592) and K (n held at 2); the fit reproduces the row."""
    path = os.path.join(PROJECT, "docs", "data", "validation_table8_phi0.27.json")
    material = sbm.from_couette_results([path])
    import json
    row = json.load(open(path))["mser_window"]
    r = row["phi_core"] / material.phi_m
    assert float(material.eta_s(r)) == pytest.approx(row["eta_s"], rel=1e-9)
    assert float(material.sigma22(r)) == pytest.approx(row["Sigma_c_hat"][1], rel=1e-9)
    assert material.describe["contact_n"] == 2.0


def test_power_law_fit_recovers_its_parameters():
    phi = np.array([0.3, 0.36, 0.41, 0.46, 0.5])
    truth = -0.9 * (phi / 0.59) ** 2.4
    k, n = sbm.fit_contact_power_law(phi, truth, 0.01 * np.abs(truth), 0.59)
    assert (k, n) == (pytest.approx(0.9, rel=1e-6), pytest.approx(2.4, rel=1e-6))


def test_bad_input_is_refused_with_the_value():
    with pytest.raises(sbm.SBMError, match=r"K = -0.5"):
        sbm.MaterialFunctions.maron_pierce_power_law(contact_k=-0.5)
    with pytest.raises(sbm.SBMError, match=r"phi_m = 0.592"):
        sbm.solve(sbm.MaterialFunctions.maron_pierce_power_law(), 0.6)
    with pytest.raises(sbm.SBMError, match=r"y_edge = 0.7"):
        sbm.solve(sbm.MaterialFunctions.maron_pierce_power_law(), 0.4, y_edge=0.7)
    # a contact stress with a maximum at phi_r = 0.8: its derivative vanishes there, Eq. (62b) is singular
    flat = sbm.MaterialFunctions(phi_m=0.6, eta_s=lambda r: np.ones_like(r),
                                 sigma22=lambda r: -(np.asarray(r) - 0.8) ** 2 - 0.1 + 0.64,
                                 dsigma22=lambda r: -2 * (np.asarray(r) - 0.8))
    with pytest.raises(sbm.SBMError, match=r"singular"):
        sbm.solve(flat, 0.4)
    with pytest.raises(sbm.SBMError, match=r"not a Couette results file"):
        sbm.from_couette_results([os.path.join(PROJECT, "docs", "data", "benchmarks_coldStart.json")])
