"""Compiled inner loops of two indicators (private; use the public functions):
:func:`geardyn.classify.zero_one_test` and :func:`geardyn.classify.falling_return_distances`.

They release the GIL, so the classification of many points in threads
(the labeller's last stage, :mod:`geardyn.label`) runs on both cores.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def correlations(x: np.ndarray, cs: np.ndarray, ncut: int) -> np.ndarray:
    """K_c for each frequency c of ``cs``: the correlation of the mean-square displacement D_c(n),
    n = 1 .. ``ncut``, with n, for the (mean-removed) series ``x`` (translation variables
    p_c(j) = sum_{i <= j} x_i cos(c i), q_c likewise with sin; 0 when D_c is constant)."""
    n_pts = x.size
    ns_mean = 0.5 * (ncut + 1)
    nn2 = 0.0
    for n in range(1, ncut + 1):
        nn2 += (n - ns_mean) ** 2
    p = np.empty(n_pts)
    q = np.empty(n_pts)
    d = np.empty(ncut)
    out = np.empty(cs.size)
    for ic in range(cs.size):
        c = cs[ic]
        sp = 0.0
        sq = 0.0
        for j in range(n_pts):
            a = c * (j + 1)
            sp += x[j] * math.cos(a)
            sq += x[j] * math.sin(a)
            p[j] = sp
            q[j] = sq
        dmean = 0.0
        for n in range(1, ncut + 1):
            s = 0.0
            for k in range(n_pts - n):
                dp = p[k + n] - p[k]
                dq = q[k + n] - q[k]
                s += dp * dp + dq * dq
            d[n - 1] = s / (n_pts - n)
            dmean += d[n - 1]
        dmean /= ncut
        sdd = 0.0
        sdn = 0.0
        for n in range(1, ncut + 1):
            dn = d[n - 1] - dmean
            sdd += dn * dn
            sdn += dn * (n - ns_mean)
        den = math.sqrt(sdd * nn2)
        out[ic] = sdn / den if den > 0.0 else 0.0
    return out


@njit(cache=True, nogil=True)
def falling(p: np.ndarray, max_n: int, factor: float) -> np.ndarray:
    """For n = 1 .. ``max_n`` (entry n - 1): whether the return distance d_n(k) = max_i |p_k+n,i - p_k,i|
    of the rows of ``p`` (finite) falls: mean of its last quarter < ``factor`` x mean of its first
    quarter (quarter: max(2, len // 4) values); True when there are fewer than n + 8 rows."""
    m = p.shape[0]
    out = np.ones(max_n, dtype=np.bool_)
    for n in range(1, min(max_n, m - 8) + 1):
        size = m - n
        q = max(2, size // 4)
        first = 0.0
        last = 0.0
        for k in range(size):
            if k >= q and k < size - q:
                continue
            d = 0.0
            for i in range(p.shape[1]):
                d = max(d, abs(p[k + n, i] - p[k, i]))
            if k < q:
                first += d
            if k >= size - q:
                last += d
        out[n - 1] = last / q < factor * (first / q)
    return out
