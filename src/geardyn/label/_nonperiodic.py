"""Stage 4 of the labeller: what is neither periodic nor a slow transient is labelled from the tangent
exponent and the torus tests, undetermined records run on and are searched for long cycles
(``docs/classify.md``)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

import geardyn.label.indicators as indicators
import geardyn.label.vocabulary as vocabulary
from geardyn.label._stages import (
    CHAOS,
    NAN,
    QP,
    TRANSIENT,
    UNDET,
    Point,
    certify,
    diverged_verdict,
    periodic_verdicts,
    shoot,
    tables_of,
)
from geardyn.label.growth import growth_test
from geardyn.label.policy import Policy
from geardyn.label.torus import OrderTest, TorusTest, coordinates, order_test, torus_digits, torus_verdict
from geardyn.label.verdict import Verdict
from geardyn.parallel import threaded_map
from geardyn.solve.base import SimulationResult
from geardyn.solve.response import measures_of_sums
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
                [p.system for p in again],
                more,
                [p.run.final_state for p in again],
                tangent_periods=cs.tangent_periods,
                tables=tables_of(again),
                sums_last=[policy.integration.recorded_periods] * len(again),
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
            p.verdict = _undecided(p, "looks periodic but no stable orbit is found", policy)
    rest = [p for p, n in zip(bounded, periods, strict=True) if n == 0]
    for p, v in zip(rest, threaded_map(lambda p: _nonperiodic_verdict(p, policy), rest), strict=True):
        p.verdict = v
    return end_round(rest, policy)


def end_round(points: list[Point], policy: Policy) -> list[Point]:
    """The end of a round of the records of ``points``: undetermined records certified for long cycles
    (:func:`_long_periods`), the still undetermined points start their next round and are returned, the
    others are finished (``docs/classify.md``)."""
    _long_periods([p for p in points if p.verdict.stage == "undecided"], policy)
    _doubt([p for p in points if p.verdict.label == QP], policy)
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
        [p.system for p in points],
        s,
        [(p.run if p.piece is None else p.piece).final_state for p in points],
        tables=tables_of(points),
        tangent_periods=periods,
        tangent_start=[None if p.piece is None else p.piece.tangent for p in points],
        # the sums of the round's last ``measured`` periods, over the pieces that hold them
        sums_last=[p.measured - (p.left - periods) for p in points],
        sums_start=[None if p.piece is None else p.piece.sums for p in points],
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


def finish(points: list[Point], policy: Policy) -> None:
    """The last step for points whose record is done: long cycles (:func:`_long_periods`), the orbit born at a
    period doubling (:func:`_doubled`), slowly gathered cycles (:func:`_locked`), orbits circled at the unit
    circle (:func:`_at_circle`), held verdicts confirmed (:func:`_doubt`) (``docs/classify.md``)."""
    for newest_half in (True, False):
        _long_periods([p for p in points if p.verdict.label == QP], policy, newest_half=newest_half)
    _locked([p for p in points if p.verdict.label == QP], policy)
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
    (:func:`_long_periods`)."""
    cs = policy.classifier
    return max(cs.max_n, min(cs.long_max_n, length // policy.cycle_repeats))


def _doubt(points: list[Point], policy: Policy) -> None:
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
            p.verdict = _undecided(p, f"{why} ({cap} periods)", policy)


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
                p.verdict = _undecided(p, why, policy)


def _long_periods(points: list[Point], policy: Policy, newest_half: bool = True) -> None:
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


def _locked(points: list[Point], policy: Policy) -> None:
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
        gaps = (known or order_test(_order_part(record, cs), 0)).gaps
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


def _order_part(points: np.ndarray, cs: indicators.ClassifierSettings) -> np.ndarray:
    """The part of a record that the order tests read: its newest half (of the last 2N points), or its
    newest ``order_min_n`` points where that half is shorter (all of a shorter record)."""
    n = max(1, points.shape[0] // 2)
    return points[-2 * n :][-max(cs.order_min_n, n) :]


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
        order = order_test(_order_part(points, cs), cs.order_min_n)
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
    # kept for :func:`_locked`, which reads the same part of the record (the same points, the same gaps)
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
    return _unless_growing(p, policy, _record_verdict(p, policy, label, lam, sig, "tangent", stage, why, **measured))


def _unless_growing(p: Point, policy: Policy, v: Verdict) -> Verdict:
    """A torus or chaos verdict ``v`` unless the record grows (:func:`geardyn.label.growth.growth_test`): a
    growing record runs on (undetermined) while it is shorter than the record cap, and is ``transient`` at the
    cap.  The line goes on from ``v`` (``Point.handed``: the growth test corrects its own point only;
    ``docs/classify.md``, "Growing records")."""
    if v.label not in (QP, CHAOS):
        return v
    g = growth_test(p.run.poincare, policy.growth)
    if not g.growing:
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


def _undecided(p: Point, why: str, policy: Policy) -> Verdict:
    return _record_verdict(p, policy, UNDET, NAN, NAN, "none", "undecided", why)


def _record_verdict(
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
