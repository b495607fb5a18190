"""Integrate the 3-DOF backlash system: :func:`simulate`, with an optional variational part, and
:func:`simulate_batch` for many points (integrators and variational options: ``docs/numerics.md``)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache

import numba
import numpy as np

import geardyn.solve._batch as _batch
import geardyn.solve._kernel as _kernel
import geardyn.solve._period as _period
import geardyn.solve._response as _response
from geardyn.solve.base import (
    EarlyStop,
    Lane,
    Monodromy,
    SimulationResult,
    SimulationSettings,
    Sums,
    System,
    Tangent,
    divergence_limits,
    drive_side,
    static_mesh_force,
)


@lru_cache(maxsize=64)
def step_tables(system: System, n: int, aligned: bool = True):
    """Per-step tables of one mesh period (c, h, s, seg, kappa and TE at the 3 stage times, polys), cached
    per (system, n, aligned), read-only (``docs/numerics.md``)."""
    if aligned:  # the tables of simulate_batch: one lane
        c, poly = system.kernel_array(), system.stiffness_polys()
        H, S, SEG, K, P = _empty_tables(1, n)
        _batch.fill_tables(0, *_table_scalars(system), poly, n, H, S, SEG, K, P)
        h, s, seg, tab_k, tab_p = H[0], S[0], SEG[0], K[0], P[0]
    else:
        c = system.kernel_array()
        poly = system.stiffness_polys()
        s, seg = np.arange(n) / n, np.full(n, -1, dtype=np.int64)
        ds = np.diff(np.append(s, 1.0))
        e1 = system.eps - math.floor(system.eps)
        sv = s[:, None] + np.array([0.0, 0.5, 1.0])[None, :] * ds[:, None]
        sv_k = sv % 1.0
        sg = np.where(sv_k < e1, 0, 1)
        tab_k = (poly[sg, 0] * sv_k + poly[sg, 1]) * sv_k + poly[sg, 2]
        te = system.te_forcing
        tab_p = np.array([te * math.sin(2 * math.pi * v + system.phi) for v in sv.ravel()]).reshape(sv.shape)
        h = ds * system.period
    for a in (c, poly, tab_k, tab_p, h, s, seg):
        a.setflags(write=False)
    return c, h, s, seg, tab_k, tab_p, poly


def simulate(
    system: System,
    settings: SimulationSettings = SimulationSettings(),
    x0: np.ndarray | None = None,
    dense: bool = False,
    variational: Tangent | Monodromy | None = None,
) -> SimulationResult:
    """Integrate the dimensionless 3-DOF system from x0 (default: the static deflection), optionally with
    a tangent vector or the monodromy over the last periods; never raises on divergence (``docs/numerics.md``)."""
    y0 = system.static_state() if x0 is None else np.asarray(x0, dtype=float).copy()
    if settings.integrator == "dop853":
        if variational is not None:
            raise ValueError("the variational part needs a fixed-step integrator ('rk4' or 'rk4_event')")
        from geardyn.solve.reference import simulate_reference  # noqa: PLC0415 - scipy.integrate: 0.5 s to import

        return simulate_reference(system, settings, y0, dense=dense)
    n = settings.steps_per_period
    # writable copies of the cached tables: the loop then has the argument types it has in the batch's
    # lanes, and one compiled version serves both (the copies cost nothing next to a run)
    c, *tabs = (np.array(a) for a in step_tables(system, n, settings.aligned))
    n_trans, n_rec = settings.transient_periods, settings.recorded_periods
    stride = max(1, settings.dense_stride)
    nd = (n_rec * n) // stride if dense else 0
    dt = np.empty(nd)
    dy = np.empty((nd, 6))
    b = _buffers(np.array([n_trans]), np.array([n_rec]), [variational])
    status, per, nev, ndense, used, stop_n = _kernel.run(
        c,
        tuple(tabs),
        y0,
        n_trans,
        n_rec,
        settings.integrator == "rk4_event",
        divergence_limits(system, settings),
        stride,
        b.poinc[0],
        dt,
        dy,
        b.W[0],
        int(b.ntan[0]),
        b.m == 1,
        b.growth[0],
        b.strobe[0],
        b.final[0],
        _kernel.NO_EARLY_STOP,
        np.empty(0),
        0.0,
        0,
    )
    b.out[0] = (status, per, nev, used, stop_n)
    r = _lane_result(0, system, settings, b)
    r.tangent = None  # only simulate_batch hands a tangent on (its Tangent.start)
    if dense:
        r.tau, r.states = dt[:ndense], dy[:ndense]
    return r


@dataclass(frozen=True)
class LaneTables:
    """The per-point inputs of the batch loops (:func:`simulate_batch`): kernel coefficients C (L, 19), the
    step tables H, S, SEG (L, n), kappa and TE at the RK4 stages K, P (L, n, 3), the stiffness
    polynomials POLY (L, 2, 3) and the divergence limits (L, 6).  :meth:`take` selects points."""

    C: np.ndarray
    H: np.ndarray
    S: np.ndarray
    SEG: np.ndarray
    K: np.ndarray
    P: np.ndarray
    POLY: np.ndarray
    limits: np.ndarray

    def take(self, idx: Sequence[int] | np.ndarray) -> LaneTables:
        idx = np.asarray(idx, dtype=np.int64)
        return LaneTables(*(np.ascontiguousarray(getattr(self, f)[idx]) for f in _TABLE_FIELDS))

    @staticmethod
    def gather(rows: Sequence[tuple[LaneTables, int]]) -> LaneTables:
        """The tables of points drawn from several tables: (tables, row) per point, in order."""
        return LaneTables(*(np.stack([getattr(t, f)[r] for t, r in rows]) for f in _TABLE_FIELDS))


_TABLE_FIELDS = ("C", "H", "S", "SEG", "K", "P", "POLY", "limits")


def lane_tables(systems: Sequence[System], settings: SimulationSettings) -> LaneTables:
    """The :class:`LaneTables` of ``systems`` at ``settings`` (steps per period, alignment, divergence
    threshold): the arrays :func:`simulate_batch` builds on every call, built once."""
    L, n = len(systems), settings.steps_per_period
    C = np.empty((L, 19))
    H, S, SEG, K, P = _empty_tables(L, n)
    POLY = np.empty((L, 2, 3))
    for lane, system in enumerate(systems):
        if settings.aligned:
            C[lane] = system.kernel_array()
            POLY[lane] = system.stiffness_polys()
            _batch.fill_tables(lane, *_table_scalars(system), POLY[lane], n, H, S, SEG, K, P)
        else:
            C[lane], H[lane], S[lane], SEG[lane], K[lane], P[lane], POLY[lane] = step_tables(system, n, False)
    limits = np.stack([divergence_limits(system, settings) for system in systems]) if L else np.empty((0, 6))
    return LaneTables(C, H, S, SEG, K, P, POLY, limits)


def _periods(lanes: Sequence[Lane], settings: SimulationSettings) -> tuple[np.ndarray, np.ndarray]:
    """The transient and recorded periods (L,) int64 each of a batch's lanes (the settings' where None)."""
    ntr = [settings.transient_periods if q.transient_periods is None else q.transient_periods for q in lanes]
    nrec = [settings.recorded_periods if q.recorded_periods is None else q.recorded_periods for q in lanes]
    return np.asarray(ntr, dtype=np.int64), np.asarray(nrec, dtype=np.int64)


def _empty_tables(L: int, n: int) -> tuple[np.ndarray, ...]:
    """H, S, SEG (L, n) and K, P (L, n, 3), to be filled by :func:`geardyn.solve._batch.fill_tables`."""
    return np.empty((L, n)), np.empty((L, n)), np.empty((L, n), np.int64), np.empty((L, n, 3)), np.empty((L, n, 3))


def _table_scalars(system: System) -> tuple[float, float, float, float]:
    """The scalars of a system's aligned step tables (:func:`geardyn.solve._batch.fill_tables`): contact ratio,
    period, TE forcing amplitude and phase."""
    return float(system.eps), float(system.period), float(system.te_forcing), float(system.phi)


def _tangent_columns(
    variational: Sequence[Tangent | Monodromy | None], total: np.ndarray
) -> tuple[int, np.ndarray, np.ndarray, np.ndarray]:
    """(m, ntan, W, mono) of a batch of one kind of variational part: m tangent columns per point (1: a
    renormalised vector, 6: the monodromy matrix, 0: none), carried over the last ntan (L,) of the ``total``
    periods, starting from W (L, 6, m); mono (L,): the monodromy's periods (0: none)."""
    L = total.shape[0]
    ask = np.array([0 if v is None else v.periods for v in variational], dtype=np.int64)
    if any(isinstance(v, Tangent) for v in variational):
        W = np.full((L, 6, 1), 1.0 / math.sqrt(6.0))
        for lane, v in enumerate(variational):
            if isinstance(v, Tangent) and v.start is not None:
                W[lane, :, 0] = v.start
        return 1, np.minimum(ask, total), W, np.zeros(L, np.int64)
    if np.any(ask):
        W = np.zeros((L, 6, 6))
        W[:, range(6), range(6)] = 1.0
        return 6, np.minimum(ask, total), W, ask
    return 0, np.zeros(L, np.int64), np.empty((L, 6, 0)), ask


@dataclass
class _Buffers:
    """The per-point periods and the loops' output arrays of a batch of L points (:func:`_buffers`): the
    Poincare records, final states, tangent columns W and their growth and strobe, and ``out`` (L, 5): status,
    period reached, contact switches, transient used, period of the early stop."""

    ntr: np.ndarray
    nrec: np.ndarray
    mono: np.ndarray
    m: int
    ntan: np.ndarray
    W: np.ndarray
    growth: np.ndarray
    strobe: np.ndarray
    poinc: np.ndarray
    final: np.ndarray
    out: np.ndarray


def _buffers(ntr: np.ndarray, nrec: np.ndarray, variational: Sequence[Tangent | Monodromy | None]) -> _Buffers:
    """The :class:`_Buffers` of points with transient and recorded periods (L,) each and a variational part
    each, of one kind."""
    L = ntr.shape[0]
    m, ntan, W, mono = _tangent_columns(variational, ntr + nrec)
    ng = int(ntan.max()) if m == 1 else 0
    growth, strobe = np.full((L, ng), np.nan), np.full((L, ng), np.nan)
    poinc = np.full((L, int(nrec.max()), 6), np.nan)
    return _Buffers(ntr, nrec, mono, m, ntan, W, growth, strobe, poinc, np.empty((L, 6)), np.zeros((L, 5), np.int64))


def full_batch() -> int:
    """The fewest points that keep every lane of every thread busy in :func:`simulate_batch`: the lockstep
    width times the number of numba threads."""
    return _batch.WIDTH * numba.get_num_threads()


#: lanes left over after the full lockstep blocks that run one per thread instead (measured with the tangent:
#: a block of 8 lanes costs the time of 2 scalar runs when it holds 1-2 points, and less from 3 points on)
SCALAR_REMAINDER = 2


def _blocked_lanes(L: int) -> int:
    """How many of L lanes (the first ones) the lockstep blocks take: all, but a remainder of at most
    :data:`SCALAR_REMAINDER` lanes after the full blocks runs on the scalar loop (the same numbers)."""
    r = L % _batch.WIDTH
    return L - r if r <= SCALAR_REMAINDER else L


def _lanes(arrays: tuple, part: slice) -> tuple:
    """The lanes ``part`` of every array (and of the tables' tuple): views, written in place."""
    return tuple(_lanes(a, part) if isinstance(a, tuple) else a[part] for a in arrays)


def _start_states(lanes: Sequence[Lane]) -> np.ndarray:
    """The initial states (L, 6) of a batch: each lane's start, or the static deflection where None."""
    Y0 = np.empty((len(lanes), 6))
    for k, q in enumerate(lanes):
        Y0[k] = q.system.static_state() if q.start is None else np.asarray(q.start, dtype=float)
    return Y0


def _lane_result(lane: int, system: System, settings: SimulationSettings, b: _Buffers) -> SimulationResult:
    """The :class:`SimulationResult` of lane ``lane`` of a batch from the loops' outputs."""
    status, per, nev, used, stop_n = (int(v) for v in b.out[lane])
    diverged = status == 1
    npts = max(0, per - used) if diverged else int(b.nrec[lane])
    tan_start = int(b.ntr[lane] + b.nrec[lane] - b.ntan[lane])
    if stop_n:
        ngrowth = 0
    else:
        ngrowth = max(0, per - tan_start) if diverged else int(b.ntan[lane])
    tangent = b.m == 1
    return SimulationResult(
        poincare=b.poinc[lane, :npts],
        final_state=b.final[lane],
        diverged=diverged,
        diverged_period=per if diverged else -1,
        n_events=nev,
        period=system.period,
        settings=settings,
        growth=b.growth[lane, :ngrowth] if tangent else np.zeros(0),
        strobe=b.strobe[lane, :ngrowth] if tangent else np.zeros(0),
        monodromy=b.W[lane] if (b.m == 6 and b.mono[lane] and not diverged) else None,
        transient_used=used,
        stop_period=stop_n,
        tangent=b.W[lane, :, 0].copy() if tangent and b.ntan[lane] else None,
    )


def simulate_batch(
    lanes: Sequence[Lane],
    settings: SimulationSettings = SimulationSettings(),
    *,
    early_stop: EarlyStop | None = None,
    tables: LaneTables | None = None,
) -> list[SimulationResult]:
    """:func:`simulate` of many points (a :class:`~geardyn.solve.base.Lane` each) at once (``rk4``/``rk4_event``,
    no dense output), in parallel, each point bit-identical to :func:`simulate` without ``early_stop``; cached
    ``tables`` (``docs/numerics.md``).  Lanes with a tangent and lanes with the monodromy run as two batches."""
    if settings.integrator == "dop853":
        raise ValueError("simulate_batch integrates with 'rk4' or 'rk4_event'")
    mono = [k for k, q in enumerate(lanes) if isinstance(q.variational, Monodromy)]
    if mono and any(isinstance(q.variational, Tangent) for q in lanes):
        rest = [k for k, q in enumerate(lanes) if not isinstance(q.variational, Monodromy)]
        out: list[SimulationResult] = [None] * len(lanes)  # type: ignore[list-item]
        for part in (rest, mono):
            sub = None if tables is None else tables.take(part)
            runs = simulate_batch([lanes[k] for k in part], settings, early_stop=early_stop, tables=sub)
            for k, r in zip(part, runs, strict=True):
                out[k] = r
        return out
    return _one_kind(lanes, settings, early_stop, tables)


def _one_kind(
    lanes: Sequence[Lane], settings: SimulationSettings, early_stop: EarlyStop | None, tables: LaneTables | None
) -> list[SimulationResult]:
    """:func:`simulate_batch` of lanes whose variational parts are of one kind (or none)."""
    L = len(lanes)
    if L == 0:
        return []
    n = settings.steps_per_period
    systems = [q.system for q in lanes]
    ntr, nrec = _periods(lanes, settings)
    lt = lane_tables(systems, settings) if tables is None else tables
    if lt.H.shape != (L, n):
        raise ValueError(f"lane tables for {lt.H.shape[0]} points of {lt.H.shape[1]} steps, not {L} of {n}")
    C, TABS, limits = lt.C, (lt.H, lt.S, lt.SEG, lt.K, lt.P, lt.POLY), lt.limits
    Y0 = _start_states(lanes)
    b = _buffers(ntr, nrec, [q.variational for q in lanes])
    es = _kernel.NO_EARLY_STOP if early_stop is None else early_stop.as_kernel_args()
    event = settings.integrator == "rk4_event"
    sums = [q.sums for q in lanes]
    acc, sgn, last = _sums(systems, sums, b.m)
    k = _blocked_lanes(L) if b.m <= 1 else 0
    arrays = (C, TABS, Y0, ntr, nrec, limits, b.poinc, b.final, b.out, b.W, b.ntan, b.growth, b.strobe, acc, sgn, last)
    if k:
        c, tabs, y0, nt, nr, lim, po, fi, ou, w, na, gr, sb, ac, sg, la = _lanes(arrays, slice(0, k))
        _batch.run_blocks(c, tabs, y0, nt, nr, event, lim, po, fi, es, ou, w, na, gr, sb, ac, sg, la)
    if k < L:
        c, tabs, y0, nt, nr, lim, po, fi, ou, w, na, gr, sb, ac, sg, la = _lanes(arrays, slice(k, L))
        tan = b.m == 1
        _batch.run_batch(c, tabs, y0, nt, nr, event, lim, w, na, tan, gr, sb, po, fi, es, ou, ac, sg, la)
    results = [_lane_result(lane, systems[lane], settings, b) for lane in range(L)]
    if any(s is not None for s in sums):
        for r, a, m in zip(results, acc, last, strict=True):
            r.sums = a.copy() if m > 0 else None
    return results


def _sums(systems: Sequence[System], sums: Sequence[Sums | None], m: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The response measures' arrays of a batch (:func:`geardyn.solve._batch.run_blocks`): the sums (L,
    N_OUT) (from each lane's start where given; (L, 0) when no lane asks for them), the drive sides (L,) and
    the periods (L,) they cover (0 where a lane asks for none)."""
    L = len(systems)
    if all(s is None for s in sums):
        return np.empty((L, 0)), np.empty(L), np.zeros(L, np.int64)
    if m > 1:
        raise ValueError("the response measures' sums are added in runs without the monodromy")
    acc = np.zeros((L, _response.N_OUT))
    for lane, s in enumerate(sums):
        if s is not None and s.start is not None:
            acc[lane] = s.start
    sgn = np.array([drive_side(static_mesh_force(s)) for s in systems])
    return acc, sgn, np.array([0 if s is None else s.last for s in sums], dtype=np.int64)


def warm_up(system: System) -> None:
    """Compile (or load from the numba cache) the kernels once per process, on ``system``."""
    for integ in ("rk4", "rk4_event"):
        tiny = SimulationSettings(integrator=integ, steps_per_period=16, transient_periods=1, recorded_periods=1)
        simulate(system, tiny, dense=True)
        simulate(system, tiny, variational=Tangent(1))
        simulate(system, tiny, variational=Monodromy(1))
        # the batch loops of simulate_batch (lockstep, with tangent, lanes with monodromy)
        simulate_batch([Lane(system)] * 9, tiny, early_stop=EarlyStop(min_periods=0, confirm=1))
        simulate_batch([Lane(system, variational=Tangent(1))] * 9, tiny)
        simulate_batch([Lane(system, variational=Monodromy(1))] * 2, tiny)


#: rule 3, compiled: stated once in :mod:`geardyn.solve._period`, read by :mod:`geardyn.label.indicators`
strict_period, strict_periods = _period.strict_period, _period.strict_periods
