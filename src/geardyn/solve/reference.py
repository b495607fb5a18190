"""Reference solution: scipy ``solve_ivp`` (DOP853) with the switching events, rtol 1e-12, zone by zone
and region by region, independent of the RK4 kernels (method: ``docs/numerics.md``)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit
from scipy.integrate import solve_ivp

import geardyn.solve._cache as _cache
from geardyn.solve.base import (
    C11,
    C21,
    C23,
    C33,
    CM,
    G1,
    G3,
    K11,
    K21,
    K23,
    K33,
    P1,
    P3,
    PHI,
    TE,
    B,
    SimulationResult,
    SimulationSettings,
    System,
    T,
    divergence_limits,
)

#: The reference solver's relative tolerance (scipy's DOP853; the independent check of the fixed-step loops), and
#: the fraction of a period below which what is left of it after an event is not integrated.
RTOL = 1e-12
END_FRACTION = 1e-14

_cache.renew_once()  # before the loops: numba's cache renewed when any kernel source changed


@njit(cache=True)
def _rhs_region(t, y, c, poly, seg, reg, per):
    # c: kernel_array (named indices of geardyn.solve.base.LAYOUT); poly: (2, 3);
    # reg: -1, 0, 1 (or 2 = no backlash: f = x2)
    s = t / c[T] - per
    kap = (poly[seg, 0] * s + poly[seg, 1]) * s + poly[seg, 2]
    x2 = y[1]
    if reg == 2:
        f = x2
    elif reg == 1:
        f = x2 - c[B]
    elif reg == -1:
        f = x2 + c[B]
    else:
        f = 0.0
    fm = kap * f + c[CM] * y[4]
    pe = c[TE] * math.sin(2.0 * math.pi * s + c[PHI])
    out = np.empty(6)
    out[0] = y[3]
    out[1] = y[4]
    out[2] = y[5]
    out[3] = c[P1] - c[K11] * y[0] - c[C11] * y[3] - c[G1] * fm
    out[4] = pe - c[K21] * y[0] - c[C21] * y[3] - c[K23] * y[2] - c[C23] * y[5] - fm
    out[5] = c[P3] - c[K33] * y[2] - c[C33] * y[5] - c[G3] * fm
    return out


@dataclass(frozen=True)
class _Crossing:
    """A terminal event of :func:`scipy.integrate.solve_ivp`: the displacement y[1] reaches ``edge`` moving in
    ``direction``."""

    edge: float
    direction: float
    terminal: bool = True

    def __call__(self, t: float, y: np.ndarray, *_: object) -> float:
        return y[1] - self.edge


def _events(b: float, reg: int) -> tuple[list[_Crossing], list[int]]:
    if reg == 0:
        return [_Crossing(b, 1.0), _Crossing(-b, -1.0)], [1, -1]
    if reg == 1:
        return [_Crossing(b, -1.0)], [0]
    return [_Crossing(-b, 1.0)], [0]


def _initial_region(y: np.ndarray, b: float) -> int:
    x, v = y[1], y[4]
    if x > b or (x == b and v > 0):
        return 1
    if x < -b or (x == -b and v < 0):
        return -1
    return 0


def integrate_period(
    coeffs: System,
    y: np.ndarray,
    per: int = 0,
    rtol: float = RTOL,
    atol: float | None = None,
    reg: int | None = None,
    collect: list | None = None,
    max_step_fraction: float = 1.0 / 128,
):
    """Integrate one mesh period (phase 0 -> 1) from y; returns (y_end, region, n_events).

    max_step_fraction: largest DOP853 step in mesh periods (``inf``: unlimited).
    """
    c = coeffs.kernel_array()
    poly = coeffs.stiffness_polys()
    T = coeffs.period
    b = coeffs.b
    atol = rtol if atol is None else atol
    backlash = coeffs.backlash_on
    if reg is None:
        reg = _initial_region(y, b) if backlash else 2
    nev = 0
    f = coeffs.eps - math.floor(coeffs.eps)
    bounds = ((0.0, f, 0), (f, 1.0, 1)) if f > 0.0 else ((0.0, 1.0, 1),)
    if coeffs.stiffness_mode == "mean":
        bounds = ((0.0, 1.0, 0),)
    for sa, sb, seg in bounds:
        t = (per + sa) * T
        t_end = (per + sb) * T
        while True:
            evs, nxt = _events(b, reg) if reg != 2 else ([], [])
            sol = solve_ivp(
                _rhs_region,
                (t, t_end),
                y,
                method="DOP853",
                rtol=rtol,
                atol=atol,
                max_step=T * max_step_fraction,
                events=evs or None,
                args=(c, poly, seg, reg, float(per)),
            )
            if collect is not None:
                collect.append((sol.t, sol.y.T))
            if sol.status == 1:
                k = next(i for i, te in enumerate(sol.t_events) if len(te))
                t = float(sol.t_events[k][0])
                y = sol.y_events[k][0].copy()
                if reg == 0:
                    reg = nxt[k]
                else:
                    reg = 0
                nev += 1
                if t_end - t <= END_FRACTION * T:
                    break
                continue
            y = sol.y[:, -1].copy()
            break
    return y, reg, nev


def simulate_reference(
    coeffs: System,
    settings: SimulationSettings,
    y0: np.ndarray,
    dense: bool = False,
    max_step_fraction: float = 1.0 / 128,
) -> SimulationResult:
    """DOP853 counterpart of :func:`geardyn.solve.simulate` (same result type)."""
    y = np.asarray(y0, dtype=float).copy()
    reg = None
    ntr, nrec = settings.transient_periods, settings.recorded_periods
    poinc = np.full((nrec, 6), np.nan)
    nev = 0
    limit = divergence_limits(coeffs, settings)
    chunks: list | None = [] if dense else None
    for per in range(ntr + nrec):
        collect = chunks if (dense and per >= ntr) else None
        y, reg, k = integrate_period(
            coeffs, y, per, settings.rtol, reg=reg, collect=collect, max_step_fraction=max_step_fraction
        )
        nev += k
        if not np.all(np.abs(y) <= limit):
            return SimulationResult(
                poinc[: max(0, per - ntr)], np.full(6, np.nan), True, per, nev, period=coeffs.period, settings=settings
            )
        if per >= ntr:
            poinc[per - ntr] = y
    tau = states = None
    if dense and chunks:
        tau = np.concatenate([t for t, _ in chunks])
        states = np.concatenate([s for _, s in chunks])
    return SimulationResult(poinc, y.copy(), False, -1, nev, tau, states, coeffs.period, settings)
