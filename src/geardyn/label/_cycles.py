"""The searches for the cycle a quasi-periodic or undecided record hides, run when its record is done
(:func:`finish`): long cycles, the orbit born at a period doubling, slowly gathered cycles, orbits circled at the
unit circle, held verdicts confirmed (``docs/classify.md``)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

import geardyn.label.indicators as indicators
from geardyn.label._stages import (
    QP,
    Point,
    certify,
    periodic_verdicts,
    shoot,
    undecided,
)
from geardyn.label.policy import Policy
from geardyn.label.torus import order_test


def finish(points: list[Point], policy: Policy) -> None:
    """The last step for points whose record is done: long cycles (:func:`long_periods`), the orbit born at a
    period doubling (:func:`_doubled`), slowly gathered cycles (:func:`locked`), orbits circled at the unit
    circle (:func:`_at_circle`), held verdicts confirmed (:func:`doubt`) (``docs/classify.md``)."""
    for newest_half in (True, False):
        long_periods([p for p in points if p.verdict.label == QP], policy, newest_half=newest_half)
    locked([p for p in points if p.verdict.label == QP], policy)
    _at_circle([p for p in points if p.verdict.label == QP], policy)
    _doubled([p for p in points if p.verdict.label == QP], policy)
    for p in points:
        if p.held is not None:
            p.handed = p.handed or p.held
            if p.verdict.label == QP:
                n = p.run.poincare.shape[0]
                p.verdict = dataclasses.replace(p.held, reason=f"{p.held.reason}; confirmed on {n} recorded periods")
    for p in points:
        if p.verdict.label == QP:
            n = period_searched(p.run.poincare.shape[0], policy)
            why = f"{p.verdict.reason}; a torus or a cycle longer than {n} periods (the long-cycle search's reach)"
            p.verdict = dataclasses.replace(p.verdict, period_searched=n, reason=why)


def period_searched(length: int, policy: Policy) -> int:
    """The longest period the searches exclude on a record of ``length`` periods: rule 3 up to ``max_n`` on the
    whole record, the long-cycle search up to ``long_max_n`` with ``cycle_repeats`` cycles in it
    (:func:`long_periods`)."""
    cs = policy.classifier
    return max(cs.max_n, min(cs.long_max_n, length // policy.cycle_repeats))


def doubt(points: list[Point], policy: Policy) -> None:
    """Quasi-periodic verdicts in doubt (past a period doubling of the followed orbit, or after a point with a
    positive exponent) run on to ``policy.doubt_periods``, undetermined meanwhile; the verdict first reached,
    after :func:`finish`, is held and kept where the longer record confirms it (``docs/classify.md``)."""
    cs = policy.classifier
    cap = min(policy.doubt_periods, cs.torus_max_periods)
    doubted = []
    for p in points:
        prev = p.prev
        # a positive exponent as the verdicts' own: above the zero band by two standard errors
        chaotic = prev is not None and not prev.periodic and bool(prev.exponent > cs.lam_tol + 2 * prev.exponent_sigma)
        if p.run.poincare.shape[0] < cap and (p.bifurcation == "period_doubling" or chaotic):
            doubted.append(p)
    finish([p for p in doubted if p.held is None], policy)
    for p in doubted:
        if p.verdict.label == QP:
            p.held = p.verdict if p.held is None else p.held
            why = "a torus after a period doubling or a chaotic point: in doubt until a longer record confirms it"
            p.verdict = undecided(p, f"{why} ({cap} periods)", policy)


def _doubled(points: list[Point], policy: Policy) -> None:
    """Past the period doubling of the followed period-n orbit (the follow stage's orbit point and monodromy),
    the period-2n orbit born there, shot for from that point displaced along the eigenvector of the multiplier
    past -1 on either side (branch switching; ``docs/classify.md``)."""
    todo = [p for p in points if p.bifurcation == "period_doubling" and p.lost and p.lost.monodromy is not None]
    for side in (1.0, -1.0):
        todo = [p for p in todo if p.verdict.label == QP]
        if not todo:
            return
        starts = [_switched(p.lost.state, p.lost.monodromy, side * policy.switch_step) for p in todo]
        shots = shoot(todo, starts, [2 * p.lost.n for p in todo], policy)
        why = "the orbit born at the followed orbit's period doubling"
        for p, s, v in zip(todo, shots, periodic_verdicts(todo, shots, policy, "period_test", why), strict=True):
            if v is not None and v.period == s.n:  # the new orbit, not the old one's n / 2 periods
                p.handed, p.verdict = p.handed or p.verdict, v


def _switched(x: np.ndarray, monodromy: np.ndarray, step: float) -> np.ndarray:
    """x displaced by ``step`` times max(1, |x|) along the (real) eigenvector of the multiplier of ``monodromy``
    nearest -1, scaled to a largest component of 1."""
    mu, vectors = np.linalg.eig(monodromy)
    v = np.real(vectors[:, int(np.argmin(np.abs(mu + 1.0)))])
    return x + step * max(1.0, float(np.max(np.abs(x)))) * v / float(np.max(np.abs(v)))


def _at_circle(points: list[Point], policy: Policy) -> None:
    """Quasi-periodic records that closely circle a period-n orbit (n <= ``policy.locked.circle_max_n``)
    whose max|mu| is within the stability margin of 1: undetermined, a Neimark-Sacker point to the
    labeller's accuracy (``docs/classify.md``)."""
    tol = policy.locked.return_tol
    circled: set[int] = set()  # points whose record circles an orbit of a shorter period: decided there
    for n in range(1, policy.locked.circle_max_n + 1):
        todo, records, centroids = [], [], []
        for p in points:
            r = p.run.poincare[(p.run.poincare.shape[0] - 1) % n :: n]
            c = np.mean(r, axis=0) if p.verdict.label == QP and id(p) not in circled and r.shape[0] >= 3 else None
            # only a record thin enough to lie within the tolerance of an orbit point is shot for it
            if c is not None and np.max(np.abs(r - c)) < 2.0 * tol * max(1.0, float(np.max(np.abs(c)))):
                todo.append(p)
                records.append(r)
                centroids.append(c)
        shots = shoot(todo, centroids, [n] * len(todo), policy) if todo else []
        for p, r, s in zip(todo, records, shots, strict=True):
            if not s.converged or float(np.max(np.abs(r - s.state))) >= tol * max(1.0, float(np.max(np.abs(s.state)))):
                continue
            circled.add(id(p))
            if abs(s.spectral_radius - 1.0) < policy.stability_margin:
                why = (
                    f"circles a period-{n} orbit with |mu|max = {s.spectral_radius:.6f}, within the stability "
                    "margin of 1: at its bifurcation, to this accuracy"
                )
                p.verdict = undecided(p, why, policy)


def long_periods(points: list[Point], policy: Policy, newest_half: bool = True) -> None:
    """Points whose record returns after n periods, n <= long_max_n (rule 3 with the larger bound, on the
    newest half of the record, or on all of it with ``newest_half=False``; at least three cycles): a torus
    locked to a long cycle (n > max_n), or a record whose older part was still approaching a short cycle
    (n <= max_n: rule 3 reads the whole record and missed it), certified by shooting (:func:`_try_periods`)."""
    cs = policy.classifier
    if not points or cs.long_max_n <= 0:
        return
    half = [p.run.poincare[p.run.poincare.shape[0] // 2 if newest_half else 0 :] for p in points]
    big = dataclasses.replace(cs, max_n=max(cs.long_max_n, cs.max_n))
    reps = policy.cycle_repeats
    ns = [
        n if 0 < n and reps * n <= r.shape[0] else 0
        for n, r in zip(indicators.strict_periods(half, big), half, strict=True)
    ]
    short = [n if n <= cs.max_n else 0 for n in ns]
    _try_periods(points, short, policy, "the newest part of the record returns after a few periods")
    _try_periods(
        points, [n if n > cs.max_n else 0 for n in ns], policy, "the longer record returns after a long period"
    )


def locked(points: list[Point], policy: Policy) -> None:
    """Quasi-periodic records that approach a cycle too slowly for rule 3, certified by shooting for the
    candidate period from the order test's nearest neighbours or the gathering test; the verdict draws the
    cycle's points (the choice of n: ``docs/classify.md``)."""
    cs = policy.classifier
    if not points or cs.long_max_n <= 0:
        return
    ns, doubled = [], []
    for p in points:
        record = p.run.poincare
        known = p.order[1] if p.order is not None and p.order[0] is record else None  # the torus test's
        gaps = (known or order_test(order_part(record, cs), 0)).gaps
        n = gaps[0] if _gathers_at(record, gaps[0], policy, len(gaps) == 1) else 0
        # the nearest neighbours in pairs (differences m, 2m and multiples of m): a cycle of twice m, tried last
        if 1 < gaps[0] and 2 * gaps[0] in gaps and all(g % gaps[0] == 0 for g in gaps):
            doubled.append(2 * gaps[0])
        else:
            doubled.append(0)
        if n:
            ns.append(n)
        else:  # a short cycle whose approach the newest half still shows (nearest neighbours not yet n apart)
            falling = indicators.falling_return_distances(record, cs.max_n, policy.return_fall)  # compiled, cheap
            short = (m for m in range(1, cs.max_n + 1) if falling[m - 1] and _gathers(record, m, policy))
            ns.append(next(short, 0))
    locked = dataclasses.replace(
        policy,
        newton=dataclasses.replace(
            policy.newton, max_iter=policy.locked.newton_max_iter, max_growth=policy.locked.max_growth
        ),
    )
    why = "the record gathers about the points of a cycle"
    _try_periods(points, ns, locked, why, record_on_orbit=False)
    todo = [(p, m) for p, m in zip(points, doubled, strict=True) if m and p.verdict.label == QP]
    todo = [(p, m) for p, m in todo if _gathers_at(p.run.poincare, m, policy, False)]
    if not todo:
        return
    before = [p.verdict for p, _ in todo]
    _try_periods([p for p, _ in todo], [m for _, m in todo], locked, why, record_on_orbit=False)
    for (p, _), v in zip(todo, before, strict=True):  # a finding of the checks of doubt: not followed
        if p.verdict is not v:
            p.handed = p.handed or v


def _gathers_at(record: np.ndarray, n: int, policy: Policy, alone: bool) -> bool:
    """Whether the record gathers about a cycle of the period n its nearest neighbours point to: its return
    distance after n periods over the newest third below ``locked.return_tol`` and falling along the record
    (any fall for a short cycle), or every neighbour n periods away (``alone``)."""
    cs, lk = policy.classifier, policy.locked
    if not 0 < n <= max(cs.long_max_n, cs.max_n):
        return False
    oldest, newest = _returns(record, n, policy.cycle_repeats)
    falls = newest < (lk.fall_short if n <= cs.max_n else lk.fall_long) * oldest
    return newest < lk.return_tol and (falls or alone)


def _gathers(p: np.ndarray, n: int, policy: Policy) -> bool:
    """Whether the record ``p`` gathers about a period-n cycle: its return distance after n periods over the
    newest part is below ``policy.locked.return_tol`` (relative) and below ``policy.gather_fall`` of that over the
    oldest part (:func:`_returns`)."""
    oldest, newest = _returns(p, n, policy.cycle_repeats)
    return newest < policy.locked.return_tol and newest < policy.gather_fall * oldest


def _returns(p: np.ndarray, n: int, parts: int) -> tuple[float, float]:
    """The median return distance after ``n`` periods over the oldest and the newest of ``parts`` parts of the
    record ``p``, relative to the attractor's size (inf when the record holds fewer than ``parts`` cycles)."""
    if p.shape[0] < parts * n:
        return math.inf, math.inf
    d = np.max(np.abs(p[n:] - p[:-n]), axis=1) / (float(np.max(p.std(axis=0))) or 1.0)
    k = max(1, d.shape[0] // parts)
    return float(np.median(d[:k])), float(np.median(d[-k:]))


def _try_periods(points: list[Point], ns: list[int], policy: Policy, reason: str, record_on_orbit: bool = True) -> None:
    """Shooting for period n at each point with n > 0 (:func:`geardyn.label._stages.certify`, stage
    ``period_test``): where it certifies a stable orbit whose least period m divides n (the record's points
    return, or gather, after n periods: a cycle of period m does both) the label is ``long_period`` (or
    period-m) with m in ``period``; elsewhere the verdict stays.  ``record_on_orbit``: the record returns
    within tolerance, and its points are drawn (else the orbit's)."""
    todo = [(p, n) for p, n in zip(points, ns, strict=True) if n > 0]
    if not todo:
        return
    kept = {id(p): p.verdict for p, _ in todo}
    for p, _ in todo:
        p.verdict = None
    certify([p for p, _ in todo], [n for _, n in todo], policy, "period_test", reason, record_on_orbit)
    for p, n in todo:
        # shooting must find the cycle the record shows (from far off, Newton can reach another attractor)
        if p.verdict is None or p.verdict.period < 1 or n % p.verdict.period:
            p.verdict = kept[id(p)]


def order_part(points: np.ndarray, cs: indicators.ClassifierSettings) -> np.ndarray:
    """The part of a record that the order tests read: its newest half (of the last 2N points), or its
    newest ``order_min_n`` points where that half is shorter (all of a shorter record)."""
    n = max(1, points.shape[0] // 2)
    return points[-2 * n :][-max(cs.order_min_n, n) :]
