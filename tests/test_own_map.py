"""An own design shows its regimes: the default map of a design of your own (config.yaml's map_own_w_e: the mesh
frequency w against the TE amplitude e at mid-segment) holds more than one motion label for the README's example
design, and a figure that holds one regime, or a curves figure with no curve, says so on its face."""

import numpy as np
import pytest
import xarray as xr

import _workflow as wf
from geardyn import cli
from geardyn.config import validate
from geardyn.khv import design
from geardyn.label.vocabulary import short_name
from geardyn.plots.curves import plot_curves
from geardyn.plots.dynamics import plot_map
from geardyn.runs import maps

#: The resolution of the test's map: the shipped 100 x 100 takes minutes; 12 x 6 points of the same plane.
REDUCED = {"x": 12, "y": 6}


@pytest.fixture(scope="module")
def own_map(tmp_path_factory):
    """The README's example design (new-design --z1 40 --z2 43 --module 2) and its default map at reduced
    resolution, from the shipped config entry with its preset resolved as the workflow resolves it."""
    work = wf.workflow_copy(tmp_path_factory.mktemp("own_map"))
    path = work / "config/designs/mydrive.yaml"
    assert cli.main(["new-design", "--kind", "khv", "mydrive", "--out", str(path), "--z1", "40", "--z2", "43"]) == 0
    shipped = wf.shipped("config/config.yaml")
    own = {n: s for n, s in shipped["maps"].items() if s.get("designs") == "own"}
    assert list(own) == ["map_own_w_e"]
    cfg = {"designs": {"mydrive": "config/designs/mydrive.yaml"}, "presets": shipped["presets"], "maps": own}
    filled, _ = validate.validate_workflow(cfg, work)
    spec = filled["maps"]["map_own_w_e"]
    for axis, num in REDUCED.items():
        spec[axis]["num"] = num
    drive = design.load(path)
    return maps.run_chunk(
        drive, maps.MapSpec.from_config("map_own_w_e", {**spec, "chunks": 1}, "mydrive", drive.segment), 0
    )


def test_the_default_map_of_an_own_design_spans_w_against_e_and_holds_several_regimes(own_map):
    assert (own_map.attrs["x_parameter"], own_map.attrs["y_parameter"]) == ("w", "e")
    labels = {short_name(c) for c in np.unique(own_map["label"].values)}
    assert len(labels) > 1, labels
    assert labels & {"QP", "chaos", "P2", "P3", "P4", "P5", "Plong"}  # beyond P1


def _texts(fig):
    return [t.get_text() for ax in fig.axes for t in ax.texts]


def test_a_map_of_one_regime_says_so_on_its_face(own_map):
    one = own_map.copy()
    one["label"] = xr.full_like(own_map["label"], 1)
    assert "P1 everywhere in this plane" in _texts(plot_map(one, "one regime"))
    assert not [t for t in _texts(plot_map(own_map, "several")) if "everywhere" in t]


def test_a_curves_figure_without_a_curve_says_so_on_its_face():
    ds = xr.Dataset(
        {
            "curve_kind": (
                "curve",
                np.array([], np.int8),
                {"flag_values": np.array([1], np.int8), "flag_meanings": "fold"},
            ),
            "w": ("point", np.array([])),
            "e": ("point", np.array([])),
        },
        attrs={"curve_parameters": "w e"},
    )
    assert "no regime boundary in this plane" in _texts(plot_curves(ds, "no curve"))
