"""The stages of the labeller.  Each takes the still-undecided points of a batch and decides what it can.

1. :func:`follow`: the previous point's period-n orbit continued to this point (secant prediction, chord
   iteration with the previous monodromy, Newton shooting where the chord stalls).  A stable orbit (max|mu|
   below 1 by the policy's margin) decides the point at once; an orbit that is no longer stable types the
   bifurcation by the multiplier that left the unit circle.
2. :func:`integrate`: a run from the previous point's final state (or the line's start) with the early
   stop of the transient, then rule 3 on the recorded points; a point that returns within tolerance is
   certified by Newton shooting and its multipliers (:func:`certify`; an unstable orbit Newton converged
   to is deflated and the shooting repeated, :func:`_deflated`).
3. :func:`slow_transients`: a point not periodic on its record is checked for a slow transient onto a stable
   orbit (:mod:`geardyn.label.settle`): shooting where the return distance falls, and the run must approach it.
4. :func:`exponents`: the rest carry a tangent vector; the exponent (:func:`geardyn.classify.lyapunov_estimate`)
   and the torus test (weighted Birkhoff averages, :mod:`geardyn.label.torus`) decide between a torus and
   chaos (:func:`_nonperiodic_verdict`); undecided points run on with longer records
   (:func:`_longer_record`) and are searched for long cycles (:func:`_long_periods`).

Every stage integrates all points that reach it together (:func:`geardyn.solve.simulate.simulate_batch`,
:func:`geardyn.solve.shooting.newton_shooting_batch`, both cores); each point's numbers are those it gets
alone, so a verdict does not depend on the batch, the chunking or the number of threads.
"""

from __future__ import annotations

import dataclasses
import math
from collections import defaultdict
from dataclasses import dataclass

import numpy as np

from geardyn import classify
from geardyn.label._threads import threaded_map
from geardyn.label.policy import Policy
from geardyn.label.settle import settle_points
from geardyn.label.torus import moments, torus_test
from geardyn.label.verdict import Verdict
from geardyn.solve.base import SimulationResult, System
from geardyn.solve.shooting import ShootingResult, newton_shooting_batch, period_settings, sorted_multipliers
from geardyn.solve.simulate import EarlyStop, LaneTables, simulate_batch, strict_periods

UNDET = classify.LABELS["undetermined"]
QP = classify.LABELS["quasi_periodic"]
CHAOS = classify.LABELS["chaotic"]
DIVERGED = classify.LABELS["diverged"]
NAN = float("nan")


@dataclass
class Point:
    """A point on its way through the stages (mutable, private to the labeller).

    prev: the verdict of the previous point of the line (None for a line's first point).  start: the fixed
    initial state of the line (None: the static deflection).  run: the run whose record the later stages
    read.  notes: what earlier stages found, for the verdict's reason."""

    system: System
    prev: Verdict | None
    start: np.ndarray | None
    prev2: Verdict | None = None
    tables: LaneTables | None = None  # the step tables of the whole step's batch (built once per step)
    row: int = 0  # this point's row in them
    verdict: Verdict | None = None
    tangent: bool = False
    bifurcation: str = "none"
    run: SimulationResult | None = None
    transient_used: int = 0
    notes: list[str] = dataclasses.field(default_factory=list)


# ------------------------------------------------------------------------------------------------
# helpers
# ------------------------------------------------------------------------------------------------


def bifurcation_type(multipliers: np.ndarray) -> str:
    """How the leading multiplier of an unstable orbit left the unit circle: ``neimark_sacker`` (a complex
    pair), ``period_doubling`` (real, through -1) or ``fold`` (real, through +1)."""
    mu = complex(multipliers[0])
    if abs(mu.imag) > 1e-9 * abs(mu):
        return "neimark_sacker"
    return "period_doubling" if mu.real < 0 else "fold"


def least_period(cycle: np.ndarray, tol: float) -> int:
    """The least m such that the cycle's point m returns to its point 0 within ``tol`` (len(cycle) if none);
    ``cycle``: (n + 1, 6) points one mesh period apart, the last one back at the first."""
    n = cycle.shape[0] - 1
    for m in range(1, n):
        if n % m == 0 and float(np.max(np.abs(cycle[m] - cycle[0]))) <= tol:
            return m
    return n


def _record_length(policy: Policy) -> int:
    return policy.integration.recorded_periods


def tile(points: np.ndarray, length: int) -> np.ndarray:
    """The m cycle points repeated to ``length`` rows (what a periodic verdict draws)."""
    reps = -(-length // max(1, points.shape[0]))
    return np.tile(points, (reps, 1))[:length]


def periodic_verdicts(
    points: list[Point], shots: list[ShootingResult], policy: Policy, stage: str, why: str
) -> list[Verdict | None]:
    """Verdicts for converged Newton orbits: period-m (m the least period) when max|mu| < 1 - margin, else
    None.  The cycle points of an n > 1 orbit come from one run of n periods from its orbit point (all
    together); a period-1 orbit is its point."""
    margin = policy.stability_margin
    good = [k for k, s in enumerate(shots) if s.converged and s.spectral_radius < 1.0 - margin]
    out: list[Verdict | None] = [None] * len(shots)
    cycles: dict[int, tuple[np.ndarray, int]] = {k: (shots[k].state[None, :], -1) for k in good if shots[k].n == 1}
    by_n: dict[int, list[int]] = defaultdict(list)
    for k in good:
        if shots[k].n > 1:
            by_n[shots[k].n].append(k)
    for n, ks in by_n.items():
        s = dataclasses.replace(period_settings(policy.integration, n), recorded_periods=n)
        runs = simulate_batch(
            [points[k].system for k in ks], s, [shots[k].state for k in ks], tables=tables_of([points[k] for k in ks])
        )
        for k, r in zip(ks, runs, strict=True):
            if not r.diverged:
                cyc = np.vstack([shots[k].state[None, :], r.poincare])
                tol = 1e3 * policy.newton_tol * max(1.0, float(np.max(np.abs(shots[k].state))))
                cycles[k] = (cyc[: least_period(cyc, tol)], int(r.n_events))
    for k, (cycle, events) in cycles.items():
        shot, m = shots[k], cycle.shape[0]
        n, rho = shot.n, shot.spectral_radius
        out[k] = Verdict(
            label=m if m <= policy.classifier.max_n else classify.LABELS["long_period"],
            period=m,
            exponent=math.log(rho) / (n * points[k].system.period),
            exponent_sigma=0.0,
            exponent_method="floquet",
            stage=stage,
            reason=f"{why}: stable period-{m} orbit, |mu|max = {rho ** (m / n):.6f}",
            final_state=shot.state.copy(),
            poincare=tile(cycle, _record_length(policy)),
            multiplier=rho ** (m / n),
            bifurcation=points[k].bifurcation,
            transient_used=points[k].transient_used,
            n_events=events,
            monodromy=shot.monodromy if m == n else None,
        )
    return out


def _shoot(points: list[Point], starts: list[np.ndarray], ns: list[int], policy: Policy) -> list[ShootingResult]:
    """Newton shooting of every point for its n from its start, grouped by n (each point as alone)."""
    out: list[ShootingResult | None] = [None] * len(points)
    by_n: dict[int, list[int]] = defaultdict(list)
    for k, n in enumerate(ns):
        by_n[n].append(k)
    for n, ks in sorted(by_n.items()):
        shots = newton_shooting_batch(
            [points[k].system for k in ks],
            [starts[k] for k in ks],
            n,
            policy.integration,
            tol=policy.newton_tol,
            max_iter=policy.newton_max_iter,
            tables=tables_of([points[k] for k in ks]),
        )
        for k, s in zip(ks, shots, strict=True):
            out[k] = s
    return out  # type: ignore[return-value]


def tables_of(points: list[Point]) -> LaneTables | None:
    """The lane tables of ``points`` (rows of their step's tables), or None to build them."""
    if not points or points[0].tables is None:
        return None
    return points[0].tables.take([p.row for p in points])


def decide(points: list[Point], verdicts: list[Verdict | None]) -> list[Point]:
    """Store the verdicts found; return the points still undecided."""
    left = []
    for p, v in zip(points, verdicts, strict=True):
        if v is None:
            left.append(p)
        else:
            p.verdict = v
    return left


def diverged_verdict(p: Point, r: SimulationResult) -> Verdict:
    lam = float("inf")
    return Verdict(
        DIVERGED,
        0,
        lam,
        0.0,
        "none",
        "diverged",
        f"diverged in mesh period {r.diverged_period}",
        final_state=np.asarray(r.final_state, float).copy(),
        poincare=r.poincare,
        bifurcation=p.bifurcation,
        transient_used=r.transient_used,
        n_events=int(r.n_events),
        diverged_period=int(r.diverged_period),
    )


# ------------------------------------------------------------------------------------------------
# stage 1: follow the previous point's orbit
# ------------------------------------------------------------------------------------------------


def _predict(p: Point) -> np.ndarray:
    """The start of the follow iteration: the previous orbit point, extrapolated along the line (secant
    through the two previous orbits of the same period; the points of a line are equally spaced)."""
    a, b = p.prev, p.prev2
    if b is not None and b.periodic and b.period == a.period and b.stage in ("follow", "period_test", "shooting"):
        return 2.0 * a.final_state - b.final_state
    return a.final_state


def _small(residual: float, x: np.ndarray, tol: float) -> bool:
    """The shooting convergence test: max|phi(x) - x| <= tol max(1, max|x|) (as Newton shooting's)."""
    return residual <= tol * max(1.0, float(np.max(np.abs(x))))


def _chord(
    points: list[Point], x0s: list[np.ndarray], n: int, policy: Policy, max_iter: int = 8
) -> list[np.ndarray | None]:
    """Chord iteration x <- x - (M_prev - I)^-1 (phi(x) - x) on the n-period map, with the monodromy
    M_prev of each point's previous orbit: plain runs (no variational part), all points together.  The
    converged iterate (max|F| <= tol max(1, |x|)), or None when the residual does not fall by half at
    every iteration (then full Newton takes over)."""
    s = period_settings(policy.integration, n)
    xs = [np.asarray(x, float).copy() for x in x0s]
    lu = [np.linalg.inv(p.prev.monodromy - np.eye(6)) for p in points]
    out: list[np.ndarray | None] = [None] * len(points)
    todo = list(range(len(points)))
    last = [np.inf] * len(points)
    for _ in range(max_iter):
        if not todo:
            break
        runs = simulate_batch(
            [points[k].system for k in todo], s, [xs[k] for k in todo], tables=tables_of([points[k] for k in todo])
        )
        left = []
        for k, r in zip(todo, runs, strict=True):
            if r.diverged:
                continue
            F = r.final_state - xs[k]
            res = float(np.max(np.abs(F)))
            if not np.isfinite(res) or res > 0.5 * last[k]:
                continue
            if _small(res, xs[k], policy.newton_tol):
                out[k] = xs[k]
                continue
            last[k] = res
            xs[k] = xs[k] - lu[k] @ F
            left.append(k)
        todo = left
    return out


def _certify_states(points: list[Point], xs: list[np.ndarray], n: int, policy: Policy) -> list[ShootingResult]:
    """One monodromy run of n periods at each converged state: residual and multipliers (a ShootingResult)."""
    s = period_settings(policy.integration, n)
    runs = simulate_batch([p.system for p in points], s, xs, monodromy_periods=n, tables=tables_of(points))
    out = []
    for x, r in zip(xs, runs, strict=True):
        if r.diverged or r.monodromy is None:
            out.append(ShootingResult(x, n, False, "diverged", 0, float("inf")))
            continue
        res = float(np.max(np.abs(r.final_state - x)))
        ok = _small(res, x, 2.0 * policy.newton_tol)
        out.append(
            ShootingResult(
                x,
                n,
                ok,
                "converged" if ok else "max_iterations",
                0,
                res,
                r.monodromy.copy(),
                sorted_multipliers(r.monodromy),
            )
        )
    return out


def follow(points: list[Point], policy: Policy) -> list[Point]:
    """The previous point's period-n orbit continued to this point: a chord iteration from the secant
    prediction with the previous orbit's monodromy (full Newton shooting where it does not converge), then
    one monodromy run for the multipliers.  Returns the undecided points."""
    todo = [p for p in points if p.prev is not None and p.prev.periodic]
    rest = [p for p in points if not (p.prev is not None and p.prev.periodic)]
    if not todo:
        return rest
    shots: list[ShootingResult | None] = [None] * len(todo)
    by_n: dict[int, list[int]] = defaultdict(list)
    for k, p in enumerate(todo):
        by_n[p.prev.period].append(k)
    for n, ks in sorted(by_n.items()):
        x0 = {k: _predict(todo[k]) for k in ks}
        chord = [k for k in ks if todo[k].prev.monodromy is not None]
        got = dict(zip(chord, _chord([todo[k] for k in chord], [x0[k] for k in chord], n, policy), strict=True))
        done = [k for k in chord if got[k] is not None]
        for k, r in zip(done, _certify_states([todo[k] for k in done], [got[k] for k in done], n, policy), strict=True):
            shots[k] = r if r.converged else None
        newton = [k for k in ks if shots[k] is None]
        if newton:
            for k, r in zip(
                newton,
                _shoot([todo[k] for k in newton], [x0[k] for k in newton], [n] * len(newton), policy),
                strict=True,
            ):
                shots[k] = r
    for p, s in zip(todo, shots, strict=True):
        if not s.converged:
            p.bifurcation = "orbit_lost"
            p.notes.append(f"the period-{s.n} orbit of the previous point is lost ({s.status})")
        elif s.spectral_radius >= 1.0 - policy.stability_margin:  # not certified stable: it is losing stability
            p.bifurcation = bifurcation_type(s.multipliers)
            p.notes.append(
                f"the followed period-{s.n} orbit is not stable here (|mu|max = {s.spectral_radius:.5f}, "
                f"{p.bifurcation.replace('_', '-')})"
            )
    return rest + decide(todo, periodic_verdicts(todo, shots, policy, "follow", "followed from the previous point"))


# ------------------------------------------------------------------------------------------------
# stage 2: a run from the previous attractor (or the start), rule 3, certified by shooting
# ------------------------------------------------------------------------------------------------


def early_stop(policy: Policy) -> EarlyStop | None:
    """The early-stop criterion of the policy (None when off), scaled to the classifier's tolerance."""
    s, c = policy.integration, policy.classifier
    if not s.early_stop:
        return None
    f = s.early_stop_tol_factor
    return EarlyStop(
        min_periods=s.early_stop_min_periods,
        confirm=s.early_stop_confirm,
        max_n=c.max_n,
        floor=f * c.error_margin * c.error_floor,
        atol=f * c.atol,
        separation=c.separation,
    )


def rule3(results: list[SimulationResult], cs: classify.ClassifierSettings) -> list[int]:
    """Rule 3 (:func:`geardyn.classify.strict_period`, compiled) on every record at once; 0 for a diverged
    run or fewer than 3 points."""
    L = len(results)
    m = max([r.poincare.shape[0] for r in results] + [0])
    pts = np.zeros((L, m, 6))
    npts = np.zeros(L, np.int64)
    for i, r in enumerate(results):
        p = r.poincare
        if not r.diverged and p.shape[0] and not np.isnan(p).any():
            pts[i, : p.shape[0]] = p
            npts[i] = p.shape[0]
    out = strict_periods(pts, npts, cs.max_n, cs.atol, cs.rtol, cs.error_margin * cs.error_floor, cs.separation)
    return [int(v) for v in out[:, 0]]


def _follows_motion(p: Point) -> bool:
    """Whether the point starts from the (non-periodic) attractor of the previous point of its line."""
    return p.prev is not None and not p.prev.diverged and not p.prev.periodic


def integrate(points: list[Point], policy: Policy) -> list[Point]:
    """Run every point from the previous point's final state (``follow``) or the line's start, with the early
    stop; diverged runs and runs that return within tolerance on a certified orbit are decided.  A point that
    follows a non-periodic attractor carries the tangent vector over its record at once (it is most likely
    non-periodic again: :func:`exponents` then needs no second run)."""
    if not points:
        return points
    s, cs = policy.integration, policy.classifier
    groups = ([p for p in points if not _follows_motion(p)], [p for p in points if _follows_motion(p)])
    for tangent, group in enumerate(groups):
        if not group:
            continue
        x0s = [p.start if p.prev is None or p.prev.diverged else p.prev.final_state for p in group]
        trans = [
            s.transient_periods if p.prev is None or p.prev.diverged else policy.follow_transient_periods for p in group
        ]
        rec = [max(s.recorded_periods, cs.tangent_periods) if tangent else s.recorded_periods] * len(group)
        runs = simulate_batch(
            [p.system for p in group],
            s,
            x0s,
            early_stop=early_stop(policy),
            tables=tables_of(group),
            transient_periods=trans,
            recorded_periods=rec,
            tangent_periods=cs.tangent_periods if tangent else 0,
        )
        for p, r in zip(group, runs, strict=True):
            p.run, p.transient_used = r, r.transient_used
            p.tangent = bool(tangent) and r.growth is not None and r.growth.size >= cs.tangent_periods
            if r.diverged:
                p.verdict = diverged_verdict(p, r)
    left = [p for p in points if p.verdict is None]
    if not left:
        return left
    periods = rule3([p.run for p in left], cs)
    return certify(left, periods, policy, "period_test", "the run returns within tolerance")


def certify(points: list[Point], ns: list[int], policy: Policy, stage: str, why: str) -> list[Point]:
    """Newton shooting for period n (n > 0) from each point's final state: a stable orbit decides the point
    (period-m with its Floquet exponent; its record is kept as the points drawn); returns the undecided."""
    todo = [(p, n) for p, n in zip(points, ns, strict=True) if n > 0]
    if not todo:
        return points
    tp = [p for p, _ in todo]
    shots = _shoot(tp, [p.run.final_state for p in tp], [n for _, n in todo], policy)
    # Newton may converge onto a nearby unstable orbit (past a period doubling the old period-n orbit is
    # also a fixed point of the 2n-period map, close to the new one): deflate it and shoot again
    again = [k for k, s in enumerate(shots) if s.converged and s.spectral_radius >= 1.0 - policy.stability_margin]
    if again:
        for k, r in zip(again, _deflated([tp[k] for k in again], [shots[k] for k in again], policy), strict=True):
            if r.converged:
                shots[k] = r
    verdicts = periodic_verdicts(tp, shots, policy, stage, why)
    for k, (p, s, v) in enumerate(zip(tp, shots, verdicts, strict=True)):
        if v is None:
            p.notes.append(
                f"looks period-{s.n} on its record, but shooting finds no stable orbit "
                f"({s.status}, |mu|max = {s.spectral_radius:.5f})"
            )
        elif p.run.poincare.shape[0]:  # the record is on the orbit within tolerance: draw what was integrated
            verdicts[k] = dataclasses.replace(
                v, poincare=p.run.poincare[-_record_length(policy) :], n_events=int(p.run.n_events)
            )
    decide(tp, verdicts)
    return [p for p in points if p.verdict is None]


def _deflated(
    points: list[Point], found: list[ShootingResult], policy: Policy, max_iter: int = 20
) -> list[ShootingResult]:
    """Newton shooting for period n from each point's final state on the deflated residual
    G(x) = m(x) (phi(x) - x), m(x) = 1 / |x - r|^2 + 1, r the unstable orbit point already found (Farrell,
    Birkisson & Funke, SIAM J. Sci. Comput. 37 (2015) A2026): the deflated Newton iteration cannot
    converge to r again.  All points together; convergence on the plain residual, as in Newton shooting."""
    n_of = [f.n for f in found]
    xs = [np.asarray(p.run.final_state, float).copy() for p in points]
    out: list[ShootingResult] = [
        ShootingResult(x, n, False, "max_iterations", max_iter, float("inf")) for x, n in zip(xs, n_of, strict=True)
    ]
    todo = list(range(len(points)))
    for it in range(max_iter + 1):
        if not todo:
            break
        left = []
        for n in sorted({n_of[k] for k in todo}):
            ks = [k for k in todo if n_of[k] == n]
            runs = simulate_batch(
                [points[k].system for k in ks],
                period_settings(policy.integration, n),
                [xs[k] for k in ks],
                monodromy_periods=n,
                tables=tables_of([points[k] for k in ks]),
            )
            for k, r in zip(ks, runs, strict=True):
                if r.diverged or r.monodromy is None:
                    out[k] = ShootingResult(xs[k], n, False, "diverged", it, float("inf"))
                    continue
                F = r.final_state - xs[k]
                res = float(np.max(np.abs(F)))
                if _small(res, xs[k], policy.newton_tol):
                    out[k] = ShootingResult(
                        xs[k].copy(), n, True, "converged", it, res, r.monodromy.copy(), sorted_multipliers(r.monodromy)
                    )
                    continue
                d = xs[k] - found[k].state
                d2 = float(d @ d)
                if d2 == 0.0 or it == max_iter:
                    continue
                m = 1.0 / d2 + 1.0
                grad = -2.0 * d / d2**2
                A = m * (r.monodromy - np.eye(6)) + np.outer(F, grad)
                try:
                    step = np.linalg.solve(A, -m * F)
                except np.linalg.LinAlgError:
                    continue
                cap = 10.0 * max(1.0, float(np.max(np.abs(xs[k]))))
                size = float(np.max(np.abs(step)))
                xs[k] = xs[k] + (step * (cap / size) if size > cap else step)
                left.append(k)
        todo = left
    return out


# ------------------------------------------------------------------------------------------------
# stage 3: slow transients onto a stable orbit
# ------------------------------------------------------------------------------------------------


def slow_transients(points: list[Point], policy: Policy) -> list[Point]:
    """The slow-transient check (:func:`geardyn.label.settle.settle_points`) of every point not periodic on its
    record: a stable orbit the run is seen to approach decides it (the cycle is what is drawn)."""
    if not points or policy.classifier.settle_max_n <= 0:
        return points
    settled = settle_points(
        [p.system for p in points],
        [p.run for p in points],
        [UNDET] * len(points),
        [NAN] * len(points),
        policy.integration,
        policy.classifier,
        tables=tables_of(points),
        always_one=[not _follows_motion(p) for p in points],
    )
    found = [(p, s) for p, s in zip(points, settled, strict=True) if s.state is not None and not s.possible]
    for p, s in zip(points, settled, strict=True):
        if s.possible or (s.state is None and s.reason):
            p.notes.append(s.reason)
    if not found:
        return points
    fp = [p for p, _ in found]
    shots = [ShootingResult(s.state, s.n, True, "converged", 0, 0.0, None, s.multipliers) for _, s in found]
    verdicts = periodic_verdicts(fp, shots, policy, "shooting", "a slow transient")
    decide(
        fp,
        [
            None if v is None else dataclasses.replace(v, reason=s.reason)
            for v, (_, s) in zip(verdicts, found, strict=True)
        ],
    )
    return [p for p in points if p.verdict is None]


# ------------------------------------------------------------------------------------------------
# stage 4: exponent, 0-1 test, spectrum and the torus test
# ------------------------------------------------------------------------------------------------


def exponents(points: list[Point], policy: Policy) -> list[Point]:
    """Continue every point with a tangent vector (unless its run carried one); a record that returns
    within tolerance (rule 3) goes back to :func:`certify`; the rest are labelled from the exponent and the
    torus test (:func:`_nonperiodic_verdict`), undetermined where they disagree."""
    if not points:
        return points
    s, cs = policy.integration, policy.classifier
    more = dataclasses.replace(s, transient_periods=0, recorded_periods=max(s.recorded_periods, cs.tangent_periods))
    again = [p for p in points if not p.tangent]
    cont = dict(
        zip(
            map(id, again),
            simulate_batch(
                [p.system for p in again],
                more,
                [p.run.final_state for p in again],
                tangent_periods=cs.tangent_periods,
                tables=tables_of(again),
            ),
            strict=True,
        )
    )
    for p in points:
        p.run = cont.get(id(p), p.run)
    bounded = []
    for p in points:
        if p.run.diverged:
            p.verdict = diverged_verdict(p, p.run)
        else:
            bounded.append(p)
    periods = rule3([p.run for p in bounded], cs)
    periodic = [(p, n) for p, n in zip(bounded, periods, strict=True) if n > 0]
    if periodic:
        left = certify(
            [p for p, _ in periodic],
            [n for _, n in periodic],
            policy,
            "period_test",
            "periodic on the continued record",
        )
        for p in left:
            p.verdict = _undecided(p, p.run, "looks periodic but no stable orbit is found", policy)
    rest = [p for p, n in zip(bounded, periods, strict=True) if n == 0]
    for p, v in zip(rest, threaded_map(lambda p: _nonperiodic_verdict(p, policy), rest), strict=True):
        p.verdict = v
    _longer_record(rest, policy)
    return []


def _longer_record(points: list[Point], policy: Policy) -> None:
    """Points left undetermined: the run goes on with the tangent vector, its record growing by the factor
    ``1 + torus_extend`` each round up to ``torus_max_periods``, and the same decision
    (:func:`_nonperiodic_verdict`) reads the whole, longer record each time (the torus test converges on a
    torus and stays low on a chaotic set; the exponent's error bar shrinks).  Last, periods up to
    ``long_max_n`` are looked for on the longest record (:func:`_long_periods`)."""
    cs = policy.classifier
    retry = [p for p in points if p.verdict.stage == "undecided"]
    while retry and cs.torus_extend > 0:
        length = retry[0].run.poincare.shape[0]
        n = min(cs.torus_extend * length, cs.torus_max_periods - length)
        if n <= 0:
            break
        s = dataclasses.replace(policy.integration, transient_periods=0, recorded_periods=n)
        runs = simulate_batch(
            [p.system for p in retry], s, [p.run.final_state for p in retry], tables=tables_of(retry), tangent_periods=n
        )
        for p, r in zip(retry, runs, strict=True):
            if r.diverged:
                p.verdict = diverged_verdict(p, r)
                continue
            old = p.run
            p.run = dataclasses.replace(
                r,
                poincare=np.vstack([old.poincare, r.poincare]),
                growth=np.concatenate([old.growth, r.growth]),
                strobe=np.concatenate([old.strobe, r.strobe]),
            )
            p.verdict = _nonperiodic_verdict(p, policy)
        retry = [p for p in retry if p.verdict.stage == "undecided"]
    _long_periods(retry, policy)


def _long_periods(points: list[Point], policy: Policy) -> None:
    """Undecided points whose longer record returns after n periods, max_n < n <= long_max_n (rule 3 with
    the larger bound, on the newest half of the record): a torus locked to a long cycle.  Shooting for period
    n certifies the orbit; the label is then ``long_period`` with the least period in ``period``."""
    cs = policy.classifier
    if not points or cs.long_max_n <= cs.max_n:
        return
    half = [dataclasses.replace(p.run, poincare=p.run.poincare[p.run.poincare.shape[0] // 2 :]) for p in points]
    big = dataclasses.replace(cs, max_n=cs.long_max_n)
    ns = [
        n if n > cs.max_n and 3 * n <= r.poincare.shape[0] else 0 for n, r in zip(rule3(half, big), half, strict=True)
    ]
    todo = [(p, n) for p, n in zip(points, ns, strict=True) if n > 0]
    if not todo:
        return
    undecided = {id(p): p.verdict for p, _ in todo}
    for p, _ in todo:
        p.verdict = None
    left = certify(
        [p for p, _ in todo],
        [n for _, n in todo],
        policy,
        "period_test",
        "the longer record returns after a long period",
    )
    for p in left:
        p.verdict = undecided[id(p)]


def standardised(points: np.ndarray) -> np.ndarray:
    """The torus test's observable: each coordinate of the Poincare points, standardised (the first
    moments of :func:`geardyn.label.torus.moments`; the higher ones converge too slowly on the model's
    slowly attracting tori to decide within a few hundred periods, docs/classify.md)."""
    return moments(points)[:, : points.shape[1]]


def _torus(points: np.ndarray, cs: classify.ClassifierSettings):
    """The torus test on the record (2N Poincare points): a torus at log10 sqrt(N) + torus_margin digits,
    chaos below log10 sqrt(N) + chaos_margin."""
    n = max(1, points.shape[0] // 2)
    return torus_test(
        points[-2 * n :],
        0.5 * math.log10(n) + cs.torus_margin,
        cs.chaos_margin,
        cs.torus_min_n,
        observable=standardised,
    )


def _nonperiodic_verdict(p: Point, policy: Policy) -> Verdict:
    """Chaos needs a positive exponent that the torus test confirms (no torus: the Birkhoff averages do not
    converge); quasi-periodic needs the torus test and an exponent that is not positive; anything else is
    undetermined, with the reason.  The 0-1 test and the spectral flatness cross-check a chaos label."""
    r, cs = p.run, policy.classifier
    lam, sig = classify.lyapunov_estimate(r.growth, r.period)
    tt = _torus(r.poincare, cs)
    digits = tt.digits
    positive = bool(np.isfinite(lam) and lam > cs.lam_tol + 2 * sig)
    negative = bool(np.isfinite(lam) and lam < -(cs.lam_tol + 2 * sig))
    k01 = flat = NAN
    cross = -1
    if positive and tt.verdict == "chaotic":
        phi = r.strobe if r.strobe is not None and r.strobe.size else r.poincare[:, 1]
        k01, flat = classify.zero_one_test(phi), classify.spectral_flatness(phi)
        cross = int(k01 > cs.k_chaos) + int(flat > cs.flat_broadband) - 1
        label, stage, why = (
            CHAOS,
            "exponent",
            (f"positive exponent {lam:.2g} +- {sig:.1g}; the Birkhoff averages do not converge (digits {digits:.1f})"),
        )
    elif tt.verdict == "torus" and not positive and not negative:
        label, stage, why = QP, "torus", f"Birkhoff averages converge (digits {digits:.1f}); exponent {lam:.2g}"
    elif negative:
        label, stage, why = (
            UNDET,
            "undecided",
            (
                f"negative exponent {lam:.2g} +- {sig:.1g}: attracted to a periodic "
                f"orbit that shooting did not find (digits {digits:.1f})"
            ),
        )
    elif tt.verdict == "torus":
        label, stage, why = (
            UNDET,
            "undecided",
            (f"positive exponent {lam:.2g} but the Birkhoff averages converge (digits {digits:.1f})"),
        )
    elif positive:
        label, stage, why = UNDET, "undecided", f"positive exponent {lam:.2g}, torus test inconclusive ({digits:.1f})"
    else:
        label, stage, why = (
            UNDET,
            "undecided",
            (
                f"exponent {lam:.2g} +- {sig:.1g} not positive and the Birkhoff "
                f"averages do not converge (digits {digits:.1f})"
            ),
        )
    why += f" ({r.poincare.shape[0]} recorded periods)"
    if p.notes:
        why += "; " + "; ".join(p.notes)
    return Verdict(
        label,
        0,
        lam,
        sig,
        "tangent",
        stage,
        why,
        final_state=r.final_state.copy(),
        poincare=r.poincare[-_record_length(policy) :],
        bifurcation=p.bifurcation,
        k01=k01,
        flatness=flat,
        torus_digits=digits,
        crosscheck=cross,
        transient_used=p.transient_used,
        n_events=int(r.n_events),
    )


def _undecided(p: Point, r: SimulationResult, why: str, policy: Policy) -> Verdict:
    if p.notes:
        why += "; " + "; ".join(p.notes)
    return Verdict(
        UNDET,
        0,
        NAN,
        NAN,
        "none",
        "undecided",
        why,
        final_state=r.final_state.copy(),
        poincare=r.poincare[-_record_length(policy) :],
        bifurcation=p.bifurcation,
        transient_used=p.transient_used,
        n_events=int(r.n_events),
    )
