"""The mesh resolution of the rheology (docs/validation.md, "Mesh resolution of the rheology"): the Table 8
rows phi_bulk 0.47 and 0.52 run again at a1/Delta 4 (cases/couette/table8.py --a-over-delta 4), checked on
their stored records without running the solver: each pair is the same scene but for the mesh, each run is
finished with a full averaging window and closes its stress balance, and what the docs say of the change of
mesh holds on the stored numbers."""
import math
import os

import pytest

from conftest import PROJECT
from fdmsubgrid.results import read_data

DATA = os.path.join(PROJECT, "docs", "data")
VALIDATION = os.path.join(PROJECT, "docs", "validation.md")
PHIS = ("0.47", "0.52")


def read_pair(phi: str) -> tuple:
    """The row at a1/Delta 4 and the row at a1/Delta 3 it is compared with."""
    stored = read_data(os.path.join(DATA, "validation_table8_resolution_phi%s.json" % phi))
    coarse = read_data(os.path.join(DATA, os.path.basename(stored["a1_over_delta_3"])))
    return stored["a1_over_delta_4"], coarse


@pytest.fixture(scope="module")
def pairs() -> dict:
    """Each phi_bulk's pair, read once for the module."""
    return {phi: read_pair(phi) for phi in PHIS}


def eta_change(fine: dict, coarse: dict) -> tuple:
    """eta_s at a1/Delta 4 over eta_s at a1/Delta 3, minus 1, and its standard error."""
    ratio = fine["eta_s"] / coarse["eta_s"]
    error = ratio * math.hypot(fine["eta_s_err"] / fine["eta_s"], coarse["eta_s_err"] / coarse["eta_s"])
    return ratio - 1, error


@pytest.mark.parametrize("phi", PHIS)
def test_the_pair_differs_in_the_mesh_only(phi, pairs):
    fine, coarse = pairs[phi]
    assert fine["phi_bulk_table8"] == pytest.approx(float(phi))
    for key in ("dt", "n_particles"):
        assert fine[key] == coarse[key], key
    # the run's name carries the box, a1/Delta, dt, seed, contact model and fluid_every
    assert fine["run_dir"] == coarse["run"].replace("_ad3_", "_ad4_")
    # a1/Delta 4 against 3 in the same box: (4/3)^3 the cells
    assert fine["cells"] / coarse["cells"] == pytest.approx((4 / 3) ** 3, rel=1e-9)


@pytest.mark.parametrize("phi", PHIS)
def test_each_row_is_finished_with_a_full_window_and_its_balance(phi, pairs):
    fine, coarse = pairs[phi]
    assert fine["status"] == "finished" and not fine["window_short"]
    for row in (fine, coarse):
        assert row["strain_units"] - row["steady_from_strain"] >= 20 - 0.1
        assert abs(row["stress_balance_rel_error"]) < 0.01
        assert row["unconverged_steps"] == 0
    # the finer mesh lets no pair deeper into its roughness layer
    assert fine["min_pair_gap"] > coarse["min_pair_gap"]


def test_what_the_docs_say_of_the_change_of_mesh(pairs):
    # docs/validation.md: eta_s -7 +- 5 % at 0.47 and +3 +- 5 % at 0.52 from a1/Delta 3 to 4, of opposite
    # signs, their mean within 5 % (no effect of the mesh at that level); at 0.52 every other quantity
    # within its error bars and the contact normal stresses within 0.9 %
    changes = [eta_change(*pairs[phi]) for phi in PHIS]
    (low, low_err), (high, high_err) = changes
    assert -0.09 < low < -0.05 and 0.04 < low_err < 0.06
    assert 0.02 < high < 0.04 and 0.04 < high_err < 0.06
    assert low * high < 0
    mean = 0.5 * (low + high)
    mean_err = 0.5 * math.hypot(low_err, high_err)
    assert abs(mean) < 0.05 and abs(mean) < mean_err
    fine, coarse = pairs["0.52"]
    for key, err in (("phi_core", "phi_core_err"), ("gamma_core_over_gamma0", "gamma_core_err"),
                     ("N1_hat", "N1_hat_err"), ("N2_hat", "N2_hat_err")):
        assert abs(fine[key] - coarse[key]) < math.hypot(fine[err], coarse[err]), key
    for f, c in zip(fine["Sigma_c_hat"], coarse["Sigma_c_hat"]):
        assert abs(f / c - 1) < 0.009
    with open(VALIDATION) as f:
        text = f.read()
    for phi, rows in pairs.items():
        for row in rows:
            assert "%.1f ± %.1f" % (row["eta_s"], row["eta_s_err"]) in text, (phi, row["eta_s"])
