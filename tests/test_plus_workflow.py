"""The paper-2 adapter scripts run without Snakemake and write self-describing files."""

import importlib.util
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import pandas as pd
import pytest
import xarray as xr
import yaml

from geardyn.plus import files, tables
from geardyn.plus.design import default_design

ROOT = Path(__file__).resolve().parents[1]


def _script(name):
    spec = importlib.util.spec_from_file_location(name, ROOT / "workflow" / "scripts" / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("yue2014")
    raw = yaml.safe_load((ROOT / "config" / "designs" / "yue2014.yaml").read_text())
    raw["relief"].update(landscape_points=7, maxiter=20, popsize=8)  # small and fast
    raw["transmission_error"]["points_per_period"] = 100
    design = tmp / "design.yaml"
    design.write_text(yaml.safe_dump(raw))
    p = {k: tmp / v for k, v in dict(
        modal="modal.nc", t2c="t2.csv", t2m="t2.md", scc="sc.csv", scm="sc.md", t5c="t5.csv", t5m="t5.md",
        f6="f6.png", f7="f7.png", f7b="f7b.png", te="te.nc", oc="opt.csv", om="opt.md", sc2="st.csv", sm2="st.md", lc="load.csv", lm="load.md", land="land.nc",
        f4="f4.png", f9="f9.png", f9b="f9b.png").items()}
    _script("yue2014_modal").main(design, p["modal"], p["t2c"], p["t2m"], p["scc"], p["scm"], p["t5c"], p["t5m"], tmp / "m.log")
    _script("yue2014_modal_figures").main(p["modal"], p["f6"], p["f7"], p["f7b"], tmp / "mf.log")
    _script("yue2014_relief").main(design, p["te"], p["oc"], p["om"], p["sc2"], p["sm2"], p["lc"], p["lm"], tmp / "r.log",
                                    torques=(43.0, 1000.0))
    _script("yue2014_landscape").main(design, p["land"], tmp / "l.log")
    _script("yue2014_te_figures").main(design, p["te"], p["land"], p["oc"], p["f4"], p["f9"], p["f9b"], tmp / "tf.log")
    return p


def test_all_outputs_written(run):
    for key, path in run.items():
        assert path.exists() and path.stat().st_size > 0, key
        if path.suffix == ".png":
            caption = Path(str(path) + ".txt").read_text()
            assert len(caption) > 200 and "paper" in caption


@pytest.mark.parametrize("key", ["modal", "te", "land"])
def test_netcdf_self_describing(run, key):
    with xr.open_dataset(run[key]) as ds:
        for name, var in {**ds.data_vars, **ds.coords}.items():
            assert "units" in var.attrs and "long_name" in var.attrs, name
        for attr in ("source", "history", "config_hash", "model_variant"):
            assert ds.attrs.get(attr), attr


def test_netcdf_round_trip(tmp_path):
    ds = tables.modal_dataset(default_design())
    path = tmp_path / "modal.nc"
    files.write_netcdf(ds, path, {"source": "test"})
    with xr.open_dataset(path) as back:
        expected = ds.copy()
        expected.attrs["source"] = "test"
        xr.testing.assert_identical(back.load(), expected)


def test_table2_csv_matches_library(run):
    t = pd.read_csv(run["t2c"])
    assert len(t) == 18
    assert list(t.paper_theoretical_hz[:6]) == [1295, 4519, 6456, 6559, 8293, 9316]  # Table 2, condition I
    pd.testing.assert_series_equal(t.freq_hz, tables.frequency_table(default_design()).freq_hz, rtol=1e-5)
