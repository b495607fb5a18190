"""Regime boundaries of a map (or of a ``curves:`` study's plane) as curves: branches along lines seeded by the
labeller, the curves of their events, then the map's records as seeds (docs/orbits.md, section 5)."""

from __future__ import annotations

import logging
import time
from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
import xarray as xr

from geardyn.io import Var
from geardyn.jsontypes import Json
from geardyn.khv import point
from geardyn.khv.design import KHVDesign
from geardyn.label import Policy, label_points
from geardyn.runs.continuation.boundaries import Boundaries, BoundarySpec, Line, RecordFate, Region, Unseeded
from geardyn.runs.continuation.branch import Bifurcation, Branch
from geardyn.runs.continuation.corrector import CURVES, ContinuationSettings
from geardyn.runs.continuation.curve_check import pixel_check
from geardyn.runs.continuation.curves import RECORD_KINDS, BoundaryCurve, Curve, bounds_stable, continue_curve, lies_on
from geardyn.runs.continuation.driver import run_middles
from geardyn.runs.continuation.events import sign_changes
from geardyn.runs.continuation.family import KHVFamily, KHVPlane
from geardyn.runs.continuation.output import FILE_KINDS, RECORD_FATES, curve_dataset, index, quantity, table
from geardyn.runs.continuation.pixel_samples import CheckSettings, PixelCheck
from geardyn.runs.continuation.problem import BranchProblem
from geardyn.runs.continuation.switching import add_branch
from geardyn.solve import bifurcations as kinds
from geardyn.solve.base import SimulationSettings
from geardyn.solve.bifurcations import CODES, CURVE_KINDS, decode

if TYPE_CHECKING:  # for the annotations only
    from geardyn.runs.maps import MapSpec

log = logging.getLogger("geardyn.curves")


# --- orbits and branches along a line ----------------------------------------------------------------------


class SeedOrbit(NamedTuple):
    """The stable orbit the labeller certifies at a seed: the parameter t along its line, its state, its period."""

    t: float
    state: np.ndarray
    n: int


def labelled_orbits(
    seeds: Sequence[tuple[KHVFamily, float, int]], policy: Policy, max_period: int
) -> list[SeedOrbit | None]:
    """The orbit the labeller certifies at each seed (family, t, n) from the static deflection (all in one call):
    of period n, or of any period up to ``max_period`` for n = 0; None where it certifies none."""
    verdicts = label_points([family.coefficients(t) for family, t, _ in seeds], policy)
    return [
        SeedOrbit(t, v.final_state, v.period)
        if v.period >= 1 and (v.period == n if n else v.period <= max_period)
        else None
        for (_, t, n), v in zip(seeds, verdicts, strict=True)
    ]


def line_family(design: KHVDesign, region: Region, line: Line, settings: SimulationSettings, nodes: int) -> KHVFamily:
    """The one-parameter family along ``line`` over the box (5 spline nodes along b, e or w: the coefficients
    are linear in them, a spline through 5 nodes is exact)."""
    (xp, yp), (x0, x1, y0, y1) = region.names, region.box
    held, free, lo, hi = (xp, yp, y0, y1) if line.axis == "x" else (yp, xp, x0, x1)
    fixed = {**dict(region.fixed), held: line.value}
    return KHVFamily(design, free, fixed, lo, hi, settings, 5 if free in point.COEFFICIENT_FIELDS else nodes)


def map_line_seeds(map_ds: xr.Dataset, line: Line, max_period: int, max_seeds: int) -> list[tuple[float, int]]:
    """(t, n): the middle pixel of each run of equal label P1..P<max_period> along the map's row or column
    nearest the line, longest runs first (at most ``max_seeds`` per period)."""
    xs, ys, lab = map_ds["x"].values, map_ds["y"].values, map_ds["label"].values
    if line.axis == "x":
        grid, labels = ys, lab[:, int(np.argmin(np.abs(xs - line.value)))]
    else:
        grid, labels = xs, lab[int(np.argmin(np.abs(ys - line.value))), :]
    per: dict[int, int] = {}
    out = []
    for j, n in run_middles(np.asarray(labels), max_period):
        if per.get(n, 0) < max_seeds:
            per[n] = per.get(n, 0) + 1
            out.append((float(grid[j]), n))
    return out


# --- curves: merged periods, the polyline, one branch's events ----------------------------------------------


def branch_curves(
    plane: KHVPlane,
    bd: Boundaries,
    br: Branch,
    line: Line,
    cs: ContinuationSettings,
    origin: str,
    kinds: Sequence[str] = CURVE_KINDS,
    flank: str = "working",
) -> None:
    """A curve from each event of ``br`` (along ``line``), located or only bracketed, that lies on no curve of
    ``bd`` of its ``flank`` yet (:meth:`Boundaries.known`); an event whose seed the corrector does not reach goes
    to ``bd.unseeded``."""
    for bf in br.bifurcations:
        pq = (line.value, bf.p) if line.axis == "x" else (bf.p, line.value)
        if bf.kind in kinds and not bd.known(bf.kind, bf.n, pq, cs.on_curve_tol, flank):
            c = continue_curve(plane, bf.kind, bf.n, bf.state, pq, bf.critical, cs, line.along)
            if c is None:
                log.info("%s: %s (P%d) at %s seeds no curve (located: %s)", origin, bf.kind, bf.n, pq, bf.located)
                bd.unseeded.append(Unseeded("back_grazing" if flank == "back" else bf.kind, bf.n, *pq, bf.located))
            bd.add(c, origin, flank)


def curves_from_branch(
    plane: KHVPlane,
    branch: Branch,
    axis: str,
    at: float,
    cs: ContinuationSettings = CURVES,
    kinds: Sequence[str] = CURVE_KINDS,
    existing: Sequence[Curve] = (),
) -> list[Curve]:
    """:func:`branch_curves` of a ``branch`` along the plane's ``axis`` ("p" or "q", the other coordinate at
    ``at``), ``existing`` the curves known already: the new curves."""
    if axis not in ("p", "q"):
        raise ValueError(f"axis {axis!r}; allowed: 'p', 'q'")
    bd = Boundaries(Region(("p", "q"), plane.box), curves=[BoundaryCurve(c) for c in existing])
    branch_curves(plane, bd, branch, Line("y" if axis == "p" else "x", at), cs, f"branch at {at:g}", kinds)
    return [b.curve for b in bd.curves[len(existing) :]]


# --- the map's records as seeds -----------------------------------------------------------------------------


def pixel_size(map_ds: xr.Dataset) -> tuple[float, float]:
    xs, ys = map_ds["x"].values, map_ds["y"].values
    return float(abs(xs[1] - xs[0])), float(abs(ys[1] - ys[0]))


class MapRecord(NamedTuple):
    """A pixel (row j, column i) whose row's followed orbit lost stability by a fold, period doubling or
    Neimark-Sacker (the map's ``bifurcation``): that kind, and the period n of the pixel before (0: not periodic)."""

    j: int
    i: int
    kind: str
    n: int


def map_records(map_ds: xr.Dataset) -> list[MapRecord]:
    """The map's records (:class:`MapRecord`), in the order of the map's pixels."""
    names = decode(map_ds["bifurcation"].attrs)
    code, period, label = map_ds["bifurcation"].values, map_ds["period"].values, map_ds["label"].values
    out = []
    for j, i in zip(*np.nonzero(code > 0), strict=True):
        kind = names.get(int(code[j, i]), "")
        if kind not in RECORD_KINDS or i == 0:
            continue
        n = int(period[j, i - 1]) if label[j, i - 1] >= 1 else 0
        out.append(MapRecord(int(j), int(i), kind, n))
    return out


def _record_curves(
    design: KHVDesign,
    plane: KHVPlane,
    bd: Boundaries,
    map_ds: xr.Dataset,
    rec: MapRecord,
    spec: BoundarySpec,
    policy: Policy,
) -> list[Curve]:
    """A curve from one map record (added to ``bd``): the orbit the labeller certifies at the pixel before (or
    half way back along the row's run), continued along the row past the pixel, the event of the record's kind
    nearest the pixel (within ``record_tol`` pixels); [] when not reproduced."""
    j, i, kind, n = rec
    xs, ys, lab = map_ds["x"].values, map_ds["y"].values, map_ds["label"].values
    first = i - 1
    while first > 0 and lab[j, first - 1] == lab[j, i - 1]:
        first -= 1
    lo, hi = float(xs[max(first, i - 12)]), float(xs[min(i + 3, xs.size - 1)])
    (xp, yp), fixed = bd.region.names, dict(bd.region.fixed)
    row = Line("y", float(ys[j]))
    fam = KHVFamily(design, xp, {**fixed, yp: row.value}, lo, hi, plane.settings, 5)
    cs = spec.record_settings()
    px = pixel_size(map_ds)[0]
    origin = f"map record ({float(xs[i]) - 0.5 * px:.6g}, {row.value:.6g})"
    known: list[Branch] = []  # a second orbit on the first one's branch starts none
    for t in dict.fromkeys((float(xs[i - 1]), float(xs[(max(first, i - 12) + i - 1) // 2]))):
        (found,) = labelled_orbits([(fam, t, n)], policy, spec.max_period)
        br = None if found is None else add_branch(fam, t, found.state, n, known, cs)
        if br is None:
            continue
        near = [b for b in br.bifurcations if b.kind == kind and abs(b.p - xs[i]) <= spec.record_tol * px]
        if near:
            before = len(bd.curves)
            branch_curves(plane, bd, replace(br, bifurcations=near[:1]), row, spec.curve_settings(), origin, (kind,))
            return [b.curve for b in bd.curves[before:]]
    return []


def record_seeds(
    design: KHVDesign, plane: KHVPlane, bd: Boundaries, map_ds: xr.Dataset, spec: BoundarySpec, policy: Policy
) -> None:
    """The fate of each of the map's records (:data:`RECORD_FATES`): on a curve (:func:`lies_on`, within
    ``record_tol`` pixels), or the seed of a new one (at most ``max_map_seeds`` tried), or not reproduced;
    appended to ``bd.records``, curves to ``bd``."""
    px, py = pixel_size(map_ds)
    xs, ys = map_ds["x"].values, map_ds["y"].values
    tried = 0
    for rec in sorted(map_records(map_ds), key=lambda r: (r.n, r.kind, r.j, r.i)):
        j, i, kind, n = rec
        x, y = float(xs[i]) - 0.5 * px, float(ys[j])  # the loss lies between the pixel and the one before
        if not 1 <= n <= spec.max_period:
            fate = "period_out_of_range"
        elif any(lies_on(b.curve, kind, n, x, y, spec.record_tol, (px, py)) for b in bd.curves):
            fate = "on_curve"
        elif tried < spec.max_map_seeds:
            tried += 1
            new = _record_curves(design, plane, bd, map_ds, rec, spec, policy)
            on = any(lies_on(c, kind, n, x, y, spec.record_tol, (px, py)) for c in new)
            fate = "started_curve" if on else "not_reproduced"
        else:
            fate = "not_reproduced"
        bd.records.append(RecordFate(kind, n, x, y, fate))


def boundary_curves(
    design: KHVDesign,
    region: Region,
    spec: BoundarySpec,
    settings: SimulationSettings,
    map_ds: xr.Dataset | None = None,
    policy: Policy | None = None,
) -> tuple[Boundaries, KHVPlane]:
    """The regime boundaries of ``region`` (module doc), the seeds labelled by ``policy`` (default: the labeller's
    with ``settings``): the map's periodic pixels along its lines or, without a map, ``probes`` points per line."""
    t0 = time.perf_counter()
    policy = policy or Policy(settings)
    plane = KHVPlane(design, region.names, dict(region.fixed), region.box, settings, spec.nodes)
    x0, x1, y0, y1 = region.box  # the lines inside the box; a direction without any gets the middle line
    lines = [Line("x", float(v)) for v in spec.lines_x if x0 <= v <= x1] or [Line("x", 0.5 * (x0 + x1))]
    lines += [Line("y", float(v)) for v in spec.lines_y if y0 <= v <= y1] or [Line("y", 0.5 * (y0 + y1))]
    bd = Boundaries(region, lines)
    back = plane.back_flank()
    cs = spec.curve_settings()
    fams = [line_family(design, region, line, settings, spec.nodes) for line in lines]
    seeds = [
        [(fam, t, n) for t, n in map_line_seeds(map_ds, line, spec.max_period, spec.max_seeds)]
        if map_ds is not None
        else [(fam, float(t), 0) for t in np.linspace(fam.lo, fam.hi, spec.probes + 2)[1:-1]]
        for line, fam in zip(lines, fams, strict=True)
    ]
    found = iter(labelled_orbits([s for line_seeds in seeds for s in line_seeds], policy, spec.max_period))
    for line, fam, line_seeds in zip(lines, fams, seeds, strict=True):
        known: list[Branch] = []  # the distinct branches through the seeds' orbits, with their period doublings'
        for orbit in [next(found) for _ in line_seeds]:
            if orbit is not None:
                add_branch(fam, *orbit, known, spec.branch_settings(), spec.max_period)
        for br in known:
            bd.branches.append((line, br))
            events = [(b.kind, round(b.p, 5)) for b in br.bifurcations]
            log.info("line %s: P%d branch, %d points, events %s", line, br.n, len(br), events)
            branch_curves(plane, bd, br, line, cs, f"line {line}")
            if spec.back_grazing:  # where back-side contact begins: the back flank's grazing curves
                nan = complex("nan")
                bfs = [
                    Bifurcation("grazing", q.p, q.x, q.multipliers, nan, nan.real, -1, ok, br.n)
                    for q, ok in sign_changes(BranchProblem.of(fam, br), br, fam.back_grazing)
                ]
                branch_curves(back, bd, replace(br, bifurcations=bfs), line, cs, f"line {line}", ("grazing",), "back")
    bd.timing["lines"] = time.perf_counter() - t0
    if map_ds is not None and spec.map_seeds and "bifurcation" in map_ds:
        t1 = time.perf_counter()
        record_seeds(design, plane, bd, map_ds, spec, policy)
        bd.timing["records"] = time.perf_counter() - t1
    bd.timing["total"] = sum(bd.timing.values())
    return bd, plane


# --- a map's boundaries and their file ----------------------------------------------------------------------


def map_boundaries(
    design: KHVDesign, spec: MapSpec, entry: Mapping[str, Json], map_ds: xr.Dataset
) -> tuple[Boundaries, PixelCheck, SimulationSettings]:
    """The regime boundaries of a map (``spec``: its :class:`~geardyn.runs.maps.MapSpec`, ``entry``: its config
    entry) along the lines of its ``curves:`` settings, else along its cut lines, and their pixel check."""
    bs = BoundarySpec.from_config(entry["curves"])
    bs = replace(
        bs, lines_x=bs.lines_x or tuple(entry.get("cuts_x", [])), lines_y=bs.lines_y or tuple(entry.get("cuts_y", []))
    )
    policy = spec.policy(design)
    settings = policy.integration
    bd, plane = boundary_curves(design, Region.of_map(spec), bs, settings, map_ds, policy)
    check = pixel_check(plane, bd.curves, map_ds, CheckSettings(every=bs.check_every))
    bd.timing["check"] = check.seconds
    return bd, check, settings


def boundary_dataset(bd: Boundaries, check: PixelCheck | None = None) -> xr.Dataset:
    """The curves file of the :class:`Boundaries` ``bd``: the curves
    (:func:`curve_dataset`) with the kind ``back_grazing``, ``bounds_stable`` per point, the seeds (``curve_<k>_seed``),
    the map's records and their fates (``record_*``), the seconds per stage (``time_<stage>_s``) and, given a
    :class:`~geardyn.runs.continuation.pixel_samples.PixelCheck`, its samples (``check_*``, ``pixel_check_*``)."""
    names, rec, R = bd.region.names, bd.records, "record"
    ds = curve_dataset([bc.curve for bc in bd.curves], names)
    bounds = [bounds_stable(bc.curve.kind, pt.multipliers, pt.crit) for bc in bd.curves for pt in bc.curve.points]
    stable = "the curve bounds a stable orbit here (the other multipliers inside)"
    period, file_kinds = "period of the orbit before the record (0: not periodic)", kinds.flags(FILE_KINDS)
    rows = [
        (
            Var("curve_kind", "curve", None, "curve kind", file_kinds),
            [CODES[bc.kind] for bc in bd.curves],
        ),
        (Var("bounds_stable", "point", None, stable, index(("interior", "boundary"))), bounds),
        (Var("record_kind", R, None, "kind of the map's record", file_kinds), [CODES[r.kind] for r in rec]),
        (Var("record_period", R, "1", period, dtype=np.int16), [r.n for r in rec]),
        *[
            (Var(f"record_{nm}", R, *quantity(nm)), np.array([getattr(r, xy) for r in rec], float))
            for xy, nm in zip("xy", names, strict=True)
        ],
        (
            Var("record_fate", R, None, "fate of the map's record as a seed", index(RECORD_FATES)),
            [RECORD_FATES.index(r.fate) for r in rec],
        ),
    ]
    ds.update(table(rows))
    ds.attrs.update({f"curve_{k}_seed": bc.origin for k, bc in enumerate(bd.curves)})
    ds.attrs.update({f"records_{f}": int(sum(r.fate == f for r in rec)) for f in RECORD_FATES})
    ds.attrs.update({f"time_{k}_s": round(v, 3) for k, v in bd.timing.items()})
    ds.attrs["unseeded_events"] = (
        "; ".join(
            f"{u.kind} P{u.n} at ({u.x:.6g}, {u.y:.6g}){'' if u.located else ' (bracketed)'}" for u in bd.unseeded
        )
        or "none"
    )
    ds.attrs["lines"] = "; ".join(str(line) for line in bd.lines)
    ds.attrs["box"] = ", ".join(f"{v:g}" for v in bd.region.box)
    ds.attrs["fixed_overrides"] = point.override_text(bd.region.fixed)
    if check is not None:
        ds.update(table(check.variables(names, FILE_KINDS)))
        ds.attrs.update(check.attrs())
    return ds
