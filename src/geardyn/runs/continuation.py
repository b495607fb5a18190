"""Branches of periodic orbits along a sweep parameter: pseudo-arclength continuation, Floquet
multipliers per point, typed bifurcation points.

A *family* gives, for a parameter value p, the n-period stroboscopic map with its monodromy
(:class:`KHVFamily` for a KHV design: the parameter enters through
:func:`geardyn.khv.point.point_coefficients`).  :func:`continue_branch` follows the fixed points of
that map, F(x, p) = phi_nT(x; p) - x = 0, in both directions from a seed:

* predictor: a step ds along the unit tangent of the branch in the scaled variables
  u = (x / x_scale, p / p_scale) (p_scale: the sweep's range, x_scale: max(1, max |x|) at the seed);
* corrector: Newton on (F(x, p) = 0, t . (u - u_pred) = 0) with dF/dx = M - I from the
  variational equations and dF/dp by a forward difference; the extra equation lets the corrector
  pass folds, where M - I is singular;
* step control: ds grows by 1.3 after a corrector that needed at most 3 evaluations, halves after a
  failure, and never exceeds ``ds_max`` (in units of the sweep range), so a branch of the sweep's
  range has about 1 / ds_max points.

Bifurcation points (test functions between consecutive points, then located):

=================  ==========================================  ===============================
type               test function changes sign                  located by
=================  ==========================================  ===============================
period_doubling    det(M + I) (a real multiplier crosses -1)    secant-bisection (Brent) on p
neimark_sacker     |mu| - 1 of the complex pair that crosses    Brent on p; rotation number
                   (the count of complex |mu| > 1 changes by 2)  arg(mu) / (2 pi) at the point
fold               dp/ds (the branch turns; a multiplier        quadratic interpolation of p(s)
                   crosses +1)
branch_point       det(M - I) without a turn of p               Brent on p
grazing            g = min over the cycle of |x_VH| - b          Brent on p (dense run of the
                   (g < 0: contact is lost during the cycle)     cycle at each trial)
=================  ==========================================  ===============================

Brent's method re-shoots the orbit at fixed p (Newton from the state interpolated between the
two bracketing points), so the located parameter is accurate to the shooting tolerance, not to
the step size.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np
from scipy.interpolate import CubicSpline
from scipy.optimize import brentq

from geardyn.config import settings_from
from geardyn.khv import point
from geardyn.khv.model import Coefficients
from geardyn.solve.base import SimulationSettings
from geardyn.solve.shooting import FlowMap, khv_flow, newton_shooting, rotation_number, sorted_multipliers
from geardyn.solve.simulate import simulate

log = logging.getLogger("geardyn.continuation")

BIFURCATION_TYPES = ("period_doubling", "neimark_sacker", "fold", "branch_point", "grazing")


# ----------------------------------------------------------------------------------------------
# families
# ----------------------------------------------------------------------------------------------


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
    at every p instead.
    """

    def __init__(self, design: Any, parameter: str, fixed: Mapping[str, float], lo: float, hi: float,
                 settings: SimulationSettings | None = None, nodes: int = 101):
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
            mids = 0.5 * (grid[1:] + grid[:-1])
            probe = mids[:: max(1, len(mids) // 5)]
            err = 0.0
            for v in probe:
                direct = np.array([self._direct(v).as_dict()[k] for k in self._floats])
                interp = self._spline(v)
                err = max(err, float(np.max(np.abs(interp - direct) / np.maximum(np.abs(direct), 1e-300))))
            self.interpolation_error = err
        self._cache: dict[float, Coefficients] = {}

    def _direct(self, p: float) -> Coefficients:
        return point.point_coefficients(self.design, {**self.fixed, self.parameter: float(p)})

    def coefficients(self, p: float) -> Coefficients:
        p = float(p)
        c = self._cache.get(p)
        if c is None:
            if self.nodes >= 4:
                vals = self._spline(p)
                d = dict(self._const)
                d.update({k: float(v) for k, v in zip(self._floats, vals)})
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
    s = SimulationSettings(integrator="rk4_event", steps_per_period=settings.steps_per_period, transient_periods=0,
                           recorded_periods=n, divergence_threshold=settings.divergence_threshold)
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


# ----------------------------------------------------------------------------------------------
# results
# ----------------------------------------------------------------------------------------------


@dataclass
class Bifurcation:
    """A typed bifurcation point of a branch (multipliers of the n-period map at the point)."""

    kind: str
    p: float
    state: np.ndarray
    multipliers: np.ndarray
    critical: complex  # the multiplier that crosses (nan for grazing)
    rotation_number: float  # arg(mu) / (2 pi) for neimark_sacker, else nan
    index: int  # the branch point just before it
    located: bool  # refined (Brent / parabola) rather than only bracketed
    n: int = 1


@dataclass
class Branch:
    """One continued branch of period-n orbits, ordered along the arclength.

    p (m,), states (m, d) at phase 0, multipliers (m, d) by decreasing modulus, arclength (m,),
    grazing (m,) margin g = min |x_VH| - b over the cycle (NaN when not computed), iterations (m,)
    corrector evaluations.  end_status: why each end stopped (``down``, ``up``).
    """

    n: int
    p: np.ndarray
    states: np.ndarray
    multipliers: np.ndarray
    arclength: np.ndarray
    grazing: np.ndarray
    iterations: np.ndarray
    end_status: dict[str, str] = field(default_factory=dict)
    bifurcations: list[Bifurcation] = field(default_factory=list)
    seed_p: float = float("nan")
    tangents: np.ndarray | None = None  # (m, d + 1) unit tangents in the scaled variables

    @property
    def stable(self) -> np.ndarray:
        return np.max(np.abs(self.multipliers), axis=1) < 1.0

    def __len__(self) -> int:
        return int(self.p.size)


@dataclass(frozen=True)
class ContinuationSettings:
    """Numbers of :func:`continue_branch` (ds in units of the parameter range; see module doc).

    tol: shooting residual max |phi(x) - x| <= tol * max(1, max |x|).  dp_rel: forward-difference
    step of dF/dp relative to the range.  max_points: per direction.  grazing: compute the grazing
    margin at every point (one dense run of the cycle each).  locate: refine bifurcation points.
    """

    ds: float = 1e-3
    ds_min: float = 1e-7
    ds_max: float = 1e-3
    tol: float = 1e-9
    max_corrector: int = 8
    dp_rel: float = 1e-6
    max_points: int = 5000
    grazing: bool = True
    locate: bool = True
    locate_xtol: float = 1e-9

    @classmethod
    def from_mapping(cls, spec: Mapping[str, Any] | None) -> ContinuationSettings:
        return settings_from(cls, spec, "continuation settings")


# ----------------------------------------------------------------------------------------------
# continuation
# ----------------------------------------------------------------------------------------------


class _Corrector:
    """Newton on the augmented system in scaled variables u = (x / sx, p / sp)."""

    def __init__(self, family: Family, n: int, sx: float, sp: float, cs: ContinuationSettings):
        self.family, self.n, self.sx, self.sp, self.cs = family, n, sx, sp, cs
        self.evals = 0

    def evaluate(self, x: np.ndarray, p: float, Fp: np.ndarray | None = None):
        """F, dF/dx (= M - I), dF/dp, M at (x, p); None when the orbit diverged.  dF/dp by a forward
        difference unless ``Fp`` is given (the corrector reuses the one of its first iterate: a chord
        step in the parameter column, which saves one new system per iteration)."""
        phi, M = self.family.flow(p, self.n)(x, True)
        self.evals += 1
        if phi is None:
            return None
        if Fp is None:
            dp = self.cs.dp_rel * self.sp
            phi2, _ = self.family.flow(p + dp, self.n)(x, False)
            if phi2 is None:
                return None
            Fp = (phi2 - phi) / dp
        F = phi - x
        return F, M - np.eye(x.size), Fp, M

    def tangent(self, A: np.ndarray, Fp: np.ndarray, t_prev: np.ndarray) -> np.ndarray:
        """Unit null vector of [A sx, Fp sp] oriented like t_prev."""
        d = A.shape[0]
        J = np.zeros((d + 1, d + 1))
        J[:d, :d] = A * self.sx
        J[:d, d] = Fp * self.sp
        J[d] = t_prev
        rhs = np.zeros(d + 1)
        rhs[d] = 1.0
        t = np.linalg.solve(J, rhs)
        t /= np.linalg.norm(t)
        return t if float(t @ t_prev) >= 0 else -t

    def correct(self, x: np.ndarray, p: float, t: np.ndarray):
        """Converged (x, p, M, A, Fp, evaluations) or None."""
        d = x.size
        u_pred = np.append(x / self.sx, p / self.sp)
        last = np.inf
        Fp = None
        for it in range(self.cs.max_corrector):
            ev = self.evaluate(x, p, Fp)
            if ev is None:
                return None
            F, A, Fp, M = ev
            res = float(np.max(np.abs(F)))
            if not np.isfinite(res):
                return None
            if res <= self.cs.tol * max(1.0, float(np.max(np.abs(x)))) and last < 1e-6:
                return x, p, M, A, Fp, it + 1
            J = np.zeros((d + 1, d + 1))
            J[:d, :d] = A * self.sx
            J[:d, d] = Fp * self.sp
            J[d] = t
            g = np.append(F, float(t @ (np.append(x / self.sx, p / self.sp) - u_pred)))
            try:
                du = np.linalg.solve(J, -g)
            except np.linalg.LinAlgError:
                return None
            last = float(np.max(np.abs(du)))
            if last > 0.5:  # far off the predicted point: let the step control shorten ds
                return None
            x = x + du[:d] * self.sx
            p = p + du[d] * self.sp
        return None


def _merged_period(corr: _Corrector, x: np.ndarray, p: float, rtol: float = 1e-6) -> int:
    """For a period-n branch (n > 1): the proper divisor m of n for which x is already a fixed point of
    the m-period map (within rtol * x_scale), else 0.  A period-2n branch that reaches a second
    period doubling merges there into the period-n orbit (traversed twice) and would otherwise
    continue along it."""
    n = corr.n
    for m in range(1, n):
        if n % m:
            continue
        y, _ = corr.family.flow(p, m)(x, False)
        if y is not None and float(np.max(np.abs(y - x))) <= rtol * corr.sx:
            return m
    return 0


def _march(corr: _Corrector, x: np.ndarray, p: float, t: np.ndarray, lo: float, hi: float,
           cs: ContinuationSettings, first: tuple) -> tuple[list, str]:
    """Points along one direction (excluding the start); returns (points, end status)."""
    pts: list = []
    ds = cs.ds
    sx, sp = corr.sx, corr.sp
    d = x.size
    _, _, _, A, Fp, _ = first
    u_start, t_start = np.append(x / sx, p / sp), t.copy()
    while len(pts) < cs.max_points:
        u = np.append(x / sx, p / sp) + ds * t
        xp, pp = u[:d] * sx, u[d] * sp
        if pp > hi or pp < lo:
            bound = hi if pp > hi else lo
            if abs(t[d]) < 1e-12:
                return pts, "range"
            frac = (bound - p) / (pp - p)
            if frac <= 1e-9:
                return pts, "range"
            # last point exactly on the bound: fixed-p Newton from the shortened prediction
            xs = x + frac * (xp - x)
            r = newton_shooting(corr.family.flow(bound, corr.n), xs, corr.n, cs.tol)
            if r.converged:
                ev = corr.evaluate(r.state, bound)
                if ev is not None:
                    F, A2, Fp2, M = ev
                    t = corr.tangent(A2, Fp2, t)
                    pts.append((r.state, bound, M, t, r.iterations + 1))
            return pts, "range"
        out = corr.correct(xp, pp, t)
        if out is None:
            ds *= 0.5
            if ds < cs.ds_min:
                return pts, "step_too_small"
            continue
        x_new, p_new, M, A, Fp, its = out
        merged = _merged_period(corr, x_new, p_new)
        if merged:
            return pts, f"merged_into_period_{merged}"
        try:
            t = corr.tangent(A, Fp, t)
        except np.linalg.LinAlgError:
            return pts, "singular_tangent"
        x, p = x_new, p_new
        pts.append((x, p, M, t, its))
        u_now = np.append(x / sx, p / sp)
        if len(pts) > 10 and float(np.linalg.norm(u_now - u_start)) < ds and float(t @ t_start) > 0:
            return pts, "closed_loop"  # an isola: back at the seed
        if its <= 3:
            ds = min(ds * 1.3, cs.ds_max)
        if float(np.max(np.abs(sorted_multipliers(M)))) > 1e8:
            return pts, "multipliers_too_large"
    return pts, "max_points"


def continue_branch(family: Family, p0: float, x0: np.ndarray, n: int, lo: float, hi: float,
                    cs: ContinuationSettings = ContinuationSettings(),
                    directions: tuple[str, ...] = ("down", "up")) -> Branch | None:
    """Shoot the period-n orbit at p0 from x0, then continue it within [lo, hi] in ``directions``
    (``up``: the direction of increasing p at the seed).

    Returns None when the shooting at p0 does not converge.  Bifurcations are detected (and located
    when ``cs.locate``) on the returned branch.
    """
    r = newton_shooting(family.flow(p0, n), x0, n, cs.tol)
    if not r.converged:
        log.info("seed at p = %g (period %d) not converged: %s", p0, n, r.status)
        return None
    sx = max(1.0, float(np.max(np.abs(r.state))))
    sp = (hi - lo) if hi > lo else 1.0
    corr = _Corrector(family, n, sx, sp, cs)
    ev = corr.evaluate(r.state, p0)
    if ev is None:
        return None
    F, A, Fp, M = ev
    d = r.state.size
    # tangent at the seed: (dx/dp, 1) from A dx = -Fp, in scaled variables
    try:
        dxdp = np.linalg.solve(A, -Fp)
        t0 = np.append(dxdp * sp / sx, 1.0)
    except np.linalg.LinAlgError:
        t0 = np.zeros(d + 1)
        t0[d] = 1.0
    t0 /= np.linalg.norm(t0)
    first = (r.state, p0, M, A, Fp, 1)
    up, st_up = _march(corr, r.state, p0, t0, lo, hi, cs, first) if "up" in directions else ([], "not_followed")
    if st_up == "closed_loop":
        down, st_down = [], "closed_loop"  # the up march went round the whole isola
    else:
        down, st_down = (_march(corr, r.state, p0, -t0, lo, hi, cs, first) if "down" in directions
                         else ([], "not_followed"))
    # the down march's tangents point down the branch: flip them to the branch order
    down = [(q[0], q[1], q[2], -q[3], q[4]) for q in reversed(down)]
    pts = down + [(r.state, p0, M, t0, r.iterations)] + up
    ends = {"down": st_down, "up": st_up}
    br = _assemble(family, pts, n, sx, sp, ends, p0, cs, corr)
    if n > 1:
        # a fold of a period-n branch on a period-m orbit (m | n) is where the branch was born at (or
        # merges back into) a period doubling of the period-m orbit: beyond it lies the same orbit
        # shifted by m periods.  Cut there (the period doubling is a point of the period-m branch).
        seed = len(down)
        for bf in br.bifurcations:
            m = _merged_period(corr, bf.state, bf.p, 1e-4) if bf.kind == "fold" else 0
            if m:
                if bf.index >= seed:
                    pts, ends["up"] = pts[:bf.index + 1], f"merged_into_period_{m}"
                else:
                    pts, ends["down"] = pts[bf.index + 1:], f"merged_into_period_{m}"
                br = _assemble(family, pts, n, sx, sp, ends, p0, cs, corr)
                break
    return br


def _assemble(family: Family, pts: list, n: int, sx: float, sp: float, ends: dict[str, str], p0: float,
              cs: ContinuationSettings, corr: _Corrector) -> Branch:
    states = np.array([q[0] for q in pts])
    ps = np.array([q[1] for q in pts])
    mult = np.array([sorted_multipliers(q[2]) for q in pts])
    tang = np.array([q[3] for q in pts])
    u = np.column_stack([states / sx, ps / sp])
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(u, axis=0), axis=1))])
    graz = np.array([family.grazing(q[1], q[0], n) for q in pts]) if cs.grazing else np.full(len(pts), np.nan)
    br = Branch(n=n, p=ps, states=states, multipliers=mult, arclength=arc, grazing=graz,
                iterations=np.array([q[4] for q in pts], dtype=np.int32), end_status=dict(ends), seed_p=float(p0))
    br.bifurcations = detect_bifurcations(family, br, tang, cs, corr)
    return br


# ----------------------------------------------------------------------------------------------
# bifurcation detection
# ----------------------------------------------------------------------------------------------


def _is_complex(mu: np.ndarray) -> np.ndarray:
    return np.abs(mu.imag) > 1e-8 * np.maximum(np.abs(mu), 1e-300)


def _counts(mu: np.ndarray) -> tuple[int, int]:
    out = np.abs(mu) > 1.0
    return int(out.sum()), int((out & _is_complex(mu)).sum())


def pd_test(mu: np.ndarray) -> float:
    """det(M + I) = prod(mu + 1): changes sign when a real multiplier crosses -1."""
    return float(np.prod(mu + 1.0).real)


def fold_test(mu: np.ndarray) -> float:
    """det(M - I) = prod(mu - 1): changes sign when a real multiplier crosses +1."""
    return float(np.prod(mu - 1.0).real)


def ns_pair(mu: np.ndarray) -> complex | None:
    """The complex multiplier (upper half plane) nearest the unit circle, if any."""
    c = mu[_is_complex(mu) & (mu.imag > 0)]
    if c.size == 0:
        return None
    return complex(c[np.argmin(np.abs(np.abs(c) - 1.0))])


def ns_product(mu: np.ndarray) -> float:
    """prod over the complex multipliers in the upper half plane of (|mu| - 1): changes sign when one
    pair crosses the unit circle, whatever the other pairs do (NaN without complex multipliers)."""
    c = mu[_is_complex(mu) & (mu.imag > 0)]
    return float(np.prod(np.abs(c) - 1.0)) if c.size else float("nan")


def _lin_zero(a: float, b: float) -> float:
    return a / (a - b) if a != b else 0.5


@dataclass
class _Onb:
    """A corrected point on the branch between two stored points (u: fraction of the arclength step)."""

    u: float
    state: np.ndarray
    p: float
    multipliers: np.ndarray
    tangent: np.ndarray


def _stored(br: Branch, i: int, u: float) -> _Onb:
    return _Onb(u, br.states[i], float(br.p[i]), br.multipliers[i], br.tangents[i])


def _on_branch(corr: _Corrector, br: Branch, i: int, u: float) -> _Onb | None:
    """Predict u * (s_{i+1} - s_i) along the tangent at point i and correct (pseudo-arclength), so
    the point stays on this branch even next to a fold or another branch."""
    d = br.states.shape[1]
    t = br.tangents[i]
    h = float(br.arclength[i + 1] - br.arclength[i])
    up = np.append(br.states[i] / corr.sx, br.p[i] / corr.sp) + u * h * t
    out = corr.correct(up[:d] * corr.sx, float(up[d] * corr.sp), t)
    if out is None:
        return None
    x, p, M, A, Fp, _ = out
    try:
        tn = corr.tangent(A, Fp, t)
    except np.linalg.LinAlgError:
        tn = t
    return _Onb(u, x, float(p), sorted_multipliers(M), tn)


def _bifurcation(kind: str, q: _Onb, i: int, located: bool, br: Branch,
                 critical_of: Callable[[np.ndarray], complex | None]) -> Bifurcation:
    crit = critical_of(q.multipliers)
    rot = rotation_number(crit) if kind == "neimark_sacker" and crit is not None else float("nan")
    return Bifurcation(kind, float(q.p), np.asarray(q.state), np.asarray(q.multipliers),
                       complex(crit) if crit is not None else complex("nan"), rot, i, located, br.n)


def _interpolated(br: Branch, i: int, w: float) -> _Onb:
    """Linear interpolation of state and parameter; the multipliers of the nearer end point (the sorted
    multiplier lists of two points need not correspond element by element)."""
    return _Onb(w, br.states[i] + w * (br.states[i + 1] - br.states[i]), float(br.p[i] + w * (br.p[i + 1] - br.p[i])),
                br.multipliers[i if w < 0.5 else i + 1], br.tangents[i])


def _locate(family: Family, br: Branch, i: int, test: Callable[[_Onb], float], corr: _Corrector | None,
            cs: ContinuationSettings, w0: float) -> tuple[_Onb, bool]:
    """Brent on the arclength fraction u in [0, 1] between points i and i+1 (corrected points)."""
    if corr is None or not cs.locate:
        return _interpolated(br, i, w0), False
    cache: dict[float, _Onb] = {0.0: _stored(br, i, 0.0), 1.0: _stored(br, i + 1, 1.0)}

    def at(u: float) -> _Onb:
        if u not in cache:
            q = _on_branch(corr, br, i, u)
            if q is None:
                raise RuntimeError("correction failed while locating")
            cache[u] = q
        return cache[u]

    def f(u: float) -> float:
        v = test(at(u))
        if not np.isfinite(v):
            raise RuntimeError("test function undefined")
        return v

    try:
        if (f(0.0) > 0) == (f(1.0) > 0):
            return _interpolated(br, i, w0), False
        u = brentq(f, 0.0, 1.0, xtol=cs.locate_xtol, rtol=1e-15, maxiter=60)
        return at(u), True
    except (RuntimeError, ValueError):
        return _interpolated(br, i, w0), False


def detect_bifurcations(family: Family, br: Branch, tangents: np.ndarray, cs: ContinuationSettings,
                        corr: _Corrector | None = None) -> list[Bifurcation]:
    """Typed bifurcation points between consecutive branch points (see the module table)."""
    found: list[Bifurcation] = []
    br.tangents = tangents
    mu = br.multipliers
    dpds = tangents[:, -1]
    near_m1 = lambda m: complex(m[np.argmin(np.abs(m + 1.0))])  # noqa: E731
    near_p1 = lambda m: complex(m[np.argmin(np.abs(m - 1.0))])  # noqa: E731
    for i in range(len(br) - 1):
        m0, m1 = mu[i], mu[i + 1]
        a, b = pd_test(m0), pd_test(m1)
        if (a > 0) != (b > 0):
            q, ok = _locate(family, br, i, lambda q: pd_test(q.multipliers), corr, cs, _lin_zero(a, b))
            found.append(_bifurcation("period_doubling", q, i, ok, br, near_m1))
        turn = (dpds[i] > 0) != (dpds[i + 1] > 0)
        fa, fb = fold_test(m0), fold_test(m1)
        if turn:
            q, ok = _fold(br, i, corr)
            found.append(_bifurcation("fold", q, i, ok, br, near_p1))
        elif (fa > 0) != (fb > 0):
            q, ok = _locate(family, br, i, lambda q: fold_test(q.multipliers), corr, cs, _lin_zero(fa, fb))
            found.append(_bifurcation("branch_point", q, i, ok, br, near_p1))
        (o0, c0), (o1, c1) = _counts(m0), _counts(m1)
        if abs(o1 - o0) == 2 and abs(c1 - c0) == 2 and (o1 - o0) == (c1 - c0):
            n0, n1 = ns_product(m0), ns_product(m1)
            w = _lin_zero(n0, n1) if np.isfinite(n0) and np.isfinite(n1) else 0.5

            def ns_test(q: _Onb) -> float:
                return ns_product(q.multipliers)

            q, ok = _locate(family, br, i, ns_test, corr, cs, w)
            found.append(_bifurcation("neimark_sacker", q, i, ok, br, ns_pair))
        g0, g1 = br.grazing[i], br.grazing[i + 1]
        if np.isfinite(g0) and np.isfinite(g1) and (g0 > 0) != (g1 > 0):
            q, ok = _locate(family, br, i, lambda q: family.grazing(q.p, q.state, br.n), corr, cs, _lin_zero(g0, g1))
            found.append(_bifurcation("grazing", q, i, ok, br, lambda m: None))
    return found


def _fold(br: Branch, i: int, corr: _Corrector | None, iterations: int = 12) -> tuple[_Onb, bool]:
    """Fold between points i and i+1: the extremum of the cubic Hermite interpolant of p(s) (values
    and dp/ds at the bracket ends), corrected onto the branch there; the bracket shrinks to the
    corrected point and its tangent until dp/ds = 0 (then one multiplier is +1)."""
    d = br.states.shape[1]
    lo, hi = _stored(br, i, 0.0), _stored(br, i + 1, 1.0)
    if corr is None:
        return _interpolated(br, i, 0.5), False
    h = float(br.arclength[i + 1] - br.arclength[i])
    best, ok = None, False
    for _ in range(iterations):
        span = (hi.u - lo.u) * h
        p0, p1 = lo.p, hi.p
        m0, m1 = float(lo.tangent[d]) * corr.sp * span, float(hi.tangent[d]) * corr.sp * span
        c2 = 3 * (p1 - p0) - 2 * m0 - m1
        c3 = 2 * (p0 - p1) + m0 + m1
        roots = np.atleast_1d(np.roots([3 * c3, 2 * c2, m0])) if (c3 != 0 or c2 != 0) else np.array([])
        cand = [float(r.real) for r in roots if abs(r.imag) < 1e-12 and 0.0 < r.real < 1.0]
        v = min(cand, key=lambda r: abs(r - 0.5)) if cand else 0.5
        q = _on_branch(corr, br, i, lo.u + v * (hi.u - lo.u))
        if q is None:
            break
        best, ok = q, True
        if abs(float(q.tangent[d])) < 1e-10 or (hi.u - lo.u) < 1e-12:
            break
        if (q.tangent[d] > 0) == (lo.tangent[d] > 0):
            lo = q
        else:
            hi = q
    return (best, ok) if best is not None else (_interpolated(br, i, 0.5), False)


def switch_at_period_doubling(family: Family, bf: Bifurcation, lo: float, hi: float,
                              cs: ContinuationSettings = ContinuationSettings()) -> Branch | None:
    """The period-2n branch born at a period-doubling point of a period-n branch.

    Shooting for period 2n from the bifurcating orbit moved along the eigenvector of the multiplier
    -1, a little past the point on either side (1e-3 and 1e-2 of the range; amplitudes 1e-2 to 1 of
    max(1, max|x|) times the square root of the parameter offset, the scaling of a
    period-doubling normal form); the first orbit that is genuinely of period 2n (not the period-n
    orbit) is continued away from the bifurcation point only: towards it, the period-2n branch
    ends in the bifurcating orbit and turns back as the same orbit shifted by n periods.  None when
    none is found.
    """
    n = bf.n
    flow = family.flow(bf.p, n)
    phi, M = flow(bf.state, True)
    if phi is None:
        return None
    mu, vecs = np.linalg.eig(M)
    k = int(np.argmin(np.abs(mu + 1.0)))
    v = np.real(vecs[:, k])
    v /= float(np.max(np.abs(v)))
    scale = max(1.0, float(np.max(np.abs(bf.state))))
    span = hi - lo
    for frac in (1e-3, 1e-2):
        for side in (1.0, -1.0):
            p = bf.p + side * frac * span
            if not lo <= p <= hi:
                continue
            for amp in (1e-2, 1e-1, 1.0):
                x0 = bf.state + amp * scale * math.sqrt(frac) * v
                r = newton_shooting(family.flow(p, 2 * n), x0, 2 * n, cs.tol)
                if not r.converged:
                    continue
                back, _ = family.flow(p, n)(r.state, False)
                if back is None or float(np.max(np.abs(back - r.state))) < 1e-6 * scale:
                    continue  # the period-n orbit itself
                return continue_branch(family, p, r.state, 2 * n, lo, hi, cs, ("up",) if side > 0 else ("down",))
    return None


# ----------------------------------------------------------------------------------------------
# a whole sweep: seeds from the simulated cube, branches, dataset, table
# ----------------------------------------------------------------------------------------------

#: Integer codes of the bifurcation types in netCDF files (``flag_values``).
TYPE_CODES = {kind: k for k, kind in enumerate(BIFURCATION_TYPES)}


@dataclass(frozen=True)
class OrbitSpec:
    """One ``orbits:`` entry of the configuration (keyed by the sweep it continues).

    max_period: sweep points labelled P1..P<max_period> are seeds.  max_seeds: per case.
    nodes: coefficient interpolation nodes of :class:`KHVFamily`.  continuation: the
    :class:`ContinuationSettings`.  attractors: the mapping for :mod:`geardyn.runs.attractors`.
    switch_period_doubling: continue the period-2n branch born at each located period doubling
    (when 2n <= max_period), see :func:`switch_at_period_doubling`.
    """

    max_period: int = 6
    max_seeds: int = 6
    nodes: int = 101
    continuation: ContinuationSettings = ContinuationSettings()
    attractors: tuple[tuple[str, Any], ...] = ()
    switch_period_doubling: bool = True

    @classmethod
    def from_config(cls, spec: Mapping[str, Any] | None) -> OrbitSpec:
        spec = dict(spec or {})
        spec.pop("designs", None)
        known = {"max_period", "max_seeds", "nodes", "continuation", "attractors", "switch_period_doubling"}
        unknown = set(spec) - known
        if unknown:
            raise ValueError(f"unknown orbits settings {sorted(unknown)}; allowed: {sorted(known)}")
        return cls(max_period=int(spec.get("max_period", 6)), max_seeds=int(spec.get("max_seeds", 6)),
                   nodes=int(spec.get("nodes", 101)),
                   continuation=ContinuationSettings.from_mapping(spec.get("continuation")),
                   attractors=tuple(sorted((spec.get("attractors") or {}).items())),
                   switch_period_doubling=bool(spec.get("switch_period_doubling", True)))


STATE_VARS = ("x_dh", "x_vh", "x_vl", "v_dh", "v_vh", "v_vl")


def seeds_from_cube(cube: Any, case: int, max_period: int, max_seeds: int) -> list[tuple[float, np.ndarray, int]]:
    """(p, final state, n) at the middle of each run of equal label P1..P<max_period> along the sweep
    (first direction of the cube), longest runs first, at most ``max_seeds``."""
    par = cube.attrs["control_parameter"]
    values = np.asarray(cube[par].values, dtype=float)
    labels = np.asarray(cube["label"].values[case, 0], dtype=int)
    runs: list[tuple[int, int, int]] = []
    start = 0
    for i in range(1, labels.size + 1):
        if i == labels.size or labels[i] != labels[start]:
            if 1 <= labels[start] <= max_period:
                runs.append((i - start, start, int(labels[start])))
            start = i
    runs.sort(key=lambda r: (-r[0], r[1]))
    seeds = []
    for length, first, n in runs[:max_seeds]:
        j = first + length // 2
        x = np.array([float(cube[v].values[case, 0, j, -1]) for v in STATE_VARS])
        if np.all(np.isfinite(x)):
            seeds.append((float(values[j]), x, n))
    return seeds


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


def on_branch(br: Branch, p: float, points: np.ndarray, tol: float) -> bool:
    """True when one of ``points`` (phase-0 points of an orbit at p) lies on the branch."""
    scale = max(1.0, float(np.max(np.abs(br.states))))
    for i in range(len(br) - 1):
        a, b = br.p[i], br.p[i + 1]
        if min(a, b) - 1e-12 <= p <= max(a, b) + 1e-12:
            w = 0.0 if a == b else (p - a) / (b - a)
            x = br.states[i] + w * (br.states[i + 1] - br.states[i])
            if float(np.min(np.max(np.abs(points - x), axis=1))) <= tol * scale:
                return True
    return False


def sweep_branches(family_of: Callable[[int], KHVFamily], cube: Any, n_cases: int, spec: OrbitSpec
                   ) -> list[tuple[int, Branch]]:
    """Continue every distinct branch seeded by the cube's periodic points, case by case."""
    out: list[tuple[int, Branch]] = []
    for case in range(n_cases):
        family = family_of(case)
        mine: list[Branch] = []
        for p, x, n in seeds_from_cube(cube, case, spec.max_period, spec.max_seeds):
            r = newton_shooting(family.flow(p, n), x, n, spec.continuation.tol)
            if not r.converged:
                log.info("case %d: seed P%d at %g not converged (%s)", case, n, p, r.status)
                continue
            cyc = cycle_states(family, p, r.state, n)
            if any(b.n == n and on_branch(b, p, cyc, 1e-3) for b in mine):
                continue
            br = continue_branch(family, p, r.state, n, family.lo, family.hi, spec.continuation)
            if br is not None:
                log.info("case %d: P%d branch from %g: %d points, %d bifurcations, ends %s", case, n, p, len(br),
                         len(br.bifurcations), br.end_status)
                mine.append(br)
                if spec.switch_period_doubling:
                    mine.extend(_doubled(family, br, mine, spec, case))
        out.extend((case, b) for b in mine)
    return out


def _doubled(family: KHVFamily, br: Branch, known: list[Branch], spec: OrbitSpec, case: int,
             depth: int = 0) -> list[Branch]:
    """Branches born at the located period doublings of ``br`` (recursively, up to max_period)."""
    out: list[Branch] = []
    for bf in br.bifurcations:
        if bf.kind != "period_doubling" or not bf.located or 2 * br.n > spec.max_period:
            continue
        pts = cycle_states(family, bf.p, bf.state, br.n)
        if any(b.n == 2 * br.n and on_branch(b, bf.p, pts, 1e-2) for b in known + out):
            continue
        new = switch_at_period_doubling(family, bf, family.lo, family.hi, spec.continuation)
        if new is None:
            log.info("case %d: no period-%d branch found at the period doubling at %g", case, 2 * br.n, bf.p)
            continue
        log.info("case %d: P%d branch switched at %g: %d points, %d bifurcations", case, new.n, bf.p, len(new),
                 len(new.bifurcations))
        out.append(new)
        if depth < 4:
            out.extend(_doubled(family, new, known + out, spec, case, depth + 1))
    return out


def branch_dataset(branches: Sequence[tuple[int, Branch]], families: Mapping[int, Family], parameter: str,
                   case_labels: Sequence[str]):
    """All branches of a sweep as one CF dataset (points of all branches along ``point``)."""
    import xarray as xr

    units, long_name = point.CONTROLS.get(parameter, (point.units_of(parameter), parameter))
    nmax = max([b.n for _, b in branches], default=1)
    rows = sum(len(b) for _, b in branches)
    d = 6
    bid = np.zeros(rows, np.int32)
    case = np.zeros(rows, np.int32)
    per = np.zeros(rows, np.int16)
    pv = np.zeros(rows)
    st = np.zeros((rows, d))
    mu = np.zeros((rows, d), complex)
    arc = np.zeros(rows)
    graz = np.zeros(rows)
    cyc = np.full((rows, nmax), np.nan)
    k = 0
    for j, (c, b) in enumerate(branches):
        m = len(b)
        sl = slice(k, k + m)
        bid[sl], case[sl], per[sl] = j, c, b.n
        pv[sl], st[sl], mu[sl], arc[sl], graz[sl] = b.p, b.states, b.multipliers, b.arclength, b.grazing
        for i in range(m):
            cyc[k + i, :b.n] = cycle_states(families[c], float(b.p[i]), b.states[i], b.n)[:, 1] if b.n > 1 else b.states[i, 1]
        k += m
    bifs = [(j, c, bf) for j, (c, b) in enumerate(branches) for bf in b.bifurcations]
    nb = len(bifs)
    one = {"units": "1"}
    data = {
        "branch": ("point", bid, {**one, "long_name": "index of the continued branch"}),
        "case_index": ("point", case, {**one, "long_name": "index of the sweep case (fixed overrides)"}),
        "orbit_period": ("point", per, {**one, "long_name": "period of the orbit in mesh periods"}),
        "parameter": ("point", pv, {"units": units, "long_name": long_name}),
        "orbit_state": (("point", "state"), st, {**one, "long_name": "orbit state at mesh phase 0 (x / b_c, dx/dtau / b_c)"}),
        "multiplier_real": (("point", "multiplier"), mu.real, {**one, "long_name": "Floquet multiplier, real part"}),
        "multiplier_imag": (("point", "multiplier"), mu.imag, {**one, "long_name": "Floquet multiplier, imaginary part"}),
        "spectral_radius": ("point", np.max(np.abs(mu), axis=1) if rows else np.zeros(0),
                            {**one, "long_name": "largest Floquet multiplier modulus (< 1: stable)"}),
        "stable": ("point", (np.max(np.abs(mu), axis=1) < 1.0).astype(np.int8) if rows else np.zeros(0, np.int8),
                   {"long_name": "orbit asymptotically stable", "flag_values": np.array([0, 1], np.int8),
                    "flag_meanings": "unstable stable"}),
        "arclength": ("point", arc, {**one, "long_name": "arclength along the branch in scaled variables"}),
        "grazing_margin": ("point", graz, {**one, "long_name": "min over the cycle of |X_VH| / b_c - b (< 0: contact lost)"}),
        "cycle_x_vh": (("point", "cycle"), cyc, {**one, "long_name": "X_VH / b_c at the phase-0 points of the cycle"}),
        "bifurcation_branch": ("bifurcation", np.array([j for j, _, _ in bifs], np.int32),
                               {**one, "long_name": "branch of the bifurcation point"}),
        "bifurcation_type": ("bifurcation", np.array([TYPE_CODES[bf.kind] for _, _, bf in bifs], np.int8),
                             {"long_name": "type of the bifurcation point",
                              "flag_values": np.arange(len(BIFURCATION_TYPES), dtype=np.int8),
                              "flag_meanings": " ".join(BIFURCATION_TYPES)}),
        "bifurcation_parameter": ("bifurcation", np.array([bf.p for _, _, bf in bifs]), {"units": units,
                                  "long_name": f"{long_name} at the bifurcation point"}),
        "bifurcation_x_vh": ("bifurcation", np.array([bf.state[1] for _, _, bf in bifs]),
                             {**one, "long_name": "X_VH / b_c of the orbit at the bifurcation point (phase 0)"}),
        "critical_multiplier_real": ("bifurcation", np.array([bf.critical.real for _, _, bf in bifs]),
                                     {**one, "long_name": "crossing multiplier, real part (NaN for grazing)"}),
        "critical_multiplier_imag": ("bifurcation", np.array([bf.critical.imag for _, _, bf in bifs]),
                                     {**one, "long_name": "crossing multiplier, imaginary part"}),
        "rotation_number": ("bifurcation", np.array([bf.rotation_number for _, _, bf in bifs]),
                            {**one, "long_name": "arg(mu) / (2 pi) of the Neimark-Sacker pair (NaN otherwise)"}),
        "located": ("bifurcation", np.array([int(bf.located) for _, _, bf in bifs], np.int8),
                    {"long_name": "point refined on the branch (else interpolated between two points)",
                     "flag_values": np.array([0, 1], np.int8), "flag_meanings": "bracketed located"}),
        "bifurcation_multiplier_real": (("bifurcation", "multiplier"),
                                        np.array([bf.multipliers.real for _, _, bf in bifs]).reshape(nb, d),
                                        {**one, "long_name": "Floquet multipliers at the bifurcation point, real part"}),
        "bifurcation_multiplier_imag": (("bifurcation", "multiplier"),
                                        np.array([bf.multipliers.imag for _, _, bf in bifs]).reshape(nb, d),
                                        {**one, "long_name": "Floquet multipliers at the bifurcation point, imaginary part"}),
    }
    coords = {
        "state": ("state", list(STATE_VARS), {"long_name": "state component"}),
        "multiplier": ("multiplier", np.arange(d, dtype=np.int32), {**one, "long_name": "multiplier index (by decreasing modulus)"}),
        "cycle": ("cycle", np.arange(nmax, dtype=np.int32), {**one, "long_name": "index of the phase-0 point in the cycle"}),
        "case": ("case", list(case_labels), {"long_name": "case (fixed overrides)"}),
    }
    ends = {f"branch_{j}_ends": f"down={b.end_status.get('down')} up={b.end_status.get('up')}"
            for j, (_, b) in enumerate(branches)}
    return xr.Dataset(data, coords=coords, attrs={"control_parameter": parameter, **ends})


TABLE_COLUMNS = ("case", "branch", "period", "type", "parameter", "value", "critical_multiplier", "modulus",
                 "rotation_number", "located", "multipliers", "paper_transition", "paper_difference")


def bifurcation_rows(branches: Sequence[tuple[int, Branch]], parameter: str, case_labels: Sequence[str],
                     paper_transitions: Sequence[float] | None = None) -> list[dict[str, Any]]:
    """One row per bifurcation point; ``paper_transitions``: the paper's transition values along the
    same parameter (only for a design that names its paper), nearest one and the difference."""
    rows = []
    for j, (c, b) in enumerate(branches):
        for bf in b.bifurcations:
            near, diff = "", ""
            if paper_transitions:
                t = min(paper_transitions, key=lambda v: abs(v - bf.p))
                near, diff = f"{t:g}", f"{bf.p - t:+.4f}"
            crit = bf.critical
            rows.append({
                "case": case_labels[c], "branch": j, "period": b.n, "type": bf.kind, "parameter": parameter,
                "value": f"{bf.p:.7f}",
                "critical_multiplier": "" if not np.isfinite(crit.real) else f"{crit.real:+.6f}{crit.imag:+.6f}j",
                "modulus": "" if not np.isfinite(crit.real) else f"{abs(crit):.6f}",
                "rotation_number": "" if not np.isfinite(bf.rotation_number) else f"{bf.rotation_number:.5f}",
                "located": int(bf.located),
                "multipliers": " ".join(f"{m.real:+.4f}{m.imag:+.4f}j" for m in bf.multipliers),
                "paper_transition": near, "paper_difference": diff,
            })
    rows.sort(key=lambda r: (r["case"], float(r["value"])))
    return rows


def rows_to_csv(rows: Sequence[Mapping[str, Any]]) -> str:
    import csv
    from io import StringIO

    buf = StringIO()
    w = csv.DictWriter(buf, fieldnames=list(TABLE_COLUMNS), lineterminator="\n")
    w.writeheader()
    for r in rows:
        w.writerow(r)
    return buf.getvalue()


def branches_from_dataset(ds: Any) -> list[tuple[int, Branch]]:
    """The branches of a :func:`branch_dataset` file (points, states, multipliers; no bifurcations)."""
    out = []
    ids = ds["branch"].values
    for b in np.unique(ids):
        m = ids == b
        mu = ds["multiplier_real"].values[m] + 1j * ds["multiplier_imag"].values[m]
        br = Branch(n=int(ds["orbit_period"].values[m][0]), p=ds["parameter"].values[m],
                    states=ds["orbit_state"].values[m], multipliers=mu, arclength=ds["arclength"].values[m],
                    grazing=ds["grazing_margin"].values[m], iterations=np.zeros(int(m.sum()), np.int32))
        out.append((int(ds["case_index"].values[m][0]), br))
    return out


def label_agreement(cube: Any, case: int, branches: Sequence[Branch], max_period: int,
                    tol: float = 1e-4) -> tuple[int, int, list[float]]:
    """Consistency of the simulated labels with the branches: of the sweep points labelled P1..P<max_period>,
    how many have their last Poincare point on a *stable* part of a branch of that period (within
    tol * max(1, max|x|)).  Returns (checked, agreeing, parameter values that disagree)."""
    par = cube.attrs["control_parameter"]
    values = np.asarray(cube[par].values, dtype=float)
    labels = np.asarray(cube["label"].values[case, 0], dtype=int)
    checked, agree, bad = 0, 0, []
    for j, lab in enumerate(labels):
        if not 1 <= lab <= max_period:
            continue
        x = np.array([float(cube[v].values[case, 0, j, -1]) for v in STATE_VARS])
        if not np.all(np.isfinite(x)):
            continue
        checked += 1
        ok = False
        for br in branches:
            if br.n != lab:
                continue
            scale = max(1.0, float(np.max(np.abs(br.states))))
            st = br.stable
            for i in range(len(br) - 1):
                a, b = br.p[i], br.p[i + 1]
                if st[i] and st[i + 1] and min(a, b) <= values[j] <= max(a, b) and a != b:
                    w = (values[j] - a) / (b - a)
                    y = br.states[i] + w * (br.states[i + 1] - br.states[i])
                    if float(np.max(np.abs(y - x))) <= tol * scale:
                        ok = True
                        break
            if ok:
                break
        agree += int(ok)
        if not ok:
            bad.append(float(values[j]))
    return checked, agree, bad


def sweep_orbits(drive: Any, spec: Any, cube: Any, orbit_spec: OrbitSpec,
                 settings: SimulationSettings | None = None) -> tuple[Any, list[dict[str, Any]]]:
    """Branches of one sweep (a :class:`geardyn.runs.sweep.SweepSpec` and its merged cube): the CF
    dataset and the bifurcation table rows.  The paper's transitions are named only for a design
    that names its paper and only along x1 (the paper's Fig. 7 sequence)."""
    import time

    from geardyn.papers import paper_of

    settings = settings or point.integration_settings(drive, **dict(spec.integration))
    fams: dict[int, KHVFamily] = {}

    def family_of(case: int) -> KHVFamily:
        if case not in fams:
            fixed = {**dict(spec.fixed), **dict(spec.cases[case])}
            fams[case] = KHVFamily(drive, spec.parameter, fixed, spec.start, spec.stop, settings, orbit_spec.nodes)
            log.info("case %d: coefficient interpolation error %.2e", case, fams[case].interpolation_error)
        return fams[case]

    t0 = time.perf_counter()
    branches = sweep_branches(family_of, cube, len(spec.cases), orbit_spec)
    log.info("%d branches in %.1f s", len(branches), time.perf_counter() - t0)
    labels = [spec.case_label(i) for i in range(len(spec.cases))]
    for c in range(len(spec.cases)):
        family_of(c)
    ds = branch_dataset(branches, fams, spec.parameter, labels)
    ds.attrs.update({"sweep": spec.name, "design": spec.design,
                     "interpolation_error": max((f.interpolation_error for f in fams.values()), default=0.0),
                     "continuation_ds_max": orbit_spec.continuation.ds_max,
                     "shooting_tol": orbit_spec.continuation.tol, "steps_per_period": settings.steps_per_period,
                     "integrator": "rk4_event"})
    for c in range(len(spec.cases)):
        n_chk, n_ok, bad = label_agreement(cube, c, [b for cc, b in branches if cc == c], orbit_spec.max_period)
        ds.attrs[f"case_{c}_label_agreement"] = (f"{n_ok} of {n_chk} simulated P-n points lie on a stable branch"
                                                 + (f"; not: {', '.join(f'{v:g}' for v in bad[:20])}" if bad else ""))
        log.info("case %d: %s", c, ds.attrs[f"case_{c}_label_agreement"])
    mod = paper_of(getattr(drive, "paper", None))
    transitions = getattr(mod, "TRANSITIONS", None) if (mod is not None and spec.parameter == "x1") else None
    rows = bifurcation_rows(branches, spec.parameter, labels, transitions)
    return ds, rows
