"""Periodic orbits by Newton shooting on the stroboscopic (mesh-period) map, with Floquet multipliers.
Works on a flow map ``flow(x, jacobian) -> (phi(x), M or None)`` ((None, None): diverged); non-convergence
is never silent (:class:`ShootingResult`; the method: ``docs/numerics.md``)."""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numba
import numpy as np

from geardyn import libm
from geardyn.solve.base import SHOOTING, Lane, Monodromy, ShootingSettings, SimulationSettings, Sums, System
from geardyn.solve.run import LaneTables, lane_tables, simulate, simulate_batch

#: flow(x, jacobian) -> (state after n periods, monodromy or None); (None, None) when diverged.
FlowMap = Callable[[np.ndarray, bool], tuple[np.ndarray | None, np.ndarray | None]]


#: Status words of :class:`ShootingResult`.
STATUSES = ("converged", "max_iterations", "diverged", "singular", "not_finite", "residual_grows")


@dataclass
class ShootingResult:
    """A periodic orbit found (or not) by :func:`newton_shooting`: state, period n, convergence and
    :data:`STATUSES` word, iterations, residual, monodromy and multipliers (``docs/numerics.md``)."""

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
) -> tuple[ShootingResult | None, float]:
    """The :class:`ShootingResult` when the iteration ends at the iterate ``x`` given phi(x) (None: diverged)
    and M(x) (None: a chord iteration, which carries none): diverged, not finite, converged, the residual
    grown more than ``max_growth`` times over the ``previous`` iterate's (checked before convergence in a
    chord iteration), or the last iteration; else None.  With it, the residual max |phi(x) - x| (the next
    iteration's ``previous``)."""
    if phi is None:
        return ShootingResult(x, n, False, "diverged", it, float("inf")), float("inf")
    F = phi - x
    res = float(np.max(np.abs(F)))
    if not (np.all(np.isfinite(F)) and (M is None or np.all(np.isfinite(M)))):
        return ShootingResult(x, n, False, "not_finite", it, res), res
    grows = res > max_growth * previous
    if M is None and grows:  # a chord iteration stops on a growing residual before convergence
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


def _newton_next(go: list[tuple[int, np.ndarray, np.ndarray, np.ndarray]], it: int, n: int, caps: list[float]) -> list:
    """The next Newton iterates x - (M - I)^-1 (phi - x) of the points ``go`` ((point, x, phi, M) each), each
    step capped at ``caps[point]`` (max norm), by one stacked solve (the same LAPACK call per point as alone);
    a point whose M - I is singular gets its ``singular`` :class:`ShootingResult` instead."""
    X = np.stack([x for _, x, _, _ in go])
    F = np.stack([phi for _, _, phi, _ in go]) - X
    A = np.stack([M for _, _, _, M in go]) - np.eye(X.shape[1])
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
    for (i, x, _, M), f, d in zip(go, F, dx, strict=True):
        if d is None:
            out.append(ShootingResult(x, n, False, "singular", it, float(np.max(np.abs(f))), M, sorted_multipliers(M)))
            continue
        step = float(np.max(np.abs(d)))
        if step > caps[i]:
            d *= caps[i] / step
        out.append(x + d)
    return out


def _step_cap(x0: np.ndarray, factor: float = SHOOTING.step_cap) -> float:
    return factor * max(1.0, float(np.max(np.abs(x0))))


def _iterate(
    evaluate: Callable, step: Callable, x0s: list, n: int, tol: float, max_iter: int, max_growth: float
) -> list:
    """The shooting iteration of the points from ``x0s``, scalar or batch: each iteration evaluates the
    unfinished points together (``evaluate(points, xs)``: (phi(x), M(x) or None) each), ends those that
    :func:`_newton_end` ends and steps the others (``step(go, it)``, go: (point, x, phi, M) each)."""
    xs = [np.asarray(x, dtype=float).copy() for x in x0s]
    previous = [math.inf] * len(xs)
    out: list[ShootingResult | None] = [None] * len(xs)
    todo = list(range(len(xs)))  # the unfinished points
    for it in range(max_iter + 1):
        go = []  # (point, x, phi, M) of the points whose iteration goes on
        for i, (phi, M) in zip(todo, evaluate(todo, [xs[i] for i in todo]) if todo else [], strict=True):
            end, previous[i] = _newton_end(xs[i], phi, M, n, tol, it, max_iter, max_growth, previous[i])
            if end is None:
                go.append((i, xs[i], phi, M))
            else:
                out[i] = end
        todo = []
        for (i, _, _, _), x in zip(go, step(go, it) if go else [], strict=True):
            if isinstance(x, ShootingResult):
                out[i] = x
            else:
                xs[i] = x
                todo.append(i)
    return out


def newton_shooting(
    flow: FlowMap,
    x0: np.ndarray,
    n: int = 1,
    tol: float = SHOOTING.tol,
    max_iter: int = SHOOTING.max_iter,
    max_growth: float = SHOOTING.max_growth,
) -> ShootingResult:
    """Newton on F(x) = phi(x) - x from x0 (:class:`ShootingSettings`)."""
    caps = [_step_cap(np.asarray(x0, dtype=float))]
    step = functools.partial(_newton_next, caps=caps, n=n)
    return _iterate(lambda _, xs: [flow(xs[0], True)], step, [x0], n, tol, max_iter, max_growth)[0]


@dataclass(frozen=True)
class Shot:
    """One point of a batch shooting: its system and the start of the iteration."""

    system: System
    start: np.ndarray


@dataclass(frozen=True)
class ChordShot(Shot):
    """A point of a chord iteration: the fixed matrix (M - I)^-1 of its steps x <- x - matrix (phi(x) - x)."""

    matrix: np.ndarray


@dataclass(frozen=True)
class DeflatedShot(Shot):
    """A point of a deflated Newton iteration: the root it is kept away from."""

    root: np.ndarray


def newton_shooting_batch(
    shots: Sequence[Shot],
    n: int = 1,
    settings: SimulationSettings | None = None,
    shooting: ShootingSettings = SHOOTING,
    tables: LaneTables | None = None,
) -> list[ShootingResult]:
    """:func:`newton_shooting` on the n-period map of many points at once, every iteration one
    :func:`geardyn.solve.run.simulate_batch` (each result bit for bit that of the point alone)."""
    caps = [_step_cap(np.asarray(p.start, dtype=float), shooting.step_cap) for p in shots]
    step = functools.partial(_newton_next, caps=caps, n=n)
    return _shooting_batch(shots, n, settings, shooting, tables, True, step)


def chord_shooting_batch(
    shots: Sequence[ChordShot],
    n: int = 1,
    settings: SimulationSettings | None = None,
    shooting: ShootingSettings = SHOOTING,
    tables: LaneTables | None = None,
) -> list[ShootingResult]:
    """The chord iteration of :func:`newton_shooting_batch`: each point's fixed matrix in place of the
    monodromy, plain runs (a growing residual stops it before convergence: ``docs/numerics.md``)."""

    def step(go: list, it: int) -> list:
        return [x - shots[i].matrix @ (phi - x) for i, x, phi, _ in go]

    return _shooting_batch(shots, n, settings, shooting, tables, False, step)


def deflated_shooting_batch(
    shots: Sequence[DeflatedShot],
    n: int = 1,
    settings: SimulationSettings | None = None,
    shooting: ShootingSettings = SHOOTING,
    tables: LaneTables | None = None,
    shift: float = 1.0,
) -> list[ShootingResult]:
    """Deflated Newton of :func:`newton_shooting_batch`: each point kept away from its root by the factor
    1 / |x - root|^2 + ``shift`` (``docs/numerics.md``)."""

    def step(go: list, it: int) -> list:
        return [_deflated_step(x, phi, M, shots[i].root, shift, shooting.step_cap, n, it) for i, x, phi, M in go]

    return _shooting_batch(shots, n, settings, shooting, tables, True, step)


def _shooting_batch(
    shots: Sequence[Shot],
    n: int,
    settings: SimulationSettings | None,
    shooting: ShootingSettings,
    tables: LaneTables | None,
    monodromy: bool,
    step: Callable,
) -> list[ShootingResult]:
    """The loop of the batch iterations (:func:`_iterate`): the unfinished points' n-period maps in one
    batch run, with the monodromy where ``monodromy``; ``step(go, it)`` makes the next iterates."""
    s = period_settings(settings, n)
    systems = [p.system for p in shots]
    # the unfinished points whose rows the lane tables hold, and the tables
    held, held_tables = list(range(len(shots))), lane_tables(systems, s) if tables is None else tables
    variational = Monodromy(n) if monodromy else None

    def evaluate(todo: list[int], xs: list[np.ndarray]) -> list:
        nonlocal held, held_tables
        if len(todo) < len(held):  # copied only when a point has finished
            at = {i: k for k, i in enumerate(held)}
            held, held_tables = todo, held_tables.take([at[i] for i in todo])
        lanes = [Lane(systems[i], x, variational=variational) for i, x in zip(todo, xs, strict=True)]
        runs = simulate_batch(lanes, s, tables=held_tables)
        return [
            (None, None) if r.diverged else (r.final_state.copy(), np.array(r.monodromy) if monodromy else None)
            for r in runs
        ]

    x0s = [p.start for p in shots]
    return _iterate(evaluate, step, x0s, n, shooting.tol, shooting.max_iter, shooting.max_growth)


def _deflated_step(
    x: np.ndarray, phi: np.ndarray, M: np.ndarray, root: np.ndarray, shift: float, cap: float, n: int, it: int
) -> np.ndarray | ShootingResult:
    """The next iterate of deflated Newton (:func:`deflated_shooting_batch`), or the result
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
    systems: Sequence[System],
    states: list[np.ndarray],
    n: int,
    settings: SimulationSettings | None,
    tables=None,
    measure: bool = False,
) -> list[tuple[np.ndarray, int, bool, np.ndarray | None]]:
    """The n phase-0 points of the period-n orbits through ``states``, from one run of n periods each: (points,
    contact switches (-1: not run), diverged, sums); ``measure`` adds the response sums (``docs/response.md``)."""
    if n == 1 and not measure:
        return [(np.asarray(x)[None, :], -1, False, None) for x in states]
    sums = Sums(n) if measure else None
    lanes = [Lane(y, x, sums=sums) for y, x in zip(systems, states, strict=True)]
    runs = simulate_batch(lanes, period_settings(settings, n), tables=tables)
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
        r = simulate(system, s, x, variational=Monodromy(n) if jacobian else None)
        if r.diverged:
            return None, None
        return r.final_state.copy(), (np.array(r.monodromy) if jacobian else None)

    return flow


def khv_flows(
    systems: Sequence[System],
    xs: Sequence[np.ndarray],
    n: int,
    jacobian: Sequence[bool],
    settings: SimulationSettings | None = None,
) -> list[tuple[np.ndarray | None, np.ndarray | None]]:
    """The n-period maps of :func:`khv_flow` of many (system, x) pairs, the monodromy where ``jacobian`` asks for
    it, in one :func:`geardyn.solve.run.simulate_batch` (each pair bit for bit the flow of its system alone); the
    step tables built once per distinct system object.  On one numba thread: a few lanes of a fraction of a
    millisecond each, where starting the other threads' share costs more than it saves (``docs/orbits.md``)."""
    s = period_settings(settings, n)
    distinct: dict[int, int] = {}  # id(system) -> its row of the tables
    rows = [distinct.setdefault(id(y), len(distinct)) for y in systems]
    own = list({id(y): y for y in systems}.values())  # in the order of the rows
    lanes = [Lane(y, x, variational=Monodromy(n) if j else None) for y, x, j in zip(systems, xs, jacobian, strict=True)]
    tables = lane_tables(own, s).take(rows)
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        runs = simulate_batch(lanes, s, tables=tables)
    finally:
        numba.set_num_threads(threads)
    return [
        (None, None) if r.diverged else (r.final_state.copy(), np.array(r.monodromy) if j else None)
        for r, j in zip(runs, jacobian, strict=True)
    ]


def rotation_number(mu: complex) -> float:
    """arg(mu) / (2 pi) in [0, 0.5] for a multiplier of a conjugate pair."""
    return abs(math.atan2(mu.imag, mu.real)) / (2.0 * math.pi)
