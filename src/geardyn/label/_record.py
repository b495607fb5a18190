"""Stages 2 and 3 of the labeller: a run from the previous attractor (or the line's start) with the
early stop, rule 3 and the certification by shooting; then the slow-transient check of what is not
periodic on its record (:mod:`geardyn.label.settle`).
"""

from __future__ import annotations

import dataclasses

import geardyn.label.indicators as indicators
from geardyn.label._stages import (
    NAN,
    UNDET,
    Point,
    certify,
    decide,
    diverged_verdict,
    periodic_verdicts,
    tables_of,
)
from geardyn.label.policy import Policy
from geardyn.label.settle import settle_points
from geardyn.solve.base import EarlyStop, Lane, Sums, Tangent
from geardyn.solve.run import simulate_batch
from geardyn.solve.shooting import ShootingResult

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


def _follows_motion(p: Point) -> bool:
    """Whether the point starts from the (non-periodic) attractor of the previous point of its line."""
    return p.prev is not None and not p.prev.periodic


def integrate(points: list[Point], policy: Policy) -> list[Point]:
    """Run every point from the previous point's final state (``follow``) or the line's start, with the early
    stop; diverged runs and runs that return within tolerance on a certified orbit are decided.  The run sums
    the response measures over its last ``recorded_periods`` (those of a verdict read off this record).  A point that
    follows a non-periodic attractor carries the tangent vector over its record at once (it is most likely
    non-periodic again: :func:`exponents` then needs no second run)."""
    if not points:
        return points
    s, cs = policy.integration, policy.classifier
    groups = ([p for p in points if not _follows_motion(p)], [p for p in points if _follows_motion(p)])
    for tangent, group in enumerate(groups):
        if not group:
            continue
        x0s = [p.start if p.prev is None else p.prev.final_state for p in group]
        trans = [s.transient_periods if p.prev is None else policy.follow_transient_periods for p in group]
        rec = [max(s.recorded_periods, cs.tangent_periods) if tangent else s.recorded_periods] * len(group)
        var = Tangent(cs.tangent_periods) if tangent else None
        sums = Sums(policy.integration.recorded_periods)
        lanes = [
            Lane(p.system, x, t, r, variational=var, sums=sums)
            for p, x, t, r in zip(group, x0s, trans, rec, strict=True)
        ]
        runs = simulate_batch(lanes, s, early_stop=early_stop(policy), tables=tables_of(group))
        for p, r in zip(group, runs, strict=True):
            p.run, p.transient_used, p.measured = r, r.transient_used, policy.integration.recorded_periods
            p.tangent = bool(tangent) and r.growth is not None and r.growth.size >= cs.tangent_periods
            if r.diverged:
                p.verdict = diverged_verdict(p, r)
    left = [p for p in points if p.verdict is None]
    if not left:
        return left
    periods = indicators.strict_periods([p.run.poincare for p in left], cs)
    return certify(left, periods, policy, "period_test", "the run returns within tolerance")


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
        policy,
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
