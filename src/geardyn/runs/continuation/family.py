"""The model adapter: a parameter family of periodic systems (the system at a parameter value, its
stroboscopic map with monodromy, the grazing margin of an orbit), with the spline cache of
:class:`KHVFamily` for a KHV design."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any, Protocol

import numpy as np
from scipy.interpolate import CubicSpline

from geardyn.khv import point
from geardyn.khv.model import Coefficients
from geardyn.solve.base import SimulationSettings
from geardyn.solve.run import simulate
from geardyn.solve.shooting import FlowMap, khv_flow


class Family(Protocol):
    """What continuation needs of a parameter family of periodic systems."""

    def flow(self, p: float, n: int) -> FlowMap: ...

    def grazing(self, p: float, x: np.ndarray, n: int) -> float: ...


class KHVFamily:
    """A KHV design along one control parameter, with the other overrides fixed.

    The coefficients come from :func:`geardyn.khv.point.point_coefficients` at ``nodes`` values of
    the parameter over [lo, hi] and are interpolated in between by cubic splines (field by field):
    one call of point_coefficients costs about 2 ms (geometry and mesh stiffness), a spline
    evaluation microseconds.  For b, e and w the coefficients are linear in the parameter (exact);
    for x1 the largest relative difference to a direct evaluation at the mid-points between nodes is
    measured on construction (:attr:`interpolation_error`).  ``nodes = 0`` calls point_coefficients
    at every p instead.  Coefficient sets are cached by p (the cache is emptied past 256 entries).
    """

    def __init__(
        self,
        design: Any,
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
            cs = [self._direct(v) for v in grid]
            d0 = cs[0].as_dict()
            self._const = {k: v for k, v in d0.items() if not isinstance(v, float)}
            self._floats = [k for k, v in d0.items() if isinstance(v, float)]
            table = np.array([[c.as_dict()[k] for k in self._floats] for c in cs])
            self._spline = CubicSpline(grid, table, axis=0)
            self.interpolation_error = self._spline_error(grid)
        self._cache: dict[float, Coefficients] = {}

    def _spline_error(self, grid: np.ndarray) -> float:
        """Largest relative difference of the splines to a direct evaluation at about five mid-points."""
        mids = 0.5 * (grid[1:] + grid[:-1])
        probe = mids[:: max(1, len(mids) // 5)]
        err = 0.0
        for v in probe:
            direct = np.array([self._direct(v).as_dict()[k] for k in self._floats])
            interp = self._spline(v)
            err = max(err, float(np.max(np.abs(interp - direct) / np.maximum(np.abs(direct), 1e-300))))
        return err

    def _direct(self, p: float) -> Coefficients:
        return point.point_coefficients(self.design, {**self.fixed, self.parameter: float(p)})

    def coefficients(self, p: float) -> Coefficients:
        """The system at parameter value p (spline-interpolated when ``nodes >= 4``)."""
        p = float(p)
        c = self._cache.get(p)
        if c is None:
            if self.nodes >= 4:
                vals = self._spline(p)
                d = dict(self._const)
                d.update({k: float(v) for k, v in zip(self._floats, vals, strict=True)})
                d["backlash_on"] = bool(d.get("backlash_on", True))
                c = Coefficients(**d)
            else:
                c = self._direct(p)
            if len(self._cache) > 256:
                self._cache.clear()
            self._cache[p] = c
        return c

    def flow(self, p: float, n: int) -> FlowMap:
        return khv_flow(self.coefficients(p), n, self.settings)

    def grazing(self, p: float, x: np.ndarray, n: int) -> float:
        return grazing_margin(self.coefficients(p), x, n, self.settings)


def grazing_margin(system: Coefficients, x: np.ndarray, n: int, settings: SimulationSettings) -> float:
    """g = min over the cycle of |x_VH| - b (NaN without backlash): g < 0 when contact is lost.

    Dense run of the n periods from x (every step).  When x_VH changes sign the orbit crosses the
    whole backlash zone and g = -b (|x_VH| has a kink at 0, which a parabola would misread as a
    minimum above 0).  Otherwise the discrete minimum of |x_VH| is refined by the parabola through it
    and its two neighbours.
    """
    if not system.backlash_on or system.b <= 0.0:
        return float("nan")
    s = SimulationSettings(
        integrator="rk4_event",
        steps_per_period=settings.steps_per_period,
        transient_periods=0,
        recorded_periods=n,
        divergence_threshold=settings.divergence_threshold,
    )
    r = simulate(system, s, x, dense=True)
    if r.diverged or r.states is None or r.states.shape[0] < 3:
        return float("nan")
    x2 = np.concatenate([[x[1]], r.states[:, 1]])
    if x2.min() < 0.0 < x2.max():
        return -float(system.b)  # x_VH changes sign: the orbit passes right through the backlash
    a = np.abs(x2)
    i = int(np.argmin(a))
    m = float(a[i])
    if 0 < i < a.size - 1:
        y0, y1, y2 = a[i - 1], a[i], a[i + 1]
        den = y0 - 2 * y1 + y2
        if den > 0:
            m = float(y1 - 0.125 * (y2 - y0) ** 2 / den)
    return m - system.b


class CallableFamily:
    """A family from plain functions: ``flow_of(p, n) -> FlowMap`` (no grazing)."""

    def __init__(self, flow_of: Callable[[float, int], FlowMap]):
        self._flow_of = flow_of

    def flow(self, p: float, n: int) -> FlowMap:
        return self._flow_of(p, n)

    def grazing(self, p: float, x: np.ndarray, n: int) -> float:
        return float("nan")


def cycle_states(family: Family, p: float, x: np.ndarray, n: int) -> np.ndarray:
    """The n phase-0 points (n, d) of a period-n orbit through x (x first)."""
    pts = [np.asarray(x, dtype=float)]
    fl = family.flow(p, 1)
    for _ in range(n - 1):
        y, _ = fl(pts[-1], False)
        if y is None:
            break
        pts.append(y)
    return np.array(pts)
