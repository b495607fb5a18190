"""Periodic orbits by Newton shooting on the stroboscopic (mesh-period) map, with Floquet multipliers.
Works on a flow map ``flow(x, jacobian) -> (phi(x), M or None)`` ((None, None): diverged); non-convergence
is never silent (:class:`ShootingResult`; the method: ``docs/numerics.md``)."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from geardyn import libm
from geardyn.solve.base import SimulationSettings, System
from geardyn.solve.run import lane_tables, simulate, simulate_batch

#: flow(x, jacobian) -> (state after n periods, monodromy or None); (None, None) when diverged.
FlowMap = Callable[[np.ndarray, bool], tuple[np.ndarray | None, np.ndarray | None]]

#: Status words of :class:`ShootingResult`.
STATUSES = ("converged", "max_iterations", "diverged", "singular", "not_finite", "residual_grows")


@dataclass
class ShootingResult:
    """A periodic orbit found (or not) by :func:`newton_shooting`: state, period n, convergence and
    :data:`STATUSES` word, iterations, residual, monodromy and multipliers (fields: ``docs/numerics.md``)."""

    state: np.ndarray
    n: int
    converged: bool
    status: str
    iterations: int
    residual: float
    monodromy: np.ndarray | None = None
    multipliers: np.ndarray = field(default_factory=lambda: np.zeros(0, complex))

    @property
    def spectral_radius(self) -> float:
        return float(np.max(libm.cabs(self.multipliers))) if self.multipliers.size else float("nan")

    @property
    def stable(self) -> bool:
        return bool(self.converged and self.spectral_radius < 1.0)


def sorted_multipliers(monodromy: np.ndarray) -> np.ndarray:
    """Eigenvalues of the monodromy, by decreasing modulus (conjugate pairs adjacent)."""
    mu = np.linalg.eigvals(monodromy)
    return mu[np.lexsort((-mu.imag, -np.round(libm.cabs(mu), 12)))]


def _newton_end(
    x: np.ndarray,
    phi: np.ndarray | None,
    M: np.ndarray | None,
    n: int,
    tol: float,
    it: int,
    max_iter: int,
    max_growth: float = math.inf,
    previous: float = math.inf,
    growth_first: bool = False,
) -> tuple[ShootingResult | None, float]:
    """The :class:`ShootingResult` when the iteration ends at the iterate ``x`` given phi(x) (None: diverged)
    and M(x) (None: a chord iteration, which carries none): diverged, not finite, converged, the residual
    grown more than ``max_growth`` times over the ``previous`` iterate's (checked before convergence with
    ``growth_first``), or the last iteration; else None.  With it, the residual max |phi(x) - x| (the next
    iteration's ``previous``)."""
    if phi is None:
        return ShootingResult(x, n, False, "diverged", it, float("inf")), float("inf")
    F = phi - x
    res = float(np.max(np.abs(F)))
    if not (np.all(np.isfinite(F)) and (M is None or np.all(np.isfinite(M)))):
        return ShootingResult(x, n, False, "not_finite", it, res), res
    grows = res > max_growth * previous
    if growth_first and grows:
        return ShootingResult(x, n, False, "residual_grows", it, res), res
    if res <= tol * max(1.0, float(np.max(np.abs(x)))):
        return _result(x, n, True, "converged", it, res, M), res
    if grows:
        return _result(x, n, False, "residual_grows", it, res, M), res
    if it == max_iter:
        return _result(x, n, False, "max_iterations", max_iter, res, M), res
    return None, res


def _result(x: np.ndarray, n: int, ok: bool, status: str, it: int, res: float, M: np.ndarray | None) -> ShootingResult:
    """A :class:`ShootingResult` with the monodromy M and its multipliers (none for a chord iteration)."""
    if M is None:
        return ShootingResult(x, n, ok, status, it, res)
    return ShootingResult(x, n, ok, status, it, res, M, sorted_multipliers(M))


def _newton_next(
    xs: list[np.ndarray], phis: list[np.ndarray], Ms: list[np.ndarray], caps: list[float], n: int, it: int
) -> list[np.ndarray | ShootingResult]:
    """The next Newton iterates x - (M - I)^-1 (phi - x), each step capped at its ``cap`` (max norm), of
    points whose iteration goes on, by one stacked solve (the same LAPACK call per point as alone); a
    point whose M - I is singular gets its ``singular`` :class:`ShootingResult` instead."""
    X = np.stack(xs)
    F = np.stack(phis) - X
    A = np.stack(Ms) - np.eye(X.shape[1])
    try:
        dx = list(np.linalg.solve(A, -F[:, :, None])[:, :, 0])
    except np.linalg.LinAlgError:  # a singular matrix among them: find it, point by point
        dx = []
        for a, f in zip(A, F, strict=True):
            try:
                dx.append(np.linalg.solve(a[None], -f[None, :, None])[0, :, 0])
            except np.linalg.LinAlgError:
                dx.append(None)
    out: list[np.ndarray | ShootingResult] = []
    for x, f, M, d, cap in zip(xs, F, Ms, dx, caps, strict=True):
        if d is None:
            out.append(ShootingResult(x, n, False, "singular", it, float(np.max(np.abs(f))), M, sorted_multipliers(M)))
            continue
        step = float(np.max(np.abs(d)))
        if step > cap:
            d *= cap / step
        out.append(x + d)
    return out


def _step_cap(x0: np.ndarray, factor: float = 10.0) -> float:
    return factor * max(1.0, float(np.max(np.abs(x0))))


def newton_shooting(
    flow: FlowMap,
    x0: np.ndarray,
    n: int = 1,
    tol: float = 1e-9,
    max_iter: int = 30,
    max_growth: float = math.inf,
) -> ShootingResult:
    """Newton on F(x) = phi(x) - x from x0: converged when max |F| <= tol max(1, max |x|), the step capped
    at 10 max(1, max |x0|), stopped when the residual grows ``max_growth`` times (``docs/numerics.md``)."""
    x = np.asarray(x0, dtype=float).copy()
    cap = _step_cap(x)
    previous = math.inf
    for it in range(max_iter + 1):
        phi, M = flow(x, True)
        end, previous = _newton_end(x, phi, M, n, tol, it, max_iter, max_growth, previous)
        if end is not None:
            return end
        nxt = _newton_next([x], [phi], [M], [cap], n, it)[0]
        if isinstance(nxt, ShootingResult):
            return nxt
        x = nxt
    raise AssertionError("unreachable: the last iteration returns")  # pragma: no cover


def newton_shooting_batch(
    systems: list[System],
    x0s: list[np.ndarray],
    n: int = 1,
    settings: SimulationSettings | None = None,
    tol: float = 1e-9,
    max_iter: int = 30,
    tables=None,
    max_growth: float = math.inf,
    *,
    chord: list[np.ndarray] | None = None,
    deflate: list[np.ndarray] | None = None,
    deflation_shift: float = 1.0,
    step_cap: float = 10.0,
) -> list[ShootingResult]:
    """:func:`newton_shooting` on the n-period map of many systems at once, every iteration one
    :func:`geardyn.solve.run.simulate_batch` (each result bit for bit that of the point alone); ``chord``:
    a fixed matrix per point, ``deflate``: a root per point to avoid (``docs/numerics.md``)."""
    s = period_settings(settings, n)
    tables = lane_tables(systems, s) if tables is None else tables
    xs = [np.asarray(x, dtype=float).copy() for x in x0s]
    caps = [_step_cap(x, step_cap) for x in xs]
    previous = [math.inf] * len(xs)
    out: list[ShootingResult | None] = [None] * len(xs)
    todo = list(range(len(xs)))  # the unfinished points; ``tables`` holds their rows, in this order
    for it in range(max_iter + 1):
        if not todo:
            break
        runs = simulate_batch(
            [systems[i] for i in todo], s, [xs[i] for i in todo], monodromy_periods=0 if chord else n, tables=tables
        )
        go = []  # (position in todo, phi, M) of the points whose iteration goes on
        for k, (i, r) in enumerate(zip(todo, runs, strict=True)):
            phi, M = (None, None) if r.diverged else (r.final_state.copy(), None if chord else r.monodromy.copy())
            end, previous[i] = _newton_end(
                xs[i], phi, M, n, tol, it, max_iter, max_growth, previous[i], growth_first=chord is not None
            )
            if end is None:
                go.append((k, phi, M))
            else:
                out[i] = end
        if not go:
            nxt = []
        elif chord is not None:
            nxt = [xs[todo[k]] - chord[todo[k]] @ (phi - xs[todo[k]]) for k, phi, _ in go]
        elif deflate is not None:
            nxt = [
                _deflated_step(xs[todo[k]], phi, M, deflate[todo[k]], deflation_shift, step_cap, n, it)
                for k, phi, M in go
            ]
        else:
            nxt = _newton_next(
                [xs[todo[k]] for k, _, _ in go],
                [phi for _, phi, _ in go],
                [M for _, _, M in go],
                [caps[todo[k]] for k, _, _ in go],
                n,
                it,
            )
        left = []
        for (k, _, _), x in zip(go, nxt, strict=True):
            if isinstance(x, ShootingResult):
                out[todo[k]] = x
            else:
                xs[todo[k]] = x
                left.append(k)
        if len(left) < len(todo):
            tables = tables.take(left)  # copied only when a point has finished
        todo = [todo[k] for k in left]
    return out  # type: ignore[return-value]


def _deflated_step(
    x: np.ndarray, phi: np.ndarray, M: np.ndarray, root: np.ndarray, shift: float, cap: float, n: int, it: int
) -> np.ndarray | ShootingResult:
    """The next iterate of deflated Newton (:func:`newton_shooting_batch` with ``deflate``), or the result
    where it stops: at the root itself, or on a singular matrix."""
    F = phi - x
    d = x - root
    d2 = float(d @ d)
    if d2 == 0.0:
        return ShootingResult(x, n, False, "singular", it, float(np.max(np.abs(F))))
    m = 1.0 / d2 + shift
    grad = -2.0 * d / d2**2
    A = m * (M - np.eye(x.size)) + np.outer(F, grad)
    try:
        step = np.linalg.solve(A, -m * F)
    except np.linalg.LinAlgError:
        return ShootingResult(x, n, False, "singular", it, float(np.max(np.abs(F))))
    limit = _step_cap(x, cap)
    size = float(np.max(np.abs(step)))
    return x + (step * (limit / size) if size > limit else step)


def cycle_points(
    systems: list[System],
    states: list[np.ndarray],
    n: int,
    settings: SimulationSettings | None,
    tables=None,
    measure: bool = False,
) -> list[tuple[np.ndarray, int, bool, np.ndarray | None]]:
    """The n phase-0 points of the period-n orbits through ``states``, from one run of n periods each: (points,
    contact switches (-1: not run), diverged, sums); ``measure`` adds the response sums (``docs/numerics.md``)."""
    if n == 1 and not measure:
        return [(np.asarray(x)[None, :], -1, False, None) for x in states]
    last = [n] * len(states) if measure else None
    runs = simulate_batch(systems, period_settings(settings, n), list(states), tables=tables, sums_last=last)
    return [
        (
            np.vstack([np.asarray(x)[None, :], r.poincare])[:n],
            int(r.n_events) if n > 1 else -1,
            n > 1 and r.diverged,
            r.sums,
        )
        for x, r in zip(states, runs, strict=True)
    ]


# ----------------------------------------------------------------------------------------------
# flow maps
# ----------------------------------------------------------------------------------------------


def period_settings(settings: SimulationSettings | None, n: int) -> SimulationSettings:
    """The settings of one shooting evaluation: no transient, n recorded periods, event-located RK4
    (``rk4_event``) unless plain ``rk4`` was asked for (DOP853 carries no variational part)."""
    s = settings or SimulationSettings()
    integ = s.integrator if s.integrator in ("rk4", "rk4_event") else "rk4_event"
    return SimulationSettings(
        integrator=integ,
        steps_per_period=s.steps_per_period,
        transient_periods=0,
        recorded_periods=n,
        divergence_threshold=s.divergence_threshold,
        aligned=s.aligned,
    )


def khv_flow(system: System, n: int = 1, settings: SimulationSettings | None = None) -> FlowMap:
    """The n-period stroboscopic map of ``system`` with its monodromy (variational equations)."""
    s = period_settings(settings, n)

    def flow(x: np.ndarray, jacobian: bool = True):
        r = simulate(system, s, x, monodromy_periods=n if jacobian else 0)
        if r.diverged:
            return None, None
        return r.final_state.copy(), (r.monodromy.copy() if jacobian else None)

    return flow


def rotation_number(mu: complex) -> float:
    """arg(mu) / (2 pi) in [0, 0.5] for a multiplier of a conjugate pair."""
    return abs(math.atan2(mu.imag, mu.real)) / (2.0 * math.pi)
