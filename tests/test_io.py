"""netCDF output: round trip, CF attributes, provenance, atomic writes."""

import numpy as np
import pytest
import xarray as xr

from geardyn import __version__, io
from geardyn.io import provenance


def _dataset():
    x = np.linspace(0, 1, 5)
    return xr.Dataset(
        {"k": ("x1", x**2, {"units": "N m-1", "long_name": "stiffness"})},
        coords={"x1": ("x1", x, {"units": "1", "long_name": "profile shift"})},
    )


def test_round_trip_is_identical_and_carries_provenance(tmp_path):
    ds = _dataset()
    attrs = provenance.attributes(title="t", paper="li2013", config={"a": 1, "b": [1, 2]}, model_variant="v")
    path = io.write_netcdf(ds, tmp_path / "a.nc", attrs)
    with xr.open_dataset(path) as back:
        back.load()
    expected = ds.assign_attrs(attrs)
    xr.testing.assert_identical(back, expected)
    for key in (
        "Conventions",
        "title",
        "source",
        "history",
        "references",
        "geardyn_version",
        "git_commit",
        "config_hash",
        "model_variant",
    ):
        assert back.attrs[key]
    assert back.attrs["geardyn_version"] == __version__
    assert [p.name for p in tmp_path.iterdir()] == ["a.nc"]  # no temporary file left behind


def test_config_hash_ignores_key_order_and_sees_values():
    assert provenance.config_hash({"a": 1, "b": 2}) == provenance.config_hash({"b": 2, "a": 1})
    assert provenance.config_hash({"a": 1}) != provenance.config_hash({"a": 1.0001})


def test_references_name_the_paper_of_the_design_or_the_docs():
    assert provenance.attributes(title="t", paper="li2013")["references"].startswith("Li H., Niu W.")
    assert provenance.attributes(title="t")["references"] == "geardyn documentation (docs/)"


def test_missing_units_refused(tmp_path):
    ds = _dataset()
    ds["k"].attrs.pop("units")
    with pytest.raises(ValueError, match="k: units"):
        io.write_netcdf(ds, tmp_path / "b.nc")
    assert not list(tmp_path.iterdir())
