"""Two-parameter regime maps: the motion label over a grid of (x, y) control parameters.

A map is like a sweep with two swept parameters and no stored Poincaré sections: each point keeps its
verdict (label, period, exponent and how it was obtained, the stage that decided it, the bifurcation the
followed orbit met) and the mean and spread of its Poincaré X_VH.  Each row (one y value, x increasing) is
a *line* of :func:`geardyn.label.label_lines`: with ``start_from: follow`` (the default) each point starts from
the attractor of its left neighbour; with ``start_from: fixed`` every point starts from the static deflection.
A chunk holds whole rows, so the result does not depend on the chunking.

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

from geardyn import label  # label.label_lines on first use: the workflow's DAG reads MapSpec without the solver
from geardyn.khv import point
from geardyn.khv.design import KHVDesign, resolve_fractions
from geardyn.khv.model import Coefficients
from geardyn.label import Policy
from geardyn.runs.cube import (
    COMPUTED_ATTRS,
    TRANSIENT_USED_ATTRS,
    coexistence_variables,
    label_variables,
    line_responses,
    policy_attrs,
    response_variables,
    store_response,
    store_verdict,
)

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
    start_from: str = "follow"
    coexistence: bool = False

    @classmethod
    def from_config(cls, name: str, spec: Mapping[str, Any], design: str, segment: tuple[float, float]) -> MapSpec:
        """The map ``name`` of ``config["maps"]`` for ``design``, whose admissible segment (x1_min,
        x1_max) resolves percentages of x1 (:func:`geardyn.khv.design.resolve_fractions`)."""
        spec = resolve_fractions(spec, segment)

        def axis(a: Mapping[str, Any]) -> Axis:
            return Axis(a["parameter"], float(a["start"]), float(a["stop"]), int(a["num"]))

        return cls(
            name=name,
            design=design,
            x=axis(spec["x"]),
            y=axis(spec["y"]),
            fixed=tuple(sorted(spec.get("fixed", {}).items())),
            chunks=int(spec.get("chunks", 1)),
            integration=tuple(sorted(spec.get("integration", {}).items())),
            classifier=tuple(sorted(spec.get("classifier", {}).items())),
            start_from=spec.get("start_from", "follow"),
            coexistence=bool(spec.get("coexistence", False)),
        )

    @property
    def n_points(self) -> int:
        return self.x.num * self.y.num

    @property
    def n_chunks(self) -> int:
        return max(1, min(self.chunks, self.y.num))


def chunk_rows(spec: MapSpec, chunk: int) -> np.ndarray:
    """The rows (y indices) of chunk ``chunk``: every n-th row from row ``chunk`` (n chunks), so the chunks
    tile the map by whole rows (lines) and share its costly regions evenly."""
    if not 0 <= chunk < spec.n_chunks:
        raise ValueError(f"chunk {chunk} outside 0..{spec.n_chunks - 1} for map {spec.name}")
    return np.arange(chunk, spec.y.num, spec.n_chunks)


def _direct_ok(design: KHVDesign, par: str) -> bool:
    if par not in _DIRECT:
        return False
    if par == "w":
        opts = dict(design.dynamics).get("options", {})
        return opts.get("frequency_mode", "dimensionless") == "dimensionless"
    return True


def point_coefficients(
    design: KHVDesign, spec: MapSpec, xv: float, yv: float, base: Coefficients | None = None
) -> Coefficients:
    """Coefficients at (xv, yv); ``base`` = coefficients at xv with the fixed values (reused)."""
    if base is not None and _direct_ok(design, spec.y.parameter):
        field = _DIRECT[spec.y.parameter]
        return base.replace(**{field: float(yv)})
    return point.point_coefficients(
        design, {**dict(spec.fixed), spec.x.parameter: float(xv), spec.y.parameter: float(yv)}
    )


def map_policy(design: KHVDesign, spec: MapSpec) -> Policy:
    """The labelling policy of a map: integration, classifier, initial state and coexistence."""
    return Policy.from_spec(
        point.integration_settings(design, **dict(spec.integration)),
        {"classifier": dict(spec.classifier), "start_from": spec.start_from, "coexistence": spec.coexistence},
    )


def empty_map(spec: MapSpec, policy: Policy) -> xr.Dataset:
    dims = ("y", "x")
    shape = (spec.y.num, spec.x.num)
    settings = policy.integration
    data: dict[str, Any] = label_variables(dims, shape, policy.classifier)
    data.update(response_variables(dims, shape))
    if policy.coexistence:
        data.update(coexistence_variables(dims, shape, policy.classifier))
    data["diverged"] = (
        dims,
        np.full(shape, -1, np.int8),
        {
            "long_name": "unbounded growth detected",
            "flag_values": np.array([-1, 0, 1], np.int8),
            "flag_meanings": "not_computed bounded diverged",
        },
    )
    data["x_vh_mean"] = (dims, np.full(shape, np.nan), {"units": "1", "long_name": "mean Poincare X_VH / b_c"})
    data["x_vh_spread"] = (
        dims,
        np.full(shape, np.nan),
        {"units": "1", "long_name": "peak-to-peak of Poincare X_VH / b_c"},
    )
    data["transient_used"] = (dims, np.full(shape, -1, np.int32), TRANSIENT_USED_ATTRS)
    data["computed"] = (dims, np.zeros(shape, np.int8), COMPUTED_ATTRS)
    coords = {}
    for dim, ax in (("x", spec.x), ("y", spec.y)):
        units, long_name = point.CONTROLS.get(ax.parameter, ("1", ax.parameter))
        coords[dim] = (dim, ax.values, {"units": units, "long_name": long_name, "parameter": ax.parameter})
    attrs = {
        "map": spec.name,
        "design": spec.design,
        "x_parameter": spec.x.parameter,
        "y_parameter": spec.y.parameter,
        "fixed_overrides": ",".join(f"{k}={v:g}" for k, v in spec.fixed) or "none",
        "integrator": settings.integrator,
        "steps_per_period": settings.steps_per_period,
        "transient_periods": settings.transient_periods,
        "recorded_periods": settings.recorded_periods,
        "lines": "rows: x increasing at fixed y",
        **policy_attrs(policy),
    }
    return xr.Dataset(data, coords=coords, attrs=attrs)


def _arrays(ds: xr.Dataset) -> dict[str, SimpleNamespace]:
    """The data variables of ``ds`` as objects with a writable numpy ``values`` (the same memory)."""
    return {name: SimpleNamespace(values=ds[name].values) for name in ds.data_vars}


def run_chunk(design: KHVDesign, spec: MapSpec, chunk: int) -> xr.Dataset:
    """Label the rows of one chunk; a partial map (``computed`` marks them)."""
    policy = map_policy(design, spec)
    ds = empty_map(spec, policy)
    xs, ys = spec.x.values, spec.y.values
    rows = chunk_rows(spec, chunk)
    t0 = time.perf_counter()
    direct = _direct_ok(design, spec.y.parameter)
    bases = [
        point.point_coefficients(design, {**dict(spec.fixed), spec.x.parameter: float(x)}) if direct else None
        for x in xs
    ]
    lines = [[point_coefficients(design, spec, xs[i], ys[j], bases[i]) for i in range(spec.x.num)] for j in rows]
    verdicts = label.label_lines(lines, policy, progress=f"{spec.name} chunk {chunk}")
    fixed = label.label_lines(lines, policy.with_start("fixed")) if policy.coexistence else None
    responses = line_responses(lines, verdicts, policy.integration)
    arrays = _arrays(ds)  # numpy views: no xarray lookup per point
    for k, j in enumerate(rows):
        for i, v in enumerate(verdicts[k]):
            store_verdict(arrays, (j, i), v, None if fixed is None else fixed[k][i])
            store_response(arrays, (j, i), responses[k][i])
            arrays["diverged"].values[j, i] = int(v.diverged)
            p = v.poincare[np.all(np.isfinite(v.poincare), axis=1)]
            if p.shape[0]:
                arrays["x_vh_mean"].values[j, i] = float(np.mean(p[:, 1]))
                arrays["x_vh_spread"].values[j, i] = float(np.ptp(p[:, 1]))
            arrays["transient_used"].values[j, i] = v.transient_used
            arrays["computed"].values[j, i] = 1
    el = time.perf_counter() - t0
    n = len(rows) * spec.x.num
    log.info("%s chunk %d: %d points, %.1f s (%.2f ms/point)", spec.name, chunk, n, el, 1e3 * el / max(1, n))
    ds.attrs["wall_time_s"] = el
    return ds
