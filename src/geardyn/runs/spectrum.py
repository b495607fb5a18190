"""The amplitude spectrum of a point run's X_VH and its highest peaks, what the point figures and the
paper's "peaks" claims read (docs/classify.md)."""

from __future__ import annotations

import numpy as np

from geardyn import libm


def amplitude_spectrum(x: np.ndarray, samples_per_period: int) -> tuple[np.ndarray, np.ndarray]:
    """One-sided amplitude spectrum of a uniformly sampled signal (mean removed, Hann window), frequencies in
    multiples of the mesh frequency, amplitudes corrected for the window's coherent gain (a sine of amplitude A: A)."""
    x = np.asarray(x, dtype=float)
    n = x.size
    window = np.hanning(n)
    amp = 2.0 * libm.cabs(np.fft.rfft((x - x.mean()) * window)) / window.sum()
    return np.fft.rfftfreq(n, d=1.0 / samples_per_period), amp


def local_maxima(x: np.ndarray) -> np.ndarray:
    """Indices of the local maxima of a 1-D array, as ``scipy.signal.find_peaks(x)`` returns them (a value
    above both neighbours; a flat top above both of its neighbours counts once, at its middle, rounded down;
    the ends never count).  Without ``scipy.signal``, whose import (0.6-0.9 CPU-s: it parses its functions'
    docstrings) would be most of a point figure's start-up."""
    x = np.asarray(x)
    if x.size < 3:
        return np.zeros(0, dtype=np.intp)
    start = np.flatnonzero(np.r_[True, x[1:] != x[:-1]])  # the first index of each run of equal values
    end = np.r_[start[1:] - 1, x.size - 1]  # and its last
    inner = (start > 0) & (end < x.size - 1)
    start, end = start[inner], end[inner]
    top = (x[start - 1] < x[start]) & (x[end + 1] < x[start])
    return (start[top] + end[top]) // 2


def spectral_peaks(freq, amp, n: int = 5, fmax: float = 3.0) -> list[float]:
    """The ``n`` highest local maxima of a spectrum below ``fmax`` (>= 2 % of the largest), by height."""

    keep = (freq > 0.02) & (freq <= fmax)
    if keep.sum() < 3:
        return []
    f, a = freq[keep], amp[keep]
    idx = local_maxima(a)
    idx = idx[a[idx] >= 0.02 * a.max()]
    return [float(f[i]) for i in idx[np.argsort(-a[idx], kind="stable")[:n]]]  # ties: the lower frequency first
