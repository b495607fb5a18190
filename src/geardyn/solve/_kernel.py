"""The compiled core: one fixed-step RK4 loop with contact-switch location and an optional variational
(tangent) part.  Private to :mod:`geardyn.solve`; use :func:`geardyn.solve.simulate` (the method: aligned
grid, Hermite-located switches, tangent columns, divergence check: ``docs/numerics.md``)."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

import geardyn.solve._cache as _cache
from geardyn.solve._model import hermite_root, region, rk4, rk4_tangent, rk4_tangent_at, slope
from geardyn.solve._period import early_stop
from geardyn.solve._response import STATUS, add_step, start_sums
from geardyn.solve.base import BACKLASH_ON, CM, EPS, PHI, TE, B, T

#: A crossing located within this fraction of a step from either end lies at that end (the step is accepted as it
#: is, no sliver step of rounding size follows).
END_FRACTION = 1e-12

_cache.renew_once()  # before the loops: numba's cache renewed when any kernel source changed


@njit(cache=True, inline="always")
def orbit_step(c, y, h, k0, k1, k2, p0, p1, p2, ynew):
    """The orbit's RK4 step of size h from y (6,) into ynew (6,) (:func:`geardyn.solve._model.rk4`); returns
    the stiffness slopes kappa f'(x2) at its four stage states, for the tangent columns."""
    on = c[BACKLASH_ON]
    b = c[B] if on != 0.0 else 0.0
    x2 = y[1]
    n1, n2, n3, n4, n5, n6, X2, Z2, Q2 = rk4(c, b, h, k0, k1, k2, p0, p1, p2, y[0], x2, y[2], y[3], y[4], y[5])
    ynew[0], ynew[1], ynew[2], ynew[3], ynew[4], ynew[5] = n1, n2, n3, n4, n5, n6
    return k0 * slope(on, b, x2), k1 * slope(on, b, X2), k1 * slope(on, b, Z2), k2 * slope(on, b, Q2)


@njit(cache=True, inline="always")
def step(c, y, W, m, h, k0, k1, k2, p0, p1, p2, ynew, Wnew, fixed):
    """One RK4 step of size h from y into ynew, with m > 0 the m tangent columns W into Wnew; the slopes
    f'(x2) are the orbit's four stage states', or ``fixed`` (0 or 1) for all four when ``fixed >= 0`` (a
    sub-step on a located switch; why: ``docs/numerics.md``)."""
    s1, s2, s3, s4 = orbit_step(c, y, h, k0, k1, k2, p0, p1, p2, ynew)
    if m > 0:
        if fixed >= 0.0:
            s1, s2, s3, s4 = k0 * fixed, k1 * fixed, k1 * fixed, k2 * fixed
        for col in range(m):
            w = rk4_tangent(c, h, s1, s2, s3, s4, W[0, col], W[1, col], W[2, col], W[3, col], W[4, col], W[5, col])
            Wnew[0, col], Wnew[1, col], Wnew[2, col], Wnew[3, col], Wnew[4, col], Wnew[5, col] = w


#: Tangent columns of one point stepped together by :func:`step_columns` (one AVX-512 register of doubles):
#: the 6 columns of the monodromy matrix and 2 of padding.
COLUMNS = 8


@njit(cache=True, inline="always")
def step_columns(c, y, h, k0, k1, k2, p0, p1, p2, ynew, A):
    """:func:`step` with the 6 monodromy columns packed in A (96,) (column q's component i at
    ``A[COLUMNS * i + q]``, new values at ``A[COLUMNS * (6 + i) + q]``): the same bits, vectorised over the
    columns (measured: ``docs/numerics.md``)."""
    s1, s2, s3, s4 = orbit_step(c, y, h, k0, k1, k2, p0, p1, p2, ynew)
    for q in range(COLUMNS):
        rk4_tangent_at(c, h, s1, s2, s3, s4, A, 0, 6, COLUMNS, q)


@njit(cache=True, inline="always")
def _columns(A, W, half, to_buffer):
    """Copy the 6 columns W (6, 6) into half ``half`` of the buffer of :func:`step_columns` (0: the
    columns, 1: their new values) when ``to_buffer``, or back into W."""
    for i in range(6):
        for col in range(6):
            if to_buffer:
                A[COLUMNS * (6 * half + i) + col] = W[i, col]
            else:
                W[i, col] = A[COLUMNS * (6 * half + i) + col]


@njit(cache=True, inline="always")
def kappa_at(poly, seg, eps1, s):
    """kappa at phase s (0 <= s <= 1 + tiny) on segment seg (0, 1), or the global function if seg < 0."""
    if seg < 0:
        s = s - math.floor(s)
        seg = 0 if s < eps1 else 1
    return (poly[seg, 0] * s + poly[seg, 1]) * s + poly[seg, 2]


@njit(cache=True, inline="always")
def te_at(c, s):
    return c[TE] * math.sin(2.0 * math.pi * s + c[PHI])


@njit(cache=True, inline="always")
def sub_step(c, poly, seg, y, W, m, s0, dt, yout, Wout, fixed):
    """RK4 sub-step of length dt (time) from phase s0, kappa and TE evaluated on the fly; the m
    tangent columns follow when m > 0.  Inlined into :func:`locate_switches`, as is :func:`hermite_root`:
    as calls with their arrays they took a third of a contact switch (383 against 257 ns, measured)."""
    period = c[T]
    eps1 = c[EPS] - math.floor(c[EPS])
    sm = s0 + 0.5 * dt / period
    se = s0 + dt / period
    k0, k1, k2 = kappa_at(poly, seg, eps1, s0), kappa_at(poly, seg, eps1, sm), kappa_at(poly, seg, eps1, se)
    p0, p1, p2 = te_at(c, s0), te_at(c, sm), te_at(c, se)
    step(c, y, W, m, dt, k0, k1, k2, p0, p1, p2, yout, Wout, fixed)


@njit(cache=True)
def locate_switches(c, poly, y, ynew, W, Wnew, mt, h, s0, seg, reg, rnew, b, period):
    """Locate the contact switches inside the step from y whose plain result ynew left region ``reg`` for
    ``rnew``, restart there and redo the rest of the step (y, ynew and the tangent columns updated); returns
    (region at the end of the step, crossings located) (``docs/numerics.md``)."""
    s_cur = s0
    left = h
    n_events = 0
    for _it in range(8):
        if reg == 0:
            target = b if rnew > 0 else -b
        else:
            target = b if reg > 0 else -b
        th = hermite_root(y[1], ynew[1], y[4], ynew[4], left, target)
        if th <= END_FRACTION * h or th >= left * (1.0 - END_FRACTION):
            # crossing at an end point: accept the step as it is
            reg = rnew
            break
        dt = th
        for part in range(2):
            sub_step(c, poly, seg, y, W, mt, s_cur, dt, ynew, Wnew, 0.0 if reg == 0 else 1.0)
            if part == 1:
                break
            # at the crossing: restart there, in the new region (entering from the dead zone or leaving a
            # contact side), for the rest of the step
            n_events += 1
            for i in range(6):
                y[i] = ynew[i]
            for col in range(mt):
                for i in range(6):
                    W[i, col] = Wnew[i, col]
            if reg == 0:
                reg = 1 if target > 0 else -1
            else:
                reg = 0
            s_cur += th / period
            left -= th
            dt = left
        rnew = region(ynew[1], b)
        if rnew == reg:
            break
    return rnew, n_events


#: The early-stop tuple of :func:`run` that stops nothing: (es_min, es_confirm, es_max_n, es_floor, es_atol, es_sep).
NO_EARLY_STOP = (0, 0, 1, 0.0, 0.0, 0.0)


@njit(cache=True, nogil=True)
def run(
    c,
    tabs,
    y0,
    n_trans,
    n_rec,
    event,
    limits,
    stride,
    poinc,
    dense_t,
    dense_y,
    W,
    n_tan,
    renorm,
    growth,
    strobe,
    yfinal,
    es,
    acc,
    sgn,
    acc_last,
):
    """Integrate n_trans + n_rec mesh periods from y0 (phase 0): the one loop of the solver, with Poincare
    points, dense output, tangent columns, the early stop ``es`` (:data:`NO_EARLY_STOP`: off) and, with acc
    (N_OUT,) (empty: none), the response measures' sums over the last ``acc_last`` periods (drive side
    ``sgn``), as the lanes add them.  Returns (status, last_period, n_events, n_dense, transient_used,
    stop_period) (arguments: ``docs/numerics.md``)."""
    # coefficients as a tuple: numba keeps them in registers instead of reloading the array
    # fmt: off
    c = (c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7], c[8], c[9], c[10], c[11], c[12], c[13],
         c[14], c[15], c[16], c[17], c[18])
    # fmt: on
    tab_h, tab_s, tab_seg, tab_k, tab_p, poly = tabs
    es_max_n = es[2]
    nsteps = tab_h.shape[0]
    period = c[T]
    b = c[B]
    m = W.shape[1]
    use_events = event and c[BACKLASH_ON] != 0.0 and b > 0.0
    y = y0.copy()
    ynew = np.empty(6)
    Wnew = np.empty((6, m))
    n_events = 0
    n_dense = 0
    ndmax = dense_t.shape[0]
    tan_start = n_trans + n_rec - n_tan
    # early stop: ring of the last max_n + 1 Poincaré points, consecutive counts per n
    ring = np.empty((es_max_n + 1, 6))
    count = np.zeros(es_max_n + 1, dtype=np.int64)
    dcur = np.full(es_max_n + 1, np.inf)
    stop_n = 0
    n_tr = n_trans
    reg = region(y[1], b)
    per = 0
    status = 0
    summed = acc.shape[0] > 0 and acc_last > 0
    b_sums = b if c[BACKLASH_ON] != 0.0 else 0.0
    # the monodromy matrix's columns in one buffer (step_columns); W and Wnew hold them only at switches
    packed = m == 6 and not renorm
    A = np.zeros(12 * COLUMNS if packed else 0)
    if packed:
        _columns(A, W, 0, True)
    while per < n_tr + n_rec:
        mt = m if (per >= tan_start and stop_n == 0) else 0
        cols = packed and mt > 0  # this period's columns step in the buffer
        adding = summed and per >= n_tr + n_rec - acc_last
        if adding and per == n_tr + n_rec - acc_last:
            start_sums(acc, tab_k[0, 0], c[CM], b_sums, y[1], y[4], sgn)
        for j in range(nsteps):
            h = tab_h[j]
            k0, k1, k2, p0, p1, p2 = tab_k[j, 0], tab_k[j, 1], tab_k[j, 2], tab_p[j, 0], tab_p[j, 1], tab_p[j, 2]
            if cols:
                step_columns(c, y, h, k0, k1, k2, p0, p1, p2, ynew, A)
            else:
                step(c, y, W, mt, h, k0, k1, k2, p0, p1, p2, ynew, Wnew, -1.0)
            xs, vs = y[1], y[4]  # the step's start (a located switch moves y to the crossing)
            if use_events:
                rnew = region(ynew[1], b)
                if rnew != reg:
                    if cols:
                        _columns(A, W, 0, False)
                        _columns(A, Wnew, 1, False)
                    reg, nev = locate_switches(
                        c, poly, y, ynew, W, Wnew, mt, h, tab_s[j], tab_seg[j], reg, rnew, b, period
                    )
                    if cols:  # the new values only: they replace the columns below
                        _columns(A, Wnew, 1, True)
                    n_events += nev
            if adding:
                add_step(acc, h, k0, k2, c[CM], b_sums, sgn, xs, vs, ynew[1], ynew[4])
            for i in range(6):
                y[i] = ynew[i]
            if cols:
                for i in range(6 * COLUMNS):
                    A[i] = A[6 * COLUMNS + i]
            else:
                for col in range(mt):
                    for i in range(6):
                        W[i, col] = Wnew[i, col]
            if per >= n_tr and ndmax > 0 and (j % stride) == stride - 1 and n_dense < ndmax:
                dense_t[n_dense] = (per + tab_s[j]) * period + h
                for i in range(6):
                    dense_y[n_dense, i] = y[i]
                n_dense += 1
        if diverged(y, limits):
            status = 1
            if summed:
                acc[STATUS] = 1.0
            break
        k_tan = per - tan_start if (mt > 0 and renorm) else -1
        stop_n, n_tr = end_period(y, W, k_tan, per, n_tr, growth, strobe, poinc, es, ring, count, dcur, stop_n)
        per += 1
    for i in range(6):
        yfinal[i] = y[i]
    if packed:
        _columns(A, W, 0, False)
    return status, per, n_events, n_dense, min(per + 1, n_tr), stop_n


@njit(cache=True)
def diverged(y, limits):
    """Whether any |y_i| exceeds limits[i] or is not finite (checked at the end of every mesh period)."""
    for i in range(6):
        if not (abs(y[i]) <= limits[i]):
            return True
    return False


@njit(cache=True)
def end_period(y, W, k_tan, per, n_tr, growth, strobe, poinc, es, ring, count, dcur, stop_n):
    """The records of the end of mesh period ``per`` (state y, tangent columns W) in both loops, and the early
    stop's running record (ring, count, dcur: the points fed so far are the ``per`` transient periods before).
    Returns (stop_n, the transient periods n_tr, shortened by an early stop) (``docs/numerics.md``)."""
    if k_tan >= 0:  # renormalise W[:, 0]: growth[k_tan] = log of its norm before that, strobe[k_tan] = x2
        nrm = 0.0
        for i in range(6):
            nrm += W[i, 0] * W[i, 0]
        nrm = math.sqrt(nrm)
        growth[k_tan] = math.log(nrm) if nrm > 0.0 else -np.inf
        strobe[k_tan] = y[1]
        for i in range(6):
            W[i, 0] /= nrm
    if per >= n_tr and per - n_tr < poinc.shape[0]:  # a recorded period (a poinc of length 0 records none)
        for i in range(6):
            poinc[per - n_tr, i] = y[i]
    if per < n_tr and es[1] > 0:
        _, stop_n = early_stop(ring, count, dcur, per, y, es, per + 1 >= es[0] and per + 1 < n_tr)
        if stop_n > 0:
            n_tr = per + 1
    return stop_n, n_tr
