"""The model adapters: one- and two-parameter families of periodic systems (flow with monodromy, cycle, grazing
margins), :class:`KHVFamily` and :class:`KHVPlane` of a KHV design, a line of a plane as a family."""

from __future__ import annotations

import copy
from collections.abc import Callable, Mapping, Sequence
from typing import Protocol, TypeVar

import numpy as np
from scipy.interpolate import CubicSpline

from geardyn import libm
from geardyn.khv import point
from geardyn.khv.design import KHVDesign
from geardyn.khv.model import Coefficients
from geardyn.solve.base import SimulationSettings
from geardyn.solve.run import simulate
from geardyn.solve.shooting import FlowMap, cycle_points, khv_flow, khv_flows, period_settings

#: Relative agreement of a coefficient from the line's spline with the design's at the box corner, where the
#: spline passes through its node: rounding only (1e-9 is about 4e6 times the double's resolution).
CORNER_RTOL = 1e-9


class Family(Protocol):
    """What continuation needs of a parameter family of periodic systems: the n-period map with its monodromy,
    the n phase-0 points of the orbit through x (x first), the grazing margin of the orbit."""

    def flow(self, p: float, n: int) -> FlowMap: ...

    def cycle(self, p: float, x: np.ndarray, n: int) -> np.ndarray: ...

    def grazing(self, p: float, x: np.ndarray, n: int) -> float: ...


class Plane(Protocol):
    """What a two-parameter curve needs of a plane of periodic systems: its box (p_lo, p_hi, q_lo, q_hi), the
    n-period map at (p, q) with its monodromy, the n phase-0 points of the orbit through x, its grazing margin."""

    @property
    def box(self) -> tuple[float, float, float, float]: ...

    def flow(self, p: float, q: float, n: int) -> FlowMap: ...

    def cycle(self, p: float, q: float, x: np.ndarray, n: int) -> np.ndarray: ...

    def grazing(self, p: float, q: float, x: np.ndarray, n: int) -> float: ...


class KHVFamily:
    """A KHV design along one control parameter, the other overrides fixed: the coefficients of
    :func:`geardyn.khv.point.point_coefficients` at ``nodes`` values over [lo, hi], cubic splines in between
    (``nodes = 0``: direct), the measured :attr:`interpolation_error`, cached by p (docs/orbits.md, section 2)."""

    def __init__(
        self,
        design: KHVDesign,
        parameter: str,
        fixed: Mapping[str, float],
        lo: float,
        hi: float,
        settings: SimulationSettings | None = None,
        nodes: int = 101,
    ):
        self.design, self.parameter, self.fixed = design, parameter, dict(fixed)
        self.lo, self.hi = float(lo), float(hi)
        self.settings = settings or point.integration_settings(design)
        self.nodes = int(nodes)
        self.interpolation_error = 0.0
        if self.nodes >= 4:
            grid = np.linspace(self.lo, self.hi, self.nodes)
            at_nodes = [self._direct(v) for v in grid]
            d0 = at_nodes[0].as_dict()
            self._const = {k: v for k, v in d0.items() if not isinstance(v, float)}
            self._floats = [k for k, v in d0.items() if isinstance(v, float)]
            table = np.array([self._values(c) for c in at_nodes])
            self._spline = CubicSpline(grid, table, axis=0)
            mids = 0.5 * (grid[1:] + grid[:-1])  # the error: the largest relative one at about five mid-points
            for v in mids[:: max(1, len(mids) // 5)]:
                direct = np.array(self._values(self._direct(v)))
                err = np.abs(self._spline(v) - direct) / np.maximum(np.abs(direct), libm.TINY)
                self.interpolation_error = max(self.interpolation_error, float(np.max(err)))
        self._cache: dict[float, Coefficients] = {}

    def _values(self, c: Coefficients) -> list[float | str | int]:
        """The float fields of ``c`` that the splines interpolate, in their order."""
        d = c.as_dict()
        return [d[k] for k in self._floats]

    def _direct(self, p: float) -> Coefficients:
        return point.point_coefficients(self.design, {**self.fixed, self.parameter: float(p)})

    def coefficients(self, p: float) -> Coefficients:
        """The system at parameter value p (spline-interpolated when ``nodes >= 4``)."""
        return cached(self._cache, float(p), self._make)

    def _make(self, p: float) -> Coefficients:
        if self.nodes < 4:
            return self._direct(p)
        d: dict[str, float | int | str | bool] = dict(self._const)
        d.update({k: float(v) for k, v in zip(self._floats, self._spline(p), strict=True)})
        d["backlash_on"] = bool(d.get("backlash_on", True))
        return Coefficients(**d)  # type: ignore[arg-type]  # the fields of as_dict(), each of its own type

    def flow(self, p: float, n: int) -> FlowMap:
        return khv_flow(self.coefficients(p), n, self.settings)

    def cycle(self, p: float, x: np.ndarray, n: int) -> np.ndarray:
        return cycle_points([self.coefficients(p)], [x], n, self.settings)[0][0]

    def grazing(self, p: float, x: np.ndarray, n: int) -> float:
        return grazing_margin(self.coefficients(p), x, n, self.settings)

    def back_grazing(self, p: float, x: np.ndarray, n: int) -> float:
        return back_margin(self.coefficients(p), x, n, self.settings)


def grazing_margin(system: Coefficients, x: np.ndarray, n: int, settings: SimulationSettings) -> float:
    """g = min over the cycle of |x_VH| - b (NaN without backlash): g < 0 when contact is lost; -b when x_VH
    changes sign, else the minimum of |x_VH| over a dense run refined by a parabola (docs/orbits.md, section 3)."""
    x2 = _dense_xvh(system, x, n, settings)
    if x2 is None:
        return float("nan")
    if x2.min() < 0.0 < x2.max():
        return -float(system.b)  # x_VH changes sign: the orbit passes right through the backlash
    return refined_min(np.abs(x2)) - system.b


def back_margin(system: Coefficients, x: np.ndarray, n: int, settings: SimulationSettings) -> float:
    """h = min over the cycle of s X_VH + b, s the drive side (the sign of the static mesh deflection beyond
    the backlash): h < 0 when the teeth strike on the back flank (NaN without backlash); refined as g."""
    x2 = _dense_xvh(system, x, n, settings)
    if x2 is None:
        return float("nan")
    return refined_min((-1.0 if float(system.static_state()[1]) < 0.0 else 1.0) * x2) + system.b


def _dense_xvh(system: Coefficients, x: np.ndarray, n: int, settings: SimulationSettings) -> np.ndarray | None:
    """X_VH at x and every step of a dense run of n periods from x with the shooting's settings (the caller's
    integrator, steps, alignment and divergence threshold); None without backlash, when the run diverges or has
    fewer than 3 points."""
    if not system.backlash_on or system.b <= 0.0:
        return None
    r = simulate(system, period_settings(settings, n), x, dense=True)
    if r.diverged or r.states is None or r.states.shape[0] < 3:
        return None
    return np.concatenate([[x[1]], r.states[:, 1]])


def refined_min(a: np.ndarray) -> float:
    """The discrete minimum of ``a`` refined by the parabola through it and its two neighbours."""
    i = int(np.argmin(a))
    m = float(a[i])
    if 0 < i < a.size - 1:
        y0, y1, y2 = a[i - 1], a[i], a[i + 1]
        den = y0 - 2 * y1 + y2
        if den > 0:
            m = float(y1 - 0.125 * (y2 - y0) ** 2 / den)
    return m


#: (state after n periods, monodromy or None) per point; (None, None) where the run diverged.
Flows = list[tuple[np.ndarray | None, np.ndarray | None]]


def flows(
    plane: Plane, at: Sequence[tuple[float, float]], xs: Sequence[np.ndarray], n: int, jac: Sequence[bool]
) -> Flows:
    """The n-period maps of ``plane`` at the points ``at`` (p, q), each from its x, with the monodromy where
    ``jac`` asks for it: in one kernel call when the plane batches them (its ``flows``, a :class:`KHVPlane`), else
    one :meth:`Plane.flow` each; the same numbers either way."""
    batch = getattr(plane, "flows", None)
    if batch is not None:
        return batch(at, xs, n, jac)
    return [plane.flow(p, q, n)(x, j) for (p, q), x, j in zip(at, xs, jac, strict=True)]


K = TypeVar("K")
V = TypeVar("V")


def cached(cache: dict[K, V], key: K, make: Callable[[K], V]) -> V:
    """cache[key], made by ``make(key)`` on a miss (the cache is emptied past 256 entries)."""
    c = cache.get(key)
    if c is None:
        c = make(key)
        if len(cache) > 256:
            cache.clear()
        cache[key] = c
    return c


class PlaneLine:
    """The line of ``plane`` along p (``along`` = "p", q held at ``at``) or along q, as a :class:`Family`."""

    def __init__(self, plane: Plane, along: str, at: float):
        self.plane, self.along, self.at = plane, along, float(at)

    def _pq(self, t: float) -> tuple[float, float]:
        return (t, self.at) if self.along == "p" else (self.at, t)

    def flow(self, t: float, n: int) -> FlowMap:
        return self.plane.flow(*self._pq(t), n)

    def cycle(self, t: float, x: np.ndarray, n: int) -> np.ndarray:
        return self.plane.cycle(*self._pq(t), x, n)

    def grazing(self, t: float, x: np.ndarray, n: int) -> float:
        return self.plane.grazing(*self._pq(t), x, n)


class KHVPlane:
    """A KHV design over two control parameters ``names`` = (p, q) in ``box`` = (p_lo, p_hi, q_lo, q_hi),
    the other overrides ``fixed`` (docs/orbits.md, section 2: the coefficients along one parameter from a
    :class:`KHVFamily` when the other is b, e or w and agrees at the box corner).  Cached by (p, q)."""

    def __init__(
        self,
        design: KHVDesign,
        names: tuple[str, str],
        fixed: Mapping[str, float],
        box: tuple[float, float, float, float],
        settings: SimulationSettings | None = None,
        nodes: int = 0,
    ):
        self.design, self.names, self.fixed = design, (names[0], names[1]), dict(fixed)
        self.box = (float(box[0]), float(box[1]), float(box[2]), float(box[3]))
        self.settings = settings or point.integration_settings(design)
        swap = self.names[0] in point.COEFFICIENT_FIELDS and self.names[1] not in point.COEFFICIENT_FIELDS
        self._swap, fast = swap, self.names[0 if swap else 1]
        self._field = point.COEFFICIENT_FIELDS.get(fast)
        self._cache: dict[tuple[float, float], Coefficients] = {}
        self.margin: Callable[..., float] = grazing_margin
        if self._field is not None:
            lo, hi = self.box[2:] if swap else self.box[:2]
            mid = 0.5 * (self.box[0] + self.box[1]) if swap else 0.5 * (self.box[2] + self.box[3])
            self._line = KHVFamily(design, self.names[1 if swap else 0], {**self.fixed, fast: mid}, lo, hi, None, nodes)
            corner = self.coefficients(self.box[1], self.box[3]).as_dict()
            direct = self._direct((self.box[1], self.box[3])).as_dict()
            off = (
                abs(float(corner[k]) - v) > CORNER_RTOL * max(1.0, abs(v))
                for k, v in direct.items()
                if isinstance(v, float)
            )
            if any(off):
                self._field = None
            self._cache.clear()

    def _direct(self, key: tuple[float, float]) -> Coefficients:
        return point.point_coefficients(self.design, {**self.fixed, self.names[0]: key[0], self.names[1]: key[1]})

    def _make(self, key: tuple[float, float]) -> Coefficients:
        if self._field is None:
            return self._direct(key)
        slow, fast = (key[1], key[0]) if self._swap else key
        return self._line.coefficients(slow).replace(**{self._field: fast})

    def coefficients(self, p: float, q: float) -> Coefficients:
        return cached(self._cache, (float(p), float(q)), self._make)

    def flow(self, p: float, q: float, n: int) -> FlowMap:
        return khv_flow(self.coefficients(p, q), n, self.settings)

    def flows(self, at: Sequence[tuple[float, float]], xs: Sequence[np.ndarray], n: int, jac: Sequence[bool]) -> Flows:
        """:meth:`flow` at each point ``at`` (p, q) from its x, in one batch (:func:`flows`)."""
        return khv_flows([self.coefficients(p, q) for p, q in at], xs, n, jac, self.settings)

    def cycle(self, p: float, q: float, x: np.ndarray, n: int) -> np.ndarray:
        return cycle_points([self.coefficients(p, q)], [x], n, self.settings)[0][0]

    def grazing(self, p: float, q: float, x: np.ndarray, n: int) -> float:
        return self.margin(self.coefficients(p, q), x, n, self.settings)

    def back_flank(self) -> KHVPlane:
        """This plane (sharing its coefficients) with the back flank's margin (:func:`back_margin`) as its
        grazing margin: its grazing curves are where back-side contact begins."""
        back = copy.copy(self)
        back.margin = back_margin
        return back
