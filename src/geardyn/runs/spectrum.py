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


def spectral_peaks(freq, amp, n: int = 5, fmax: float = 3.0) -> list[float]:
    """The ``n`` highest local maxima of a spectrum below ``fmax`` (>= 2 % of the largest), by height."""

    keep = (freq > 0.02) & (freq <= fmax)
    if keep.sum() < 3:
        return []
    f, a = freq[keep], amp[keep]
    from scipy.signal import find_peaks  # noqa: PLC0415 - 0.3 s to import: only the captions with spectra

    idx, _ = find_peaks(a, height=0.02 * a.max())
    return [float(f[i]) for i in idx[np.argsort(-a[idx], kind="stable")[:n]]]  # ties: the lower frequency first
