"""Regime boundaries as curves: the codimension-1 bifurcations of period-n orbits continued in a plane (p, q) by
the one corrector (the problem :class:`~geardyn.runs.continuation.problem.CurveProblem`), with the codimension-2
points on them; and the one test of whether a point already lies on a curve (docs/orbits.md, section 5)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import partial
from typing import NamedTuple

import numpy as np

from geardyn import libm
from geardyn.runs.continuation.corrector import CURVES, ContinuationSettings, Point, correct, merged, step
from geardyn.runs.continuation.events import brent_on_step, fold_test, ns_test, pd_test, unstable_counts
from geardyn.runs.continuation.family import Plane
from geardyn.runs.continuation.problem import TARGET, CurveProblem, others
from geardyn.runs.continuation.stepping import both_ways, box_end, inside, march
from geardyn.solve.bifurcations import CODIM2

#: The map's ``bifurcation`` flags that seed curves (each the kind of the curve it seeds).
RECORD_KINDS = ("fold", "period_doubling", "neimark_sacker")
#: The codimension-2 points that end a curve.
TERMINAL = ("resonance_1_1", "resonance_1_2")
#: The codimension-2 tests of each kind of curve, in the order of :func:`tests`.
TESTS = {
    "fold": ("cusp", "resonance_1_1", "fold_flip", "fold_neimark_sacker", "grazing_fold"),
    "period_doubling": ("fold_flip", "resonance_1_2", "flip_neimark_sacker", "grazing_flip"),
    "neimark_sacker": (*CODIM2[1:3], *CODIM2[4:7], "grazing_neimark_sacker"),
    "grazing": CODIM2[7:],
}


@dataclass(frozen=True)
class Codim2:
    """A codimension-2 point on a curve of kind ``curve_kind`` (multipliers of the n-period map)."""

    kind: str
    curve_kind: str
    p: float
    q: float
    state: np.ndarray
    multipliers: np.ndarray
    located: bool
    n: int


@dataclass
class Curve:
    """A continued curve of codimension-1 points (:class:`~geardyn.runs.continuation.corrector.Point`, two
    parameters), ordered along its arclength; end_status: why each end stopped (``box``, ``resonance_1_1``,
    ``step_too_small``, ...)."""

    kind: str
    n: int
    points: list[Point]
    scales: tuple[float, float, float]
    end_status: dict[str, str] = field(default_factory=dict)
    codim2: list[Codim2] = field(default_factory=list)

    def __len__(self) -> int:
        return len(self.points)

    p = property(lambda self: np.array([c.z[-2] for c in self.points]), doc="p at every point")
    q = property(lambda self: np.array([c.z[-1] for c in self.points]), doc="q at every point")
    residual = property(lambda self: np.array([c.G for c in self.points]), doc="the defining condition G")


class BoundaryCurve(NamedTuple):
    """A curve of a plane with its ``flank`` ("back": a back-flank grazing curve, else "working") and its
    ``origin`` (the seed it started from)."""

    curve: Curve
    flank: str = "working"
    origin: str = ""

    @property
    def kind(self) -> str:
        """Its kind in the curves file: ``back_grazing`` for a back-flank grazing curve."""
        return "back_grazing" if self.curve.kind == "grazing" and self.flank == "back" else self.curve.kind


def tests(kind: str, pt: Point) -> dict[str, float]:
    """The codimension-2 tests of a point (docs/orbits.md, section 5): the fold's normal-form coefficient, the
    Neimark-Sacker pair's trace -+ 2, det(others -+ I), the others' pair nearest the circle, the margin g."""
    o = pt.multipliers if kind == "grazing" else others(pt.multipliers, pt.crit)
    tr = float(sum(pt.crit).real)
    pre = {"fold": [pt.fold_a], "neimark_sacker": [tr - 2.0, tr + 2.0]}.get(kind, [])
    post = [] if kind == "grazing" else [pt.grazing]
    return dict(zip(TESTS[kind], [*pre, fold_test(o), pd_test(o), ns_test(o), *post], strict=True))


def _crossed(kind: str, name: str, a: Point, b: Point, ta: float, tb: float) -> bool:
    if not (np.isfinite(ta) and np.isfinite(tb)) or (ta > 0) == (tb > 0):
        return False
    if name.endswith("neimark_sacker") and not (kind == "neimark_sacker" and name != "double_neimark_sacker"):
        mu_a, mu_b = (
            (a.multipliers, b.multipliers)
            if kind == "grazing"
            else (others(a.multipliers, a.crit), others(b.multipliers, b.crit))
        )
        return abs(unstable_counts(mu_a)[1] - unstable_counts(mu_b)[1]) == 2
    return True


def _codim2(prob: CurveProblem, name: str, pt: Point, located: bool) -> Codim2:
    return Codim2(name, prob.kind, float(pt.z[-2]), float(pt.z[-1]), pt.x.copy(), pt.multipliers, located, prob.n)


def _events(prob: CurveProblem, a: Point, b: Point) -> list[Codim2]:
    """The codimension-2 points between consecutive points a and b, located by Brent on the arclength."""
    ta, tb = tests(prob.kind, a), tests(prob.kind, b)
    h = float(np.linalg.norm(b.z / prob.scale - a.z / prob.scale))
    found = []
    for name in ta:
        if not _crossed(prob.kind, name, a, b, ta[name], tb[name]):
            continue
        test = partial(lambda nm, pt: tests(prob.kind, pt)[nm], name)
        q = brent_on_step(lambda s: step(prob, a, s * h, prob.cs), test, a, b, prob.cs.locate_xtol)
        bracketed = a if abs(ta[name]) < abs(tb[name]) else b
        found.append(_codim2(prob, name, q, True) if q is not None else _codim2(prob, name, bracketed, False))
    return found


def shorter_period(plane: Plane, p: float, q: float, x: np.ndarray, n: int, tol: float = CURVES.merge_tol) -> bool:
    """True when the period-n orbit through x at (p, q) is one of a proper divisor m of n traversed n / m times
    (its m-th cycle point within ``tol`` max(1, max |x|) of x)."""
    return n > 1 and merged(plane.cycle(p, q, x, n), n, tol * max(1.0, float(np.max(np.abs(x))))) > 0


def _merged(prob: CurveProblem, pt: Point | None, tol: float | None = None) -> bool:
    tol = prob.cs.merge_tol if tol is None else tol
    return pt is not None and shorter_period(prob.plane, pt.p, pt.q, pt.x, prob.n, tol)


def _advance(
    prob: CurveProblem, box: Sequence[float], found: list[Codim2], cur: Point, ds: float
) -> tuple[list[Point], str] | None:
    """One step of a curve (:func:`~geardyn.runs.continuation.stepping.march`), ending on the box, at a 1:1 or 1:2
    resonance or on an orbit of a shorter period; the codimension-2 points passed go to ``found``."""
    z_pred = (cur.z / prob.scale + ds * cur.tangent) * prob.scale
    if not inside(z_pred, box, 2):
        end = box_end(prob, cur, z_pred, box, prob.cs)
        if _merged(prob, end):
            return [], "merged_into_shorter_period"
        found += _events(prob, cur, end) if end is not None else []
        return ([end] if end is not None else []), "box"
    new = step(prob, cur, ds, prob.cs)
    if new is None:
        return None
    if _merged(prob, new):
        return [], "merged_into_shorter_period"
    ev = _events(prob, cur, new)
    found += ev
    term = [c.kind for c in ev if c.kind in TERMINAL]
    return ([], term[0]) if term else ([new], "")


def continue_curve(
    plane: Plane,
    kind: str,
    n: int,
    x0: np.ndarray,
    start: tuple[float, float],
    critical: complex = complex("nan"),
    cs: ContinuationSettings = CURVES,
    along: str = "p",
) -> Curve | None:
    """The curve of ``kind`` (period n) through the point near (x0, start = (p0, q0)) with the critical multiplier
    ``critical`` (a Neimark-Sacker pair's upper one; default +1 / -1), both ways to ``plane.box``; the seed solved on
    the line through ``start`` along ``along``.  None when that fails or its orbit is of a shorter period (a fold's
    within ``merge_tol_fold``: the curve is then that orbit's period-doubling curve)."""
    box = tuple(plane.box)
    x0 = np.asarray(x0, dtype=float)
    if not inside(np.asarray(start), box, 2):
        return None
    prob = CurveProblem(
        plane, kind, n, x0.size, (max(1.0, float(np.max(np.abs(x0)))), box[1] - box[0], box[3] - box[2]), cs
    )
    crit = () if kind == "grazing" else (complex(critical if np.isfinite(critical) else TARGET[kind]),)
    z0 = np.concatenate([x0, start])
    k = 1 if along == "p" else 0
    ref = Point(z0, z0[:0], None, npar=2, crit=crit)
    seed = correct(prob, z0, np.eye(z0.size)[x0.size + k], start[k] / prob.scale[x0.size + k], cs, ref)
    if seed is None or _merged(prob, seed, cs.merge_tol_fold if kind == "fold" else cs.merge_tol):
        return None
    found: list[list[Codim2]] = []  # per march: up, then down

    def run(first: Point) -> tuple[list[Point], str]:
        found.append([])
        return march(first, partial(_advance, prob, box, found[-1]), prob.scale, cs)

    pts, ends = both_ways(run, seed)
    return Curve(kind, n, pts, prob.scales, ends, [c for events in reversed(found) for c in events])


def line_points(plane: Plane, curve: Curve, axis: str, value: float, cs: ContinuationSettings = CURVES) -> list[Point]:
    """The points where ``curve`` crosses the line ``axis`` ("p" or "q") = value, each solved by the corrector
    with the line as the extra equation (from the chord between the bracketing points; the last point counts)."""
    k, d = (0 if axis == "p" else 1), curve.points[0].z.size - 2
    prob = CurveProblem(plane, curve.kind, curve.n, d, curve.scales, cs)
    along = curve.p if axis == "p" else curve.q
    out = []
    for i, w in crossings(np.append(along, along[-1:]), value):
        a, b = curve.points[i], curve.points[min(i + 1, len(curve) - 1)]
        pt = correct(prob, a.z + w * (b.z - a.z), np.eye(d + 2)[d + k], value / prob.scale[d + k], cs, a)
        out += [pt] if pt is not None else []
    return out


def lies_on(curve: Curve, kind: str, n: int, p: float, q: float, tol: float, units: tuple[float, float]) -> bool:
    """The one test of whether (p, q) already lies on ``curve``: of that kind and period, within ``tol`` of its
    polyline in ``units`` (the box's sides, or the map's pixel)."""
    if curve.kind != kind or curve.n != n:
        return False
    pts, pt = np.column_stack([curve.p / units[0], curve.q / units[1]]), np.array([p / units[0], q / units[1]])
    return (float(np.linalg.norm(pts[0] - pt)) if len(pts) == 1 else segment_distance(pts[:-1], pts[1:], pt)) <= tol


def segment_distance(a: np.ndarray, b: np.ndarray, pt: np.ndarray) -> float:
    """Distance of pt from the nearest of the segments a[i] -> b[i] (inf without segments)."""
    if not len(a):
        return np.inf
    ab = b - a
    w = np.clip(np.sum((pt - a) * ab, axis=1) / np.maximum(np.sum(ab * ab, axis=1), libm.TINY), 0.0, 1.0)
    return float(np.min(np.linalg.norm(a + w[:, None] * ab - pt, axis=1)))


def crossings(values: np.ndarray, line: float) -> list[tuple[int, float]]:
    """(segment i, fraction w) where the polyline coordinate ``values`` crosses ``line``."""
    d = values - line
    out = []
    for i in range(d.size - 1):
        if d[i] == 0.0 or (d[i + 1] != 0.0 and (d[i] > 0) != (d[i + 1] > 0)):
            out.append((i, d[i] / (d[i] - d[i + 1]) if d[i] != d[i + 1] else 0.0))
    return out


def bounds_stable(kind: str, multipliers: np.ndarray, crit: Sequence[complex]) -> bool:
    """True when every multiplier but the critical ones lies inside the unit circle (for grazing: all): the curve
    is a boundary of a stable orbit there."""
    mu = np.asarray(multipliers)
    return bool(np.all(libm.cabs(mu if kind == "grazing" else others(mu, tuple(crit))) < 1.0))
