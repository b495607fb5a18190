"""The engineer's response measures of one operating point: dynamic mesh force, dynamic factor, DTE,
contact fractions, impact class, and the standard errors of the RMS values (definitions and
how they are summed: ``docs/response.md``)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, fields

import numpy as np

from geardyn.solve.base import Lane, SimulationSettings, Sums, System, drive_side, static_mesh_force

#: Impact classes (cube variable ``impact_class``; -1: not computed or diverged).
IMPACT_CLASSES = {"no_impact": 0, "single_sided": 1, "double_sided": 2}

#: Fraction of the record below which a contact region counts as not visited: a trajectory that touches
#: x2 = +-b within the integration's resolution (a crossing time of order 1e-12 of the period) is not an
#: impact.
CONTACT_LOSS_MIN = 1.0e-9


@dataclass(frozen=True)
class ResponseMeasures:
    """The response of one point over ``periods`` mesh periods (forces / (k_mean b_c), lengths / b_c); NaN
    and class ``"diverged"`` where the run diverged (definitions: ``docs/response.md``)."""

    static_force: float
    force_mean: float
    force_rms: float
    force_max: float
    dynamic_factor: float
    dte_mean: float
    dte_rms: float
    dte_pp: float
    drive_fraction: float
    separation_fraction: float
    back_fraction: float
    impact_class: str
    n_switches: int
    periods: int
    diverged: bool = False

    @classmethod
    def not_computed(cls, static_force: float = math.nan, diverged: bool = True) -> ResponseMeasures:
        """The measures of a point whose run diverged: NaN, class ``"diverged"``."""
        nan = math.nan
        return cls(static_force, nan, nan, nan, nan, nan, nan, nan, nan, nan, nan, "diverged", 0, 0, diverged)


FLOAT_FIELDS = tuple(f.name for f in fields(ResponseMeasures) if f.type == "float")


def impact_class(separation_fraction: float, back_fraction: float) -> str:
    """The impact class from the contact fractions: ``"double_sided"`` when the teeth strike on the back
    side, else ``"single_sided"`` when they separate, else ``"no_impact"`` (fractions above
    :data:`CONTACT_LOSS_MIN` count)."""
    if not (math.isfinite(separation_fraction) and math.isfinite(back_fraction)):
        raise ValueError(f"contact fractions must be finite, got {separation_fraction}, {back_fraction}")
    if back_fraction > CONTACT_LOSS_MIN:
        return "double_sided"
    if separation_fraction > CONTACT_LOSS_MIN:
        return "single_sided"
    return "no_impact"


#: Blocks of the batch-means error of an RMS value (:func:`rms_errors_many`): 10 blocks of 5 mesh periods
#: for the 50 recorded periods of the regime maps' preset.
RMS_BLOCKS = 10


@dataclass(frozen=True)
class RMSErrors:
    """Standard errors of the RMS values of a record (:func:`rms_errors_many`) and the number of blocks
    they come from; NaN with fewer than 2 blocks or where the record diverged."""

    dte_rms_error: float
    force_rms_error: float
    blocks: int

    @classmethod
    def not_computed(cls, blocks: int = 0) -> RMSErrors:
        return cls(math.nan, math.nan, blocks)


#: points per call of the lanes in :func:`response_measures_many` (a multiple of the lockstep width)
GROUP = 512


def response_measures(
    system: System,
    y0: np.ndarray,
    settings: SimulationSettings | None = None,
    periods: int | None = None,
) -> ResponseMeasures:
    """The response measures over ``periods`` mesh periods (default: ``settings.recorded_periods``) from the
    state y0 (6,) at phase 0, at the settings' (default: :class:`SimulationSettings`) steps per period and
    integrator (``rk4_event`` locates the contact switches).  Start on the attractor (a verdict's final
    state): no transient is integrated here.  A run that diverges gives :meth:`ResponseMeasures.not_computed`."""
    return response_measures_many([system], [y0], settings, None if periods is None else [periods])[0]


def _runnable(
    systems: Sequence[System], y0s: Sequence[np.ndarray], settings: SimulationSettings, periods: Sequence[int] | None
) -> tuple[list[int], list[np.ndarray], list[int]]:
    """Each point's period count (``settings.recorded_periods`` by default) and start state, and the points
    that can run (a finite start state (6,)), after checking the arguments of the response measures: an RK4
    integrator, one start state (and one period count) per system."""
    if settings.integrator == "dop853":
        raise ValueError("the response measures integrate with 'rk4' or 'rk4_event'")
    if len(y0s) != len(systems) or (periods is not None and len(periods) != len(systems)):
        raise ValueError("response measures: one start state (and one period count) per system")
    n_per = [settings.recorded_periods] * len(systems) if periods is None else [int(n) for n in periods]
    if any(n < 1 for n in n_per):
        raise ValueError(f"periods must be >= 1, got {min(n_per)}")
    starts = [np.asarray(y0, dtype=float) for y0 in y0s]
    return n_per, starts, [i for i, y0 in enumerate(starts) if y0.shape == (6,) and np.all(np.isfinite(y0))]


def response_measures_many(
    systems: Sequence[System],
    y0s: Sequence[np.ndarray],
    settings: SimulationSettings | None = None,
    periods: Sequence[int] | None = None,
) -> list[ResponseMeasures]:
    """:func:`response_measures` of many points: system i from the state ``y0s[i]`` over ``periods[i]`` mesh
    periods, the sums of :mod:`geardyn.solve._response` added at every step in the batch's lanes
    (:func:`geardyn.solve.simulate_batch` with :class:`~geardyn.solve.base.Sums`).  Each point's measures are
    its own."""
    from geardyn.solve.run import simulate_batch  # noqa: PLC0415 - compiled: not imported by jobs that read results

    settings = SimulationSettings() if settings is None else settings
    n_per, starts, runnable = _runnable(systems, y0s, settings, periods)
    measures: list[ResponseMeasures | None] = [None] * len(systems)
    # the points that can run, those of equal length side by side (a block runs as long as its longest lane)
    order = sorted(runnable, key=n_per.__getitem__)
    for g in range(0, len(order), GROUP):  # groups of points: step tables that stay in the caches
        group = order[g : g + GROUP]
        # the sums over the whole run
        lanes = [Lane(systems[i], starts[i], 0, n_per[i], sums=Sums(n_per[i])) for i in group]
        runs = simulate_batch(lanes, settings)
        for i, r in zip(group, runs, strict=True):
            measures[i] = measures_of_sums(r.sums, systems[i], n_per[i])
    f_s = [static_mesh_force(system) for system in systems]
    return [ResponseMeasures.not_computed(f) if m is None else m for m, f in zip(measures, f_s, strict=True)]


def measures_of_sums(sums: np.ndarray | None, system: System, periods: int) -> ResponseMeasures:
    """The measures of ``system`` from the sums a batch run added over its last ``periods`` mesh periods
    (:attr:`geardyn.solve.base.SimulationResult.sums`, the :class:`~geardyn.solve.base.Sums` of
    :func:`geardyn.solve.simulate_batch`): the numbers of :func:`response_measures_many` from the state where
    those periods begin, bit for bit; :meth:`ResponseMeasures.not_computed` where there are none or the run diverged."""
    import geardyn.solve._response as _acc  # noqa: PLC0415 - compiled: not imported by jobs that read results

    f_s = static_mesh_force(system)
    if sums is None or sums[_acc.STATUS] != 0.0:
        return ResponseMeasures.not_computed(f_s)
    sgn = drive_side(f_s)
    out = [float(v) for v in sums]
    t = out[_acc.TIME]
    mf, mx = out[_acc.SUM_F] / t, out[_acc.SUM_X] / t
    f_var = max(out[_acc.SUM_F2] / t - mf * mf, 0.0)
    x_var = max(out[_acc.SUM_X2] / t - mx * mx, 0.0)
    f_max = out[_acc.MAX_SF]
    pos, zero, neg = out[_acc.T_POS] / t, out[_acc.T_ZERO] / t, out[_acc.T_NEG] / t
    drive, back = (pos, neg) if sgn > 0 else (neg, pos)
    return ResponseMeasures(
        static_force=f_s,
        force_mean=sgn * (out[_acc.F_REF] + mf),
        force_rms=math.sqrt(f_var),
        force_max=f_max,
        dynamic_factor=f_max / abs(f_s) if f_s != 0.0 else math.nan,
        dte_mean=out[_acc.X_REF] + mx,
        dte_rms=math.sqrt(x_var),
        dte_pp=out[_acc.MAX_X] - out[_acc.MIN_X],
        drive_fraction=drive,
        separation_fraction=zero,
        back_fraction=back,
        impact_class=impact_class(zero, back),
        n_switches=int(out[_acc.N_SWITCH]),
        periods=periods,
    )


def batch_means_rms_error(weights: np.ndarray, means: np.ndarray, rms: np.ndarray) -> float:
    """The batch-means standard error of the RMS of a record cut into B >= 2 blocks (``weights``, ``means``,
    ``rms``: (B,) each); 0 when the RMS is 0 (the delta-method derivation: ``docs/numerics.md``)."""
    w = np.asarray(weights, dtype=float)
    m, r = np.asarray(means, dtype=float), np.asarray(rms, dtype=float)
    if w.ndim != 1 or w.size < 2 or m.shape != w.shape or r.shape != w.shape or np.any(w <= 0.0):
        raise ValueError("batch means: at least 2 blocks of positive duration, one mean and one RMS each")
    w = w / w.sum()
    a = float(w @ m)
    spread = r * r + (m - a) ** 2
    q = float(w @ spread)
    if not math.isfinite(q):
        return math.nan
    if q <= 0.0:
        return 0.0
    u = (spread - q) / (2.0 * math.sqrt(q))
    return math.sqrt(w.size / (w.size - 1) * float(np.sum((w * u) ** 2)))


def rms_errors_many(
    systems: Sequence[System],
    records: Sequence[np.ndarray],
    measures: Sequence[ResponseMeasures],
    settings: SimulationSettings | None = None,
    blocks: int = RMS_BLOCKS,
) -> list[RMSErrors]:
    """The standard errors of ``measures[i].dte_rms`` and ``force_rms``, summed over the last
    ``measures[i].periods`` mesh periods of a record whose Poincare points (its states at phase 0 at the ends
    of its periods, the last its final state) end with ``records[i]``: batch means over min(``blocks``,
    periods) blocks of whole periods of that very record (``docs/response.md``).  Blocks 2, 3, ... are
    integrated again from the record's states where they begin (at the settings of the record: the same
    steps, bit for bit); block 1, whose start the record does not hold, is the record less the others."""
    settings = SimulationSettings() if settings is None else settings
    if blocks < 2:
        raise ValueError(f"batch means need at least 2 blocks, got {blocks}")
    out, cuts = [], {}
    b_sys, b_y0, b_n = [], [], []
    for i, (system, points, m) in enumerate(zip(systems, records, measures, strict=True)):
        n, points = m.periods, np.asarray(points, dtype=float)
        out.append(RMSErrors.not_computed(min(blocks, n)))
        if m.diverged or n < 2:
            continue
        if points.ndim != 2 or points.shape[0] < n:
            raise ValueError(f"a record measured over {n} periods needs its last {n} Poincare points at least")
        cuts[i] = edges = np.array([n * k // min(blocks, n) for k in range(min(blocks, n) + 1)])
        for k in range(1, edges.size - 1):
            b_sys.append(system)
            b_y0.append(points[edges[k] - n - 1])  # the state where block k + 1 begins
            b_n.append(int(edges[k + 1] - edges[k]))
    measured = iter(response_measures_many(b_sys, b_y0, settings, b_n))
    for i, edges in cuts.items():
        parts = [next(measured) for _ in range(edges.size - 2)]
        if not any(p.diverged for p in parts):
            w = np.diff(edges).astype(float)
            dte, force = (_record_error(w, measures[i], parts, k) for k in ("dte", "force"))
            out[i] = RMSErrors(dte, force, edges.size - 1)
    return out


def _record_error(w: np.ndarray, record: ResponseMeasures, parts: list[ResponseMeasures], key: str) -> float:
    """:func:`batch_means_rms_error` of ``{key}_rms`` of a record cut into blocks of durations ``w``, all but the
    first measured (``parts``): the first block's mean and RMS follow from the record's, A = sum_b w_b m_b and
    R^2 = sum_b w_b (r_b^2 + (m_b - A)^2) (w_b the shares of time)."""
    s, mean, rms = w / w.sum(), getattr(record, f"{key}_mean"), getattr(record, f"{key}_rms")
    m, r = (np.array([getattr(p, f"{key}_{v}") for p in parts]) for v in ("mean", "rms"))
    m1 = mean - float(s[1:] @ (m - mean)) / s[0]
    r1 = (rms * rms - float(s[1:] @ (r * r + (m - mean) ** 2))) / s[0] - (m1 - mean) ** 2
    return batch_means_rms_error(w, np.append(m1, m), np.append(math.sqrt(max(r1, 0.0)), r))
