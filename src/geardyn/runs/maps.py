"""Two-parameter regime maps: the motion label over a grid of (x, y) control parameters.

A map is like a sweep with two swept parameters and no stored Poincaré sections: each point keeps
its label, period, largest Lyapunov exponent (with uncertainty), 0-1 statistic, spectral flatness
and the mean and spread of its Poincaré X_VH.  Points are numbered x-major (all y values of the
first x, then the next x, ...) and split into contiguous chunks; every point is computed from its
own parameters from the static deflection, so the result does not depend on the chunking.

A chunk's points are integrated together (:func:`geardyn.runs.points.analyse_points`, see
docs/performance.md); ``transient_used`` records the transient periods each point needed, and
periodic points get their exponent from the monodromy of their cycle.

Coefficients are built once per x value (:func:`point.point_coefficients`, ~3-7 ms: geometry and
stiffness) and the y parameter is then set directly on the dimensionless coefficients when it is
``b``, ``e`` or ``w`` (b / b_c, e / b_c and w_m / w_n enter them unscaled); any other y parameter
falls back to :func:`point.point_coefficients` per point.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Mapping
from dataclasses import dataclass
from types import SimpleNamespace
from typing import Any

import numpy as np
import xarray as xr

from geardyn import classify
from geardyn.khv import point
from geardyn.khv.design import KHVDesign, resolve_fractions
from geardyn.khv.model import Coefficients
from geardyn.runs.cube import COMPUTED_ATTRS, classifier_attrs, label_variables, store_label
from geardyn.runs.points import TRANSIENT_USED_ATTRS, analyse_points, speed_attrs

log = logging.getLogger("geardyn.maps")

#: y parameters that can be set on the dimensionless coefficients directly (design option permitting).
_DIRECT = {"b": "b", "e": "e", "w": "omega"}


@dataclass(frozen=True)
class Axis:
    parameter: str
    start: float
    stop: float
    num: int

    @property
    def values(self) -> np.ndarray:
        return np.linspace(self.start, self.stop, self.num)


@dataclass(frozen=True)
class MapSpec:
    """One map as declared in ``config.yaml`` under ``maps:``."""

    name: str
    design: str
    x: Axis
    y: Axis
    fixed: tuple[tuple[str, float], ...] = ()
    chunks: int = 1
    integration: tuple[tuple[str, Any], ...] = ()
    classifier: tuple[tuple[str, Any], ...] = ()

    @classmethod
    def from_config(cls, name: str, spec: Mapping[str, Any], design: str,
                    segment: tuple[float, float]) -> MapSpec:
        """The map ``name`` of ``config["maps"]`` for ``design``, whose admissible segment (x1_min,
        x1_max) resolves percentages of x1 (:func:`geardyn.khv.design.resolve_fractions`)."""
        spec = resolve_fractions(spec, segment)

        def axis(a: Mapping[str, Any]) -> Axis:
            return Axis(a["parameter"], float(a["start"]), float(a["stop"]), int(a["num"]))

        return cls(name=name, design=design, x=axis(spec["x"]), y=axis(spec["y"]),
                   fixed=tuple(sorted(spec.get("fixed", {}).items())), chunks=int(spec.get("chunks", 1)),
                   integration=tuple(sorted(spec.get("integration", {}).items())),
                   classifier=tuple(sorted(spec.get("classifier", {}).items())))

    @property
    def n_points(self) -> int:
        return self.x.num * self.y.num

    @property
    def n_chunks(self) -> int:
        return max(1, min(self.chunks, self.n_points))


def chunk_points(spec: MapSpec, chunk: int) -> np.ndarray:
    """Flat point indices (x-major) of chunk ``chunk``; the chunks tile the map."""
    if not 0 <= chunk < spec.n_chunks:
        raise ValueError(f"chunk {chunk} outside 0..{spec.n_chunks - 1} for map {spec.name}")
    return np.array_split(np.arange(spec.n_points), spec.n_chunks)[chunk]


def _direct_ok(design: KHVDesign, par: str) -> bool:
    if par not in _DIRECT:
        return False
    if par == "w":
        opts = dict(design.dynamics).get("options", {})
        return opts.get("frequency_mode", "dimensionless") == "dimensionless"
    return True


def point_coefficients(design: KHVDesign, spec: MapSpec, xv: float, yv: float,
                       base: Coefficients | None = None) -> Coefficients:
    """Coefficients at (xv, yv); ``base`` = coefficients at xv with the fixed values (reused)."""
    if base is not None and _direct_ok(design, spec.y.parameter):
        field = _DIRECT[spec.y.parameter]
        return base.replace(**{field: float(yv)})
    return point.point_coefficients(design, {**dict(spec.fixed), spec.x.parameter: float(xv),
                                           spec.y.parameter: float(yv)})


def empty_map(spec: MapSpec, classifier: classify.ClassifierSettings, settings) -> xr.Dataset:
    dims = ("y", "x")
    shape = (spec.y.num, spec.x.num)
    data: dict[str, Any] = label_variables(dims, shape, classifier)
    data["diverged"] = (dims, np.full(shape, -1, np.int8), {
        "long_name": "unbounded growth detected", "flag_values": np.array([-1, 0, 1], np.int8),
        "flag_meanings": "not_computed bounded diverged"})
    data["x_vh_mean"] = (dims, np.full(shape, np.nan), {"units": "1", "long_name": "mean Poincare X_VH / b_c"})
    data["x_vh_spread"] = (dims, np.full(shape, np.nan), {"units": "1",
                                                           "long_name": "peak-to-peak of Poincare X_VH / b_c"})
    data["transient_used"] = (dims, np.full(shape, -1, np.int32), TRANSIENT_USED_ATTRS)
    data["computed"] = (dims, np.zeros(shape, np.int8), COMPUTED_ATTRS)
    coords = {}
    for dim, ax in (("x", spec.x), ("y", spec.y)):
        units, long_name = point.CONTROLS.get(ax.parameter, ("1", ax.parameter))
        coords[dim] = (dim, ax.values, {"units": units, "long_name": long_name, "parameter": ax.parameter})
    attrs = {"map": spec.name, "design": spec.design, "x_parameter": spec.x.parameter,
             "y_parameter": spec.y.parameter,
             "fixed_overrides": ",".join(f"{k}={v:g}" for k, v in spec.fixed) or "none",
             "integrator": settings.integrator, "steps_per_period": settings.steps_per_period,
             "transient_periods": settings.transient_periods, "recorded_periods": settings.recorded_periods,
             **speed_attrs(settings), **classifier_attrs(classifier)}
    return xr.Dataset(data, coords=coords, attrs=attrs)


def _arrays(ds: xr.Dataset) -> dict[str, SimpleNamespace]:
    """The data variables of ``ds`` as objects with a writable numpy ``values`` (the same memory)."""
    return {name: SimpleNamespace(values=ds[name].values) for name in ds.data_vars}


def run_chunk(design: KHVDesign, spec: MapSpec, chunk: int) -> xr.Dataset:
    """Classify the points of one chunk; a partial map (``computed`` marks them)."""
    settings = point.integration_settings(design, **dict(spec.integration))
    classifier = classify.ClassifierSettings.from_mapping(dict(spec.classifier))
    ds = empty_map(spec, classifier, settings)
    xs, ys = spec.x.values, spec.y.values
    idx = chunk_points(spec, chunk)
    base_cache: dict[int, Coefficients | None] = {}
    t0 = time.perf_counter()
    where, systems = [], []
    for flat in idx:
        i, j = divmod(int(flat), spec.y.num)  # x index, y index
        if i not in base_cache:
            base_cache.clear()
            base_cache[i] = (point.point_coefficients(design, {**dict(spec.fixed), spec.x.parameter: float(xs[i])})
                             if _direct_ok(design, spec.y.parameter) else None)
        where.append((j, i))
        systems.append(point_coefficients(design, spec, xs[i], ys[j], base_cache[i]))
    # the whole chunk at once (simulate_batch: both cores, 8 lanes in lockstep); point by point when
    # settings.batch is False (the previous method)
    arrays = _arrays(ds)  # numpy views: no xarray lookup per point
    for (j, i), (res, lab) in zip(where, analyse_points(systems, settings, classifier, cheap=True), strict=True):
        store_label(arrays, (j, i), lab)
        arrays["diverged"].values[j, i] = int(res.diverged)
        if res.poincare.shape[0]:
            arrays["x_vh_mean"].values[j, i] = float(np.mean(res.poincare[:, 1]))
            arrays["x_vh_spread"].values[j, i] = float(np.ptp(res.poincare[:, 1]))
        arrays["transient_used"].values[j, i] = res.transient_used
        arrays["computed"].values[j, i] = 1
    el = time.perf_counter() - t0
    log.info("%s chunk %d: %d points, %.1f s (%.2f ms/point)", spec.name, chunk, len(idx), el,
             1e3 * el / max(1, len(idx)))
    ds.attrs["wall_time_s"] = time.perf_counter() - t0
    return ds


def fractions(ds: xr.Dataset) -> dict[str, float]:
    """Share of each label over the map."""
    lab = ds["label"].values.ravel()
    codes, n = np.unique(lab, return_counts=True)
    return {classify.short_name(int(c)): float(k) / lab.size for c, k in zip(codes, n, strict=True)}
