"""Rule 3 of the classifier, stated once, compiled: the strict period test of Poincaré points and the
early stop of the transient that applies it while the run goes on.  Private to :mod:`geardyn.solve`
(the rule: ``docs/classify.md``; the early stop: ``docs/numerics.md``)."""

from __future__ import annotations

import numpy as np
from numba import njit

import geardyn.solve._cache as _cache

_cache.renew_once()  # before the loops: numba's cache renewed when any kernel source changed


@njit(cache=True)
def first_period(d, hits, need, max_n, distinct):
    """Rule 3: the smallest n in 1 .. max_n with hits[n] >= need whose return distances d[m], m < n,
    all exceed ``distinct`` (= separation * tol); 0 if none.  d, hits: (max_n + 1,), entry 0 unused."""
    dmin = np.inf
    for n in range(1, max_n + 1):
        if hits[n] >= need and dmin > distinct:
            return n
        dmin = min(dmin, d[n])
    return 0


@njit(cache=True)
def tolerance(p, m, atol, rtol, floor_tol):
    """Return-distance tolerance of the points p[:m] (m >= 1): max(atol max(|p|, 1) + rtol size,
    floor_tol) with size the largest peak-to-peak range of a state (``tests/_oracle.py``, ``tolerance``)."""
    size = 0.0
    scale = 0.0
    for i in range(p.shape[1]):
        lo = p[0, i]
        hi = lo
        for k in range(m):
            v = p[k, i]
            lo = min(lo, v)
            hi = max(hi, v)
            scale = max(scale, abs(v))
        size = max(size, hi - lo)
    scale = max(scale, 1.0)
    return max(atol * scale + rtol * size, floor_tol)


@njit(cache=True)
def strict_period(p, m, max_n, atol, rtol, floor_tol, separation):
    """Rule 3 on the points p[:m] (no NaN): (period n or 0, tolerance); (0, nan) for m = 0."""
    if m == 0:
        return 0, np.nan
    tol = tolerance(p, m, atol, rtol, floor_tol)
    distinct = separation * tol
    # d_n is wanted only as far as rule 3 compares it (with tol and with distinct): its sum stops beyond both
    cap = max(tol, distinct)
    d = np.full(max_n + 1, np.inf)
    hits = np.zeros(max_n + 1, dtype=np.int64)
    for n in range(1, min(max_n, m - 1) + 1):
        dn = 0.0
        for k in range(m - n):
            for i in range(p.shape[1]):
                dn = max(dn, abs(p[k + n, i] - p[k, i]))
            if dn > cap:
                break
        d[n] = dn
        hits[n] = 1 if dn <= tol else 0
        if dn <= distinct:  # no larger n has distinct cycle points: rule 3 is decided
            break
    return first_period(d, hits, 1, max_n, distinct), tol


@njit(cache=True)
def strict_periods(POINC, npts, max_n, atol, rtol, floor_tol, separation, OUT):
    """:func:`strict_period` for every lane l on POINC[l, :npts[l]] (rows without NaN assumed);
    OUT[l] = (n, tol), (0, nan) for fewer than 3 points (rule 2 of the classifier)."""
    for lane in range(POINC.shape[0]):
        OUT[lane, 0] = 0.0
        OUT[lane, 1] = np.nan
        if npts[lane] >= 3:
            n, tol = strict_period(POINC[lane], npts[lane], max_n, atol, rtol, floor_tol, separation)
            OUT[lane, 0] = n
            OUT[lane, 1] = tol


@njit(cache=True)
def early_stop(ring, count, dcur, n_seen, y, es, check):
    """Feed the Poincaré point y of a transient period to the running record (ring, counts, current distances)
    and, with ``check``, apply rule 3 to the counts; returns (n_seen + 1, n), n the period at which the
    transient may stop, 0 if none (``docs/numerics.md``)."""
    confirm, max_n, floor_tol, atol, separation = es[1], es[2], es[3], es[4], es[5]
    slot = n_seen % (max_n + 1)
    scale = 1.0
    for i in range(6):
        ring[slot, i] = y[i]
        scale = max(scale, abs(y[i]))
    tol = max(atol * scale, floor_tol)
    n_seen += 1
    for n in range(1, max_n + 1):
        dcur[n] = np.inf
        if n < n_seen:
            old = (n_seen - 1 - n) % (max_n + 1)
            d = 0.0
            for i in range(6):
                d = max(d, abs(y[i] - ring[old, i]))
            dcur[n] = d
            count[n] = count[n] + 1 if d <= tol else 0
    if not check:
        return n_seen, 0
    return n_seen, first_period(dcur, count, confirm, max_n, separation * tol)
