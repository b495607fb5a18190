"""Parameter sweeps: bifurcation cubes built in chunks that can run in any order, anywhere.

A sweep varies one control parameter (``x1``, ``b``, ``e``, ``w``, ... see :mod:`geardyn.khv`)
over a range, for one or more *cases* (fixed overrides, e.g. three x1 values for Figs. 9 and 11).
The points are numbered case-major and split into contiguous chunks; every point is computed
from its own parameters only, so a chunk's numbers do not depend on how the sweep was cut.

Every point is labelled by the one labeller, :func:`geardyn.label.label_lines`.  With ``start_from: follow``
(the default) a case in one direction is a *line*: its first point starts from the static deflection and
each next point from the attractor of the previous one (Newton shooting from its orbit, or a run from its
final state), so the figure draws attractors, never transients.  ``continuation`` says the directions: up
(``none`` and ``up``: from the first value to the last), ``down``, or ``both`` (hysteresis).  A chunk holds
whole lines; the lines of a chunk advance on their own, their points batched together.  With ``start_from: fixed``
every point starts from the static deflection (a line of its own) and a chunk holds any points.  Either way
a point's verdict depends only on its line, never on the chunking or the threads.  With ``coexistence``
every point is also labelled from the fixed start, and ``coexisting`` flags where the two end on different
attractors.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import SimpleNamespace
from typing import Any

import numpy as np
import xarray as xr

from geardyn import label  # label.label_lines on first use: the workflow's DAG reads SweepSpec without the solver
from geardyn.khv import point
from geardyn.khv.design import KHVDesign, resolve_fractions
from geardyn.khv.model import COEFFICIENT_ATTRS
from geardyn.label import Policy, Verdict
from geardyn.runs.cube import (
    COMPUTED_ATTRS,
    STATE_NAMES,
    STATES,
    TRANSIENT_USED_ATTRS,
    coexistence_variables,
    label_variables,
    line_responses,
    policy_attrs,
    response_variables,
    store_response,
    store_verdict,
)
from geardyn.solve import SimulationSettings

log = logging.getLogger("geardyn.sweep")


@dataclass(frozen=True)
class SweepSpec:
    """One sweep as declared in ``config.yaml`` under ``sweeps:``."""

    name: str
    design: str
    parameter: str
    start: float
    stop: float
    num: int
    cases: tuple[tuple[tuple[str, float], ...], ...] = ((),)
    fixed: tuple[tuple[str, float], ...] = ()
    chunks: int = 1
    continuation: str = "none"
    integration: tuple[tuple[str, Any], ...] = ()
    classifier: tuple[tuple[str, Any], ...] = ()
    start_from: str = "follow"
    coexistence: bool = False

    @classmethod
    def from_config(cls, name: str, spec: Mapping[str, Any], design: str, segment: tuple[float, float]) -> SweepSpec:
        """The sweep ``name`` of ``config["sweeps"]`` for ``design``, whose admissible segment
        (x1_min, x1_max) resolves percentages of x1 (:func:`geardyn.khv.design.resolve_fractions`)."""
        spec = resolve_fractions(spec, segment)
        cases = tuple(tuple(sorted(c.items())) for c in spec.get("cases") or [{}])
        return cls(
            name=name,
            design=design,
            parameter=spec["parameter"],
            start=float(spec["start"]),
            stop=float(spec["stop"]),
            num=int(spec["num"]),
            cases=cases,
            fixed=tuple(sorted(spec.get("fixed", {}).items())),
            chunks=int(spec.get("chunks", 1)),
            continuation=spec.get("continuation", "none"),
            integration=tuple(sorted(spec.get("integration", {}).items())),
            classifier=tuple(sorted(spec.get("classifier", {}).items())),
            start_from=spec.get("start_from", "follow"),
            coexistence=bool(spec.get("coexistence", False)),
        )

    @property
    def values(self) -> np.ndarray:
        return np.linspace(self.start, self.stop, self.num)

    @property
    def directions(self) -> tuple[str, ...]:
        return ("up", "down") if self.continuation == "both" else (self.continuation,)

    @property
    def n_lines(self) -> int:
        return len(self.cases) * len(self.directions)

    @property
    def n_chunks(self) -> int:
        """Number of chunk jobs: the configured count, at most one per line (``follow``) or per point."""
        units = self.n_lines if self.start_from == "follow" else len(self.cases) * len(self.directions) * self.num
        return max(1, min(self.chunks, units))

    def case_label(self, i: int) -> str:
        return ",".join(f"{k}={v:g}" for k, v in self.cases[i]) or "base"


@dataclass
class ChunkWork:
    """The points one chunk computes: (case index, direction index, parameter indices in order)."""

    items: list[tuple[int, int, list[int]]] = field(default_factory=list)


def chunk_work(spec: SweepSpec, chunk: int) -> ChunkWork:
    """Which points chunk ``chunk`` (0-based) computes; deterministic and covering each point once.  With
    ``start_from: follow`` a chunk holds whole lines (case, direction), each in its direction's order."""
    if not 0 <= chunk < spec.n_chunks:
        raise ValueError(f"chunk {chunk} outside 0..{spec.n_chunks - 1} for sweep {spec.name}")
    nd = len(spec.directions)
    if spec.start_from == "follow":
        work = ChunkWork()
        for line in np.array_split(np.arange(spec.n_lines), spec.n_chunks)[chunk]:
            case, d = divmod(int(line), nd)
            order = list(range(spec.num))
            if spec.directions[d] == "down":
                order.reverse()
            work.items.append((case, d, order))
        return work
    flat = np.arange(len(spec.cases) * nd * spec.num)
    mine = np.array_split(flat, spec.n_chunks)[chunk]
    work = ChunkWork()
    for line in range(len(spec.cases) * nd):
        idx = [int(i) - line * spec.num for i in mine if line * spec.num <= i < (line + 1) * spec.num]
        if idx:
            work.items.append((*divmod(line, nd), idx))
    return work


def point_overrides(spec: SweepSpec, case: int, value: float) -> dict[str, float]:
    """Overrides of one point: fixed values, then the case's, then the swept parameter."""
    return {**dict(spec.fixed), **dict(spec.cases[case]), spec.parameter: float(value)}


def sweep_policy(design: KHVDesign, spec: SweepSpec, settings: SimulationSettings | None = None) -> Policy:
    """The labelling policy of a sweep: the design's integration with the sweep's changes, its classifier
    settings, start and coexistence."""
    settings = settings or point.integration_settings(design, **dict(spec.integration))
    return Policy.from_spec(
        settings, {"classifier": dict(spec.classifier), "start_from": spec.start_from, "coexistence": spec.coexistence}
    )


def run_chunk(design: KHVDesign, spec: SweepSpec, chunk: int, settings: SimulationSettings | None = None) -> xr.Dataset:
    """Label the points of one chunk and return them as a partial cube (see :func:`empty_cube`)."""
    policy = sweep_policy(design, spec, settings)
    work = chunk_work(spec, chunk)
    values = spec.values
    cube = empty_cube(spec, policy)
    t0 = time.perf_counter()
    lines = [
        [point.point_coefficients(design, point_overrides(spec, case, values[j])) for j in order]
        for case, _, order in work.items
    ]
    verdicts = label.label_lines(lines, policy, progress=f"{spec.name} chunk {chunk}")
    fixed = label.label_lines(lines, policy.with_start("fixed")) if policy.coexistence else None
    arrays = {name: SimpleNamespace(values=cube[name].values) for name in cube.data_vars}  # numpy views
    keep = np.zeros((len(spec.cases), len(spec.directions), spec.num), dtype=bool)
    responses = line_responses(lines, verdicts, policy.integration)
    for k, (case, d, order) in enumerate(work.items):
        for m, (j, system, v) in enumerate(zip(order, lines[k], verdicts[k], strict=True)):
            _store(arrays, (case, d, j), system, v, None if fixed is None else fixed[k][m])
            store_response(arrays, (case, d, j), responses[k][m])
            keep[case, d, j] = True
    log.info("%s chunk %d: %d points in %.1f s", spec.name, chunk, int(keep.sum()), time.perf_counter() - t0)
    # keep only this chunk's points along the parameter axis (a chunk may cover several cases)
    cube["computed"] = (("case", "direction", spec.parameter), keep.astype(np.int8), COMPUTED_ATTRS)
    return cube


def empty_cube(spec: SweepSpec, policy: Policy) -> xr.Dataset:
    """A cube of NaN (float) / -1 (int) for every point of the sweep, with CF attributes."""
    settings, classifier = policy.integration, policy.classifier
    nc, nd, npar, ns = len(spec.cases), len(spec.directions), spec.num, settings.recorded_periods
    shape = (nc, nd, npar, ns)
    dims = ("case", "direction", spec.parameter, "section")
    data: dict[str, Any] = {}
    for name in STATES:
        data[name] = (
            dims,
            np.full(shape, np.nan),
            {"units": "1", "long_name": f"Poincare section: {STATE_NAMES[name]}"},
        )
    pdims = dims[:3]
    data["diverged"] = (
        pdims,
        np.full(shape[:3], -1, np.int8),
        {
            "long_name": "unbounded growth detected (parametric instability)",
            "flag_values": np.array([-1, 0, 1], np.int8),
            "flag_meanings": "not_computed bounded diverged",
        },
    )
    data["diverged_period"] = (
        pdims,
        np.full(shape[:3], -1, np.int32),
        {"units": "1", "long_name": "mesh period at which the state exceeded the threshold (-1: never)"},
    )
    data["n_events"] = (
        pdims,
        np.full(shape[:3], -1, np.int64),
        {"units": "1", "long_name": "number of contact-switch events located (rk4_event)"},
    )
    data["transient_used"] = (pdims, np.full(shape[:3], -1, np.int32), TRANSIENT_USED_ATTRS)
    data.update(label_variables(pdims, shape[:3], classifier))
    data.update(response_variables(pdims, shape[:3]))
    if policy.coexistence:
        data.update(coexistence_variables(pdims, shape[:3], classifier))
    for cname, (units, long_name) in COEFFICIENT_ATTRS.items():
        data[f"coef_{cname}"] = (pdims, np.full(shape[:3], np.nan), {"units": units, "long_name": long_name})
    coords = {
        "case": ("case", [spec.case_label(i) for i in range(nc)], {"long_name": "case (fixed overrides)"}),
        "direction": ("direction", list(spec.directions), {"long_name": "continuation direction of the sweep"}),
        spec.parameter: (
            spec.parameter,
            spec.values,
            {
                "units": point.CONTROLS.get(spec.parameter, ("1", spec.parameter))[0],
                "long_name": point.CONTROLS.get(spec.parameter, ("1", spec.parameter))[1],
            },
        ),
        "section": (
            "section",
            np.arange(ns, dtype=np.int32),
            {"units": "1", "long_name": "index of the recorded mesh period (Poincare section at phase 0)"},
        ),
    }
    attrs = {
        "sweep": spec.name,
        "design": spec.design,
        "control_parameter": spec.parameter,
        "integrator": settings.integrator,
        "steps_per_period": settings.steps_per_period,
        "transient_periods": settings.transient_periods,
        "recorded_periods": settings.recorded_periods,
        "divergence_threshold": settings.divergence_threshold,
        "continuation": spec.continuation,
        **policy_attrs(policy),
        "fixed_overrides": ",".join(f"{k}={v:g}" for k, v in spec.fixed) or "none",
    }
    return xr.Dataset(data, coords=coords, attrs=attrs)


def _store(cube: Any, idx: tuple[int, int, int], coeffs: Any, v: Verdict, fixed: Verdict | None) -> None:
    case, d, j = idx
    n = v.poincare.shape[0]
    for k, name in enumerate(STATES):
        cube[name].values[case, d, j, :n] = v.poincare[:, k]
    cube["diverged"].values[idx] = 1 if v.diverged else 0
    cube["diverged_period"].values[idx] = v.diverged_period
    cube["n_events"].values[idx] = v.n_events
    cube["transient_used"].values[idx] = v.transient_used
    store_verdict(cube, idx, v, fixed)
    values = coeffs.as_dict()
    for cname in COEFFICIENT_ATTRS:
        cube[f"coef_{cname}"].values[idx] = float(values[cname])
