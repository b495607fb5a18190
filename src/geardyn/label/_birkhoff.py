"""The compiled loops of the torus test (:mod:`geardyn.label.torus`): standardised coordinates, centred
and scaled observables, weighted averages over windows, in index order, no fast-math (why:
``docs/classify.md``).  Private to :mod:`geardyn.label.torus`."""

from __future__ import annotations

import numba as nb
import numpy as np

from geardyn.label.indicators import CONSTANT_SPREAD, FLAT_COMPONENT


@nb.njit(cache=True)
def _mean_std(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Column means and population standard deviations of the (m, d) array ``p``."""
    m, d = p.shape
    mean = np.zeros(d)
    for i in range(m):
        for j in range(d):
            mean[j] += p[i, j]
    for j in range(d):
        mean[j] /= m
    var = np.zeros(d)
    for i in range(m):
        for j in range(d):
            t = p[i, j] - mean[j]
            var[j] += t * t
    return mean, np.sqrt(var / m)


@nb.njit(cache=True)
def standardised(p: np.ndarray) -> np.ndarray:
    """(p - mean) / std per column of the (m, d) points; 0 in a column whose spread is below 1e-12 of its
    magnitude max(1, max |p|)."""
    m, d = p.shape
    mean, s = _mean_std(p)
    z = np.zeros((m, d))
    for j in range(d):
        big = 1.0
        for i in range(m):
            big = max(big, abs(p[i, j]))
        if s[j] > CONSTANT_SPREAD * big:
            for i in range(m):
                z[i, j] = (p[i, j] - mean[j]) / s[j]
    return z


@nb.njit(cache=True)
def scaled(f: np.ndarray, points: np.ndarray) -> np.ndarray:
    """The (m, k) observed values ``f`` of the (m, d) ``points``, centred and divided by their standard
    deviations, without the components whose spread is below 1e-9 of the largest: (m, k') values; (m, 0)
    when the points do not vary (to 1e-12 of their magnitude max(1, max |points|)) or ``f`` does not."""
    m, k = f.shape
    mag = 1.0
    for i in range(points.shape[0]):
        for j in range(points.shape[1]):
            mag = max(mag, abs(points[i, j]))
    _, sp = _mean_std(points)
    mean, s = _mean_std(f)
    top = 0.0
    for j in range(k):
        top = max(top, s[j])
    if sp.max() <= CONSTANT_SPREAD * mag or top == 0.0:
        return np.zeros((m, 0))
    keep = np.nonzero(s > FLAT_COMPONENT * top)[0]
    out = np.empty((m, keep.size))
    for i in range(m):
        for c in range(keep.size):
            j = keep[c]
            out[i, c] = (f[i, j] - mean[j]) / s[j]
    return out


@nb.njit(cache=True)
def averages(f: np.ndarray, w: np.ndarray, starts: np.ndarray) -> np.ndarray:
    """Weighted averages sum_i w_i f[s + i, :] of the (m, k) values over the windows [s, s + len(w)) of
    ``starts``: (len(starts), k)."""
    n, k = w.size, f.shape[1]
    out = np.zeros((starts.size, k))
    for r in range(starts.size):
        s = starts[r]
        for i in range(n):
            for j in range(k):
                out[r, j] += w[i] * f[s + i, j]
    return out
