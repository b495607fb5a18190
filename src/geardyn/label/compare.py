"""Whether two verdicts (or two runs) describe the same attractor: cycles by Hausdorff distance,
other attractors by centroids and bounding boxes (tolerances: ``docs/classify.md``)."""

from __future__ import annotations

import numpy as np

import geardyn.label.vocabulary as vocabulary
from geardyn.label.policy import Same
from geardyn.label.verdict import Verdict


def hausdorff(a: np.ndarray, b: np.ndarray) -> float:
    """Symmetric Hausdorff distance of two point sets (max norm over the states)."""
    return max(directed_distance(a, b), directed_distance(b, a))


def nearest_distances(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The distance (max norm over the states) from each point of ``a`` (k x d, or one point) to the nearest
    point of ``b`` (n x d)."""
    return np.max(np.abs(np.atleast_2d(a)[:, None, :] - b[None, :, :]), axis=2).min(axis=1)


def directed_distance(a: np.ndarray, b: np.ndarray) -> float:
    """The largest distance (max norm over the states) from a point of ``a`` to the nearest point of ``b``:
    0 when every point of ``a`` lies on ``b``."""
    return float(nearest_distances(a, b).max())


def least_period(cycle: np.ndarray, tol: float) -> int:
    """The least m dividing n such that point m of the n points of a closed cycle (n x d, one mesh period
    apart) returns to its point 0 within ``tol`` in the max norm; n if none."""
    n = cycle.shape[0]
    for m in range(1, n):
        if n % m == 0 and float(np.max(np.abs(cycle[m] - cycle[0]))) <= tol:
            return m
    return n


def same_attractor(
    label_a: int,
    pa: np.ndarray,
    label_b: int,
    pb: np.ndarray,
    tol: Same = Same(),
) -> bool:
    """Same label and Poincare sets within the tolerances ``tol`` (``docs/classify.md``).  ``pa``, ``pb``: for a
    periodic label, one cycle (its n points)."""
    if label_a != label_b:
        return False
    if label_a == vocabulary.LABELS["diverged"]:
        return True
    if pa.shape[0] == 0 or pb.shape[0] == 0:
        return False
    size = max(float(np.max(np.ptp(pa, axis=0))), float(np.max(np.ptp(pb, axis=0))))
    if label_a >= 1:
        return hausdorff(pa, pb) <= tol.distance_tol * max(1.0, size)
    # a Hausdorff distance of two samples of a cloud is sampling noise: compare centroids and bounding boxes
    cloud = tol.chaotic_distance_tol * max(1.0, size)
    box = max(float(np.max(np.abs(pa.min(0) - pb.min(0)))), float(np.max(np.abs(pa.max(0) - pb.max(0)))))
    return float(np.max(np.abs(pa.mean(0) - pb.mean(0)))) <= cloud and box <= cloud


def attractor_points(v: Verdict) -> np.ndarray:
    """The points that stand for a verdict's attractor: one cycle of a periodic one, else its record."""
    p = v.poincare[np.all(np.isfinite(v.poincare), axis=1)]
    return p[: v.period] if v.period > 0 else p


def same(a: Verdict, b: Verdict, tol: Same = Same()) -> bool:
    """Whether two verdicts at one point describe the same attractor."""
    return same_attractor(a.label, attractor_points(a), b.label, attractor_points(b), tol)
