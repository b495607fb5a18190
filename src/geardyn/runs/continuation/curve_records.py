"""The map's records as seeds of regime-boundary curves (each record's fate kept, :data:`RECORD_FATES`), the
driver of both stages and the curves file (docs/orbits.md, section 9, "In the workflow")."""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import replace
from typing import Any

import numpy as np
import xarray as xr

from geardyn.runs.continuation.curve_maps import (
    FILE_KINDS,
    Boundaries,
    BoundarySpec,
    Line,
    Region,
    attractor_orbit,
    branch_curves,
    line_curves,
)
from geardyn.runs.continuation.curves import Curve, bounds_stable, polyline_distance
from geardyn.runs.continuation.family import KHVFamily, KHVPlane
from geardyn.runs.continuation.output import curve_dataset, flags, variables
from geardyn.runs.continuation.stepping import continue_branch
from geardyn.solve.base import SimulationSettings

#: The map's ``bifurcation`` flags that seed curves, and the curve kind of each.
RECORD_KINDS = {"fold": "fold", "period_doubling": "period_doubling", "neimark_sacker": "neimark_sacker"}
#: Fates of a map record (``record_fate``).
RECORD_FATES = ("on_curve", "started_curve", "not_reproduced", "period_out_of_range")


def pixel_size(map_ds: xr.Dataset) -> tuple[float, float]:
    xs, ys = map_ds["x"].values, map_ds["y"].values
    return float(abs(xs[1] - xs[0])), float(abs(ys[1] - ys[0]))


def map_records(map_ds: xr.Dataset) -> list[tuple[int, int, str, int]]:
    """(row j, column i, curve kind, period n) of every pixel whose row's followed orbit lost stability by a
    fold, period doubling or Neimark-Sacker (``bifurcation``), n the period of the pixel before (0: not
    periodic)."""
    var = map_ds["bifurcation"]
    names = dict(zip(np.asarray(var.attrs["flag_values"]).tolist(), var.attrs["flag_meanings"].split(), strict=True))
    code, period, label = var.values, map_ds["period"].values, map_ds["label"].values
    out = []
    for j, i in zip(*np.nonzero(code > 0), strict=True):
        kind = RECORD_KINDS.get(names.get(int(code[j, i]), ""))
        if kind is None or i == 0:
            continue
        n = int(period[j, i - 1]) if label[j, i - 1] >= 1 else 0
        out.append((int(j), int(i), kind, n))
    return out


def _record_curves(
    design: Any,
    plane: KHVPlane,
    bd: Boundaries,
    map_ds: xr.Dataset,
    rec: tuple[int, int, str, int],
    spec: BoundarySpec,
    origin: str,
) -> list[Curve]:
    """A curve from one map record (added to ``bd``): the orbit at the pixel before, continued along the row
    past the pixel, the event of the record's kind nearest the pixel; [] when not reproduced."""
    j, i, kind, n = rec
    xs, ys, lab = map_ds["x"].values, map_ds["y"].values, map_ds["label"].values
    first = i - 1
    while first > 0 and lab[j, first - 1] == lab[j, i - 1]:
        first -= 1
    lo, hi = float(xs[max(first, i - 12)]), float(xs[min(i + 3, xs.size - 1)])
    (xp, yp), fixed = bd.region.names, dict(bd.region.fixed)
    fam = KHVFamily(design, xp, {**fixed, yp: float(ys[j])}, lo, hi, plane.settings, 5)
    for t in dict.fromkeys((float(xs[i - 1]), float(xs[(max(first, i - 12) + i - 1) // 2]))):
        found = attractor_orbit(fam, t, n, plane.settings, spec.max_period)
        if found is None:
            continue
        cs = replace(spec.branch_settings(), ds=0.05, ds_max=0.05)
        br = continue_branch(fam, t, found[0], n, lo, hi, cs)
        if br is None:
            continue
        px = pixel_size(map_ds)[0]
        near = [b for b in br.bifurcations if b.kind == kind and b.located and abs(b.p - xs[i]) <= 2.5 * px]
        if near:
            before = len(bd.curves)
            branch_curves(
                plane,
                bd,
                replace(br, bifurcations=near[:1]),
                Line("y", float(ys[j])),
                spec.curve_settings(),
                origin,
                (kind,),
            )
            return bd.curves[before:]
    return []


def record_seeds(design: Any, plane: KHVPlane, bd: Boundaries, map_ds: xr.Dataset, spec: BoundarySpec) -> None:
    """The fate of each of the map's records (:data:`RECORD_FATES`): on a curve, or the seed of a new one
    (at most ``max_map_seeds`` tried), or not reproduced; appended to ``bd.records``, curves to ``bd``."""
    px, py = pixel_size(map_ds)
    xs, ys = map_ds["x"].values, map_ds["y"].values
    tried = 0
    for rec in sorted(map_records(map_ds), key=lambda r: (r[3], r[2], r[0], r[1])):
        j, i, kind, n = rec
        x, y = float(xs[i]) - 0.5 * px, float(ys[j])  # the loss lies between the pixel and the one before
        if not 1 <= n <= spec.max_period:
            fate = "period_out_of_range"
        elif any(
            c.kind == kind and c.n == n and polyline_distance(c, x, y, px, py) <= spec.record_tol for c in bd.curves
        ):
            fate = "on_curve"
        elif tried < spec.max_map_seeds:
            tried += 1
            new = _record_curves(design, plane, bd, map_ds, rec, spec, f"map record ({x:.6g}, {y:.6g})")
            on = any(c.kind == kind and polyline_distance(c, x, y, px, py) <= spec.record_tol for c in new)
            fate = "started_curve" if on else "not_reproduced"
        else:
            fate = "not_reproduced"
        bd.records.append((kind, n, x, y, fate))


def boundary_curves(
    design: Any,
    region: Region,
    spec: BoundarySpec,
    settings: SimulationSettings,
    map_ds: xr.Dataset | None = None,
    lines: Sequence[Line] | None = None,
) -> tuple[Boundaries, KHVPlane]:
    """The regime boundaries of ``region``: the curves from the lines
    (:func:`~geardyn.runs.continuation.curve_maps.line_curves`), then, with a map, from its records."""
    bd, plane = line_curves(design, region, spec, settings, map_ds, lines)
    if map_ds is not None and spec.map_seeds and "bifurcation" in map_ds:
        t1 = time.perf_counter()
        record_seeds(design, plane, bd, map_ds, spec)
        bd.timing["records"] = time.perf_counter() - t1
    bd.timing["total"] = sum(bd.timing.values())
    return bd, plane


def boundary_dataset(bd: Boundaries, check: Any = None) -> xr.Dataset:
    """The curves file: the CF dataset of the curves (:func:`curve_dataset`) with the back-flank grazing
    curves as kind ``back_grazing``, ``bounds_stable`` per point, the seed of every curve (attributes
    ``curve_<k>_seed``), the fate of the map's records (variables ``record_*``, counts ``records_<fate>``),
    the seconds per stage (``time_<stage>_s``) and, given a
    :class:`~geardyn.runs.continuation.curve_check.PixelCheck`, its samples (``check_*``) and figures
    (``pixel_check_*``)."""
    names, rec, R = bd.region.names, bd.records, ("record",)
    ds = curve_dataset(bd.curves, names)
    bounds = [bounds_stable(c.kind, pt.multipliers, pt.crit) for c in bd.curves for pt in c.points]
    stable = flags(("interior", "boundary"), "the curve bounds a stable orbit here (the other multipliers inside)")
    kinds = [FILE_KINDS.index(bd.file_kind(k)) for k in range(len(bd.curves))]
    fates = [RECORD_FATES.index(r[4]) for r in rec]
    spec = [
        ("curve_kind", ("curve",), kinds, flags(FILE_KINDS, "curve kind")),
        ("bounds_stable", ("point",), bounds, stable),
        ("record_kind", R, [FILE_KINDS.index(r[0]) for r in rec], flags(FILE_KINDS, "kind of the map's record")),
        (
            "record_period",
            R,
            np.array([r[1] for r in rec], np.int16),
            "period of the orbit before the record (0: not periodic)",
        ),
        *[
            (f"record_{nm}", R, np.array([r[2 + k] for r in rec], float), {**ds[nm].attrs})
            for k, nm in enumerate(names)
        ],
        ("record_fate", R, fates, flags(RECORD_FATES, "fate of the map's record as a seed")),
    ]
    ds.update(variables(spec))
    ds.attrs.update({f"curve_{k}_seed": o for k, o in enumerate(bd.origin)})
    ds.attrs.update({f"records_{f}": int(sum(r[4] == f for r in rec)) for f in RECORD_FATES})
    ds.attrs.update({f"time_{k}_s": round(v, 3) for k, v in bd.timing.items()})
    ds.attrs["lines"] = "; ".join(str(line) for line in bd.lines)
    ds.attrs["box"] = ", ".join(f"{v:g}" for v in bd.region.box)
    ds.attrs["fixed_overrides"] = ",".join(f"{k}={v:g}" for k, v in bd.region.fixed) or "none"
    if check is not None:
        ds.update(check.variables(names, FILE_KINDS))
        ds.attrs.update(check.attrs())
    return ds
