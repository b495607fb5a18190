"""Regime boundaries of a regime map (or of a plane without a map, a ``curves:`` study) as curves: the
settings, the plane and its lines, the one-parameter branches along the lines and the two-parameter curves
of their events (:func:`line_curves`, the first stage below); the map's records, the driver of both stages
and the curves file are in :mod:`~geardyn.runs.continuation.curve_records`, the pixel check against the map
in :mod:`~geardyn.runs.continuation.curve_check` (docs/orbits.md, "Regime boundaries as curves").

Seeds, in order:

1. *Lines*: the map's cut lines (``cuts_x``: the lines x = c, along y; ``cuts_y``: y = c, along x), or the
   entry's own ``lines_x`` / ``lines_y``; a direction without any gets the middle line of the plane.
   On each line the attractors at the map's pixels labelled P1..P<max_period> (the middle pixel of each run
   of equal label, longest runs first) or, without a map, at ``probes`` points spread over the line, are
   simulated from the static deflection and shot; each distinct orbit is continued along the line
   (:func:`~geardyn.runs.continuation.continue_branch`), with the period-2n branch of every located period
   doubling (2n <= max_period).  Every located event of every branch seeds a curve
   (:func:`~geardyn.runs.continuation.curves_from_branch`); a sign change of the back-flank margin along a
   branch seeds a back-flank grazing curve (:class:`BackFlank`).
2. *The map's records*: a pixel where the row's followed orbit lost stability (the map's ``bifurcation``:
   fold, period doubling, Neimark-Sacker; the orbit's period that of the pixel before) either lies on a
   curve of that kind and period (within ``record_tol`` pixels) or seeds one: the orbit is found at the
   pixel before, continued along the row past the pixel, and the event located there starts a curve.

A curve stops on the box of the plane.  A curve of period n > 1 that reaches an orbit of a shorter period (it
runs on along that orbit's curve, traversed twice) is cut there (:func:`cut_merged`); a seed within 0.005 of
the box of a curve of its kind, period and flank starts none (:meth:`Boundaries.known`).
"""

from __future__ import annotations

import logging
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import xarray as xr

from geardyn.config import settings_from
from geardyn.khv.design import resolve_fractions
from geardyn.runs.continuation.branch import Branch, ContinuationSettings, on_branch
from geardyn.runs.continuation.curves import (
    CURVE_KINDS,
    Curve,
    CurveSettings,
    KHVPlane,
    continue_curve,
    curves_from_branch,
)
from geardyn.runs.continuation.family import KHVFamily, cycle_states
from geardyn.runs.continuation.stepping import continue_branch
from geardyn.runs.continuation.switching import switch_at_period_doubling
from geardyn.solve.base import SimulationSettings
from geardyn.solve.run import simulate
from geardyn.solve.shooting import newton_shooting

log = logging.getLogger("geardyn.curves")

#: Kinds of the curves file: the library's four and the grazing of the back flank (onset of back-side contact).
FILE_KINDS = (*CURVE_KINDS, "back_grazing")


@dataclass(frozen=True)
class BoundarySpec:
    """The ``curves:`` settings of a map or a curves study (config schema ``curve_settings``).

    ds_max: the curves' largest step (scaled arclength, box sides = 1); branch_ds_max: the lines'
    one-parameter continuation (fraction of the line).  max_period: longest period continued.  max_seeds:
    orbits seeded per line and label run.  map_seeds, max_map_seeds, record_tol: the map's records as seeds
    (at most that many tried; on a curve within record_tol pixels).  back_grazing: curves of the back-flank
    margin.  nodes: coefficient interpolation nodes along x1 (or any costly parameter).  lines_x, lines_y:
    lines instead of the map's cuts.  probes: seed points per line without a map.  check_every: the pixel
    check crosses every n-th row and column.  max_points: per direction of a curve."""

    enabled: bool = True
    ds_max: float = 0.03
    branch_ds_max: float = 0.02
    max_period: int = 12
    max_seeds: int = 3
    map_seeds: bool = True
    max_map_seeds: int = 30
    record_tol: float = 2.5
    back_grazing: bool = True
    nodes: int = 41
    lines_x: tuple[float, ...] = ()
    lines_y: tuple[float, ...] = ()
    probes: int = 7
    check_every: int = 5
    max_points: int = 400

    @classmethod
    def from_config(cls, spec: Mapping[str, Any] | None) -> BoundarySpec:
        values = {k: v for k, v in (spec or {}).items() if k not in _ENTRY_KEYS}
        for key in ("lines_x", "lines_y"):
            if key in values:
                values[key] = tuple(float(v) for v in values[key])
        return settings_from(cls, values, "curves settings")

    def curve_settings(self) -> CurveSettings:
        return CurveSettings(ds=min(0.02, self.ds_max), ds_max=self.ds_max, max_points=self.max_points)

    def branch_settings(self) -> ContinuationSettings:
        return ContinuationSettings(ds=self.branch_ds_max, ds_max=self.branch_ds_max, max_points=2000)


#: Keys of a curves study entry that are not curve settings.
_ENTRY_KEYS = ("designs", "title", "x", "y", "fixed", "integration")
#: Parameters the coefficients are linear in (a spline through 5 nodes is exact).
_LINEAR = ("b", "e", "w")


@dataclass(frozen=True)
class Region:
    """The plane: names (x, y parameters), box (x_lo, x_hi, y_lo, y_hi), the fixed overrides."""

    names: tuple[str, str]
    box: tuple[float, float, float, float]
    fixed: tuple[tuple[str, float], ...] = ()

    @classmethod
    def of_map(cls, spec: Any) -> Region:
        """The plane of a :class:`geardyn.runs.maps.MapSpec`."""
        return cls(
            (spec.x.parameter, spec.y.parameter), (spec.x.start, spec.x.stop, spec.y.start, spec.y.stop), spec.fixed
        )

    @classmethod
    def from_config(cls, spec: Mapping[str, Any], segment: tuple[float, float]) -> Region:
        """The plane of a curves study entry (x1 percentages resolved on the design's segment)."""
        s = resolve_fractions(spec, segment)
        x, y = s["x"], s["y"]
        box = (float(x["start"]), float(x["stop"]), float(y["start"]), float(y["stop"]))
        return cls((x["parameter"], y["parameter"]), box, tuple(sorted((s.get("fixed") or {}).items())))


@dataclass(frozen=True)
class Line:
    """A line of the plane: axis "x" is the line x = value (the branch runs along y, the plane's q), "y" the
    line y = value (along x, p)."""

    axis: str
    value: float

    @property
    def along(self) -> str:
        return "q" if self.axis == "x" else "p"

    def __str__(self) -> str:
        return f"{self.axis} = {self.value:g}"


def lines_of(region: Region, xs: Sequence[float], ys: Sequence[float]) -> list[Line]:
    """The lines inside the box; a direction without any gets the middle line."""
    x0, x1, y0, y1 = region.box
    lx = [Line("x", float(v)) for v in xs if x0 <= v <= x1] or [Line("x", 0.5 * (x0 + x1))]
    ly = [Line("y", float(v)) for v in ys if y0 <= v <= y1] or [Line("y", 0.5 * (y0 + y1))]
    return lx + ly


@dataclass
class Boundaries:
    """The curves of a plane: ``flank[k]`` "back" for a back-flank grazing curve, ``origin[k]`` its seed;
    the branches along the lines; ``records``: the fate of each of the map's records (kind, n, x, y, fate);
    ``timing``: seconds per stage."""

    region: Region
    lines: list[Line] = field(default_factory=list)
    curves: list[Curve] = field(default_factory=list)
    flank: list[str] = field(default_factory=list)
    origin: list[str] = field(default_factory=list)
    branches: list[tuple[Line, Branch]] = field(default_factory=list)
    records: list[tuple[str, int, float, float, str]] = field(default_factory=list)
    timing: dict[str, float] = field(default_factory=dict)

    def add(self, curves: Sequence[Curve], origin: str, flank: str = "working", plane: Any = None) -> None:
        for c in curves:
            c = c if plane is None else cut_merged(plane, c)
            if len(c) < 2:
                continue
            self.curves.append(c)
            self.flank.append(flank)
            self.origin.append(origin)
            log.info(
                "%s: %s curve (period %d), %d points, ends %s, %d codim-2",
                origin,
                c.kind,
                c.n,
                len(c),
                c.end_status,
                len(c.codim2),
            )

    def known(self, kind: str, n: int, pq: tuple[float, float], flank: str = "working", tol: float = 5e-3) -> bool:
        """True when (p, q) lies within ``tol`` of the box (each side scaled to 1) of a curve of that kind,
        period and flank (the polyline: looser than the library's 1e-3 on the corrected seed)."""
        x0, x1, y0, y1 = self.region.box
        return any(
            c.kind == kind and c.n == n and f == flank and polyline_distance(c, *pq, x1 - x0, y1 - y0) <= tol
            for c, f in zip(self.curves, self.flank, strict=True)
        )

    def file_kind(self, k: int) -> str:
        c = self.curves[k]
        return "back_grazing" if c.kind == "grazing" and self.flank[k] == "back" else c.kind


# --- the back flank ---------------------------------------------------------------------------------------


def back_margin(system: Any, x: np.ndarray, n: int, settings: SimulationSettings) -> float:
    """h = min over the cycle of s X_VH + b (s the drive side, the sign of the static mesh deflection beyond
    the backlash): h < 0 when the teeth strike on the back flank.  NaN without backlash.  Dense run of the n
    periods from x; the discrete minimum refined by the parabola through it and its neighbours."""
    if not system.backlash_on or system.b <= 0.0:
        return float("nan")
    s = SimulationSettings(steps_per_period=settings.steps_per_period, transient_periods=0, recorded_periods=n)
    r = simulate(system, s, x, dense=True)
    if r.diverged or r.states is None or r.states.shape[0] < 3:
        return float("nan")
    side = -1.0 if float(system.static_state()[1]) < 0.0 else 1.0
    a = side * np.concatenate([[x[1]], r.states[:, 1]])
    i = int(np.argmin(a))
    m = float(a[i])
    if 0 < i < a.size - 1:
        den = a[i - 1] - 2 * a[i] + a[i + 1]
        if den > 0:
            m = float(a[i] - 0.125 * (a[i + 1] - a[i - 1]) ** 2 / den)
    return m + system.b


class BackFlank:
    """A :class:`KHVPlane` whose grazing margin is the back flank's (:func:`back_margin`): its grazing
    curves are where back-side contact begins."""

    def __init__(self, plane: KHVPlane):
        self.plane, self.box = plane, plane.box

    def flow(self, p: float, q: float, n: int):
        return self.plane.flow(p, q, n)

    def grazing(self, p: float, q: float, x: np.ndarray, n: int) -> float:
        return back_margin(self.plane.coefficients(p, q), x, n, self.plane.settings)


# --- orbits and branches along a line ----------------------------------------------------------------------


def _periods_of(points: np.ndarray, max_period: int, tol: float = 0.05) -> list[int]:
    """The three least periods n <= max_period whose return distance over the recorded stroboscopic points is
    below ``tol`` of their size (candidates for shooting: the run may still be approaching its orbit)."""
    scale = max(1.0, float(np.max(np.abs(points))))
    near = [n for n in range(1, max_period + 1) if float(np.max(np.abs(points[n:] - points[:-n]))) < tol * scale]
    return near[:3]


def attractor_orbit(
    family: KHVFamily, t: float, n: int, settings: SimulationSettings, max_period: int = 12
) -> tuple[np.ndarray, int] | None:
    """The stable orbit reached from the static deflection at t (``settings.transient_periods``), shot for
    period n (n = 0: the periods whose returns the run comes closest to, up to max_period); None when none."""
    s = SimulationSettings(
        steps_per_period=settings.steps_per_period,
        transient_periods=settings.transient_periods,
        recorded_periods=2 * max(n, max_period) + 1,
    )
    r = simulate(family.coefficients(t), s)
    if r.diverged:
        return None
    for m in [n] if n else _periods_of(r.poincare, max_period):
        sh = newton_shooting(family.flow(t, m), r.poincare[-1], m, 1e-9)
        if sh.stable and (m == 1 or not shorter_period(_Fixed(family), t, 0.0, sh.state, m)):
            return sh.state, m
    return None


class _Fixed:
    """A one-parameter family seen as a plane (q ignored), for :func:`shorter_period`."""

    def __init__(self, family: KHVFamily):
        self.family = family

    def flow(self, p: float, q: float, n: int):
        return self.family.flow(p, n)


def line_family(design: Any, region: Region, line: Line, settings: SimulationSettings, nodes: int) -> KHVFamily:
    """The one-parameter family along ``line`` over the box."""
    (xp, yp), (x0, x1, y0, y1) = region.names, region.box
    fixed = dict(region.fixed)
    if line.axis == "x":
        return KHVFamily(design, yp, {**fixed, xp: line.value}, y0, y1, settings, 5 if yp in _LINEAR else nodes)
    return KHVFamily(design, xp, {**fixed, yp: line.value}, x0, x1, settings, 5 if xp in _LINEAR else nodes)


def map_line_seeds(map_ds: xr.Dataset, line: Line, max_period: int, max_seeds: int) -> list[tuple[float, int]]:
    """(t, n): the middle pixel of each run of equal label P1..P<max_period> along the map's row or column
    nearest the line, longest runs first (at most ``max_seeds`` per period)."""
    xs, ys, lab = map_ds["x"].values, map_ds["y"].values, map_ds["label"].values
    if line.axis == "x":
        grid, labels = ys, lab[:, int(np.argmin(np.abs(xs - line.value)))]
    else:
        grid, labels = xs, lab[int(np.argmin(np.abs(ys - line.value))), :]
    runs, start = [], 0
    for i in range(1, labels.size + 1):
        if i == labels.size or labels[i] != labels[start]:
            if 1 <= labels[start] <= max_period:
                runs.append((i - start, start, int(labels[start])))
            start = i
    runs.sort(key=lambda r: (-r[0], r[1]))
    per: dict[int, int] = {}
    out = []
    for length, first, n in runs:
        if per.get(n, 0) < max_seeds:
            per[n] = per.get(n, 0) + 1
            out.append((float(grid[first + length // 2]), n))
    return out


def line_branches(
    family: KHVFamily,
    seeds: Sequence[tuple[float, int]],
    settings: SimulationSettings,
    spec: BoundarySpec,
) -> list[Branch]:
    """The distinct branches through the seeds' attractors (n = 0: the period the run shows) along the
    family's range, with the period-2n branches of their period doublings."""
    out: list[Branch] = []
    cs = spec.branch_settings()
    for t, n in seeds:
        found = attractor_orbit(family, t, n, settings, spec.max_period)
        if found is None:
            log.info("line seed at %g (P%d): no stable orbit reached", t, n)
            continue
        x, n = found
        cyc = cycle_states(family, t, x, n)
        if any(b.n == n and on_branch(b, t, cyc, 1e-3) for b in out):
            continue
        br = continue_branch(family, t, x, n, family.lo, family.hi, cs)
        if br is not None:
            out.append(br)
            out.extend(_doubled(family, br, out, spec))
    return out


def _doubled(family: KHVFamily, br: Branch, known: list[Branch], spec: BoundarySpec, depth: int = 0) -> list[Branch]:
    """The period-2n branches born at the located period doublings of ``br`` (recursively, 2n <= max_period)."""
    out: list[Branch] = []
    for bf in br.bifurcations:
        if bf.kind != "period_doubling" or not bf.located or 2 * br.n > spec.max_period:
            continue
        pts = cycle_states(family, bf.p, bf.state, br.n)
        if any(b.n == 2 * br.n and (on_branch(b, bf.p, pts, 1e-2) or _touches(b, bf.p, pts)) for b in known + out):
            continue
        new = switch_at_period_doubling(family, bf, family.lo, family.hi, spec.branch_settings())
        if new is not None:
            out.append(new)
            if depth < 4:
                out.extend(_doubled(family, new, known + out, spec, depth + 1))
    return out


def _touches(br: Branch, p: float, points: np.ndarray, tol: float = 2e-3) -> bool:
    """True when a point of ``br`` lies within ``tol`` (scaled: the branch's range, max(1, max |x|)) of one of
    ``points`` at p: a branch that ends at (or was cut just short of) a period doubling it was born at."""
    span = max(float(np.ptp(br.p)), 1e-12)
    scale = max(1.0, float(np.max(np.abs(br.states))))
    dp = np.abs(br.p - p)[:, None] / span
    dx = np.max(np.abs(br.states[:, None, :] - points[None, :, :]), axis=2) / scale
    return bool(np.min(np.maximum(dp, dx)) < tol)


def back_grazing_seeds(family: KHVFamily, br: Branch, iterations: int = 8) -> list[tuple[float, np.ndarray]]:
    """(t, state) where the back-flank margin of the branch's orbit changes sign between consecutive points,
    refined by regula falsi (Illinois) on the orbit shot at each trial t."""

    def h(t: float, x: np.ndarray) -> float:
        return back_margin(family.coefficients(t), x, br.n, family.settings)

    hs = np.array([h(p, x) for p, x in zip(br.p, br.states, strict=True)])
    out = []
    for i in np.flatnonzero(np.isfinite(hs[:-1]) & np.isfinite(hs[1:]) & (np.sign(hs[:-1]) != np.sign(hs[1:]))):
        (ta, xa, ha), (tb, xb, hb) = (br.p[i], br.states[i], hs[i]), (br.p[i + 1], br.states[i + 1], hs[i + 1])
        t, x = float(ta), xa
        for _ in range(iterations):
            w = ha / (ha - hb)
            t = float(ta + w * (tb - ta))
            r = newton_shooting(family.flow(t, br.n), xa + w * (xb - xa), br.n, 1e-9)
            if not r.converged:
                break
            x, ht = r.state, h(t, r.state)
            if not np.isfinite(ht) or abs(ht) < 1e-9:
                break
            if np.sign(ht) == np.sign(ha):
                ta, xa, ha, hb = t, x, ht, 0.5 * hb
            else:
                tb, xb, hb, ha = t, x, ht, 0.5 * ha
        out.append((t, x))
    return out


# --- curves: merged periods, the polyline, one branch's events ----------------------------------------------


def shorter_period(plane: Any, p: float, q: float, x: np.ndarray, n: int) -> bool:
    """True when the period-n orbit through x at (p, q) is an orbit of a proper divisor m of n traversed n / m
    times (x a fixed point of the m-period map within 1e-6 max(1, max |x|))."""
    scale = max(1.0, float(np.max(np.abs(x))))
    for m in {n // f for f in range(2, n + 1) if n % f == 0}:
        y, _ = plane.flow(p, q, m)(x, False)
        if y is not None and float(np.max(np.abs(y - x))) <= 1e-6 * scale:
            return True
    return False


def cut_merged(plane: Any, curve: Curve) -> Curve:
    """A period-n curve (n > 1) cut to its longest run of points whose orbit is not of a shorter period: where
    it reaches one (through a period doubling of the shorter orbit) it goes on along that orbit's curve
    traversed twice.  The cut ends get ``merged_into_shorter_period``."""
    if curve.n == 1:
        return curve
    ok = [not shorter_period(plane, float(pt.z[-2]), float(pt.z[-1]), pt.z[:-2], curve.n) for pt in curve.points]
    if all(ok):
        return curve
    best, start = (0, 0), None
    for i, good in enumerate([*ok, False]):
        if good and start is None:
            start = i
        elif not good and start is not None:
            best, start = max(best, (start, i), key=lambda r: r[1] - r[0]), None
    a, b = best
    ends = dict(curve.end_status)
    ends.update({"down": "merged_into_shorter_period"} if a > 0 else {})
    ends.update({"up": "merged_into_shorter_period"} if b < len(ok) else {})
    cut = Curve(curve.kind, curve.n, curve.points[a:b], curve.scales, ends)
    if len(cut) > 1:
        cut.codim2 = [c for c in curve.codim2 if polyline_distance(cut, c.p, c.q, *curve.scales[1:]) < 1e-6]
    return cut


def polyline_distance(curve: Curve, x: float, y: float, px: float, py: float) -> float:
    """Distance of (x, y) from the curve's polyline in units of (px, py) (the map's pixel)."""
    pts = np.column_stack([curve.p / px, curve.q / py])
    pt = np.array([x / px, y / py])
    if len(pts) == 1:
        return float(np.linalg.norm(pts[0] - pt))
    a, b = pts[:-1], pts[1:]
    ab = b - a
    w = np.clip(np.sum((pt - a) * ab, axis=1) / np.maximum(np.sum(ab * ab, axis=1), 1e-300), 0.0, 1.0)
    return float(np.min(np.linalg.norm(a + w[:, None] * ab - pt, axis=1)))


def branch_curves(
    plane: KHVPlane, bd: Boundaries, br: Branch, line: Line, cs: CurveSettings, origin: str, kinds=CURVE_KINDS
) -> None:
    """A curve from each located event of ``br`` (along ``line``) that lies on no curve of ``bd`` yet
    (:meth:`Boundaries.known`), one event at a time (:func:`curves_from_branch`)."""
    for bf in br.bifurcations:
        pq = (line.value, bf.p) if line.axis == "x" else (bf.p, line.value)
        if bf.kind in kinds and bf.located and not bd.known(bf.kind, bf.n, pq):
            one = replace(br, bifurcations=[bf])
            bd.add(curves_from_branch(plane, one, line.along, line.value, cs, kinds, bd.curves), origin, plane=plane)


def line_curves(
    design: Any,
    region: Region,
    spec: BoundarySpec,
    settings: SimulationSettings,
    map_ds: xr.Dataset | None = None,
    lines: Sequence[Line] | None = None,
) -> tuple[Boundaries, KHVPlane]:
    """The first stage (module doc): branches along ``lines`` (default: the spec's lines, else the middle
    lines) seeded by the map's periodic pixels or, without a map, by ``probes`` simulations per line, and the
    curves of their events and back-flank sign changes."""
    t0 = time.perf_counter()
    plane = KHVPlane(design, region.names, dict(region.fixed), region.box, settings, spec.nodes)
    lines = list(lines) if lines is not None else lines_of(region, spec.lines_x, spec.lines_y)
    bd = Boundaries(region, lines)
    back = BackFlank(plane)
    cs = spec.curve_settings()
    for line in lines:
        fam = line_family(design, region, line, settings, spec.nodes)
        if map_ds is not None:
            seeds = map_line_seeds(map_ds, line, spec.max_period, spec.max_seeds)
        else:
            seeds = [(float(t), 0) for t in np.linspace(fam.lo, fam.hi, spec.probes + 2)[1:-1]]
        for br in line_branches(fam, seeds, settings, spec):
            bd.branches.append((line, br))
            events = [(b.kind, round(b.p, 5)) for b in br.bifurcations]
            log.info("line %s: P%d branch, %d points, events %s", line, br.n, len(br), events)
            branch_curves(plane, bd, br, line, cs, f"line {line}")
            if spec.back_grazing:
                for t, x in back_grazing_seeds(fam, br):
                    pq = (line.value, t) if line.axis == "x" else (t, line.value)
                    if not bd.known("grazing", br.n, pq, "back"):
                        c = continue_curve(back, "grazing", br.n, x, pq, cs=cs, along=line.along)
                        bd.add([c] if c is not None else [], f"line {line}", "back", plane)
    bd.timing["lines"] = time.perf_counter() - t0
    return bd, plane
