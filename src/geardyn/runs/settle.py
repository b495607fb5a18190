"""Slow transients: is a point the classifier calls quasi-periodic really on a torus?

With the light shaft damping of the KHV designs the least-damped mode decays by about 0.98-0.99 per
mesh period, so a run can still be converging onto a periodic orbit when its recorded periods
start.  Its exponent is then about -1e-3 per unit time, inside the classifier's "zero" band
(``lam_tol``), and the rules of :func:`geardyn.classify.classify_point` call it quasi-periodic or
undetermined.  :func:`settle` decides such a point by shooting instead of by a longer guess:

1. only a point labelled quasi-periodic or undetermined whose exponent is not clearly positive
   (lambda <= lam_tol, or not finite) is tried; chaos and periodic labels are never touched;
2. Newton shooting (:func:`geardyn.solve.shooting.newton_shooting`) on the n-period map, for
   n = 1 .. ``settle_max_n``, starts from the final state of the run; the first n that converges to
   an orbit whose Floquet multipliers all lie inside the unit circle is the candidate.  n = 1 is
   always tried; a larger n only when its return distance is falling over the run's recorded
   Poincare points (:func:`return_distance_falls`): a run converging onto a period-n orbit shows it,
   a torus does not, and this spares the shooting on tori, where it costs most;
3. the run must approach that orbit (else, when the multiplier is so close to 1 that the horizon
   could not show it, the point is ``undetermined``: a possible slow transient, flag 2).  First its recorded Poincare points are read
   (:func:`approached_in_record`): if their distance to the nearest cycle point shrinks at least at
   half the rate the leading multiplier predicts, and at least 2-fold over the record, the run is
   approaching.  If the record is too short to tell, the run is continued from its final state for
   as many periods as the multiplier needs to shrink a distance 4-fold, and that new record is read
   the same way.  Last, the run is continued for as many periods as the leading multiplier needs to
   shrink a distance 100-fold (at most ``settle_max_periods`` in all), and its distance to the
   nearest cycle point must fall 10-fold.  This rules out a stable orbit that
   coexists beside a torus the run stays on.

A true torus has no stable periodic orbit near it to converge to, so its label stays.  The check
runs inside :func:`geardyn.runs.points.analyse_points`, so sweep cubes, maps, the claims table and
the calibration all score the same labels.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from geardyn import classify
from geardyn.solve import SimulationSettings, simulate
from geardyn.solve.shooting import khv_flow, newton_shooting

QP = classify.LABELS["quasi_periodic"]
UNDET = classify.LABELS["undetermined"]


@dataclass(frozen=True)
class Settled:
    """What :func:`settle` did at one point: the label before and after (the orbit's least period), the
    mesh periods n of the shooting map that found it, and max |mu| of that n-period map.  ``possible``:
    a stable orbit was found, but its multiplier is so close to 1 that the run could not be seen to
    approach it within ``settle_max_periods``; the label is then ``undetermined``, not quasi-periodic."""

    before: int
    after: int
    n: int = 0
    spectral_radius: float = float("nan")
    reason: str = ""
    possible: bool = False


def needs_check(label: int, lyapunov: float, classifier: classify.ClassifierSettings) -> bool:
    """Whether :func:`settle` tries the point: quasi-periodic or undetermined with an exponent that is
    not clearly positive, and the check switched on (``settle_max_n > 0``)."""
    return (classifier.settle_max_n > 0 and label in (QP, UNDET)
            and not (np.isfinite(lyapunov) and lyapunov > classifier.lam_tol))


def minimal_period(cycle: list[np.ndarray], state: np.ndarray, rtol: float = 1e-6) -> int:
    """The least m with cycle[m] = cycle[0] (within rtol x max(1, max |x|)) among the points of a
    closed n-period orbit (cycle[0] = ``state``): n when no shorter period repeats it."""
    tol = rtol * max(1.0, float(np.max(np.abs(state))))
    for m in range(1, len(cycle)):
        if len(cycle) % m == 0 and float(np.max(np.abs(cycle[m] - cycle[0]))) <= tol:
            return m
    return len(cycle)


def return_distance_falls(poincare: np.ndarray, n: int, factor: float = 0.95) -> bool:
    """Whether the return distance d_n(k) = max_i |p_k+n,i - p_k,i| of the recorded Poincare points
    falls over the record: mean of its last quarter < ``factor`` x mean of its first quarter.  True
    when the record is too short to tell (fewer than n + 8 points).  A transient onto a stable
    period-n orbit with leading multiplier rho shrinks d_n by rho^(3K/4) over K points (0.47 for
    rho = 0.99 and K = 100); ``factor`` 0.95 skips only transients slower than about rho = 0.9993
    per period on a 100-point record."""
    p = np.asarray(poincare, dtype=float)
    p = p[np.all(np.isfinite(p), axis=1)]
    if p.shape[0] < n + 8:
        return True
    d = np.max(np.abs(p[n:] - p[:-n]), axis=1)
    q = max(2, d.size // 4)
    return bool(d[-q:].mean() < factor * d[:q].mean())


def _distance(x: np.ndarray, cycle: np.ndarray) -> np.ndarray:
    """Max-norm distance of each state in ``x`` (k x 6, or one state) to the nearest point of ``cycle`` (n x 6)."""
    return np.min(np.max(np.abs(np.atleast_2d(x)[:, None, :] - cycle[None, :, :]), axis=2), axis=1)


def approached_in_record(poincare: np.ndarray, cycle: np.ndarray, rho: float, n: int) -> bool:
    """Whether the recorded Poincare points approach the period-n ``cycle`` (n x 6) with leading
    multiplier ``rho`` < 1: the least-squares slope of log(distance to the nearest cycle point) per
    period is at most half of log(rho) / n, and the fitted distance falls at least 2-fold over the
    record (at least 20 points)."""
    p = np.asarray(poincare, dtype=float)
    p = p[np.all(np.isfinite(p), axis=1)]
    if p.shape[0] < 20 or not 0.0 < rho < 1.0:
        return False
    d = _distance(p, np.asarray(cycle))
    slope = float(np.polyfit(np.arange(d.size), np.log(np.maximum(d, 1e-300)), 1)[0])
    return slope <= 0.5 * math.log(rho) / n and math.exp(slope * (d.size - 1)) <= 0.5


def settle(system, result, label: int, lyapunov: float, settings: SimulationSettings,
           classifier: classify.ClassifierSettings) -> Settled:
    """The slow-transient check of one point (module docstring): its label after the check."""
    if not needs_check(label, lyapunov, classifier):
        return Settled(label, label)
    if result is None or result.diverged or not np.all(np.isfinite(result.final_state)):
        return Settled(label, label, reason="no final state")
    x0 = np.asarray(result.final_state, dtype=float)
    one = khv_flow(system, 1, settings)
    max_periods = classifier.settle_max_periods
    for n in range(1, classifier.settle_max_n + 1):
        if n > 1 and not return_distance_falls(result.poincare, n):
            continue  # period 1 is always tried: it is cheap, and the slowest transients are onto P1
        r = newton_shooting(khv_flow(system, n, settings), x0, n, tol=1e-9, max_iter=15)
        if not (r.converged and r.spectral_radius < 1.0):
            continue
        cycle = [r.state]
        for _ in range(n - 1):
            nxt, _ = one(cycle[-1], False)
            if nxt is None:
                break
            cycle.append(nxt)
        m = minimal_period(cycle, r.state)
        # a shorter orbit is also fixed by the n-period map (its multipliers are those of the m-map to the
        # power n/m): the m-period shooting did not reach it from here, so it is judged as found
        cyc = np.array(cycle[:m])
        rho = min(r.spectral_radius, 1.0 - 1e-6)

        def found(how: str) -> Settled:
            return Settled(label, m, n, r.spectral_radius, f"slow transient: stable period-{m} orbit by shooting "
                           f"(|mu|max = {r.spectral_radius:.4f} over {n} periods), approached {how}")

        if approached_in_record(result.poincare, cyc, rho, n):
            return found("over the recorded periods")
        # a continued record as long as the multiplier needs to shrink a distance 4-fold, read the same way
        k4 = n * math.ceil(min(max_periods, max(20, math.ceil(math.log(0.25) / math.log(rho)))) / n)
        ext = simulate(system, dataclasses.replace(settings, transient_periods=0, recorded_periods=k4), x0=x0)
        if not ext.diverged and approached_in_record(ext.poincare, cyc, rho, n):
            return found(f"over {k4} more periods")
        # last, the run continued (from the end of that record) until a 10-fold fall, within max_periods
        k = int(min(max(max_periods, n), max(n, math.ceil(math.log(0.01) / math.log(rho)))))
        k = n * math.ceil(k / n)
        more = dataclasses.replace(settings, transient_periods=k - 1 if k > 1 else 0, recorded_periods=1)
        scale = 1e-7 * max(1.0, float(np.max(np.abs(r.state))))
        d0 = float(_distance(x0, cyc)[0])
        x, d1, done = x0, d0, 0
        if not ext.diverged:
            x, done = ext.final_state, k4
            d1 = float(_distance(x, cyc)[0])
        while done < max_periods and not (d1 <= 0.1 * d0 or d1 <= scale):
            run = simulate(system, more, x0=x)
            if run.diverged:
                d1 = float("inf")
                break
            x = run.final_state
            done += k
            d1 = float(_distance(x, cyc)[0])
        if d1 <= 0.1 * d0 or d1 <= scale:
            return found("by the run")
        if rho ** (done / n) > 0.1:
            # the multiplier is so close to 1 that the horizon could not show a 10-fold fall: the run may be a
            # transient onto this orbit; say so instead of calling it quasi-periodic
            return Settled(label, UNDET, n, r.spectral_radius,
                           f"possible slow transient: stable period-{m} orbit (|mu|max = {r.spectral_radius:.5f} "
                           f"over {n} periods) too slow to confirm in {done} periods "
                           f"(distance {d0:.2g} -> {d1:.2g})", possible=True)
        return Settled(label, label, n, r.spectral_radius,
                       f"stable period-{n} orbit found, but the run does not approach it "
                       f"(distance {d0:.2g} -> {d1:.2g} in {done} periods)")
    return Settled(label, label, reason=f"no stable orbit of period <= {classifier.settle_max_n} "
                                        "(tried where the return distance falls)")


def settled_classification(before: classify.Classification, s: Settled, period: float) -> classify.Classification:
    """The classification of a point after :func:`settle`: unchanged, or period-n with the exponent of the
    orbit's leading Floquet multiplier (lambda = log |mu|max / (n T), sigma 0) and ``settled = SETTLED``; a
    possible slow transient is undetermined with ``settled = POSSIBLE_TRANSIENT``."""
    if s.possible:
        return classify.Classification(UNDET, 0, before.lyapunov, before.lyapunov_sigma, before.k01, before.flatness,
                                       before.crosscheck, s.reason, settled=classify.POSSIBLE_TRANSIENT)
    if s.after == s.before:
        return before
    lam = math.log(s.spectral_radius) / (s.n * period)
    return classify.Classification(s.after, s.after, lam, 0.0, before.k01, before.flatness, -1, s.reason,
                                   settled=classify.SETTLED)
