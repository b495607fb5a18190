"""Regime boundaries in the workflow: every map's curves file, its figure and table of codimension-2 points, the
curves drawn over the map's figure, and a `curves:` study without a map; the config's keys are checked in one
line each.  A small map and study run for real in a temporary copy (about 30 s on 2 cores)."""

import re

import matplotlib.image as mpimg
import pytest
import xarray as xr

import _workflow as wf
from geardyn import io
from geardyn.config import ConfigError, validate
from geardyn.solve.bifurcations import decode

DESIGN = "li2013_calibrated"
FAST_MAP = {"steps_per_period": 64, "transient_periods": 200, "recorded_periods": 20}


def _config():
    cfg = wf.sweep_config()
    cfg["designs"] = {DESIGN: f"config/designs/{DESIGN}.yaml"}
    cfg["sweeps"] = {}
    cfg["maps"] = {
        "small_map": {
            "designs": [DESIGN],
            "title": "small (x1, b) map",
            "x": {"parameter": "x1", "start": 0.45, "stop": 0.8, "num": 10},
            "y": {"parameter": "b", "start": 0.8, "stop": 2.2, "num": 10},
            "fixed": {"e": 5.0},
            "chunks": 1,  # one job: chunking is test_faults's
            "integration": dict(FAST_MAP),
            "cuts_x": [0.5],
            "cuts_y": [2.0],
            "curves": {"ds_max": 0.05, "max_period": 2, "max_map_seeds": 3, "check_every": 1},
        }
    }
    cfg["curves"] = {
        "small_study": {
            "designs": [DESIGN],
            "title": "small study",
            "x": {"parameter": "b", "start": 0.8, "stop": 2.2},
            "y": {"parameter": "e", "start": 4.0, "stop": 5.5},
            "fixed": {"x1": 0.626},
            "integration": dict(FAST_MAP),
            "lines_y": [5.0],
            "probes": 3,
            "max_period": 2,
            "ds_max": 0.05,
        }
    }
    return cfg


OUTPUTS = [
    f"results/{DESIGN}/maps/small_map_curves.nc",
    f"results/{DESIGN}/figures/small_map_curves.png",
    f"results/{DESIGN}/figures/small_map_curves.png.txt",
    f"results/{DESIGN}/tables/small_map_codim2.md",
    f"results/{DESIGN}/figures/small_map.png",
    f"results/{DESIGN}/curves/small_study.nc",
    f"results/{DESIGN}/figures/small_study_curves.png",
    f"results/{DESIGN}/tables/small_study_codim2.md",
]


def test_dry_run_lists_the_curves_of_every_map_and_study(tmp_path):
    work = wf.workflow_copy(tmp_path / "w", _config())
    run = wf.snakemake(work, "-n", "--cores", "2", timeout=300)
    text = run.stdout + run.stderr
    stats = dict(re.findall(r"^(\w+)\s+(\d+)$", text[text.index("Job stats") :], re.M))
    assert {k: stats.get(k) for k in ("map_curves", "map_curves_figure", "curves_study", "curves_study_figure")} == {
        "map_curves": "1",
        "map_curves_figure": "1",
        "curves_study": "1",
        "curves_study_figure": "1",
    }
    for path in OUTPUTS:
        assert path in text, path
    # the map's figure waits for its curves; with curves off neither the file nor the figure's input exists
    assert re.search(r"rule map_figure:\n\s+input: [^\n]*small_map_curves\.nc", text)
    cfg = _config()
    cfg["maps"]["small_map"]["curves"] = {"enabled": False}
    off = wf.snakemake(wf.workflow_copy(tmp_path / "off", cfg), "-n", "--cores", "2", timeout=300)
    assert "map_curves" not in off.stdout and "small_map_curves" not in off.stdout


@pytest.fixture(scope="module")
def small_run(tmp_path_factory):
    def build(work):
        wf.workflow_copy(work, _config())
        wf.snakemake(work, "--cores", "2", *OUTPUTS, timeout=600)

    return wf.shared(tmp_path_factory, "curves_workflow", build)


def test_the_workflow_writes_the_curves_file_figure_caption_and_table(small_run):
    for path in OUTPUTS:
        assert (small_run / path).stat().st_size > 0, path
    with xr.open_dataset(small_run / OUTPUTS[0]) as ds:
        assert io.missing_cf_attributes(ds) == []
        assert ds.attrs["curve_parameters"] == "x1 b" and ds.attrs["git_commit"]
        assert "neimark_sacker" in [decode(ds["curve_kind"].attrs)[k] for k in ds["curve_kind"].values]
        assert "pixel_check_fraction" in ds.attrs and "time_lines_s" in ds.attrs
    caption = (small_run / OUTPUTS[2]).read_text()
    assert "regime boundaries" in caption and "Pixel check" in caption
    assert (small_run / OUTPUTS[3]).read_text().startswith("# Codimension-2 points: small_map")
    assert "Regime boundaries drawn over" in (small_run / f"results/{DESIGN}/figures/small_map.png.txt").read_text()
    assert mpimg.imread(small_run / OUTPUTS[1]).shape[0] > 500
    with xr.open_dataset(small_run / OUTPUTS[5]) as ds:
        assert io.missing_cf_attributes(ds) == [] and ds.attrs["curve_parameters"] == "b e"


def _set(section, name, *path, **values):
    def change(cfg):
        node = cfg[section][name]
        for key in path:
            node = node[key]
        node.update(values)

    return change


BAD = [
    (
        _set("maps", "small_map", "curves", ds_max=5),
        "maps.small_map.curves.ds_max = 5 is not allowed: number > 0 and <= 0.2",
    ),
    (
        _set("maps", "small_map", "curves", max_period=13),
        "curves.max_period = 13 is not allowed: integer >= 1 and <= 12",
    ),
    (_set("curves", "small_study", probes=0), "curves.small_study.probes = 0 is not allowed: integer >= 1"),
    (_set("curves", "small_study", "y", parameter="b"), "curves.small_study.y.parameter = 'b' is not allowed"),
    (_set("curves", "small_study", "fixed", x1=0.2), "curves.small_study.fixed: x1 = 0.2 is not allowed"),
    (lambda c: c["curves"].update(small_map=c["curves"]["small_study"]), "curves name 'small_map' is not allowed"),
]


@pytest.mark.parametrize(("change", "message"), BAD)
def test_bad_curves_settings_are_one_line(change, message):
    cfg = _config()
    change(cfg)
    with pytest.raises(ConfigError) as err:
        validate.validate_workflow(cfg, wf.ROOT)
    assert message in str(err.value) and "\n" not in str(err.value)


def test_the_shipped_config_computes_the_curves_of_every_map():
    cfg = validate.fill_config(validate.read_config_file(wf.ROOT / "config" / "config.yaml"))
    assert all(spec["curves"]["enabled"] for spec in cfg["maps"].values())
    assert cfg["curves"], "an example curves study"
