"""Many points at once: the event RK4 loop of :mod:`geardyn.solve._kernel` with an early stop of the
transient, over a batch of points with ``numba.prange``.  Private to :mod:`geardyn.solve`; use
:func:`geardyn.solve.simulate_batch` (lanes, early stop, tangent: ``docs/numerics.md``)."""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

import geardyn.solve._cache as _cache
from geardyn.solve._kernel import diverged, end_period, locate_switches, run
from geardyn.solve._model import region, rk4, rk4_tangent_at, slope
from geardyn.solve._response import STATUS, add_step, start_sums
from geardyn.solve.base import BACKLASH_ON, CM, B, T

_cache.renew_once()  # before the loops: numba's cache renewed when any kernel source changed


@njit(cache=True, parallel=True)
def run_batch(
    C,
    TABS,
    Y0,
    NTRANS,
    NREC,
    event,
    LIMITS,
    W,
    NTAN,
    renorm,
    GROWTH,
    STROBE,
    POINC,
    YFINAL,
    ES,
    OUT,
    ACC,
    SGN,
    ACC_LAST,
):
    """:func:`geardyn.solve._kernel.run` (no dense output) for every lane, in parallel over lanes; W (L, 6, m)
    updated in place, OUT (L, 5) the status, last period, switches, transient used and stop period; ACC, SGN,
    ACC_LAST the response measures' sums as in :func:`run_blocks`."""
    H, S, SEG, K, P, POLY = TABS
    n_lanes = C.shape[0]
    for lane in prange(n_lanes):
        st, per, nev, _, used, stop_n = run(
            C[lane],
            (H[lane], S[lane], SEG[lane], K[lane], P[lane], POLY[lane]),
            Y0[lane],
            NTRANS[lane],
            NREC[lane],
            event,
            LIMITS[lane],
            1,
            POINC[lane],
            np.empty(0),
            np.empty((0, 6)),
            W[lane],
            NTAN[lane],
            renorm,
            GROWTH[lane],
            STROBE[lane],
            YFINAL[lane],
            ES,
            ACC[lane],
            SGN[lane],
            ACC_LAST[lane],
        )
        OUT[lane, 0] = st
        OUT[lane, 1] = per
        OUT[lane, 2] = nev
        OUT[lane, 3] = used
        OUT[lane, 4] = stop_n


#: Lanes stepped together by :func:`run_blocks` (one AVX-512 register of doubles).
WIDTH = 8


@njit(cache=True, inline="always")
def _lanes(A, tan):
    """One RK4 step of the WIDTH lanes packed in A (rows of WIDTH: 0-12 K11 .. CM, 13 b, 14 h, 15-17 kappa,
    18-20 TE, 21-26 the state, 27-32 the new state; with ``tan`` rows 33-38 -> 39-44 a tangent column,
    45 backlash on).  One buffer so the compiler vectorises the lanes (why: ``docs/numerics.md``)."""
    for q in range(WIDTH):
        # fmt: off
        k = (A[q], A[WIDTH + q], A[2 * WIDTH + q], A[3 * WIDTH + q], A[4 * WIDTH + q], A[5 * WIDTH + q],
             A[6 * WIDTH + q], A[7 * WIDTH + q], A[8 * WIDTH + q], A[9 * WIDTH + q], A[10 * WIDTH + q],
             A[11 * WIDTH + q], A[12 * WIDTH + q])
        # fmt: on
        b = A[13 * WIDTH + q]
        h = A[14 * WIDTH + q]
        k0, k1, k2 = A[15 * WIDTH + q], A[16 * WIDTH + q], A[17 * WIDTH + q]
        x2 = A[22 * WIDTH + q]
        # fmt: off
        n1, n2, n3, n4, n5, n6, X2, Z2, Q2 = rk4(k, b, h, k0, k1, k2, A[18 * WIDTH + q], A[19 * WIDTH + q],
                                                 A[20 * WIDTH + q], A[21 * WIDTH + q], x2, A[23 * WIDTH + q],
                                                 A[24 * WIDTH + q], A[25 * WIDTH + q], A[26 * WIDTH + q])
        # fmt: on
        A[27 * WIDTH + q] = n1
        A[28 * WIDTH + q] = n2
        A[29 * WIDTH + q] = n3
        A[30 * WIDTH + q] = n4
        A[31 * WIDTH + q] = n5
        A[32 * WIDTH + q] = n6
        if tan:
            on = A[45 * WIDTH + q]
            s1, s2, s3, s4 = k0 * slope(on, b, x2), k1 * slope(on, b, X2), k1 * slope(on, b, Z2), k2 * slope(on, b, Q2)
            rk4_tangent_at(k, h, s1, s2, s3, s4, A, 33, 39, WIDTH, q)


@njit(cache=True, inline="never")
def _vstep(A):
    """:func:`_lanes` without tangent."""
    _lanes(A, False)


@njit(cache=True, inline="never")
def _vstep_tan(A):
    """:func:`_lanes` with one tangent column per lane."""
    _lanes(A, True)


@njit(cache=True)
def _pack(C, H, K, P, Y0, W, lanes, A, tab):
    """Fill the lane buffer A (rows of :func:`_lanes`, 33-38 the tangent column, 45 backlash on) and
    the per-step rows 14-20 ``tab`` (nsteps, 7 WIDTH) for ``lanes``; padding lanes repeat the first."""
    nl = lanes.shape[0]
    m = W.shape[2]
    for q in range(WIDTH):
        ln = lanes[q] if q < nl else lanes[0]
        for i in range(13):
            A[i * WIDTH + q] = C[ln, i]
        A[13 * WIDTH + q] = C[ln, B] if C[ln, BACKLASH_ON] != 0.0 else 0.0
        for j in range(H.shape[1]):
            tab[j, q] = H[ln, j]
            for r in range(3):
                tab[j, (1 + r) * WIDTH + q] = K[ln, j, r]
                tab[j, (4 + r) * WIDTH + q] = P[ln, j, r]
        for i in range(6):
            A[(21 + i) * WIDTH + q] = Y0[ln, i]
            if m > 0:
                A[(33 + i) * WIDTH + q] = W[ln, i, 0]
        A[45 * WIDTH + q] = C[ln, BACKLASH_ON]


@njit(cache=True, inline="always")
def _switch(C, POLY, H, S, SEG, A, q, ln, j, reg, rnew, tan, y1, y2, Wa, Wb):
    """Lane q (point ln), whose plain step j left contact region ``reg`` for ``rnew``: the contact switches
    of :func:`geardyn.solve._kernel.locate_switches` (and of its tangent column when ``tan``), written
    back into A.  Returns (region at the end of the step, number of crossings)."""
    # fmt: off
    c = (C[ln, 0], C[ln, 1], C[ln, 2], C[ln, 3], C[ln, 4], C[ln, 5], C[ln, 6], C[ln, 7], C[ln, 8],
         C[ln, 9], C[ln, 10], C[ln, 11], C[ln, 12], C[ln, 13], C[ln, 14], C[ln, 15], C[ln, 16],
         C[ln, 17], C[ln, 18])
    # fmt: on
    mt = 1 if tan else 0
    for i in range(6):
        y1[i] = A[(21 + i) * WIDTH + q]
        y2[i] = A[(27 + i) * WIDTH + q]
        if tan:
            Wa[i, 0] = A[(33 + i) * WIDTH + q]
            Wb[i, 0] = A[(39 + i) * WIDTH + q]
    r, nv = locate_switches(c, POLY[ln], y1, y2, Wa, Wb, mt, H[ln, j], S[ln, j], SEG[ln, j], reg, rnew, c[B], c[T])
    for i in range(6):
        A[(27 + i) * WIDTH + q] = y2[i]
        if tan:
            A[(39 + i) * WIDTH + q] = Wb[i, 0]
    return r, nv


@njit(cache=True)
def _block(
    C, TABS, Y0, NTRANS, NREC, lanes, event, LIMITS, POINC, YFINAL, ES, OUT, W, NTAN, GROWTH, STROBE, ACC, SGN, ACC_LAST
):
    """Lanes ``lanes`` (<= WIDTH) stepped in lockstep, each bit-identical to the scalar loop; with ACC (L, N_OUT)
    the response measures' sums over each lane's last ACC_LAST[l] periods, going on from ACC[l] where that
    exceeds the run (``docs/response.md``)."""
    H, S, SEG, K, P, POLY = TABS
    es_max_n = ES[2]
    nl = lanes.shape[0]
    nsteps = H.shape[1]
    Wd = WIDTH
    A = np.zeros(46 * Wd)
    m = W.shape[2]
    tab = np.empty((nsteps, 7 * Wd))
    _pack(C, H, K, P, Y0, W, lanes, A, tab)
    use_ev = np.zeros(Wd, dtype=np.bool_)
    bl = np.zeros(Wd)  # half backlash per lane
    reg = np.zeros(Wd, dtype=np.int64)
    n_tr = np.empty(Wd, dtype=np.int64)
    n_end = np.empty(Wd, dtype=np.int64)
    done = np.ones(Wd, dtype=np.bool_)
    nev = np.zeros(Wd, dtype=np.int64)
    stop_n = np.zeros(Wd, dtype=np.int64)
    ring = np.empty((Wd, es_max_n + 1, 6))
    count = np.zeros((Wd, es_max_n + 1), dtype=np.int64)
    dcur = np.full(es_max_n + 1, np.inf)
    tan_start = np.zeros(Wd, dtype=np.int64)
    tan_on = np.zeros(Wd, dtype=np.bool_)
    acc = ACC.shape[1] > 0
    acc_on = np.zeros(Wd, dtype=np.bool_)
    for q in range(nl):
        ln = lanes[q]
        use_ev[q] = event and C[ln, BACKLASH_ON] != 0.0 and C[ln, B] > 0.0
        bl[q] = C[ln, B]
        reg[q] = region(Y0[ln, 1], C[ln, B])
        n_tr[q] = NTRANS[ln]
        n_end[q] = NTRANS[ln] + NREC[ln]
        tan_start[q] = NTRANS[ln] + NREC[ln] - NTAN[ln]
        done[q] = False
    y = np.empty(6)
    y2 = np.empty(6)
    Wl = np.empty((6, 1))
    Wb = np.empty((6, 1))
    per = 0
    while not np.all(done):
        any_tan = False
        for q in range(Wd):
            tan_on[q] = m > 0 and (not done[q]) and per >= tan_start[q] and stop_n[q] == 0
            any_tan = any_tan or tan_on[q]
        if acc:  # the sums' periods: the last ACC_LAST of the run (n_end: after an early stop, shortened)
            for q in range(nl):
                ln = lanes[q]
                acc_on[q] = (not done[q]) and ACC_LAST[ln] > 0 and per >= n_end[q] - ACC_LAST[ln]
                if acc_on[q] and per == n_end[q] - ACC_LAST[ln]:  # b of the sums: A's row 13, 0 without backlash
                    # fmt: off
                    start_sums(ACC[ln], K[ln, 0, 0], C[ln, CM], A[13 * Wd + q], A[22 * Wd + q], A[25 * Wd + q],
                               SGN[ln])
                    # fmt: on
        for j in range(nsteps):
            for i in range(7 * Wd):
                A[14 * Wd + i] = tab[j, i]
            if any_tan:
                _vstep_tan(A)
            else:
                _vstep(A)
            for q in range(nl):  # contact switches, lane by lane
                if use_ev[q] and not done[q]:
                    rnew = region(A[28 * Wd + q], bl[q])
                    if rnew != reg[q]:
                        reg[q], nv = _switch(
                            C, POLY, H, S, SEG, A, q, lanes[q], j, reg[q], rnew, tan_on[q], y, y2, Wl, Wb
                        )
                        nev[q] += nv
            if acc:  # the step's share of the response measures (start state rows 21-26, end 27-32)
                for q in range(nl):
                    if acc_on[q]:
                        # fmt: off
                        add_step(ACC[lanes[q]], A[14 * Wd + q], A[15 * Wd + q], A[17 * Wd + q],
                                 C[lanes[q], CM], A[13 * Wd + q], SGN[lanes[q]], A[22 * Wd + q],
                                 A[25 * Wd + q], A[28 * Wd + q], A[31 * Wd + q])
                        # fmt: on
            for i in range(6 * Wd):
                A[21 * Wd + i] = A[27 * Wd + i]
            if any_tan:
                for q in range(Wd):
                    if tan_on[q]:
                        for i in range(6):
                            A[(33 + i) * Wd + q] = A[(39 + i) * Wd + q]
        for q in range(nl):  # end of mesh period `per`, lane by lane
            if done[q]:
                continue
            ln = lanes[q]
            for i in range(6):
                y[i] = A[(21 + i) * Wd + q]
                Wl[i, 0] = A[(33 + i) * Wd + q]
            if diverged(y, LIMITS[ln]):
                A[21 * Wd + q : 27 * Wd + q : Wd] = 0.0  # keep the idle lane finite
                if acc and ACC_LAST[ln] > 0:
                    ACC[ln, STATUS] = 1.0
                _finish(OUT[ln], YFINAL[ln], y, 1, per, nev[q], min(per + 1, n_tr[q]), stop_n[q])
                for i in range(6 * m):
                    W[ln, i, 0] = Wl[i, 0]
                done[q] = True
                continue
            k = per - tan_start[q] if tan_on[q] else -1
            stop_n[q], tr = end_period(
                y, Wl, k, per, n_tr[q], GROWTH[ln], STROBE[ln], POINC[ln], ES, ring[q], count[q], dcur, stop_n[q]
            )
            for i in range(6):
                A[(33 + i) * Wd + q] = Wl[i, 0]
            n_end[q] += tr - n_tr[q]  # shortened with the transient by an early stop
            n_tr[q] = tr
            if per + 1 >= n_end[q]:
                _finish(OUT[ln], YFINAL[ln], y, 0, n_end[q], nev[q], n_tr[q], stop_n[q])
                for i in range(6 * m):  # the tangent column at the end, as the scalar loop leaves it
                    W[ln, i, 0] = Wl[i, 0]
                done[q] = True
        per += 1


@njit(cache=True)
def _finish(out, yfinal, y, status, last_period, n_events, used, stop_n):
    """A lane's results: yfinal = y, out = (status, last_period, n_events, transient_used, stop_period)."""
    for i in range(6):
        yfinal[i] = y[i]
    out[0] = status
    out[1] = last_period
    out[2] = n_events
    out[3] = used
    out[4] = stop_n


@njit(cache=True, parallel=True)
def run_blocks(
    C, TABS, Y0, NTRANS, NREC, event, LIMITS, POINC, YFINAL, ES, OUT, W, NTAN, GROWTH, STROBE, ACC, SGN, ACC_LAST
):
    """:func:`geardyn.solve._kernel.run` (no tangent, or one renormalised tangent column: W (L, 6, 0 or 1))
    for every lane, WIDTH lanes in lockstep per block (:func:`_block`), blocks in parallel.  Blocks are
    consecutive lanes; results do not depend on it.  ACC, SGN, ACC_LAST: the response measures' sums over
    each lane's last ACC_LAST periods (ACC (L, 0): none; :func:`_block`)."""
    n_lanes = C.shape[0]
    n_blocks = (n_lanes + WIDTH - 1) // WIDTH
    for blk in prange(n_blocks):
        lanes = np.arange(blk * WIDTH, min(n_lanes, (blk + 1) * WIDTH))
        # fmt: off
        _block(C, TABS, Y0, NTRANS, NREC, lanes, event, LIMITS, POINC, YFINAL, ES, OUT, W, NTAN, GROWTH, STROBE,
               ACC, SGN, ACC_LAST)
        # fmt: on


@njit(cache=True)
def fill_tables(lane, eps, period, te, phi, poly, n, H, S, SEG, K, P):
    """The aligned step tables of :func:`geardyn.solve.run.step_tables` for one lane, written
    into row ``lane`` of H, S, SEG, K, P (the same operations in the same order: the same bits)."""
    e1 = eps - math.floor(eps)
    if e1 == 0.0:  # integer contact ratio: one zone
        for k in range(n):
            S[lane, k] = k / n
            SEG[lane, k] = 1
    else:
        n1 = min(max(1, round(n * e1)), n - 1)
        a = e1 / n1
        bb = (1.0 - e1) / (n - n1)
        for k in range(n1):
            S[lane, k] = k * a
            SEG[lane, k] = 0
        for k in range(n - n1):
            S[lane, n1 + k] = e1 + k * bb
            SEG[lane, n1 + k] = 1
    for k in range(n):
        nxt = S[lane, k + 1] if k + 1 < n else 1.0
        ds = nxt - S[lane, k]
        H[lane, k] = ds * period
        sg = SEG[lane, k]
        for r in range(3):
            f = 0.5 * r
            v = S[lane, k] + f * ds
            K[lane, k, r] = (poly[sg, 0] * v + poly[sg, 1]) * v + poly[sg, 2]
            P[lane, k, r] = te * math.sin(2.0 * math.pi * v + phi)
