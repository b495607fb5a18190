"""Configuration of a sweep's orbits (:class:`OrbitSpec`, one ``orbits:`` entry) and the seeds
of its branches, read from the sweep's cube."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from geardyn import classify
from geardyn.config import settings_from
from geardyn.runs.continuation.corrector import ContinuationSettings
from geardyn.runs.cube import STATES


@dataclass(frozen=True)
class OrbitSpec:
    """One ``orbits:`` entry of the configuration (keyed by the sweep it continues; its keys in the config
    schema): ``nodes`` the coefficient interpolation nodes of :class:`~geardyn.runs.continuation.KHVFamily`,
    ``continuation`` the :class:`ContinuationSettings`, ``attractors`` the mapping for
    :mod:`geardyn.runs.attractors`."""

    max_period: int = 6
    max_seeds: int = 6
    nodes: int = 101
    continuation: ContinuationSettings = ContinuationSettings()
    attractors: tuple[tuple[str, Any], ...] = ()
    switch_period_doubling: bool = True

    @classmethod
    def from_config(cls, spec: Mapping[str, Any] | None) -> OrbitSpec:
        values = {k: v for k, v in (spec or {}).items() if k != "designs"}
        values["continuation"] = ContinuationSettings.from_mapping(values.get("continuation"))
        values["attractors"] = tuple(sorted((values.get("attractors") or {}).items()))
        return settings_from(cls, values, "orbits settings")


def final_state(cube: Any, case: int, j: int) -> np.ndarray:
    """The last Poincare point of sweep point j of ``case`` (first direction of the cube)."""
    return np.array([float(cube[v].values[case, 0, j, -1]) for v in STATES])


def seeds_from_cube(cube: Any, case: int, max_period: int, max_seeds: int) -> list[tuple[float, np.ndarray, int]]:
    """(p, final state, n) at the middle of each run of equal label P1..P<max_period> along the sweep
    (first direction of the cube), longest runs first, at most ``max_seeds``."""
    par = cube.attrs["control_parameter"]
    values = np.asarray(cube[par].values, dtype=float)
    seeds = []
    for j, n in run_middles(np.asarray(cube["label"].values[case, 0], dtype=int), max_period)[:max_seeds]:
        x = final_state(cube, case, j)
        if np.all(np.isfinite(x)):
            seeds.append((float(values[j]), x, n))
    return seeds


def run_middles(labels: np.ndarray, max_period: int) -> list[tuple[int, int]]:
    """(middle index, n) of every run of equal label P1..P<max_period>, longest runs first."""
    runs = [
        (int(last) - int(first) + 1, int(first), n)
        for first, last, n in classify.bands(np.arange(labels.size), labels)
        if 1 <= n <= max_period
    ]
    return [(first + length // 2, n) for length, first, n in sorted(runs, key=lambda r: (-r[0], r[1]))]
