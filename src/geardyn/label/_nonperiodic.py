"""Stage 4 of the labeller: what is neither periodic nor a slow transient is labelled from the tangent
exponent and the torus tests, undetermined records run on; a record done is searched for the cycle it hides
(:mod:`geardyn.label._cycles`; ``docs/classify.md``)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

import geardyn.label.indicators as indicators
import geardyn.label.vocabulary as vocabulary
from geardyn.label._cycles import doubt, finish, long_periods, order_part
from geardyn.label._stages import (
    CHAOS,
    NAN,
    QP,
    TRANSIENT,
    UNDET,
    Point,
    certify,
    diverged_verdict,
    record_verdict,
    tables_of,
    undecided,
)
from geardyn.label.growth import growing
from geardyn.label.policy import Policy
from geardyn.label.torus import OrderTest, TorusTest, coordinates, order_test, torus_digits, torus_verdict
from geardyn.label.verdict import Verdict
from geardyn.parallel import threaded_map
from geardyn.solve.base import Lane, SimulationResult, Sums, Tangent
from geardyn.solve.run import simulate_batch

# ------------------------------------------------------------------------------------------------
# stage 4: exponent, 0-1 test, spectrum and the torus test
# ------------------------------------------------------------------------------------------------


def exponents(points: list[Point], policy: Policy) -> list[Point]:
    """Continue every point with a tangent vector (unless its run carried one); a record that returns
    within tolerance (rule 3) goes back to :func:`certify`; the rest are labelled from the exponent and the
    torus test (:func:`_nonperiodic_verdict`), undetermined where they disagree.  Returns the points left
    undetermined whose record is to grow (:func:`longer_record`); the others are finished (:func:`finish`)."""
    if not points:
        return points
    s, cs = policy.integration, policy.classifier
    more = dataclasses.replace(s, transient_periods=0, recorded_periods=max(s.recorded_periods, cs.tangent_periods))
    again = [p for p in points if not p.tangent]
    cont = dict(
        zip(
            map(id, again),
            simulate_batch(
                [
                    Lane(
                        p.system,
                        p.run.final_state,
                        variational=Tangent(cs.tangent_periods),
                        sums=Sums(policy.integration.recorded_periods),
                    )
                    for p in again
                ],
                more,
                tables=tables_of(again),
            ),
            strict=True,
        )
    )
    for p in points:
        p.run = cont.get(id(p), p.run)
        if p.run.diverged:
            p.verdict = diverged_verdict(p, p.run)
    bounded = [p for p in points if not p.run.diverged]
    periods = indicators.strict_periods([p.run.poincare for p in bounded], cs)
    periodic = [(p, n) for p, n in zip(bounded, periods, strict=True) if n > 0]
    if periodic:
        ps, ns = [p for p, _ in periodic], [n for _, n in periodic]
        left = certify(ps, ns, policy, "period_test", "periodic on the continued record")
        for p in left:
            p.verdict = undecided(p, "looks periodic but no stable orbit is found", policy)
    rest = [p for p, n in zip(bounded, periods, strict=True) if n == 0]
    for p, v in zip(rest, threaded_map(lambda p: _nonperiodic_verdict(p, policy), rest), strict=True):
        p.verdict = v
    return end_round(rest, policy)


def end_round(points: list[Point], policy: Policy) -> list[Point]:
    """The end of a round of the records of ``points``: undetermined records certified for long cycles
    (:func:`long_periods`), the still undetermined points start their next round and are returned, the
    others are finished (``docs/classify.md``)."""
    long_periods([p for p in points if p.verdict.stage == "undecided"], policy)
    doubt([p for p in points if p.verdict.label == QP], policy)
    grow = {id(p) for p in points if start_round(p, policy)}
    finish([p for p in points if id(p) not in grow], policy)
    return [p for p in points if id(p) in grow]


def start_round(p: Point, policy: Policy) -> bool:
    """Start the next round of the point's record where it runs on (left undetermined, ``torus_extend`` > 0
    and the record shorter than ``torus_max_periods``): the round's length goes to ``p.left``.  Returns
    whether it runs on."""
    cs = policy.classifier
    length = p.run.poincare.shape[0]
    if p.verdict.stage != "undecided" or cs.torus_extend <= 0 or length >= cs.torus_max_periods:
        return False
    p.left, p.piece = min(cs.torus_extend * length, cs.torus_max_periods - length), None
    # the round's verdict: the measures of its last periods
    p.measured = min(policy.integration.recorded_periods, p.left)
    return True


def longer_record(points: list[Point], periods: int, policy: Policy) -> list[Point]:
    """The records of points left undetermined grow by ``periods`` (at most each point's ``left``), the run
    going on with its tangent vector; returns the points whose record grows on, the others finished
    (rounds and pieces: ``docs/classify.md``)."""
    if not points:
        return points
    if periods < 1 or any(p.left < periods for p in points):
        raise ValueError(f"{periods} periods: more than a point's round has left, or fewer than 1")
    s = dataclasses.replace(policy.integration, transient_periods=0, recorded_periods=periods)
    runs = simulate_batch(
        [
            Lane(
                p.system,
                (p.run if p.piece is None else p.piece).final_state,
                variational=Tangent(periods, None if p.piece is None else p.piece.tangent),
                # the sums of the round's last ``measured`` periods, over the pieces that hold them
                sums=Sums(p.measured - (p.left - periods), None if p.piece is None else p.piece.sums),
            )
            for p in points
        ],
        s,
        tables=tables_of(points),
    )
    diverged: set[int] = set()
    ended: list[Point] = []
    for p, r in zip(points, runs, strict=True):
        p.piece = r if p.piece is None else _joined(p.piece, r)
        p.left -= periods
        if r.diverged:
            p.verdict = diverged_verdict(p, p.piece)
            diverged.add(id(p))
        elif p.left == 0:
            p.run = _appended(p.run, p.piece)  # the round's run, reading the whole record
            p.verdict = _nonperiodic_verdict(p, policy)
            ended.append(p)
    grow = set(map(id, end_round(ended, policy)))  # of the rounds ended, the records that run on
    return [p for p in points if id(p) in grow or (p.left > 0 and id(p) not in diverged)]


def _appended(a: SimulationResult, b: SimulationResult) -> SimulationResult:
    """The run ``b`` with the records of ``a`` (which it continues) in front: Poincare points, growth, strobe."""
    return dataclasses.replace(
        b,
        poincare=np.vstack([a.poincare, b.poincare]),
        growth=np.concatenate([a.growth, b.growth]),
        strobe=np.concatenate([a.strobe, b.strobe]),
    )


def _joined(a: SimulationResult, b: SimulationResult) -> SimulationResult:
    """Two pieces of one run with a tangent vector (``b`` from ``a``'s final state and tangent): the run."""
    n = a.poincare.shape[0]
    return dataclasses.replace(
        _appended(a, b),
        n_events=a.n_events + b.n_events,
        diverged_period=n + b.diverged_period if b.diverged else -1,
        settings=dataclasses.replace(b.settings, recorded_periods=n + b.settings.recorded_periods),
    )


def _torus(points: np.ndarray, policy: Policy) -> tuple[TorusTest, str, OrderTest | None]:
    """The torus test on the record (2N Poincare points): the test, how it found a torus ("" when it did
    not) and the order test where it ran one (the rule combining plain and extrapolated digits and the
    order test: ``docs/classify.md``)."""
    cs = policy.classifier
    n = max(1, points.shape[0] // 2)
    p = points[-2 * n :]
    plain, extrapolated = torus_digits(
        p, coordinates, windows=policy.torus_windows, extrapolate=p.shape[0] >= policy.extrapolate_min
    )
    digits = plain if math.isnan(extrapolated) else max(plain, extrapolated)
    thresholds = (0.5 * math.log10(n) + cs.torus_margin, cs.chaos_margin, cs.torus_min_n)
    best = torus_verdict(digits, n, *thresholds)
    if best.verdict == "torus":
        return best, f"Birkhoff averages converge (digits {digits:.1f})", None
    order = None
    if cs.order_min_n > 0 and p.shape[0] >= cs.order_min_n:
        order = order_test(order_part(points, cs), cs.order_min_n)
        if order.passed:
            gaps = ", ".join(map(str, order.gaps))
            return (
                dataclasses.replace(best, verdict="torus"),
                (
                    f"the points follow a circle rotation (nearest-neighbour index differences {gaps} on {order.n} "
                    f"points; Birkhoff digits {digits:.1f})"
                ),
                order,
            )
    # chaos is the plain test's verdict, as before: the extrapolation only adds a way to find a torus
    return dataclasses.replace(torus_verdict(plain, n, *thresholds), digits=digits), "", order


def _nonperiodic_verdict(p: Point, policy: Policy) -> Verdict:
    """Chaos needs a positive exponent that the torus test confirms (no torus: the Birkhoff averages do not
    converge); quasi-periodic needs the torus test and an exponent that is not positive; anything else is
    undetermined, with the reason.  The 0-1 test and the spectral flatness cross-check a chaos label."""
    r, cs = p.run, policy.classifier
    lam, sig = indicators.lyapunov_estimate(r.growth, r.period)
    tt, how, order = _torus(r.poincare, policy)
    # kept for :func:`geardyn.label._cycles.locked`, which reads the same part of the record (the same points,
    # the same gaps)
    p.order = None if order is None else (r.poincare, order)
    digits = tt.digits
    positive = bool(np.isfinite(lam) and lam > cs.lam_tol + 2 * sig)
    negative = bool(np.isfinite(lam) and lam < -(cs.lam_tol + 2 * sig))
    k01 = flat = NAN
    cross = -1
    if positive and tt.verdict == "chaotic":
        phi = r.strobe if r.strobe is not None and r.strobe.size else r.poincare[:, 1]
        k01, flat = indicators.zero_one_test(phi), indicators.spectral_flatness(phi)
        cross = int(k01 > cs.k_chaos) + int(flat > cs.flat_broadband) - 1
        label, stage = CHAOS, "exponent"
        why = f"positive exponent {lam:.2g} +- {sig:.1g}; the Birkhoff averages do not converge (digits {digits:.1f})"
    elif tt.verdict == "torus" and not positive and not negative:
        label, stage, why = QP, "torus", f"{how}; exponent {lam:.2g}"
    else:
        label, stage = UNDET, "undecided"
        if negative:
            why = (
                f"negative exponent {lam:.2g} +- {sig:.1g}: attracted to a periodic orbit that shooting did not "
                f"find (digits {digits:.1f})"
            )
        elif tt.verdict == "torus":
            why = f"positive exponent {lam:.2g} but {how}"
        elif positive:
            why = f"positive exponent {lam:.2g}, torus test inconclusive ({digits:.1f})"
        else:
            why = (
                f"exponent {lam:.2g} +- {sig:.1g} not positive and the Birkhoff averages do not converge "
                f"(digits {digits:.1f})"
            )
    why += f" ({r.poincare.shape[0]} recorded periods)"
    measured = {"k01": k01, "flatness": flat, "torus_digits": digits, "crosscheck": cross}
    return _unless_growing(p, policy, record_verdict(p, policy, label, lam, sig, "tangent", stage, why, **measured))


def _unless_growing(p: Point, policy: Policy, v: Verdict) -> Verdict:
    """A torus or chaos verdict ``v`` unless the record grows (:func:`geardyn.label.growth.growing`): a
    growing record runs on (undetermined) while it is shorter than the record cap, and is ``transient`` at the
    cap.  The line goes on from ``v`` (``Point.handed``: the growth test corrects its own point only;
    ``docs/classify.md``, "Growing records")."""
    if v.label not in (QP, CHAOS):
        return v
    g = growing(p.run.poincare, policy.growth)
    if g is None:
        return v
    p.handed = p.handed or v
    cs = policy.classifier
    was = f"{vocabulary.label_name(v.label)} on its record: {v.reason}"
    if cs.torus_extend > 0 and p.run.poincare.shape[0] < cs.torus_max_periods:
        why = f"the record grows ({g.describe()}): it runs on before a verdict ({was})"
        return dataclasses.replace(v, label=UNDET, stage="undecided", reason=why)
    cap = p.run.poincare.shape[0]
    why = f"the record still grows at the cap of {cap} periods ({g.describe()}): a transient ({was})"
    return dataclasses.replace(v, label=TRANSIENT, stage="growing", reason=why)
