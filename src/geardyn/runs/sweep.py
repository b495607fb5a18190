"""Parameter sweeps: bifurcation cubes built in chunks that can run in any order, anywhere.

A sweep varies one control parameter (``x1``, ``b``, ``e``, ``w``, ... see :mod:`geardyn.khv`)
over a range, for one or more *cases* (fixed overrides, e.g. three x1 values for Figs. 9 and 11).
The points are numbered case-major and split into contiguous chunks; every point is computed
from its own parameters only, so a chunk's numbers do not depend on how the sweep was cut.

The points of a chunk are integrated together (:func:`geardyn.runs.points.analyse_points`: lanes in
lockstep on all cores, early stop of the transient, Floquet exponent for periodic points; each
point's numbers are independent of the others, docs/performance.md); ``transient_used`` records
the transient periods each point needed.

With ``continuation`` each point starts from the previous point's final state (up and/or down
the sweep), which shows hysteresis and coexisting attractors. That makes the points of one
(case, direction) sequential, so a continued sweep is chunked by (case, direction) only.
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

from geardyn import classify
from geardyn.khv.model import COEFFICIENT_ATTRS
from geardyn.runs.cube import COMPUTED_ATTRS, STATE_NAMES, STATES, classifier_attrs, label_variables, store_label
from geardyn.runs.points import TRANSIENT_USED_ATTRS, analyse_points, speed_attrs
from geardyn.khv import point
from geardyn.khv.design import KHVDesign, resolve_fractions
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

    @classmethod
    def from_config(cls, name: str, spec: Mapping[str, Any], design: str,
                    segment: tuple[float, float]) -> SweepSpec:
        """The sweep ``name`` of ``config["sweeps"]`` for ``design``, whose admissible segment
        (x1_min, x1_max) resolves percentages of x1 (:func:`geardyn.khv.design.resolve_fractions`)."""
        spec = resolve_fractions(spec, segment)
        cases = tuple(tuple(sorted(c.items())) for c in spec.get("cases") or [{}])
        return cls(
            name=name, design=design, parameter=spec["parameter"],
            start=float(spec["start"]), stop=float(spec["stop"]), num=int(spec["num"]),
            cases=cases, fixed=tuple(sorted(spec.get("fixed", {}).items())),
            chunks=int(spec.get("chunks", 1)), continuation=spec.get("continuation", "none"),
            integration=tuple(sorted(spec.get("integration", {}).items())),
            classifier=tuple(sorted(spec.get("classifier", {}).items())),
        )

    @property
    def values(self) -> np.ndarray:
        return np.linspace(self.start, self.stop, self.num)

    @property
    def directions(self) -> tuple[str, ...]:
        return ("up", "down") if self.continuation == "both" else (self.continuation,)

    @property
    def n_chunks(self) -> int:
        """Number of chunk jobs: the configured count, or one per (case, direction) when continued."""
        if self.continuation != "none":
            return len(self.cases) * len(self.directions)
        return max(1, min(self.chunks, len(self.cases) * self.num))

    def case_label(self, i: int) -> str:
        return ",".join(f"{k}={v:g}" for k, v in self.cases[i]) or "base"


@dataclass
class ChunkWork:
    """The points one chunk computes: (case index, direction index, parameter indices in order)."""

    items: list[tuple[int, int, list[int]]] = field(default_factory=list)


def chunk_work(spec: SweepSpec, chunk: int) -> ChunkWork:
    """Which points chunk ``chunk`` (0-based) computes; deterministic and covering each point once."""
    if not 0 <= chunk < spec.n_chunks:
        raise ValueError(f"chunk {chunk} outside 0..{spec.n_chunks - 1} for sweep {spec.name}")
    if spec.continuation != "none":
        case, d = divmod(chunk, len(spec.directions))
        order = list(range(spec.num))
        if spec.directions[d] == "down":
            order.reverse()
        return ChunkWork([(case, d, order)])
    flat = np.arange(len(spec.cases) * spec.num)
    mine = np.array_split(flat, spec.n_chunks)[chunk]
    work = ChunkWork()
    for case in range(len(spec.cases)):
        idx = [int(i) - case * spec.num for i in mine if case * spec.num <= i < (case + 1) * spec.num]
        if idx:
            work.items.append((case, 0, idx))
    return work


def point_overrides(spec: SweepSpec, case: int, value: float) -> dict[str, float]:
    """Overrides of one point: fixed values, then the case's, then the swept parameter."""
    return {**dict(spec.fixed), **dict(spec.cases[case]), spec.parameter: float(value)}


def run_chunk(design: KHVDesign, spec: SweepSpec, chunk: int,
              settings: SimulationSettings | None = None) -> xr.Dataset:
    """Integrate the points of one chunk and return them as a partial cube (see :func:`empty_cube`)."""
    settings = settings or point.integration_settings(design, **dict(spec.integration))
    classifier = classify.ClassifierSettings.from_mapping(dict(spec.classifier))
    work = chunk_work(spec, chunk)
    values = spec.values
    cube = empty_cube(spec, settings, classifier)
    done = 0
    total = sum(len(idx) for _, _, idx in work.items)
    t0 = time.perf_counter()
    keep = np.zeros((len(spec.cases), len(spec.directions), spec.num), dtype=bool)
    if spec.continuation == "none":
        # independent points: the whole chunk at once (simulate_batch: both cores, 8 lanes in lockstep)
        where = [(case, d, j) for case, d, indices in work.items for j in indices]
        systems = [point.point_coefficients(design, point_overrides(spec, case, values[j])) for case, d, j in where]
        arrays = {name: SimpleNamespace(values=cube[name].values) for name in cube.data_vars}  # numpy views
        # in ten slices, for the progress log (every lane's result is independent of its batch)
        for part in np.array_split(np.arange(len(where)), min(10, max(1, len(where)))):
            batch = [systems[k] for k in part]
            for k, (res, lab) in zip(part, analyse_points(batch, settings, classifier), strict=True):
                case, d, j = where[k]
                _store(arrays, case, d, j, systems[k], res, settings)
                store_label(arrays, (case, d, j), lab)
                keep[case, d, j] = True
            done += len(part)
            elapsed = time.perf_counter() - t0
            log.info("%s chunk %d: %d/%d points, %.1f s elapsed, %.1f s remaining", spec.name, chunk, done, total,
                     elapsed, elapsed / done * (total - done))
        work = ChunkWork()
    for case, d, indices in work.items:
        state = None
        for j in indices:
            coeffs = point.point_coefficients(design, point_overrides(spec, case, values[j]))
            x0 = state if (spec.continuation != "none" and state is not None) else None
            res, lab = analyse_points([coeffs], settings, classifier, x0=[x0])[0]
            _store(cube, case, d, j, coeffs, res, settings)
            store_label(cube, (case, d, j), lab)
            keep[case, d, j] = True
            state = None if res.diverged else res.final_state
            done += 1
            if done % max(1, total // 10) == 0 or done == total:
                elapsed = time.perf_counter() - t0
                log.info("%s chunk %d: %d/%d points, %.1f s elapsed, %.1f s remaining", spec.name, chunk,
                         done, total, elapsed, elapsed / done * (total - done))
    # keep only this chunk's points along the parameter axis (a chunk may cover several cases)
    cube["computed"] = (("case", "direction", spec.parameter), keep.astype(np.int8), COMPUTED_ATTRS)
    return cube


def empty_cube(spec: SweepSpec, settings: SimulationSettings,
               classifier: classify.ClassifierSettings | None = None) -> xr.Dataset:
    """A cube of NaN (float) / -1 (int) for every point of the sweep, with CF attributes."""
    classifier = classifier or classify.ClassifierSettings()
    nc, nd, npar, ns = len(spec.cases), len(spec.directions), spec.num, settings.recorded_periods
    shape = (nc, nd, npar, ns)
    dims = ("case", "direction", spec.parameter, "section")
    data: dict[str, Any] = {}
    for name in STATES:
        data[name] = (dims, np.full(shape, np.nan), {"units": "1", "long_name": f"Poincare section: {STATE_NAMES[name]}"})
    pdims = dims[:3]
    data["diverged"] = (pdims, np.full(shape[:3], -1, np.int8), {
        "long_name": "unbounded growth detected (parametric instability)",
        "flag_values": np.array([-1, 0, 1], np.int8), "flag_meanings": "not_computed bounded diverged"})
    data["diverged_period"] = (pdims, np.full(shape[:3], -1, np.int32), {
        "units": "1", "long_name": "mesh period at which the state exceeded the threshold (-1: never)"})
    data["n_events"] = (pdims, np.full(shape[:3], -1, np.int64), {
        "units": "1", "long_name": "number of contact-switch events located (rk4_event)"})
    data["transient_used"] = (pdims, np.full(shape[:3], -1, np.int32), TRANSIENT_USED_ATTRS)
    data.update(label_variables(pdims, shape[:3], classifier))
    for cname, (units, long_name) in COEFFICIENT_ATTRS.items():
        data[f"coef_{cname}"] = (pdims, np.full(shape[:3], np.nan), {"units": units, "long_name": long_name})
    coords = {
        "case": ("case", [spec.case_label(i) for i in range(nc)], {"long_name": "case (fixed overrides)"}),
        "direction": ("direction", list(spec.directions), {"long_name": "continuation direction of the sweep"}),
        spec.parameter: (spec.parameter, spec.values, {
            "units": point.CONTROLS.get(spec.parameter, ("1", spec.parameter))[0],
            "long_name": point.CONTROLS.get(spec.parameter, ("1", spec.parameter))[1]}),
        "section": ("section", np.arange(ns, dtype=np.int32), {
            "units": "1", "long_name": "index of the recorded mesh period (Poincare section at phase 0)"}),
    }
    attrs = {
        "sweep": spec.name, "design": spec.design, "control_parameter": spec.parameter,
        "integrator": settings.integrator, "steps_per_period": settings.steps_per_period,
        "transient_periods": settings.transient_periods, "recorded_periods": settings.recorded_periods,
        "divergence_threshold": settings.divergence_threshold, "continuation": spec.continuation,
        **speed_attrs(settings),
        "fixed_overrides": ",".join(f"{k}={v:g}" for k, v in spec.fixed) or "none",
        **classifier_attrs(classifier),
    }
    return xr.Dataset(data, coords=coords, attrs=attrs)


def _store(cube: xr.Dataset, case: int, d: int, j: int, coeffs: Any, res: Any, settings: SimulationSettings) -> None:
    n = res.poincare.shape[0]
    for k, name in enumerate(STATES):
        cube[name].values[case, d, j, :n] = res.poincare[:, k]
    cube["diverged"].values[case, d, j] = 1 if res.diverged else 0
    cube["diverged_period"].values[case, d, j] = res.diverged_period
    cube["n_events"].values[case, d, j] = res.n_events
    cube["transient_used"].values[case, d, j] = res.transient_used
    values = coeffs.as_dict()
    for cname in COEFFICIENT_ATTRS:
        cube[f"coef_{cname}"].values[case, d, j] = float(values[cname])


