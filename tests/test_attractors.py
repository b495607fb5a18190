"""Coexisting attractors: deduplication rules and the P1 / torus coexistence of the calibrated design.

Between the Neimark-Sacker point of the upper P1 branch (x1 = 0.7274) and the fold of the lower one
(x1 = 0.7527), the calibrated design (w = 0.7, b = 2, e = 5) has a stable P1 orbit and a torus
(quasi-periodic) side by side (tests/test_continuation.py finds both bifurcations).
"""

from pathlib import Path

import numpy as np
import pytest

import _orbits
from geardyn import io
from geardyn.io import provenance
from geardyn.khv import design, point
from geardyn.label import indicators, vocabulary
from geardyn.label.compare import same_attractor
from geardyn.label.policy import Same
from geardyn.runs import attractors as A

ROOT = Path(__file__).resolve().parents[1]
S = A.AttractorSettings()
TOLS = Same(S.distance_tol, S.chaotic_distance_tol)


def test_same_periodic_orbit_from_different_cycle_phase_is_one_attractor():
    cyc = np.array([[0.0] * 6, [1.0] * 6])
    assert same_attractor(2, cyc, 2, cyc[::-1] + 1e-9, TOLS)
    assert not same_attractor(2, cyc, 2, cyc + 0.1, TOLS)
    assert not same_attractor(1, cyc[:1], 2, cyc, TOLS)


def test_chaotic_sets_compared_relative_to_their_size():
    rng = np.random.default_rng(1)
    a = rng.uniform(-10, 10, (200, 6))
    b = rng.uniform(-10, 10, (200, 6))
    assert same_attractor(-4, a, -4, b, TOLS)  # same cloud, different samples
    assert not same_attractor(-4, a, -4, b + 15.0, TOLS)


def test_random_starts_reproducible_and_in_the_box():
    d = design.load(ROOT / "config" / "designs" / "li2013.yaml")
    c = point.point_coefficients(d, {"x1": 0.5})
    s = A.AttractorSettings(n_random=5, box_x=3.0, box_v=4.0)
    one, two = A.random_starts(c, s), A.random_starts(c, s)
    assert list(one) == [f"random_{k}" for k in range(5)]
    for k in one:
        np.testing.assert_array_equal(one[k], two[k])
        dev = np.abs(one[k] - c.static_state())
        assert np.all(dev[:3] <= 3.0) and np.all(dev[3:] <= 4.0)


@pytest.fixture(scope="module")
def coexistence():
    d, fam, br = _orbits.calibrated_branch()
    values = np.array([0.74, 0.76])
    pts = A.sweep_points(fam.coefficients, values, [0, 1], 0, lambda j: None, [br])
    ds = A.attractors_dataset(
        pts,
        A.AttractorSettings(n_random=4),
        point.integration_settings(d),
        indicators.ClassifierSettings(),
        "x1",
        "1",
        "planet profile shift x1",
    )
    return ds


def test_p1_and_torus_coexist_between_ns_and_fold(coexistence):
    ds = coexistence
    labels = sorted(int(v) for v in ds["attractor_label"].values[0] if v != vocabulary.LABELS["undetermined"])
    assert ds["n_attractors"].values[0] == 2
    assert labels == [vocabulary.LABELS["quasi_periodic"], 1]
    # past the fold only the torus is left
    assert ds["n_attractors"].values[1] == 1
    assert ds["attractor_label"].values[1, 0] == vocabulary.LABELS["quasi_periodic"]


def test_basin_fractions_sum_to_one_and_dataset_is_cf(coexistence, tmp_path):
    ds = coexistence
    frac = np.nansum(ds["basin_fraction"].values, axis=1)
    np.testing.assert_allclose(frac, 1.0)
    assert io.missing_cf_attributes(ds) == []
    io.write_netcdf(ds, tmp_path / "a.nc", provenance.attributes(title="test"))
