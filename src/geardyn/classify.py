"""Labels for steady motions from their Poincaré points (period-n, or not periodic).

A sequence of Poincaré points p_0, p_1, ... (one per mesh period) is period-n when
p_{k+n} = p_k for all k, to a tolerance scaled to the attractor size and kept above the
integration error.  The smallest such n (up to ``max_n``) is the period.
"""

from __future__ import annotations

import numpy as np

#: Label codes stored in cubes (``flag_values``/``flag_meanings``).
LABELS = {"diverged": -2, "undetermined": -1, "not_periodic": 0}


def _return_distances(p: np.ndarray, n: int) -> np.ndarray:
    """max over states of |p_{k+n} - p_k| for each k."""
    return np.max(np.abs(p[n:] - p[:-n]), axis=1)


def poincare_period(points: np.ndarray, *, max_n: int = 12, rtol: float = 1e-4, atol: float = 1e-6,
                    converging: bool = True) -> int:
    """Smallest n <= max_n with |p_{k+n} - p_k| <= tol for every k; 0 if none; -1 if too few points.

    ``points``: (n_sections, n_states) with NaN rows for missing sections.  The tolerance is
    ``atol * max(|p|, 1) + rtol * size`` with ``size`` the largest spread of any state over the
    points, so it scales with the attractor and does not depend on the units.

    With ``converging`` a sequence whose return distance for some n falls geometrically (the last
    quarter at most 1/4 of the first quarter, and falling in each quarter) also counts as period-n:
    the weakly damped shaft mode of the KHV model leaves such slowly decaying transients after the
    paper's 500 discarded periods.  Quasi-periodic and chaotic motion show no such decay.
    """
    p = np.asarray(points, dtype=float)
    if p.ndim == 1:
        p = p[:, None]
    p = p[~np.isnan(p).any(axis=1)]
    if p.shape[0] < 3:
        return -1
    size = float(np.max(np.ptp(p, axis=0)))
    scale = max(float(np.max(np.abs(p))), 1.0)
    tol = atol * scale + rtol * size
    for n in range(1, max_n + 1):
        if p.shape[0] <= n:
            return -1
        if np.max(_return_distances(p, n)) <= tol:
            return n
    if converging:
        for n in range(1, max_n + 1):
            d = _return_distances(p, n)
            if d.size < 8:
                break
            quarters = [float(np.max(q)) for q in np.array_split(d, 4)]
            falling = all(b < a for a, b in zip(quarters, quarters[1:], strict=False))
            if falling and quarters[-1] <= 0.25 * quarters[0]:
                return n
    return 0


def periods_of_cube(cube, *, max_n: int = 12, rtol: float = 1e-4) -> np.ndarray:
    """:func:`poincare_period` for every point of a sweep cube: array (case, direction, parameter).

    -2 marks diverged points.
    """
    from geardyn.sweep import STATES

    stacked = np.stack([cube[name].values for name in STATES], axis=-1)  # (..., section, state)
    out = np.empty(stacked.shape[:3], dtype=np.int16)
    for idx in np.ndindex(out.shape):
        if int(cube["diverged"].values[idx]) == 1:
            out[idx] = LABELS["diverged"]
        else:
            out[idx] = poincare_period(stacked[idx], max_n=max_n, rtol=rtol)
    return out


def bands(values: np.ndarray, labels: np.ndarray) -> list[tuple[float, float, int]]:
    """Runs of equal labels along a sweep as (first value, last value, label)."""
    out: list[tuple[float, float, int]] = []
    start = 0
    for i in range(1, len(labels) + 1):
        if i == len(labels) or labels[i] != labels[start]:
            out.append((float(values[start]), float(values[i - 1]), int(labels[start])))
            start = i
    return out


def label_name(n: int) -> str:
    if n == LABELS["diverged"]:
        return "diverged"
    if n == LABELS["undetermined"]:
        return "undetermined"
    if n == 0:
        return "not periodic (QP or chaos)"
    return f"P{n}"
