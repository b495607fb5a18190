"""Many points at once: the event RK4 loop of :mod:`geardyn.solve._kernel` with an early stop of the
transient, run over a batch of parameter points with ``numba.prange`` (both cores for one job).

Private to :mod:`geardyn.solve`; use :func:`geardyn.solve.simulate_batch`.

* Lanes: each point (lane) carries its own coefficients and step tables (eps, period, TE amplitude
  may differ) and is integrated by the same arithmetic as :func:`geardyn.solve._kernel.run` (the same
  inlined RK4 step, the same contact-switch location, the same tangent step).  No lane reads another
  lane's numbers, so a lane's result is bit-identical to the scalar loop and independent of the batch
  it is in, of its position there, and of the number of threads.
* Early stop: after every mesh period of the transient (from ``es_min`` periods on), the return
  distance d_n = max_i |p_k,i - p_k-n,i| of the stroboscopic (Poincaré) points is updated for
  n = 1 .. max_n; once d_n <= tol for ``es_confirm`` consecutive periods for some n, the transient
  ends there (the smallest such n, and only if d_m > es_sep * tol for every m < n: distinct cycle
  points, as rule 3 of the classifier asks); the recorded periods follow at once and
  ``transient_used`` says how many transient periods the lane integrated.
  tol = max(es_atol * max(|p_k|, 1), es_floor).  ``es_confirm = 0``
  switches the stop off (the full transient, bit-identical to the scalar loop).
* Tangent (m = 1, renormalised) or variational matrix (m = 6) columns are carried over the last
  ``n_tan`` periods of the *nominal* run (transient + recorded) for lanes that have not stopped
  early; a lane that stops early drops its tangent (its exponent comes from the monodromy of the
  converged cycle instead, see :mod:`geardyn.runs.points`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from geardyn.solve._kernel import locate_switches, region, run
from geardyn.solve.base import B, BACKLASH_ON, T


@njit(cache=True, parallel=True)
def run_batch(C, H, S, SEG, K, P, POLY, Y0, NTRANS, NREC, event, LIMITS, W, NTAN, renorm,
              GROWTH, STROBE, POINC, YFINAL, es_min, es_confirm, es_max_n, es_floor, es_atol, es_sep, OUT):
    """:func:`geardyn.solve._kernel.run` (no dense output) for every lane l (arrays indexed by l first),
    in parallel over lanes.

    W (L, 6, m) is updated in place; OUT (L, 5) int64 gets (status, last_period, n_events,
    transient_used, stop_period)."""
    n_lanes = C.shape[0]
    for lane in prange(n_lanes):
        st, per, nev, _, used, stop_n = run(
            C[lane], H[lane], S[lane], SEG[lane], K[lane], P[lane], POLY[lane], Y0[lane], NTRANS[lane],
            NREC[lane], event, LIMITS[lane], 1, POINC[lane], np.empty(0), np.empty((0, 6)), W[lane], NTAN[lane], renorm,
            GROWTH[lane], STROBE[lane], YFINAL[lane], es_min, es_confirm, es_max_n, es_floor, es_atol, es_sep)
        OUT[lane, 0] = st
        OUT[lane, 1] = per
        OUT[lane, 2] = nev
        OUT[lane, 3] = used
        OUT[lane, 4] = stop_n


#: Lanes stepped together by :func:`run_blocks` (one AVX-512 register of doubles).
WIDTH = 8


@njit(cache=True, inline="never")
def _vstep(A):
    """One plain RK4 step of the WIDTH lanes packed in A (rows of WIDTH: 0-12 coefficients K11 .. CM,
    13 b (0 without backlash), 14 h, 15-17 kappa and 18-20 TE at the three stage times, 21-26 the
    state, 27-32 the new state).  The expressions of :func:`geardyn.solve._kernel.rk4_step` in the
    same order; the dead zone as f = x - min(max(x, -b), b), the same bits as the branches of
    :func:`geardyn.solve._kernel.fdead`.  One buffer with constant offsets: the compiler can prove
    the lanes independent and vectorises the loop (separate arrays defeat its alias checks)."""
    for q in range(WIDTH):
        h = A[14 * WIDTH + q]
        k0 = A[15 * WIDTH + q]
        k1 = A[16 * WIDTH + q]
        k2 = A[17 * WIDTH + q]
        p0 = A[18 * WIDTH + q]
        p1 = A[19 * WIDTH + q]
        p2 = A[20 * WIDTH + q]
        cK11 = A[0 * WIDTH + q]
        cC11 = A[1 * WIDTH + q]
        cG1 = A[2 * WIDTH + q]
        cP1 = A[3 * WIDTH + q]
        cK21 = A[4 * WIDTH + q]
        cC21 = A[5 * WIDTH + q]
        cK23 = A[6 * WIDTH + q]
        cC23 = A[7 * WIDTH + q]
        cK33 = A[8 * WIDTH + q]
        cC33 = A[9 * WIDTH + q]
        cG3 = A[10 * WIDTH + q]
        cP3 = A[11 * WIDTH + q]
        cCM = A[12 * WIDTH + q]
        b = A[13 * WIDTH + q]
        x1 = A[21 * WIDTH + q]
        x2 = A[22 * WIDTH + q]
        x3 = A[23 * WIDTH + q]
        v1 = A[24 * WIDTH + q]
        v2 = A[25 * WIDTH + q]
        v3 = A[26 * WIDTH + q]
        hh2 = 0.5 * h
        # stage 1
        f = x2 - min(max(x2, -b), b)
        fm = k0 * f + cCM * v2
        a1 = cP1 - cK11 * x1 - cC11 * v1 - cG1 * fm
        a2 = p0 - cK21 * x1 - cC21 * v1 - cK23 * x3 - cC23 * v3 - fm
        a3 = cP3 - cK33 * x3 - cC33 * v3 - cG3 * fm
        X1 = x1 + hh2 * v1
        X2 = x2 + hh2 * v2
        X3 = x3 + hh2 * v3
        V1 = v1 + hh2 * a1
        V2 = v2 + hh2 * a2
        V3 = v3 + hh2 * a3
        # stage 2
        f = X2 - min(max(X2, -b), b)
        fm = k1 * f + cCM * V2
        b1 = cP1 - cK11 * X1 - cC11 * V1 - cG1 * fm
        b2 = p1 - cK21 * X1 - cC21 * V1 - cK23 * X3 - cC23 * V3 - fm
        b3 = cP3 - cK33 * X3 - cC33 * V3 - cG3 * fm
        sx1 = v1 + 2.0 * V1
        sx2 = v2 + 2.0 * V2
        sx3 = v3 + 2.0 * V3
        sv1 = a1 + 2.0 * b1
        sv2 = a2 + 2.0 * b2
        sv3 = a3 + 2.0 * b3
        W1 = v1 + hh2 * b1
        W2 = v2 + hh2 * b2
        W3 = v3 + hh2 * b3
        # stage 3
        Z1 = x1 + hh2 * V1
        Z2 = x2 + hh2 * V2
        Z3 = x3 + hh2 * V3
        f = Z2 - min(max(Z2, -b), b)
        fm = k1 * f + cCM * W2
        c1 = cP1 - cK11 * Z1 - cC11 * W1 - cG1 * fm
        c2 = p1 - cK21 * Z1 - cC21 * W1 - cK23 * Z3 - cC23 * W3 - fm
        c3 = cP3 - cK33 * Z3 - cC33 * W3 - cG3 * fm
        sx1 += 2.0 * W1
        sx2 += 2.0 * W2
        sx3 += 2.0 * W3
        sv1 += 2.0 * c1
        sv2 += 2.0 * c2
        sv3 += 2.0 * c3
        U1 = v1 + h * c1
        U2 = v2 + h * c2
        U3 = v3 + h * c3
        # stage 4
        Q1 = x1 + h * W1
        Q2 = x2 + h * W2
        Q3 = x3 + h * W3
        f = Q2 - min(max(Q2, -b), b)
        fm = k2 * f + cCM * U2
        d1 = cP1 - cK11 * Q1 - cC11 * U1 - cG1 * fm
        d2 = p2 - cK21 * Q1 - cC21 * U1 - cK23 * Q3 - cC23 * U3 - fm
        d3 = cP3 - cK33 * Q3 - cC33 * U3 - cG3 * fm
        h6 = h / 6.0
        A[27 * WIDTH + q] = x1 + h6 * (sx1 + U1)
        A[28 * WIDTH + q] = x2 + h6 * (sx2 + U2)
        A[29 * WIDTH + q] = x3 + h6 * (sx3 + U3)
        A[30 * WIDTH + q] = v1 + h6 * (sv1 + d1)
        A[31 * WIDTH + q] = v2 + h6 * (sv2 + d2)
        A[32 * WIDTH + q] = v3 + h6 * (sv3 + d3)


@njit(cache=True, inline="never")
def _vstep_tan(A):
    """:func:`_vstep` and one tangent column per lane (rows 33-38 of A -> 39-44; row 45: 1 when the
    dead zone is on), the arithmetic of :func:`geardyn.solve._kernel.tangent_step`."""
    for q in range(WIDTH):
        h = A[14 * WIDTH + q]
        k0 = A[15 * WIDTH + q]
        k1 = A[16 * WIDTH + q]
        k2 = A[17 * WIDTH + q]
        p0 = A[18 * WIDTH + q]
        p1 = A[19 * WIDTH + q]
        p2 = A[20 * WIDTH + q]
        cK11 = A[0 * WIDTH + q]
        cC11 = A[1 * WIDTH + q]
        cG1 = A[2 * WIDTH + q]
        cP1 = A[3 * WIDTH + q]
        cK21 = A[4 * WIDTH + q]
        cC21 = A[5 * WIDTH + q]
        cK23 = A[6 * WIDTH + q]
        cC23 = A[7 * WIDTH + q]
        cK33 = A[8 * WIDTH + q]
        cC33 = A[9 * WIDTH + q]
        cG3 = A[10 * WIDTH + q]
        cP3 = A[11 * WIDTH + q]
        cCM = A[12 * WIDTH + q]
        b = A[13 * WIDTH + q]
        x1 = A[21 * WIDTH + q]
        x2 = A[22 * WIDTH + q]
        x3 = A[23 * WIDTH + q]
        v1 = A[24 * WIDTH + q]
        v2 = A[25 * WIDTH + q]
        v3 = A[26 * WIDTH + q]
        hh2 = 0.5 * h
        # stage 1
        f = x2 - min(max(x2, -b), b)
        fm = k0 * f + cCM * v2
        a1 = cP1 - cK11 * x1 - cC11 * v1 - cG1 * fm
        a2 = p0 - cK21 * x1 - cC21 * v1 - cK23 * x3 - cC23 * v3 - fm
        a3 = cP3 - cK33 * x3 - cC33 * v3 - cG3 * fm
        X1 = x1 + hh2 * v1
        X2 = x2 + hh2 * v2
        X3 = x3 + hh2 * v3
        V1 = v1 + hh2 * a1
        V2 = v2 + hh2 * a2
        V3 = v3 + hh2 * a3
        # stage 2
        f = X2 - min(max(X2, -b), b)
        fm = k1 * f + cCM * V2
        b1 = cP1 - cK11 * X1 - cC11 * V1 - cG1 * fm
        b2 = p1 - cK21 * X1 - cC21 * V1 - cK23 * X3 - cC23 * V3 - fm
        b3 = cP3 - cK33 * X3 - cC33 * V3 - cG3 * fm
        sx1 = v1 + 2.0 * V1
        sx2 = v2 + 2.0 * V2
        sx3 = v3 + 2.0 * V3
        sv1 = a1 + 2.0 * b1
        sv2 = a2 + 2.0 * b2
        sv3 = a3 + 2.0 * b3
        W1 = v1 + hh2 * b1
        W2 = v2 + hh2 * b2
        W3 = v3 + hh2 * b3
        # stage 3
        Z1 = x1 + hh2 * V1
        Z2 = x2 + hh2 * V2
        Z3 = x3 + hh2 * V3
        f = Z2 - min(max(Z2, -b), b)
        fm = k1 * f + cCM * W2
        c1 = cP1 - cK11 * Z1 - cC11 * W1 - cG1 * fm
        c2 = p1 - cK21 * Z1 - cC21 * W1 - cK23 * Z3 - cC23 * W3 - fm
        c3 = cP3 - cK33 * Z3 - cC33 * W3 - cG3 * fm
        sx1 += 2.0 * W1
        sx2 += 2.0 * W2
        sx3 += 2.0 * W3
        sv1 += 2.0 * c1
        sv2 += 2.0 * c2
        sv3 += 2.0 * c3
        U1 = v1 + h * c1
        U2 = v2 + h * c2
        U3 = v3 + h * c3
        # stage 4
        Q1 = x1 + h * W1
        Q2 = x2 + h * W2
        Q3 = x3 + h * W3
        f = Q2 - min(max(Q2, -b), b)
        fm = k2 * f + cCM * U2
        d1 = cP1 - cK11 * Q1 - cC11 * U1 - cG1 * fm
        d2 = p2 - cK21 * Q1 - cC21 * U1 - cK23 * Q3 - cC23 * U3 - fm
        d3 = cP3 - cK33 * Q3 - cC33 * U3 - cG3 * fm
        h6 = h / 6.0
        A[27 * WIDTH + q] = x1 + h6 * (sx1 + U1)
        A[28 * WIDTH + q] = x2 + h6 * (sx2 + U2)
        A[29 * WIDTH + q] = x3 + h6 * (sx3 + U3)
        A[30 * WIDTH + q] = v1 + h6 * (sv1 + d1)
        A[31 * WIDTH + q] = v2 + h6 * (sv2 + d2)
        A[32 * WIDTH + q] = v3 + h6 * (sv3 + d3)
        # tangent column (rows 33-38 -> 39-44): the expressions of _kernel.tangent_step, slopes
        # kappa f'(x2) at the orbit's four stage states (the same stage values as above)
        on = A[45 * WIDTH + q]
        s1 = k0 * (1.0 if (on == 0.0 or x2 > b or x2 < -b) else 0.0)
        s2 = k1 * (1.0 if (on == 0.0 or X2 > b or X2 < -b) else 0.0)
        s3 = k1 * (1.0 if (on == 0.0 or Z2 > b or Z2 < -b) else 0.0)
        s4 = k2 * (1.0 if (on == 0.0 or Q2 > b or Q2 < -b) else 0.0)
        w0 = A[33 * WIDTH + q]
        w1 = A[34 * WIDTH + q]
        w2 = A[35 * WIDTH + q]
        w3 = A[36 * WIDTH + q]
        w4 = A[37 * WIDTH + q]
        w5 = A[38 * WIDTH + q]
        fm = s1 * w1 + cCM * w4
        A1 = -cK11 * w0 - cC11 * w3 - cG1 * fm
        A2 = -cK21 * w0 - cC21 * w3 - cK23 * w2 - cC23 * w5 - fm
        A3 = -cK33 * w2 - cC33 * w5 - cG3 * fm
        B0, B1, B2 = w0 + hh2 * w3, w1 + hh2 * w4, w2 + hh2 * w5
        B3, B4, B5 = w3 + hh2 * A1, w4 + hh2 * A2, w5 + hh2 * A3
        fm = s2 * B1 + cCM * B4
        Q1_ = -cK11 * B0 - cC11 * B3 - cG1 * fm
        Q2_ = -cK21 * B0 - cC21 * B3 - cK23 * B2 - cC23 * B5 - fm
        Q3_ = -cK33 * B2 - cC33 * B5 - cG3 * fm
        C0, C1, C2 = w0 + hh2 * B3, w1 + hh2 * B4, w2 + hh2 * B5
        C3, C4, C5 = w3 + hh2 * Q1_, w4 + hh2 * Q2_, w5 + hh2 * Q3_
        fm = s3 * C1 + cCM * C4
        R1 = -cK11 * C0 - cC11 * C3 - cG1 * fm
        R2 = -cK21 * C0 - cC21 * C3 - cK23 * C2 - cC23 * C5 - fm
        R3 = -cK33 * C2 - cC33 * C5 - cG3 * fm
        D0, D1, D2 = w0 + h * C3, w1 + h * C4, w2 + h * C5
        D3, D4, D5 = w3 + h * R1, w4 + h * R2, w5 + h * R3
        fm = s4 * D1 + cCM * D4
        S1 = -cK11 * D0 - cC11 * D3 - cG1 * fm
        S2 = -cK21 * D0 - cC21 * D3 - cK23 * D2 - cC23 * D5 - fm
        S3 = -cK33 * D2 - cC33 * D5 - cG3 * fm
        A[39 * WIDTH + q] = w0 + h6 * (w3 + 2.0 * B3 + 2.0 * C3 + D3)
        A[40 * WIDTH + q] = w1 + h6 * (w4 + 2.0 * B4 + 2.0 * C4 + D4)
        A[41 * WIDTH + q] = w2 + h6 * (w5 + 2.0 * B5 + 2.0 * C5 + D5)
        A[42 * WIDTH + q] = w3 + h6 * (A1 + 2.0 * Q1_ + 2.0 * R1 + S1)
        A[43 * WIDTH + q] = w4 + h6 * (A2 + 2.0 * Q2_ + 2.0 * R2 + S2)
        A[44 * WIDTH + q] = w5 + h6 * (A3 + 2.0 * Q3_ + 2.0 * R3 + S3)


@njit(cache=True)
def _block(C, H, S, SEG, K, P, POLY, Y0, NTRANS, NREC, lanes, event, LIMITS, POINC, YFINAL,
           es_min, es_confirm, es_max_n, es_floor, es_atol, es_sep, OUT, W, NTAN, GROWTH, STROBE):
    """Lanes ``lanes`` (<= WIDTH of them) stepped in lockstep, structure of arrays (state (6, WIDTH)):
    the plain RK4 step of every lane is one loop over the lanes that the compiler vectorises (the dead
    zone as selects, no branch); a lane whose step changed contact region is then corrected alone by
    :func:`geardyn.solve._kernel.locate_switches`.  Each lane's arithmetic is that of
    :func:`geardyn.solve._kernel.run` with no tangent (same expressions, same order), so its result is
    bit-identical."""
    nl = lanes.shape[0]
    nsteps = H.shape[1]
    Wd = WIDTH
    # structure of arrays; padding lanes repeat the first lane and are never written out
    A = np.zeros(46 * Wd)
    m = W.shape[2]
    tab = np.empty((nsteps, 7 * Wd))  # per step: rows 14-20 of A
    cc = np.empty((19, Wd))
    for q in range(Wd):
        ln = lanes[q] if q < nl else lanes[0]
        for i in range(19):
            cc[i, q] = C[ln, i]
        for i in range(13):
            A[i * Wd + q] = C[ln, i]
        A[13 * Wd + q] = C[ln, B] if C[ln, BACKLASH_ON] != 0.0 else 0.0
        for j in range(nsteps):
            tab[j, q] = H[ln, j]
            for r in range(3):
                tab[j, (1 + r) * Wd + q] = K[ln, j, r]
                tab[j, (4 + r) * Wd + q] = P[ln, j, r]
        for i in range(6):
            A[(21 + i) * Wd + q] = Y0[ln, i]
            if m > 0:
                A[(33 + i) * Wd + q] = W[ln, i, 0]
        A[45 * Wd + q] = C[ln, BACKLASH_ON]
    use_ev = np.zeros(Wd, dtype=np.bool_)
    reg = np.zeros(Wd, dtype=np.int64)
    n_tr = np.empty(Wd, dtype=np.int64)
    n_end = np.empty(Wd, dtype=np.int64)
    done = np.zeros(Wd, dtype=np.bool_)
    nev = np.zeros(Wd, dtype=np.int64)
    stop_n = np.zeros(Wd, dtype=np.int64)
    ring = np.empty((Wd, es_max_n + 1, 6))
    count = np.zeros((Wd, es_max_n + 1), dtype=np.int64)
    n_seen = np.zeros(Wd, dtype=np.int64)
    dcur = np.full(es_max_n + 1, np.inf)
    tan_start = np.zeros(Wd, dtype=np.int64)
    tan_on = np.zeros(Wd, dtype=np.bool_)
    Wa = np.empty((6, 1))
    Wb = np.empty((6, 1))
    Wt = np.empty((6, 1))
    for q in range(Wd):
        ln = lanes[q] if q < nl else lanes[0]
        use_ev[q] = event and cc[BACKLASH_ON, q] != 0.0 and cc[B, q] > 0.0
        reg[q] = region(A[22 * Wd + q], cc[B, q])
        n_tr[q] = NTRANS[ln]
        n_end[q] = NTRANS[ln] + NREC[ln]
        tan_start[q] = NTRANS[ln] + NREC[ln] - NTAN[ln]
        if q >= nl:
            done[q] = True
    y1 = np.empty(6)
    y2 = np.empty(6)
    ytmp = np.empty(6)
    W0 = np.empty((6, 0))
    per = 0
    while True:
        alive = False
        for q in range(nl):
            if not done[q]:
                alive = True
        if not alive:
            break
        any_tan = False
        for q in range(Wd):
            tan_on[q] = m > 0 and (not done[q]) and per >= tan_start[q] and stop_n[q] == 0
            any_tan = any_tan or tan_on[q]
        for j in range(nsteps):
            for i in range(7 * Wd):
                A[14 * Wd + i] = tab[j, i]
            if any_tan:
                _vstep_tan(A)
            else:
                _vstep(A)
            # contact switches, lane by lane
            for q in range(nl):
                if done[q] or not use_ev[q]:
                    continue
                b = cc[B, q]
                rnew = region(A[28 * Wd + q], b)
                if rnew != reg[q]:
                    ln = lanes[q]
                    c = (C[ln, 0], C[ln, 1], C[ln, 2], C[ln, 3], C[ln, 4], C[ln, 5], C[ln, 6], C[ln, 7], C[ln, 8],
                         C[ln, 9], C[ln, 10], C[ln, 11], C[ln, 12], C[ln, 13], C[ln, 14], C[ln, 15], C[ln, 16],
                         C[ln, 17], C[ln, 18])
                    for i in range(6):
                        y1[i] = A[(21 + i) * Wd + q]
                        y2[i] = A[(27 + i) * Wd + q]
                    if tan_on[q]:
                        for i in range(6):
                            Wa[i, 0] = A[(33 + i) * Wd + q]
                            Wb[i, 0] = A[(39 + i) * Wd + q]
                        r, nv = locate_switches(c, POLY[ln], y1, y2, Wa, Wb, 1, ytmp, Wt, H[ln, j], S[ln, j],
                                                SEG[ln, j], reg[q], rnew, b, c[T])
                        for i in range(6):
                            A[(39 + i) * Wd + q] = Wb[i, 0]
                    else:
                        r, nv = locate_switches(c, POLY[ln], y1, y2, W0, W0, 0, ytmp, W0, H[ln, j], S[ln, j],
                                                SEG[ln, j], reg[q], rnew, b, c[T])
                    reg[q] = r
                    nev[q] += nv
                    for i in range(6):
                        A[(27 + i) * Wd + q] = y2[i]
            for i in range(6 * Wd):
                A[21 * Wd + i] = A[27 * Wd + i]
            if any_tan:
                for q in range(Wd):
                    if tan_on[q]:
                        for i in range(6):
                            A[(33 + i) * Wd + q] = A[(39 + i) * Wd + q]
        # end of mesh period `per`: divergence, record, early stop
        for q in range(nl):
            if done[q]:
                continue
            ln = lanes[q]
            bad = False
            for i in range(6):
                if not (abs(A[(21 + i) * Wd + q]) <= LIMITS[ln, i]):
                    bad = True
            if bad:
                for i in range(6):
                    YFINAL[ln, i] = A[(21 + i) * Wd + q]
                    A[(21 + i) * Wd + q] = 0.0  # keep the idle lane finite
                OUT[ln, 0] = 1
                OUT[ln, 1] = per
                OUT[ln, 2] = nev[q]
                OUT[ln, 3] = min(per + 1, n_tr[q])
                OUT[ln, 4] = stop_n[q]
                done[q] = True
                continue
            if tan_on[q]:
                nrm = 0.0
                for i in range(6):
                    nrm += A[(33 + i) * Wd + q] * A[(33 + i) * Wd + q]
                nrm = math.sqrt(nrm)
                GROWTH[ln, per - tan_start[q]] = math.log(nrm) if nrm > 0.0 else -np.inf
                STROBE[ln, per - tan_start[q]] = A[22 * Wd + q]
                for i in range(6):
                    A[(33 + i) * Wd + q] /= nrm
            if per >= n_tr[q]:
                for i in range(6):
                    POINC[ln, per - n_tr[q], i] = A[(21 + i) * Wd + q]
            elif es_confirm > 0:
                slot = n_seen[q] % (es_max_n + 1)
                scale = 1.0
                for i in range(6):
                    ring[q, slot, i] = A[(21 + i) * Wd + q]
                    scale = max(scale, abs(A[(21 + i) * Wd + q]))
                tol = max(es_atol * scale, es_floor)
                n_seen[q] += 1
                for n in range(1, es_max_n + 1):
                    dcur[n] = np.inf
                    if n < n_seen[q]:
                        old = (n_seen[q] - 1 - n) % (es_max_n + 1)
                        d = 0.0
                        for i in range(6):
                            d = max(d, abs(A[(21 + i) * Wd + q] - ring[q, old, i]))
                        dcur[n] = d
                        count[q, n] = count[q, n] + 1 if d <= tol else 0
                if per + 1 >= es_min and per + 1 < n_tr[q]:
                    dmin = np.inf
                    for n in range(1, es_max_n + 1):
                        if count[q, n] >= es_confirm and dmin > es_sep * tol:
                            stop_n[q] = n
                            n_end[q] = per + 1 + (n_end[q] - n_tr[q])
                            n_tr[q] = per + 1
                            break
                        dmin = min(dmin, dcur[n])
            if per + 1 >= n_end[q]:
                for i in range(6):
                    YFINAL[ln, i] = A[(21 + i) * Wd + q]
                OUT[ln, 0] = 0
                OUT[ln, 1] = n_end[q]
                OUT[ln, 2] = nev[q]
                OUT[ln, 3] = n_tr[q]
                OUT[ln, 4] = stop_n[q]
                done[q] = True
        per += 1


@njit(cache=True, parallel=True)
def run_blocks(C, H, S, SEG, K, P, POLY, Y0, NTRANS, NREC, event, LIMITS, POINC, YFINAL,
               es_min, es_confirm, es_max_n, es_floor, es_atol, es_sep, OUT, W, NTAN, GROWTH, STROBE):
    """:func:`geardyn.solve._kernel.run` (no tangent, or one renormalised tangent column: W (L, 6, 0 or 1)) for every lane,
    WIDTH lanes in lockstep per block
    (:func:`_block`), blocks in parallel.  Blocks are consecutive lanes; results do not depend on it."""
    n_lanes = C.shape[0]
    n_blocks = (n_lanes + WIDTH - 1) // WIDTH
    for blk in prange(n_blocks):
        lanes = np.arange(blk * WIDTH, min(n_lanes, (blk + 1) * WIDTH))
        _block(C, H, S, SEG, K, P, POLY, Y0, NTRANS, NREC, lanes, event, LIMITS, POINC, YFINAL,
               es_min, es_confirm, es_max_n, es_floor, es_atol, es_sep, OUT, W, NTAN, GROWTH, STROBE)


@njit(cache=True)
def fill_tables(lane, eps, period, te, phi, poly, n, H, S, SEG, K, P):
    """The aligned step tables of :func:`geardyn.solve.simulate.step_tables` for one lane, written
    into row ``lane`` of H, S, SEG, K, P (the same operations in the same order: the same bits)."""
    e1 = eps - math.floor(eps)
    if e1 == 0.0:  # integer contact ratio: one zone
        for k in range(n):
            S[lane, k] = k / n
            SEG[lane, k] = 1
    else:
        n1 = min(max(1, int(round(n * e1))), n - 1)
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


@njit(cache=True)
def strict_periods(POINC, npts, max_n, atol, rtol, floor_tol, separation, OUT):
    """:func:`geardyn.classify.strict_period` for every lane l on POINC[l, :npts[l]] (rows without NaN
    assumed), compiled: the same max / peak-to-peak / comparison operations, so the same n.  Also writes
    the tolerance of :func:`geardyn.classify._tolerance` (OUT[l, 1])."""
    for lane in range(POINC.shape[0]):
        m = npts[lane]
        OUT[lane, 0] = 0.0
        OUT[lane, 1] = np.nan
        if m < 3:
            continue
        size = 0.0
        scale = 0.0
        for i in range(POINC.shape[2]):
            lo = POINC[lane, 0, i]
            hi = lo
            for k in range(m):
                v = POINC[lane, k, i]
                lo = min(lo, v)
                hi = max(hi, v)
                scale = max(scale, abs(v))
            size = max(size, hi - lo)
        scale = max(scale, 1.0)
        tol = max(atol * scale + rtol * size, floor_tol)
        OUT[lane, 1] = tol
        dmin = np.inf
        for n in range(1, min(max_n, m - 1) + 1):
            dn = 0.0
            for k in range(m - n):
                for i in range(POINC.shape[2]):
                    dn = max(dn, abs(POINC[lane, k + n, i] - POINC[lane, k, i]))
            if dn <= tol and dmin > separation * tol:
                OUT[lane, 0] = n
                break
            dmin = min(dmin, dn)
