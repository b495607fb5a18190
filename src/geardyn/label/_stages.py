"""The labeller's stages, and what they share: the point record, verdicts of certified orbits, Newton
shooting grouped by period, rule 3 on many records, certification by shooting (the four stages:
``docs/classify.md``)."""

from __future__ import annotations

import dataclasses
import logging
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

import geardyn.label.vocabulary as vocabulary
from geardyn.label.compare import least_period
from geardyn.label.policy import Policy
from geardyn.label.torus import OrderTest
from geardyn.label.verdict import Verdict
from geardyn.solve.base import ShootingSettings, SimulationResult, System
from geardyn.solve.response import ResponseMeasures, measures_of_sums, response_measures_many
from geardyn.solve.run import LaneTables
from geardyn.solve.shooting import (
    DeflatedShot,
    ShootingResult,
    Shot,
    cycle_points,
    deflated_shooting_batch,
    newton_shooting_batch,
)

UNDET = vocabulary.LABELS["undetermined"]
QP = vocabulary.LABELS["quasi_periodic"]
CHAOS = vocabulary.LABELS["chaotic"]
DIVERGED = vocabulary.LABELS["diverged"]
TRANSIENT = vocabulary.LABELS["transient"]
NAN = float("nan")

log = logging.getLogger("geardyn.label")


@dataclass
class Point:
    """A point on its way through the stages (mutable, private to the labeller): the previous verdict, the
    line's fixed start, the run the later stages read and the notes for the reason."""

    system: System
    prev: Verdict | None  # None for a line's first point and after a diverged one (:meth:`_Line.point`)
    start: np.ndarray | None
    prev2: Verdict | None = None
    tables: LaneTables | None = None  # the step tables of the batch the point came in (built once per batch)
    row: int = 0  # this point's row in them
    verdict: Verdict | None = None
    tangent: bool = False
    bifurcation: str = "none"
    run: SimulationResult | None = None
    left: int = 0  # periods left in the round of a growing record (stage 4)
    piece: SimulationResult | None = None  # that round's run so far
    order: tuple[np.ndarray, OrderTest] | None = None  # the torus test's order test of a record: (record, test)
    transient_used: int = 0
    measured: int = 0  # the last periods of the record whose response measures' sums the run carries
    lost: ShootingResult | None = None  # the followed orbit where it is no longer stable (the follow stage's)
    held: Verdict | None = None  # a torus verdict in doubt until its longer record confirms it
    handed: Verdict | None = None  # the verdict the line goes on from, where a check of doubt changed it
    notes: list[str] = dataclasses.field(default_factory=list)


# ------------------------------------------------------------------------------------------------
# helpers
# ------------------------------------------------------------------------------------------------


def tile(points: np.ndarray, length: int) -> np.ndarray:
    """The m cycle points repeated to ``length`` rows (what a periodic verdict draws)."""
    reps = -(-length // max(1, points.shape[0]))
    return np.tile(points, (reps, 1))[:length]


def periodic_verdicts(
    points: list[Point], shots: list[ShootingResult], policy: Policy, stage: str, why: str
) -> list[Verdict | None]:
    """Verdicts for converged Newton orbits: period-m (m the least period) when max|mu| < 1 - margin, else
    None.  The cycle points come from one run of n periods from the orbit point (all together; a period-1
    orbit is its point), which also sums the response measures over the n periods (:func:`_cycle_measures`)."""
    margin = policy.stability_margin
    good = [k for k, s in enumerate(shots) if s.converged and s.spectral_radius < 1.0 - margin]
    out: list[Verdict | None] = [None] * len(shots)
    cycles: dict[int, tuple[np.ndarray, int, np.ndarray | None]] = {}

    def run(n: int, js: list[int]) -> list:
        ks = [good[j] for j in js]
        ps, xs = [points[k] for k in ks], [shots[k].state for k in ks]
        return cycle_points([p.system for p in ps], xs, n, policy.integration, tables=tables_of(ps), measure=True)

    for k, (cyc, events, diverged, sums) in zip(good, grouped([shots[k].n for k in good], run), strict=True):
        if not diverged:
            tol = policy.newton.cycle_tol_factor * policy.newton.tol * max(1.0, float(np.max(np.abs(shots[k].state))))
            cycles[k] = (cyc[: least_period(cyc, tol)], events, sums)
    measures = _cycle_measures(points, shots, cycles, policy)
    for k, (cycle, events, _) in cycles.items():
        shot, m = shots[k], cycle.shape[0]
        n, rho = shot.n, shot.spectral_radius
        out[k] = Verdict(
            label=m if m <= policy.classifier.max_n else vocabulary.LABELS["long_period"],
            period=m,
            exponent=math.log(rho) / (n * points[k].system.period),
            exponent_sigma=0.0,
            exponent_method="floquet",
            stage=stage,
            reason=f"{why}: stable period-{m} orbit, |mu|max = {rho ** (m / n):.6f}",
            final_state=shot.state.copy(),
            poincare=tile(cycle, policy.integration.recorded_periods),
            multiplier=rho ** (m / n),
            bifurcation=points[k].bifurcation,
            transient_used=points[k].transient_used,
            n_events=events,
            monodromy=shot.monodromy if m == n else None,
            response=measures[k],
        )
    return out


def _cycle_measures(
    points: list[Point], shots: list[ShootingResult], cycles: dict, policy: Policy
) -> dict[int, ResponseMeasures]:
    """The response measures of each orbit over its least period m from its orbit point: the sums of its
    cycle run (:func:`periodic_verdicts`) where m = n, the numbers :func:`response_measures_many` gives; where
    the least period m is shorter than the n periods run, a run of its own over m periods (rare: the
    shooting's n is the period rule 3 or the previous point saw)."""
    out = {
        k: measures_of_sums(sums, points[k].system, shots[k].n)
        for k, (cycle, _, sums) in cycles.items()
        if cycle.shape[0] == shots[k].n
    }
    short = [k for k in cycles if k not in out]
    if short:
        log.debug("%d orbits of a shorter least period: their measures from a run of their own", len(short))
        ms = response_measures_many(
            [points[k].system for k in short],
            [shots[k].state for k in short],
            policy.integration,
            [cycles[k][0].shape[0] for k in short],
        )
        out.update(zip(short, ms, strict=True))
    return out


def shoot(
    points: list[Point],
    starts: list[np.ndarray],
    ns: list[int],
    policy: Policy,
    deflate: list[np.ndarray] | None = None,
) -> list[ShootingResult]:
    """Newton shooting of every point for its n from its start, grouped by n (each point as alone).  With
    ``deflate``: deflated Newton about each point's unstable orbit point already found (it cannot converge
    to it again; ``policy.deflation``, no growth stop)."""
    if deflate is None:
        return grouped(
            ns, lambda n, ks: shoot_batch([points[k] for k in ks], [starts[k] for k in ks], n, policy, policy.newton)
        )
    shooting = dataclasses.replace(policy.newton, max_iter=policy.deflation.max_iter, max_growth=math.inf)

    def deflated(n: int, ks: list[int]) -> list[ShootingResult]:
        shots = [DeflatedShot(points[k].system, starts[k], deflate[k]) for k in ks]
        tables = tables_of([points[k] for k in ks])
        return deflated_shooting_batch(shots, n, policy.integration, shooting, tables, policy.deflation.shift)

    return grouped(ns, deflated)


def grouped(keys: list[int], run: Callable[[int, list[int]], list]) -> list:
    """``run(key, ks)`` once for the indices ``ks`` of each key, by increasing key (the points of one period
    in one batch), its results put back at those indices."""
    out: list = [None] * len(keys)
    for key in sorted(set(keys)):
        ks = [k for k, x in enumerate(keys) if x == key]
        for k, r in zip(ks, run(key, ks), strict=True):
            out[k] = r
    return out


def shoot_batch(
    points: list[Point], xs: list[np.ndarray], n: int, policy: Policy, shooting: ShootingSettings
) -> list[ShootingResult]:
    """Newton shooting (:func:`geardyn.solve.shooting.newton_shooting_batch`) of the points' systems from
    ``xs``, with the policy's integration and the points' lane tables."""
    shots = [Shot(p.system, x) for p, x in zip(points, xs, strict=True)]
    return newton_shooting_batch(shots, n, policy.integration, shooting, tables_of(points))


def tables_of(points: list[Point]) -> LaneTables | None:
    """The lane tables of ``points`` (rows of the tables of the batches they came in), or None to build them."""
    if not points or any(p.tables is None for p in points):
        return None
    first = points[0].tables
    if all(p.tables is first for p in points):
        return first.take([p.row for p in points])
    return LaneTables.gather([(p.tables, p.row) for p in points])


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
    """The verdict of a run that diverged: no measures (:meth:`ResponseMeasures.not_computed`)."""
    return Verdict(
        DIVERGED,
        0,
        math.inf,
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
        response=ResponseMeasures.not_computed(),
    )


def certify(
    points: list[Point], ns: list[int], policy: Policy, stage: str, why: str, record_on_orbit: bool = True
) -> list[Point]:
    """Newton shooting for period n (n > 0) from each point's final state: a stable orbit decides the point
    (period-m with its Floquet exponent); returns the undecided.  The points drawn are the run's record when
    it returns within tolerance (``record_on_orbit``: rule 3 found the period on it), else the orbit's."""
    todo = [(p, n) for p, n in zip(points, ns, strict=True) if n > 0]
    if not todo:
        return points
    tp = [p for p, _ in todo]
    shots = shoot(tp, [p.run.final_state for p in tp], [n for _, n in todo], policy)
    # Newton may converge onto a nearby unstable orbit (past a period doubling the old period-n orbit is
    # also a fixed point of the 2n-period map, close to the new one): deflate it and shoot again
    again = [k for k, s in enumerate(shots) if s.converged and s.spectral_radius >= 1.0 - policy.stability_margin]
    if again:
        deflated = shoot(
            [tp[k] for k in again],
            [np.asarray(tp[k].run.final_state, float) for k in again],
            [shots[k].n for k in again],
            policy,
            deflate=[shots[k].state for k in again],
        )
        for k, r in zip(again, deflated, strict=True):
            if r.converged:
                shots[k] = r
    verdicts = periodic_verdicts(tp, shots, policy, stage, why)
    for k, (p, s, v) in enumerate(zip(tp, shots, verdicts, strict=True)):
        if v is None:
            p.notes.append(
                f"looks period-{s.n} on its record, but shooting finds no stable orbit "
                f"({s.status}, |mu|max = {s.spectral_radius:.5f})"
            )
        elif record_on_orbit and p.run.poincare.shape[0]:  # the record is on the orbit: draw what was integrated
            verdicts[k] = dataclasses.replace(
                v, poincare=p.run.poincare[-policy.integration.recorded_periods :], n_events=int(p.run.n_events)
            )
    decide(tp, verdicts)
    return [p for p in points if p.verdict is None]


def undecided(p: Point, why: str, policy: Policy) -> Verdict:
    return record_verdict(p, policy, UNDET, NAN, NAN, "none", "undecided", why)


def record_verdict(
    p: Point, policy: Policy, label: int, lam: float, sig: float, method: str, stage: str, why: str, **measured: float
) -> Verdict:
    """A verdict of no period read off the point's record ``p.run``: its final state, its newest Poincare points, the
    response measures of its last ``p.measured`` periods (the sums its run added), the earlier stages' notes
    appended to the reason; ``measured``: the torus and chaos measures, where computed."""
    if p.notes:
        why += "; " + "; ".join(p.notes)
    return Verdict(
        label,
        0,
        lam,
        sig,
        method,
        stage,
        why,
        final_state=p.run.final_state.copy(),
        poincare=p.run.poincare[-policy.integration.recorded_periods :],
        bifurcation=p.bifurcation,
        transient_used=p.transient_used,
        n_events=int(p.run.n_events),
        response=measures_of_sums(p.run.sums, p.system, p.measured),
        **measured,  # type: ignore[arg-type]  # Verdict's float fields (k01, flatness, ...), by name
    )
