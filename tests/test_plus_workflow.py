"""The paper-2 adapter scripts run without Snakemake and write self-describing files."""

from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.image as mpimg
import pandas as pd
import pytest
import xarray as xr
import yaml

import _workflow
from geardyn import io
from geardyn.io import provenance
from geardyn.plus import tables
from geardyn.plus.design import default_design

ROOT = Path(__file__).resolve().parents[1]


def _script(name, **job):
    _workflow.run_script(ROOT / "workflow" / "scripts" / f"{name}.py", _workflow.Job(**job))


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("yue2014")
    raw = yaml.safe_load((ROOT / "config" / "designs" / "yue2014.yaml").read_text())
    raw["relief"].update(landscape_points=7, maxiter=20, popsize=8, load_study_torques_Nm=[43.0, 1000.0])  # small
    raw["transmission_error"]["points_per_period"] = 100
    design = tmp / "design.yaml"
    design.write_text(yaml.safe_dump(raw))
    p = {
        k: tmp / v
        for k, v in dict(
            modal="modal.nc",
            t2c="t2.csv",
            t2m="t2.md",
            scc="sc.csv",
            scm="sc.md",
            t5c="t5.csv",
            t5m="t5.md",
            f6="f6.png",
            f7="f7.png",
            f7b="f7b.png",
            te="te.nc",
            oc="opt.csv",
            om="opt.md",
            sc2="st.csv",
            sm2="st.md",
            lc="load.csv",
            lm="load.md",
            land="land.nc",
            f4="f4.png",
            f9="f9.png",
            f9b="f9b.png",
            fr="forced.nc",
            frf="forced.png",
        ).items()
    }
    _script(
        "plus_modal",
        input={"design": design},
        log=[tmp / "m.log"],
        output=dict(
            modal=p["modal"],
            table02_csv=p["t2c"],
            table02_md=p["t2m"],
            scaling_csv=p["scc"],
            scaling_md=p["scm"],
            table05_csv=p["t5c"],
            table05_md=p["t5m"],
        ),
    )
    _script(
        "plus_modal_figures",
        input={"design": design, "modal": p["modal"]},
        log=[tmp / "mf.log"],
        output=dict(fig06=p["f6"], fig07=p["f7"], fig07b=p["f7b"]),
    )
    _script(
        "plus_relief",
        input={"design": design},
        log=[tmp / "r.log"],
        output=dict(
            te=p["te"],
            optima_csv=p["oc"],
            optima_md=p["om"],
            stiffness_csv=p["sc2"],
            stiffness_md=p["sm2"],
            load_csv=p["lc"],
            load_md=p["lm"],
        ),
    )
    _script("plus_landscape", input={"design": design}, output={"landscape": p["land"]}, log=[tmp / "l.log"])
    _script(
        "plus_te_figures",
        input={"design": design, "te": p["te"], "landscape": p["land"], "optima_csv": p["oc"]},
        output=dict(fig04=p["f4"], fig09=p["f9"], fig09b=p["f9b"]),
        log=[tmp / "tf.log"],
    )
    _script(
        "plus_forced_response",
        input={"design": design, "te": p["te"]},
        log=[tmp / "fr.log"],
        output=dict(data=p["fr"], figure=p["frf"]),
    )
    return p


def test_every_output_holds_what_it_should(run):

    for key, path in run.items():
        if path.suffix == ".png":
            height, width = mpimg.imread(path).shape[:2]
            assert height > 200 and width > 200, key
            caption = Path(str(path) + ".txt").read_text()
            assert "Yue et al. (2014)" in caption, key  # a design that names paper 2 is compared with it
        elif path.suffix == ".csv":
            assert len(pd.read_csv(path)) >= 1, key
        elif path.suffix == ".md":
            assert path.read_text().startswith("#") and "|---" in path.read_text(), key
        elif path.suffix == ".nc":
            with xr.open_dataset(path) as ds:
                assert ds.sizes and all(ds[v].size for v in ds.data_vars), key


@pytest.mark.parametrize("key", ["modal", "te", "land", "fr"])
def test_netcdf_self_describing(run, key):
    with xr.open_dataset(run[key]) as ds:
        for name, var in {**ds.data_vars, **ds.coords}.items():
            assert "units" in var.attrs and "long_name" in var.attrs, name
        for attr in ("source", "history", "config_hash", "model_variant"):
            assert ds.attrs.get(attr), attr


def test_netcdf_round_trip(tmp_path):
    ds = tables.modal_dataset(default_design())
    path = tmp_path / "modal.nc"
    io.write_netcdf(ds, path, {"source": "test"})
    with xr.open_dataset(path) as back:
        expected = ds.copy()
        expected.attrs.update({"source": "test", **provenance.runtime()})  # every file says where it was made
        xr.testing.assert_identical(back.load(), expected)


def test_table2_csv_matches_library(run):
    t = pd.read_csv(run["t2c"])
    assert len(t) == 18
    assert list(t.paper_theoretical_hz[:6]) == [1295, 4519, 6456, 6559, 8293, 9316]  # Table 2, condition I
    pd.testing.assert_series_equal(t.freq_hz, tables.frequency_table(default_design(), None).freq_hz, rtol=1e-5)


def test_forced_response_file_holds_each_relief_case_and_the_resonances(run):
    with xr.open_dataset(run["fr"]) as ds, xr.open_dataset(run["te"]) as te:
        assert list(ds.case.values) == list(te.case.values)
        assert ds.attrs["best_relief_case"] != "unmodified"
        # the speed range holds h = 1 meeting the highest natural frequency
        assert float(ds.speed.max()) > float(ds.resonance_speed.sel(harmonic=1).max())
        assert float(ds.dynamic_factor.min()) >= 1.0
