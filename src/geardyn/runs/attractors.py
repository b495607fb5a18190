"""Coexisting attractors at single operating points: several starts, one label each, deduplicated.

At one point (design + overrides) the motion is integrated from

* ``static``: the static deflection (what a sweep without continuation starts from),
* ``up`` / ``down``: the final states of the neighbouring sweep points (what a sweep continued
  upwards or downwards would start from), when given,
* ``orbit_k``: the stable periodic orbits of the continued branches at that point, when given,
* ``random_k``: ``n_random`` states drawn uniformly (numpy ``default_rng(seed)``) from the box
  static state +- (``box_x`` for the three displacements, ``box_v`` for the three velocities),
  in units of b_c.

Each run is labelled by :func:`geardyn.runs.points.analyse_point` (cheap path).  Two runs reached
the same attractor when their labels agree and their Poincaré sets lie within ``distance_tol``
of each other (symmetric Hausdorff distance, max norm) relative to max(1, size), where size is the
largest extent of the two sets (so two points of one periodic orbit at 1e-8 agree, two distinct
P1 orbits do not).  The basin fraction of an attractor is the share of the *random* starts that
reach it (a Monte-Carlo estimate over the box; with ``n_random`` starts its standard error is about
sqrt(f (1 - f) / n_random)).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from geardyn import classify
from geardyn.runs.points import analyse_point
from geardyn.solve.base import SimulationSettings, System


@dataclass(frozen=True)
class AttractorSettings:
    """Starts and tolerances of :func:`find_attractors` (lengths in units of b_c)."""

    n_random: int = 8
    seed: int = 0
    box_x: float = 20.0
    box_v: float = 20.0
    transient_periods: int = 1000
    recorded_periods: int = 100
    distance_tol: float = 1e-3
    chaotic_distance_tol: float = 0.2

    @classmethod
    def from_mapping(cls, spec: Mapping[str, Any] | None) -> AttractorSettings:
        spec = dict(spec or {})
        names = {f.name for f in dataclasses.fields(cls)}
        unknown = set(spec) - names
        if unknown:
            raise ValueError(f"unknown attractor settings {sorted(unknown)}; allowed: {sorted(names)}")
        return cls(**spec)


@dataclass
class Attractor:
    """One attractor: label (classify codes), Poincaré points of the first run that reached it,
    centroid and size of those points, the starts that reached it."""

    label: int
    poincare: np.ndarray
    lyapunov: float
    starts: list[str] = field(default_factory=list)

    @property
    def centroid(self) -> np.ndarray:
        return np.mean(self.poincare, axis=0) if self.poincare.size else np.full(6, np.nan)

    @property
    def size(self) -> float:
        return float(np.max(np.ptp(self.poincare, axis=0))) if self.poincare.shape[0] > 1 else 0.0

    @property
    def n_random(self) -> int:
        return sum(s.startswith("random") for s in self.starts)


def random_starts(system: System, settings: AttractorSettings) -> dict[str, np.ndarray]:
    """``n_random`` states uniformly in the box around the static state (reproducible)."""
    rng = np.random.default_rng(settings.seed)
    centre = system.static_state()
    half = np.array([settings.box_x] * 3 + [settings.box_v] * 3)
    return {f"random_{k}": centre + rng.uniform(-1.0, 1.0, 6) * half for k in range(settings.n_random)}


def hausdorff(a: np.ndarray, b: np.ndarray) -> float:
    """Symmetric Hausdorff distance of two point sets (max norm over the states)."""
    d = np.max(np.abs(a[:, None, :] - b[None, :, :]), axis=2)
    return float(max(d.min(axis=1).max(), d.min(axis=0).max()))


def same_attractor(label_a: int, pa: np.ndarray, label_b: int, pb: np.ndarray, settings: AttractorSettings) -> bool:
    """Same label and Poincaré sets within the tolerance (see the module doc)."""
    if label_a != label_b:
        return False
    if label_a == classify.LABELS["diverged"]:
        return True
    if pa.shape[0] == 0 or pb.shape[0] == 0:
        return False
    size = max(float(np.max(np.ptp(pa, axis=0))), float(np.max(np.ptp(pb, axis=0))))
    tol = settings.distance_tol if label_a >= 1 else settings.chaotic_distance_tol
    return hausdorff(pa, pb) <= tol * max(1.0, size)


def find_attractors(system: System, starts: Mapping[str, np.ndarray], settings: AttractorSettings,
                    integration: SimulationSettings,
                    classifier: classify.ClassifierSettings = classify.ClassifierSettings()
                    ) -> tuple[list[Attractor], dict[str, int]]:
    """Integrate from every start, label, deduplicate.  Returns (attractors, start -> attractor index)."""
    sim = dataclasses.replace(integration, transient_periods=settings.transient_periods,
                              recorded_periods=settings.recorded_periods)
    found: list[Attractor] = []
    where: dict[str, int] = {}
    for name, x0 in starts.items():
        res, lab = analyse_point(system, sim, classifier, x0=np.asarray(x0, dtype=float), cheap=True)
        p = res.poincare[~np.isnan(res.poincare).any(axis=1)]
        if lab.label >= 1:
            p = p[-lab.label:]  # one cycle is the whole periodic attractor
        for k, att in enumerate(found):
            if same_attractor(att.label, att.poincare, lab.label, p, settings):
                att.starts.append(name)
                where[name] = k
                break
        else:
            found.append(Attractor(int(lab.label), p, float(lab.lyapunov), [name]))
            where[name] = len(found) - 1
    return found, where


def basin_fractions(attractors: Sequence[Attractor], n_random: int) -> np.ndarray:
    """Share of the random starts that reached each attractor (NaN without random starts)."""
    if n_random <= 0:
        return np.full(len(attractors), np.nan)
    return np.array([a.n_random / n_random for a in attractors], dtype=float)
