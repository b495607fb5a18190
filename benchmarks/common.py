"""What several benchmarks share: the timer, the workflow config and designs, a map's rows as lines."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from geardyn.config import validate
from geardyn.khv import design as design_mod
from geardyn.khv import point
from geardyn.label import label_lines
from geardyn.runs import maps

#: paper 1's bifurcation sweeps (Figs. 7, 9, 11)
PAPER1_SWEEPS = ("fig07_bifurcation_x1", "fig09_bifurcation_b", "fig11_bifurcation_e")


def timed(fn, repeats: int):
    """(best wall time of ``repeats`` calls of ``fn``, its last result)."""
    best, out = np.inf, None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def workflow_config(path: Path) -> dict:
    """The validated workflow config at ``path`` (``config/config.yaml`` of a checkout)."""
    filled, _ = validate.validate_workflow(validate.read_config_file(path), path.resolve().parent.parent)
    return filled


def load_design(name: str, config: dict, root: Path):
    """The design ``name`` of the workflow config."""
    return design_mod.load(root / config["designs"][name])


def map_study(config_path: Path, map_name: str):
    """(design name, design, map spec, labelling policy) of a map of the workflow config at ``config_path``
    (its first design)."""
    config = workflow_config(config_path)
    raw = dict(config["maps"][map_name])
    dname = raw["designs"][0]
    design = load_design(dname, config, config_path.resolve().parent.parent)
    spec = maps.MapSpec.from_config(map_name, raw, dname, design.segment)
    return dname, design, spec, spec.policy(design)


def map_lines(design, spec, rows=None):
    """The rows of a map (or ``rows`` of them) as lines of systems, as maps.layout builds them."""
    xs, ys = spec.x.values, spec.y.values
    bases = [point.point_coefficients(design, {**dict(spec.fixed), spec.x.parameter: float(x)}) for x in xs]
    rows = range(len(ys)) if rows is None else rows
    return [[maps.point_coefficients(design, spec, xs[i], ys[j], bases[i]) for i in range(len(xs))] for j in rows]


def timed_labels(lines, policy):
    """The labeller on ``lines`` with its wall and CPU time."""
    t0, c0 = time.perf_counter(), time.process_time()
    out = label_lines(lines, policy)
    return out, time.perf_counter() - t0, time.process_time() - c0
