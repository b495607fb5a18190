"""Two-parameter regime maps: the motion label over an (x, y) grid of control parameters, each row (x increasing)
a line of the labeller, a chunk whole rows; the points keep their verdicts and the mean and spread of their
Poincaré X_VH, no sections."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import xarray as xr

from geardyn.io import Var
from geardyn.jsontypes import Json
from geardyn.khv import point
from geardyn.khv.design import KHVDesign
from geardyn.khv.model import Coefficients
from geardyn.label import Verdict
from geardyn.runs import study
from geardyn.runs.cube import empty
from geardyn.solve import System


@dataclass(frozen=True)
class Axis(study.Grid):
    parameter: str
    start: float
    stop: float
    num: int


@dataclass(frozen=True)
class MapSpec(study.StudySpec):
    """One map as declared in ``config.yaml`` under ``maps:`` (the shared fields: :class:`StudySpec`)."""

    x: Axis
    y: Axis

    @classmethod
    def own_fields(cls, spec: Mapping[str, Json]) -> dict[str, Json]:
        return {
            a: Axis(spec[a]["parameter"], float(spec[a]["start"]), float(spec[a]["stop"]), int(spec[a]["num"]))
            for a in ("x", "y")
        }

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
    """Whether ``par`` is set on the coefficients directly: b and e, and w where the design's mesh frequency is
    dimensionless."""
    opts = dict(design.dynamics).get("options", {})
    return par in point.COEFFICIENT_FIELDS and (
        par != "w" or opts.get("frequency_mode", "dimensionless") == "dimensionless"
    )


def point_coefficients(
    design: KHVDesign, spec: MapSpec, xv: float, yv: float, base: Coefficients | None = None
) -> Coefficients:
    """Coefficients at (xv, yv); ``base`` = coefficients at xv with the fixed values (reused)."""
    if base is not None and _direct_ok(design, spec.y.parameter):
        return base.replace(**{point.COEFFICIENT_FIELDS[spec.y.parameter]: float(yv)})
    return point.point_coefficients(
        design, {**dict(spec.fixed), spec.x.parameter: float(xv), spec.y.parameter: float(yv)}
    )


def layout(design: KHVDesign, spec: MapSpec, chunk: int) -> study.Layout:
    """The rows of chunk ``chunk`` on the (y, x) grid, x increasing, and the map's own per-point variables:
    the mean and spread of the Poincare X_VH.  The coefficients are built as the runner takes the lines."""
    dims, shape = ("y", "x"), (spec.y.num, spec.x.num)
    own = empty(("x_vh_mean", "x_vh_spread"), dims, shape)
    xs, ys = spec.x.values, spec.y.values

    def lines():
        direct = _direct_ok(design, spec.y.parameter)
        bases = [
            point.point_coefficients(design, {**dict(spec.fixed), spec.x.parameter: float(x)}) if direct else None
            for x in xs
        ]
        for j in chunk_rows(spec, chunk):
            yield [((j, i), point_coefficients(design, spec, xs[i], ys[j], bases[i])) for i in range(spec.x.num)]

    return study.Layout(dims, shape, lines(), computed=True, own=own, store_own=_store)


def _store(arrays: dict[str, np.ndarray], idx: study.Index, system: System, v: Verdict) -> None:
    p = v.poincare[np.all(np.isfinite(v.poincare), axis=1)]
    if p.shape[0]:
        arrays["x_vh_mean"][idx] = float(np.mean(p[:, 1]))
        arrays["x_vh_spread"][idx] = float(np.ptp(p[:, 1]))


def run_chunk(design: KHVDesign, spec: MapSpec, chunk: int) -> xr.Dataset:
    """Label the rows of one chunk: a map of every point, ``computed`` 1 on the chunk's rows, with CF
    attributes and the chunk's wall time."""
    policy = spec.policy(design)
    result = study.run(layout(design, spec, chunk), policy, f"{spec.name} chunk {chunk}")
    coords = {}
    for dim, ax in (("x", spec.x), ("y", spec.y)):
        units, long_name = point.CONTROLS.get(ax.parameter, ("1", ax.parameter))
        coords[dim] = Var(dim, dim, units, long_name, attrs={"parameter": ax.parameter})(ax.values)
    attrs = {
        "map": spec.name,
        "design": spec.design,
        "x_parameter": spec.x.parameter,
        "y_parameter": spec.y.parameter,
        "fixed_overrides": spec.fixed_overrides,
        "lines": "rows: x increasing at fixed y",
        **study.study_attrs(policy),
        **result.attrs,
        "wall_time_s": result.wall_time_s,
    }
    return xr.Dataset(result.data, coords=coords, attrs=attrs)
