"""Closed graph of paper 1 Fig. 3: dataset content, line 4 and the points M and N, figure."""

from __future__ import annotations

import matplotlib

import _model_oracle as oracle

matplotlib.use("Agg")

import numpy as np
import pytest
import xarray as xr

from geardyn.gears import constraints, interference
from geardyn.gears import geometry as geo
from geardyn.khv import closed_graph as cg
from geardyn.papers import li2013
from geardyn.plots.closed_graph import caption_closed_graph, plot_closed_graph

KHV = geo.GearPair(z1=30, z2=33, module=3.5, x1=0.0, x2=0.0, addendum=0.8)
X1 = np.linspace(0.0, 1.4, 71)
X2 = np.linspace(0.0, 1.8, 91)


@pytest.fixture(scope="module")
def ds() -> xr.Dataset:
    return cg.closed_graph(KHV, X1, X2, reference_points=li2013.POINTS)


@pytest.fixture(scope="module")
def fitted() -> xr.Dataset:
    cutter = oracle.cutter_shift_for_trimming_limit(KHV, 0.416, teeth=28, addendum=1.25)
    return cg.closed_graph(KHV, X1, X2, cutter=cutter, reference_points=li2013.POINTS)


def test_every_variable_and_numeric_coordinate_is_described(ds: xr.Dataset) -> None:
    for name, var in ds.variables.items():
        assert var.attrs.get("long_name"), name
        if var.dtype.kind in "fiu":  # the string label coordinate ``point`` has no unit
            assert "units" in var.attrs, name


def test_one_variable_per_constraint_and_lines_assigned(ds: xr.Dataset) -> None:
    names = set(constraints.constraints(geo.with_shifts(KHV, 0.5, 0.8)))
    assert names <= set(ds.data_vars)
    lines = {int(ds[n].attrs["closed_graph_line"]) for n in names}
    assert lines == {0, 1, 2, 3, 4}
    assert ds["overlap_interference"].attrs["closed_graph_line"] == 4


def test_feasible_mask_is_all_margins_nonnegative(ds: xr.Dataset) -> None:
    names = list(constraints.constraints(geo.with_shifts(KHV, 0.5, 0.8)))
    expected = np.all(np.stack([ds[n].values >= 0 for n in names]), axis=0)
    assert ds["feasible"].dtype == np.int8
    np.testing.assert_array_equal(ds["feasible"].values.astype(bool), expected)
    # Dropping the cutter-dependent constraints can only enlarge the region.
    assert np.all(ds["feasible_cutter_free"].values >= ds["feasible"].values)


def test_paper_points_and_residuals(ds: xr.Dataset) -> None:
    # Requirement: |x2(0.416) - 0.601| and |x2(0.835) - 0.995| below 0.002.
    assert np.all(np.abs(ds["residual_x2"].values) < 0.002)
    # G_s = 0 gives 0.60095 and 0.99443 (docs/paper1.md, "M and N lie on G_s = 0"; 5 decimals: 5e-6).
    np.testing.assert_allclose(ds["computed_x2"].sel(point=["M", "N"]).values, [0.60095, 0.99443], atol=5e-6)
    np.testing.assert_allclose(ds["paper_x2"].values, [0.601, 0.995], atol=0)


def test_line4_is_gs_zero(ds: xr.Dataset) -> None:
    pair = geo.with_shifts(KHV, ds["x1"].values, ds["x2_line4"].values)
    # brentq to 1e-12 in x2, |dG_s/dx2| < 10: 1e-9 rad.
    np.testing.assert_allclose(interference.overlap_interference(pair), 0.0, atol=1e-9)
    # a' is not constant along line 4 (the paper's "equal meshing angle"): > 1 deg change.
    a_w = ds["working_pressure_angle_line4"].sel(x1=slice(0.4, 0.85)).values
    assert a_w.max() - a_w.min() > 1.0


def test_fitted_cutter_explains_m_and_nearly_n(fitted: xr.Dataset) -> None:
    # Hypothesis documented in docs/geometry.md: a 28-tooth standard-depth cutter (ha0* = 1.25)
    # fitted to trim exactly at M puts the annulus root-interference limit at x1 = 0.8395,
    # 0.0045 beyond the paper's N = 0.835 (not a fit: a prediction, kept as a regression value).
    trim = cg.line4_crossings(fitted, "trimming_interference_annulus")
    root = cg.line4_crossings(fitted, "root_interference_annulus")
    assert trim == pytest.approx([0.416], abs=1e-3)  # linear interpolation on a 0.02 grid
    assert root == pytest.approx([0.8395], abs=2e-3)
    assert fitted.attrs["cutter_shift"] == pytest.approx(-0.1096, abs=1e-4)
    on = fitted["feasible_line4"].values.astype(bool)
    assert fitted["x1"].values[on].min() == pytest.approx(0.42, abs=1e-9)  # first grid point >= 0.416
    assert fitted["x1"].values[on].max() == pytest.approx(0.82, abs=1e-9)  # last grid point <= 0.8395


def test_netcdf_round_trip(ds: xr.Dataset, tmp_path) -> None:  # type: ignore[no-untyped-def]
    pytest.importorskip("netCDF4")
    path = tmp_path / "fig03.nc"
    ds.to_netcdf(path)
    with xr.open_dataset(path) as back:
        xr.testing.assert_identical(back.load(), ds)


def test_external_pair_rejected() -> None:
    with pytest.raises(ValueError, match="internal"):
        cg.closed_graph(geo.GearPair(19, 32, 4.0, 0.0, 0.0, internal=False), X1, X2)


def test_plot_and_caption(fitted: xr.Dataset) -> None:
    fig = plot_closed_graph(fitted)
    labels = [h.get_label() for h in fig.axes[0].get_legend().legend_handles]
    assert "printed M, N" in labels and "line 4: G_s = 0" in labels
    assert fig.axes[0].get_title() == "Closed graph, z1 = 30, z2 = 33, m = 3.5 mm"
    text = caption_closed_graph(fitted, li2013)
    for piece in ("0.60095", "0.99443", "G_s = 0", "line 4", "cutter", "reproduced within 0.0011"):
        assert piece in text
    # a design that names no paper: no printed points, no paper text
    own = cg.closed_graph(KHV, X1, X2)
    assert "point" not in own.dims
    text = caption_closed_graph(own)
    assert "paper" not in text.lower() and "G_s = 0" in text
