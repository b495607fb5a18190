"""Typed bifurcation points of a continued branch: the test functions between consecutive points and their
location on the branch, every trial point a pseudo-arclength correction (docs/orbits.md, section 3)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np
from scipy.optimize import brentq

from geardyn import libm
from geardyn.runs.continuation.branch import Bifurcation, Branch
from geardyn.runs.continuation.corrector import Point, step
from geardyn.runs.continuation.problem import BranchProblem, nearest
from geardyn.solve.floquet import is_complex
from geardyn.solve.shooting import rotation_number

#: Brent's method on a step's arclength fraction: the relative tolerance at scipy's least (4 eps = 8.9e-16), and
#: an iteration limit twice the 30 bisections that take the unit interval below the default location tolerance.
BRENT_RTOL = 1e-15
BRENT_MAXITER = 60
#: The fold's rounds (:func:`_fold`): at most ``FOLD_ROUNDS`` corrected points; a root of the Hermite cubic is real
#: when its imaginary part is below ``REAL_ROOT`` (np.roots leaves rounding there); the fold is reached when
#: dp/ds (scaled) is below ``FOLD_DPDS`` or the bracket below ``FOLD_BRACKET`` of the step.
FOLD_ROUNDS = 12
REAL_ROOT = 1e-12
FOLD_DPDS = 1e-10
FOLD_BRACKET = 1e-12


def unstable_counts(mu: np.ndarray) -> tuple[int, int]:
    """How many multipliers lie outside the unit circle, and how many of them are complex."""
    out = libm.cabs(mu) > 1.0
    return int(out.sum()), int((out & is_complex(mu)).sum())


def pd_test(mu: np.ndarray) -> float:
    """det(M + I) = prod(mu + 1): changes sign when a real multiplier crosses -1."""
    return float(np.prod(mu + 1.0).real)


def fold_test(mu: np.ndarray) -> float:
    """det(M - I) = prod(mu - 1): changes sign when a real multiplier crosses +1."""
    return float(np.prod(mu - 1.0).real)


def ns_pair(mu: np.ndarray) -> complex | None:
    """The complex multiplier (upper half plane) nearest the unit circle, if any."""
    c = mu[is_complex(mu) & (mu.imag > 0)]
    if c.size == 0:
        return None
    return complex(c[np.argmin(np.abs(libm.cabs(c) - 1.0))])


def ns_test(mu: np.ndarray) -> float:
    """|mu| - 1 of the complex pair nearest the unit circle (NaN without one): changes sign when that pair
    crosses the circle, whatever the other multipliers do (a real pair that turns complex inside the circle
    leaves it alone)."""
    c = ns_pair(mu)
    return float("nan") if c is None else abs(c) - 1.0


def _near(target: float) -> Callable[[np.ndarray], complex]:
    """The multiplier nearest ``target`` (-1: period doubling, +1: fold and branch point)."""
    return lambda mu: complex(mu[nearest(mu, target)])


def _lin_zero(a: float, b: float) -> float:
    return a / (a - b) if a != b and np.isfinite(a) and np.isfinite(b) else 0.5


def _stored(br: Branch, i: int, u: float) -> Point:
    return Point(np.append(br.states[i], br.p[i]), br.multipliers[i], br.tangents[i], u=u)


def _on_branch(prob: BranchProblem, br: Branch, i: int, u: float) -> Point | None:
    """Predict u * (s_{i+1} - s_i) along the tangent at point i and correct (pseudo-arclength), so the point stays
    on this branch (continued as ``prob``) even next to a fold or another branch."""
    out = step(prob, _stored(br, i, 0.0), u * float(br.arclength[i + 1] - br.arclength[i]), prob.cs)
    return None if out is None else replace(out, u=u)


def _interpolated(br: Branch, i: int, w: float) -> Point:
    """Linear interpolation of state and parameter at the fraction w of step i; the multipliers of the nearer end
    point (the sorted multiplier lists of two points need not correspond element by element)."""
    a, b = _stored(br, i, 0.0), _stored(br, i + 1, 1.0)
    return replace(a, z=a.z + w * (b.z - a.z), multipliers=(a if w < 0.5 else b).multipliers, u=w)


def _bifurcation(kind: str, q: Point, i: int, located: bool, br: Branch, critical_of: Callable) -> Bifurcation:
    crit = critical_of(q.multipliers)
    rot = rotation_number(crit) if kind == "neimark_sacker" and crit is not None else float("nan")
    c = complex(crit) if crit is not None else complex("nan")
    return Bifurcation(kind, q.p, np.asarray(q.x), np.asarray(q.multipliers), c, rot, i, located, br.n)


def _locate(
    prob: BranchProblem, br: Branch, i: int, tests: list[Callable[[Point], float]], w0: float
) -> tuple[Point, bool]:
    """Brent on the arclength fraction u in [0, 1] between points i and i+1 (corrected points) on the first of
    ``tests`` whose sign differs at the two ends; the point interpolated at w0 (not located) when none does, Brent
    fails or location is off (``locate``)."""
    lo, hi = _stored(br, i, 0.0), _stored(br, i + 1, 1.0)
    for test in tests if prob.cs.locate else []:
        if (test(lo) > 0) != (test(hi) > 0):
            q = brent_on_step(lambda u: _on_branch(prob, br, i, u), test, lo, hi, prob.cs.locate_xtol)
            if q is not None:
                return q, True
    return _interpolated(br, i, w0), False


def brent_on_step(
    point_at: Callable[[float], Point | None], test: Callable[[Point], float], a: Point, b: Point, xtol: float
) -> Point | None:
    """Brent on the arclength fraction s in [0, 1] of one step (a at 0, b at 1, every trial point ``point_at(s)``
    a corrected point, cached): the point where ``test`` vanishes, None when a correction fails, the test is
    undefined or has one sign at both ends."""
    cache = {0.0: a, 1.0: b}

    def f(s: float) -> float:
        if s not in cache:
            q = point_at(s)
            if q is None:
                raise RuntimeError("correction failed while locating")
            cache[s] = q
        v = test(cache[s])
        if not np.isfinite(v):
            raise RuntimeError("test function undefined")
        return v

    try:
        s = brentq(f, 0.0, 1.0, xtol=xtol, rtol=BRENT_RTOL, maxiter=BRENT_MAXITER)
    except (RuntimeError, ValueError):
        return None
    return cache[s] if s in cache else point_at(s)


def _fold(prob: BranchProblem, br: Branch, i: int) -> tuple[Point, bool]:
    """Fold between points i and i+1: the extremum of the cubic Hermite interpolant of p(s) (values and dp/ds at
    the bracket ends), corrected onto the branch there; the bracket shrinks to the corrected point and its tangent
    until dp/ds = 0 (then one multiplier is +1)."""
    lo, hi = _stored(br, i, 0.0), _stored(br, i + 1, 1.0)
    h = float(br.arclength[i + 1] - br.arclength[i])
    best = None
    for _ in range(FOLD_ROUNDS):
        span = (hi.u - lo.u) * h
        p0, p1 = lo.p, hi.p
        sp = prob.sp
        m0, m1 = float(lo.tangent[-1]) * sp * span, float(hi.tangent[-1]) * sp * span
        c2 = 3 * (p1 - p0) - 2 * m0 - m1
        c3 = 2 * (p0 - p1) + m0 + m1
        roots = np.atleast_1d(np.roots([3 * c3, 2 * c2, m0])) if (c3 != 0 or c2 != 0) else np.array([])
        cand = [float(r.real) for r in roots if abs(r.imag) < REAL_ROOT and 0.0 < r.real < 1.0]
        v = min(cand, key=lambda r: abs(r - 0.5)) if cand else 0.5
        q = _on_branch(prob, br, i, lo.u + v * (hi.u - lo.u))
        if q is None:
            break
        best = q
        if abs(float(q.tangent[-1])) < FOLD_DPDS or (hi.u - lo.u) < FOLD_BRACKET:
            break
        if (q.tangent[-1] > 0) == (lo.tangent[-1] > 0):
            lo = q
        else:
            hi = q
    return (best, True) if best is not None else (_interpolated(br, i, 0.5), False)


def _changes(h: np.ndarray) -> np.ndarray:
    """The steps i -> i + 1 over which the finite values h change sign."""
    return np.flatnonzero(np.isfinite(h[:-1]) & np.isfinite(h[1:]) & ((h[:-1] > 0) != (h[1:] > 0)))


def _step_events(prob: BranchProblem, br: Branch, i: int, grazes: bool) -> list[Bifurcation]:
    """The typed bifurcation points between points i and i + 1, in the order of the package table."""
    found: list[Bifurcation] = []
    m0, m1 = br.multipliers[i], br.multipliers[i + 1]
    a, b = pd_test(m0), pd_test(m1)
    if (a > 0) != (b > 0):
        q, ok = _locate(prob, br, i, [lambda q: pd_test(q.multipliers)], _lin_zero(a, b))
        found.append(_bifurcation("period_doubling", q, i, ok, br, _near(-1.0)))
    dpds = br.tangents[:, -1]
    fa, fb = fold_test(m0), fold_test(m1)
    if (dpds[i] > 0) != (dpds[i + 1] > 0):
        q, ok = _fold(prob, br, i)
        found.append(_bifurcation("fold", q, i, ok, br, _near(1.0)))
    elif (fa > 0) != (fb > 0):
        q, ok = _locate(prob, br, i, [lambda q: fold_test(q.multipliers)], _lin_zero(fa, fb))
        found.append(_bifurcation("branch_point", q, i, ok, br, _near(1.0)))
    (o0, c0), (o1, c1) = unstable_counts(m0), unstable_counts(m1)
    if abs(o1 - o0) == 2 and abs(c1 - c0) == 2 and (o1 - o0) == (c1 - c0):
        # the modulus of the pair that crosses; failing that (another pair turned complex or crossed inside the
        # step), the count of unstable complex multipliers, which changes by 2 just where the pair crosses
        tests = [lambda q: ns_test(q.multipliers), lambda q: unstable_counts(q.multipliers)[1] - 0.5 * (c0 + c1)]
        q, ok = _locate(prob, br, i, tests, _lin_zero(ns_test(m0), ns_test(m1)))
        found.append(_bifurcation("neimark_sacker", q, i, ok, br, ns_pair))
    if grazes:
        margin = prob.family.grazing
        q, ok = _locate(prob, br, i, [lambda q: margin(q.p, q.x, br.n)], _lin_zero(*br.grazing[i : i + 2]))
        found.append(_bifurcation("grazing", q, i, ok, br, lambda m: None))
    return found


def detect_bifurcations(prob: BranchProblem, br: Branch) -> list[Bifurcation]:
    """Typed bifurcation points between consecutive points of ``br`` (with its tangents, continued as ``prob``; see the
    package table); with ``locate`` off they are only bracketed (interpolated, ``located`` False), but the fold."""
    graze = set(_changes(br.grazing).tolist())
    return [bf for i in range(len(br) - 1) for bf in _step_events(prob, br, i, i in graze)]


def sign_changes(
    prob: BranchProblem, br: Branch, margin: Callable[[float, np.ndarray, int], float]
) -> list[tuple[Point, bool]]:
    """The points of ``br`` where ``margin(p, x, n)`` changes sign between consecutive points (e.g. a grazing
    margin), each located by :func:`_locate` (or only bracketed: located False)."""
    h = np.array([margin(p, x, br.n) for p, x in zip(br.p, br.states, strict=True)])
    tests = [lambda q: margin(q.p, q.x, br.n)]
    return [_locate(prob, br, int(i), tests, _lin_zero(h[i], h[i + 1])) for i in _changes(h)]
