"""The search space of a calibration: the unknowns, their bounds and scales, the unit cube and moves in it."""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from geardyn.jsontypes import Json


@dataclass(frozen=True)
class Unknown:
    """One searched unknown: an override name (``w`` or a KHVParameters field, SI), its bounds and
    whether it is searched on a log scale."""

    name: str
    low: float
    high: float
    log: bool = False

    def from_unit(self, u: float) -> float:
        if self.log:
            return float(math.exp(math.log(self.low) + u * (math.log(self.high) - math.log(self.low))))
        return float(self.low + u * (self.high - self.low))

    def to_unit(self, v: float) -> float:
        if self.log:
            return (math.log(v) - math.log(self.low)) / (math.log(self.high) - math.log(self.low))
        return (v - self.low) / (self.high - self.low)


@dataclass(frozen=True)
class SearchSpace:
    unknowns: tuple[Unknown, ...]

    @classmethod
    def from_config(cls, bounds: Mapping[str, Mapping[str, Json]]) -> SearchSpace:
        out = []
        for name, b in bounds.items():
            lo, hi = float(b["low"]), float(b["high"])
            if not lo < hi:
                raise ValueError(f"calibration bound of {name}: low {lo} must be below high {hi}")
            log = b.get("scale", "linear") == "log"
            if log and lo <= 0:
                raise ValueError(f"calibration bound of {name}: a log scale needs low > 0")
            out.append(Unknown(name, lo, hi, log))
        return cls(tuple(out))

    @property
    def names(self) -> list[str]:
        return [u.name for u in self.unknowns]

    def values(self, unit: Sequence[float]) -> dict[str, float]:
        """Overrides of a candidate given in the unit cube (each coordinate in [0, 1])."""
        return {u.name: u.from_unit(float(x)) for u, x in zip(self.unknowns, unit, strict=True)}

    def unit(self, values: Mapping[str, float]) -> np.ndarray:
        return np.array([u.to_unit(float(values[u.name])) for u in self.unknowns])

    def moved(self, values: Mapping[str, float], changes: Iterable[Mapping[str, float]]) -> list[list[float]]:
        """The unit vectors of ``values`` with each of ``changes`` applied (the candidates of a local study)."""
        return [list(self.unit({**values, **change})) for change in changes]

    def one_at_a_time(self, values: Mapping[str, float], steps: Sequence[float]) -> list[list[float]]:
        """The unit vectors of ``values`` with each unknown in turn moved by each relative step
        (:func:`perturbed`), unknown by unknown."""
        return self.moved(values, [{u.name: perturbed(values[u.name], u, s)} for u in self.unknowns for s in steps])


def perturbed(value: float, unknown: Unknown, step: float) -> float:
    """``value`` moved by the relative ``step`` (e.g. -0.1); a phase (or any value at 0) moves by
    ``step`` times its search range."""
    if unknown.name == "te_phase" or value == 0.0:
        return float(value + step * (unknown.high - unknown.low))
    return float(value * (1.0 + step))


def interior(unit: Sequence[float]) -> float:
    """Distance of a unit vector from the nearest bound (0 on an edge, 0.5 at the centre)."""
    u = np.clip(np.asarray(unit, float), 0.0, 1.0)
    return float(np.min(np.minimum(u, 1.0 - u)))
