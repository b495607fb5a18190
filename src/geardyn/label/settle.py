"""Slow transients: is a point the classifier calls quasi-periodic really on a torus?  Decided by shooting
for a stable period-n orbit and checking that the run approaches it (:func:`settle_points`; the three
steps and why: ``docs/classify.md``)."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

import geardyn.label.indicators as indicators
import geardyn.label.vocabulary as vocabulary
from geardyn.label.compare import least_period, nearest_distances
from geardyn.label.policy import Policy, Settle
from geardyn.parallel import threaded_map
from geardyn.solve import simulate
from geardyn.solve.base import Lane, ShootingSettings, SimulationResult
from geardyn.solve.run import LaneTables, lane_tables, simulate_batch
from geardyn.solve.shooting import Shot, cycle_points, newton_shooting_batch

QP = vocabulary.LABELS["quasi_periodic"]
UNDET = vocabulary.LABELS["undetermined"]


@dataclass(frozen=True)
class Settled:
    """What :func:`settle_points` did at one point: the label before and after (the orbit's least period), the
    mesh periods n of the shooting map that found it, and max |mu| of that n-period map.  ``possible``:
    a stable orbit was found, but its multiplier is so close to 1 that the run could not be seen to
    approach it within ``settle_max_periods``; the label is then ``undetermined``, not quasi-periodic."""

    before: int
    after: int
    n: int = 0
    spectral_radius: float = float("nan")
    reason: str = ""
    possible: bool = False
    # a point of the orbit found (None: none found) and its multipliers over n periods (arrays: compared
    # separately)
    state: np.ndarray | None = dataclasses.field(default=None, compare=False)
    multipliers: np.ndarray | None = dataclasses.field(default=None, compare=False)


def needs_check(label: int, lyapunov: float, classifier: indicators.ClassifierSettings) -> bool:
    """Whether :func:`settle_points` tries the point: quasi-periodic or undetermined with an exponent that is
    not clearly positive, and the check switched on (``settle_max_n > 0``)."""
    return (
        classifier.settle_max_n > 0
        and label in (QP, UNDET)
        and not (np.isfinite(lyapunov) and lyapunov > classifier.lam_tol)
    )


def approached_in_record(
    poincare: np.ndarray,
    cycle: np.ndarray,
    rho: float,
    n: int,
    min_points: int = Settle.min_points,
    rate_share: float = Settle.rate_share,
    fall: float = Settle.record_fall,
) -> bool:
    """Whether the recorded Poincare points approach the period-n ``cycle`` (n x 6) with leading
    multiplier ``rho`` < 1: the least-squares slope of log(distance to the nearest cycle point) per
    period is at most ``rate_share`` of log(rho) / n, and the fitted distance falls at least by ``fall``
    over the record (at least ``min_points`` points; the defaults: half the rate, 2-fold, 20 points)."""
    p = np.asarray(poincare, dtype=float)
    p = p[np.all(np.isfinite(p), axis=1)]
    if p.shape[0] < min_points or not 0.0 < rho < 1.0:
        return False
    d = nearest_distances(p, np.asarray(cycle))
    slope = float(np.polyfit(np.arange(d.size), np.log(np.maximum(d, indicators.LOG_FLOOR)), 1)[0])
    return slope <= rate_share * math.log(rho) / n and math.exp(slope * (d.size - 1)) <= fall


def settle_points(
    systems,
    results,
    labels,
    lyapunovs,
    policy: Policy,
    tables: LaneTables | None = None,
    always_one: list[bool] | None = None,
) -> list[Settled]:
    """The slow-transient check of many points at once, stage by stage, each point's numbers those of the
    point alone; ``tables``: their lane tables, ``always_one[i]`` False: period 1 tried only when its return
    distance falls (``docs/classify.md``)."""
    settings, classifier = policy.integration, policy.classifier
    out: list[Settled | None] = [None] * len(systems)
    active = []
    for i, (res, label, lam) in enumerate(zip(results, labels, lyapunovs, strict=True)):
        if not needs_check(label, lam, classifier):
            out[i] = Settled(label, label)
        elif res is None or res.diverged or not np.all(np.isfinite(res.final_state)):
            out[i] = Settled(label, label, reason="no final state")
        else:
            active.append(i)
    x0 = {i: np.asarray(results[i].final_state, dtype=float) for i in active}
    if tables is None:
        tables = lane_tables(systems, settings)  # the per-point step tables, built once for every stage
    falls = {
        i: indicators.falling_return_distances(results[i].poincare, classifier.settle_max_n, policy.return_fall)
        for i in active
    }
    one = [True] * len(systems) if always_one is None else always_one
    for n in range(1, classifier.settle_max_n + 1):
        # period 1 is tried from a fixed start even when its distance does not fall: the slowest transients
        # are onto P1
        tried = [i for i in active if (n == 1 and one[i]) or falls[i][n - 1]]
        if not tried:
            continue
        shooting = ShootingSettings(
            tol=policy.newton.tol, max_iter=policy.settle.newton_max_iter, step_cap=policy.newton.step_cap
        )
        shots = newton_shooting_batch(
            [Shot(systems[i], x0[i]) for i in tried], n, settings, shooting, tables.take(tried)
        )
        stable = {i: r for i, r in zip(tried, shots, strict=True) if r.converged and r.spectral_radius < 1.0}
        if stable:
            for i, s in _judge(systems, tables, results, labels, x0, stable, n, policy).items():
                out[i] = s
            active = [i for i in active if i not in stable]
    for i in active:
        out[i] = Settled(
            labels[i],
            labels[i],
            reason=f"no stable orbit of period <= {classifier.settle_max_n} (tried where the return distance falls)",
        )
    return out  # type: ignore[return-value]


def _cycles(systems, tables: LaneTables, shots: dict, n: int, policy: Policy) -> dict[int, np.ndarray]:
    """The least-period cycle (m x 6) of every stable n-period orbit found
    (:func:`geardyn.solve.shooting.cycle_points`), cut to the least period m
    (:func:`geardyn.label.compare.least_period`, within ``policy.settle.cycle_rtol`` of the state's size)."""
    ids = list(shots)
    found = cycle_points(
        [systems[i] for i in ids],
        [shots[i].state for i in ids],
        n,
        policy.integration,
        tables=tables.take(ids) if n > 1 else None,
    )
    out = {}
    for i, (c, _, _, _) in zip(ids, found, strict=True):
        tol = policy.settle.cycle_rtol * max(1.0, float(np.max(np.abs(shots[i].state))))
        out[i] = c[: least_period(c, tol)]
    return out


def _judge(
    systems,
    tables: LaneTables,
    results,
    labels,
    x0: dict,
    shots: dict,
    n: int,
    policy: Policy,
) -> dict[int, Settled]:
    """Whether each run approaches the stable n-period orbit found for it (``docs/classify.md``, step 3)."""
    settings = policy.integration
    cycles = _cycles(systems, tables, shots, n, policy)
    rho = {i: min(r.spectral_radius, policy.settle.rho_max) for i, r in shots.items()}
    max_periods = policy.classifier.settle_max_periods
    reads = (policy.settle.min_points, policy.settle.rate_share, policy.settle.record_fall)

    def settled(i: int, after: int, why: str, **more) -> Settled:
        return Settled(labels[i], after, n, shots[i].spectral_radius, why, **more)

    def found(i: int, how: str) -> Settled:
        r = shots[i]
        m = len(cycles[i])
        # a shorter orbit is also fixed by the n-period map (its multipliers are those of the m-map to the
        # power n/m): the m-period shooting did not reach it from here, so it is judged as found
        why = (
            f"slow transient: stable period-{m} orbit by shooting "
            f"(|mu|max = {r.spectral_radius:.4f} over {n} periods), approached {how}"
        )
        return settled(i, m, why, state=r.state.copy(), multipliers=r.multipliers)

    out = {
        i: found(i, "over the recorded periods")
        for i in shots
        if approached_in_record(results[i].poincare, cycles[i], rho[i], n, *reads)
    }
    # a continued record as long as the multiplier needs to shrink a distance 4-fold, read the same way
    k4, ext = _continued(systems, tables, policy, x0, {i: rho[i] for i in shots if i not in out}, n)
    for i, e in ext.items():
        if not e.diverged and approached_in_record(e.poincare, cycles[i], rho[i], n, *reads):
            out[i] = found(i, f"over {k4[i]} more periods")
    last = [i for i in shots if i not in out]

    def by_run(i: int) -> Settled:
        r = shots[i]
        cyc, m = cycles[i], len(cycles[i])
        # last, the run continued (from the end of that record) until a 10-fold fall, within max_periods
        k = int(min(max(max_periods, n), max(n, math.ceil(math.log(policy.settle.horizon_fall) / math.log(rho[i])))))
        k = n * math.ceil(k / n)
        more = dataclasses.replace(settings, transient_periods=k - 1 if k > 1 else 0, recorded_periods=1)
        scale = policy.settle.reached_rtol * max(1.0, float(np.max(np.abs(r.state))))
        d0 = float(nearest_distances(x0[i], cyc)[0])
        x, d1, done = x0[i], d0, 0
        if not ext[i].diverged:
            x, done = ext[i].final_state, k4[i]
            d1 = float(nearest_distances(x, cyc)[0])
        fall = policy.settle.run_fall
        while done < max_periods and not (d1 <= fall * d0 or d1 <= scale):
            run = simulate(systems[i], more, x0=x)
            if run.diverged:
                d1 = float("inf")
                break
            x = run.final_state
            done += k
            d1 = float(nearest_distances(x, cyc)[0])
        if d1 <= fall * d0 or d1 <= scale:
            return found(i, "by the run")
        if rho[i] ** (done / n) > fall:
            # the multiplier is so close to 1 that the horizon could not show a 10-fold fall: the run may be a
            # transient onto this orbit; say so instead of calling it quasi-periodic
            why = (
                f"possible slow transient: stable period-{m} orbit (|mu|max = {r.spectral_radius:.5f} "
                f"over {n} periods) too slow to confirm in {done} periods (distance {d0:.2g} -> {d1:.2g})"
            )
            return settled(i, UNDET, why, possible=True)
        why = (
            f"stable period-{n} orbit found, but the run does not approach it "
            f"(distance {d0:.2g} -> {d1:.2g} in {done} periods)"
        )
        return settled(i, labels[i], why)

    out.update(zip(last, threaded_map(by_run, last), strict=True))
    return out


def _continued(
    systems, tables: LaneTables, policy: Policy, x0: dict, rho: dict, n: int
) -> tuple[dict[int, int], dict[int, SimulationResult]]:
    """The runs of the points ``rho`` (point: its leading multiplier) continued from x0 for as many periods
    as their multiplier needs to shrink a distance by ``policy.settle.probe_fall`` (a multiple of n, at least
    ``settle_probe_min_periods``, at most the classifier's ``settle_max_periods``), points of one length in
    one batch: (lengths, runs)."""
    settings, max_periods = policy.integration, policy.classifier.settle_max_periods
    least, fall = policy.settle.probe_min_periods, policy.settle.probe_fall
    k4 = {
        i: n * math.ceil(min(max_periods, max(least, math.ceil(math.log(fall) / math.log(r)))) / n)
        for i, r in rho.items()
    }
    ext: dict[int, simulate.SimulationResult] = {}
    for group in _length_classes(k4):
        runs = simulate_batch(
            [Lane(systems[i], x0[i], recorded_periods=k4[i]) for i in group],
            dataclasses.replace(settings, transient_periods=0),
            tables=tables.take(group),
        )
        ext.update(zip(group, runs, strict=True))
    return k4, ext


def _length_classes(lengths: dict[int, int]) -> list[list[int]]:
    """The keys of ``lengths`` by increasing length, cut into runs whose longest is at most twice the
    shortest: one batch per run keeps the lockstep blocks and the record arrays from idling on a few
    long runs."""
    order = sorted(lengths, key=lambda i: (lengths[i], i))
    out: list[list[int]] = []
    for i in order:
        if out and lengths[i] <= 2 * lengths[out[-1][0]]:
            out[-1].append(i)
        else:
            out.append([i])
    return out
