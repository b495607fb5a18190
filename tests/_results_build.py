"""A small build of the files a notebook user reads, for two designs (li2013 and li2013_calibrated): a sweep of each,
and of li2013 a regime map over (w, e) with its curves, points, a frequency response, a probabilities study against
w and the closed graph. Snakemake builds only these :data:`TARGETS` (and what their jobs write with them: a sweep's
bands and diagram, the probabilities study's figure and table) in a temporary copy of the workflow; the tests of
:func:`geardyn.open_results`, the ``ds.geardyn`` accessor, ``geardyn show`` and docs/quickstart.ipynb read it."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import _workflow as wf

DESIGNS = ("li2013", "li2013_calibrated")
FAST_MAP = {"steps_per_period": 64, "transient_periods": 200, "recorded_periods": 20}
CLASSIFIER = {"error_floor": 3e-4, "tangent_periods": 30}
#: Regime boundaries of a small map: at most 2 seeds from its pixels, periods up to 2.
CURVES = {"ds_max": 0.05, "max_period": 2, "max_map_seeds": 2, "check_every": 1}


def config() -> dict[str, Any]:
    """The build's config.yaml: every study small (a few seconds each)."""
    cfg = wf.sweep_config(chunks=1, num=8)
    cfg["designs"] = {d: f"config/designs/{d}.yaml" for d in DESIGNS}
    cfg["closed_graph"] = {"x1": {"start": 0.2, "stop": 1.1, "num": 19}, "x2": {"start": 0.3, "stop": 1.4, "num": 23}}
    cfg["sweeps"]["fig07_small"]["designs"] = list(DESIGNS)
    cfg["points"] = {
        "points_small": {
            "designs": ["li2013"],
            "title": "small points",
            "fixed": {"b": 2.0, "e": 5.0},
            "cases": [{"x1": 0.5}, {"x1": 0.761}],
            "samples_per_period": 16,
        }
    }
    cfg["maps"] = {
        "map_small": {
            "designs": ["li2013"],
            "title": "small (w, e) map",
            "x": {"parameter": "w", "start": 0.3, "stop": 1.5, "num": 8},
            "y": {"parameter": "e", "start": 0.5, "stop": 5.5, "num": 6},
            "fixed": {"x1": 0.626, "b": 2.0},
            "chunks": 1,
            "integration": dict(FAST_MAP),
            "classifier": dict(CLASSIFIER),
            "curves": dict(CURVES),
        }
    }
    cfg["responses"] = {
        "response_small": {
            "designs": ["li2013"],
            "title": "small frequency response",
            "start": 0.4,
            "stop": 1.4,
            "num": 6,
            "integration": dict(wf.FAST),
            "classifier": dict(CLASSIFIER),
        }
    }
    cfg["probabilities"] = {
        "prob_small": {
            "designs": ["li2013"],
            "title": "small probabilities against w",
            "axis": {"parameter": "w", "start": 0.4, "stop": 1.4, "num": 4},
            "fixed": {"x1": 0.626, "b": 2.0, "e": 5.0},
            "inputs": {"zeta": {"low": 0.08, "high": 0.12}},
            "samples": 4,
            "sensitivity": {"samples": 8},  # 8 index lines, not the default 128
            "chunks": 1,
            "integration": dict(wf.FAST),
            "classifier": dict(CLASSIFIER),
        }
    }
    return cfg


#: The files the build writes (below results/).
TARGETS = (
    *(f"{d}/sweeps/fig07_small.nc" for d in DESIGNS),
    "li2013/maps/map_small.nc",
    "li2013/maps/map_small_curves.nc",
    "li2013/points/points_small.nc",
    "li2013/response/response_small.nc",
    "li2013/probabilities/prob_small.nc",
    "li2013/data/closed_graph.nc",
)


def build(work: Path) -> None:
    """The build in ``work``: ``snakemake --cores 2`` of :data:`TARGETS`."""
    wf.workflow_copy(work, config())
    wf.snakemake(work, "--cores", "2", *(f"results/{t}" for t in TARGETS), timeout=600)
