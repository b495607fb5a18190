"""netCDF output: round trip, CF attributes, provenance, atomic writes."""

import numpy as np
import pytest
import xarray as xr

from geardyn import __version__, io
from geardyn.io import Var, provenance


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


def test_a_table_of_variables_is_a_cf_dataset_that_round_trips(tmp_path):
    """io.dataset from a table of io.Var: every variable with its units and long name (none for a flag or a
    name, as CF has it), a flag's flag_values in the variable's own dtype and its flag_meanings in order, the
    values cast to the declared dtype, a variable named as its dimension a coordinate, the file in the table's
    order; written and read back identical (CF 3.5: flag_values of the variable's type)."""
    table = (
        Var("k", ("case", "x1"), "N m-1", "stiffness", attrs={"comment": "c"}),
        Var("ok", "x1", "1", "feasible", {"infeasible": 0, "feasible": 1}),
        Var("label", "x1", None, "motion label", {"chaotic": -4, "period_1": 1}, np.int16),
        Var("x1", "x1", "1", "profile shift"),
        Var("case", "case", None, "case"),
    )
    ds = io.dataset(
        table,
        {"k": np.ones((2, 3)), "ok": [True, False, True], "label": [1, -4, 1]}
        | {"x1": np.linspace(0.4, 0.8, 3), "case": ["a", "b"]},
        title="t",
    )
    assert list(ds.variables) == [v.name for v in table] and set(ds.coords) == {"x1", "case"}
    assert ds["ok"].dtype == ds["ok"].attrs["flag_values"].dtype == np.int8 and ds["ok"].values.tolist() == [1, 0, 1]
    assert ds["label"].dtype == ds["label"].attrs["flag_values"].dtype == np.int16
    assert ds["label"].attrs["flag_meanings"] == "chaotic period_1" and "units" not in ds["label"].attrs
    assert ds["k"].attrs == {"units": "N m-1", "long_name": "stiffness", "comment": "c"}
    with xr.open_dataset(io.write_netcdf(ds, tmp_path / "t.nc")) as back:
        back = back.load()
    assert back["label"].attrs["flag_values"].dtype == np.int16
    back.attrs, ds.attrs = {}, {}  # the provenance the writer adds
    xr.testing.assert_identical(back, ds)
    filled = Var("n", "x1", "1", "count", dtype=np.int32, fill=-1).empty((3,))
    assert filled[1].dtype == np.int32 and filled[1].tolist() == [-1, -1, -1]


def test_a_markdown_table_aligns_and_keeps_its_cells_whole():
    """A header, its rule with the stated alignment, a row per line; a '|' in a cell would end the cell early."""
    text = io.markdown_table(("name", "value", "note"), [("a", 1.5, ""), ("b|c", 2, "x")], "-r")
    assert text.splitlines() == ["| name | value | note |", "|---|---:|---|", "| a | 1.5 |  |", "| b/c | 2 | x |"]
