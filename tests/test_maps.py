"""Regime maps: chunks tile the map and the result does not depend on the chunking; the direct
setting of b / e / w on the coefficients equals the full point model."""

from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from geardyn import io
from geardyn.io import quarantine
from geardyn.khv import design, point
from geardyn.label.vocabulary import NOT_COMPUTED
from geardyn.runs import cube, maps

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def model():
    return design.load(ROOT / "tests" / "data" / "li2013_w07.yaml")


def _spec(y="b", chunks=1):
    return maps.MapSpec.from_config(
        "t",
        {
            "designs": ["li2013_w07"],
            "x": {"parameter": "x1", "start": 0.5, "stop": 0.8, "num": 3},
            "y": {"parameter": y, "start": 0.5, "stop": 2.0, "num": 4},
            "fixed": {"e": 5.0} if y != "e" else {"b": 2.0},
            "chunks": chunks,
            "integration": {"steps_per_period": 64, "transient_periods": 40, "recorded_periods": 20},
            "classifier": {"error_floor": 3e-4, "tangent_periods": 30},
        },
        "li2013_w07",
        (0.416, 0.835),
    )


def test_map_independent_of_chunking(model, tmp_path):
    merged = []
    for chunks in (1, 5):
        spec = _spec(chunks=chunks)
        # through netCDF and the merge rules' loader, as in the pipeline
        paths = [
            io.write_netcdf(maps.run_chunk(model, spec, c), tmp_path / f"{chunks}_{c}.nc") for c in range(spec.n_chunks)
        ]
        parts = quarantine.read_chunks(paths)
        out = cube.merge_chunks(parts)
        out.attrs.pop("chunk_wall_time_s")
        merged.append(out)
    xr.testing.assert_equal(merged[0], merged[1])
    assert (merged[0]["stage"].values != NOT_COMPUTED).all()  # every point computed
    with pytest.raises(ValueError, match="points missing"):
        cube.merge_chunks(parts[:2])


@pytest.mark.parametrize("y", ["b", "e", "w"])
def test_direct_coefficients_equal_point_model(model, y):
    spec = _spec(y)
    fixed = dict(spec.fixed)
    base = point.point_coefficients(model, {**fixed, "x1": 0.6})
    for value in (0.5, 1.37, 2.0):
        assert maps.point_coefficients(model, spec, 0.6, value, base) == point.point_coefficients(
            model, {**fixed, "x1": 0.6, y: value}
        )


def test_map_has_cf_attributes(model):
    ds = maps.run_chunk(model, _spec(chunks=4), 0)
    assert io.missing_cf_attributes(ds) == []
    assert np.isin(ds["label"].values, ds["label"].attrs["flag_values"]).all()
