"""The records of a continued :class:`Branch` and its typed :class:`Bifurcation` points, and the one
interpolation of a branch at a parameter value (:meth:`Branch.states_at`, used by :func:`on_branch` and the label
cross-check)."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field

import numpy as np

from geardyn import libm
from geardyn.runs.continuation.corrector import ContinuationSettings

#: How far a step's parameter interval is widened when asked which steps hold p (:func:`on_branch`): a point at a
#: step's end is on it after rounding (parameters are of order 1; the double's resolution is 2.2e-16).
PAD = 1e-12


@dataclass
class Bifurcation:
    """A typed bifurcation point of a branch (multipliers of the n-period map at the point)."""

    kind: str
    p: float
    state: np.ndarray
    multipliers: np.ndarray
    critical: complex  # the multiplier that crosses (nan for grazing)
    rotation_number: float  # arg(mu) / (2 pi) for neimark_sacker, else nan
    index: int  # the branch point just before it
    located: bool  # refined (Brent / parabola) rather than only bracketed
    n: int = 1


@dataclass
class Branch:
    """One continued branch of period-n orbits along its arclength: p (m,), states (m, d) at phase 0, multipliers
    (m, d) by decreasing modulus, grazing margins (NaN when not computed), corrector evaluations; ``end_status``:
    why each end (``down``, ``up``) stopped."""

    n: int
    p: np.ndarray
    states: np.ndarray
    multipliers: np.ndarray
    arclength: np.ndarray
    grazing: np.ndarray
    iterations: np.ndarray
    end_status: dict[str, str] = field(default_factory=dict)
    bifurcations: list[Bifurcation] = field(default_factory=list)
    tangents: np.ndarray | None = None  # (m, d + 1) unit tangents in the scaled variables
    sx: float = 1.0  # the scale of the states it was continued with
    sp: float = 1.0  # the scale of the parameter
    settings: ContinuationSettings = ContinuationSettings()  # the settings it was continued with

    @property
    def stable(self) -> np.ndarray:
        return np.max(libm.cabs(self.multipliers), axis=1) < 1.0

    def __len__(self) -> int:
        return int(self.p.size)

    def states_at(self, p: float, pad: float = 0.0) -> Iterator[tuple[int, np.ndarray]]:
        """(i, x) for every step i -> i + 1 whose parameter interval, widened by ``pad`` on both
        sides, holds p: x is the state interpolated linearly in p over the step (the state of point i
        on a step of constant p).  A branch that folds holds p on several steps."""
        for i in range(len(self) - 1):
            a, b = self.p[i], self.p[i + 1]
            if min(a, b) - pad <= p <= max(a, b) + pad:
                w = 0.0 if a == b else (p - a) / (b - a)
                yield i, self.states[i] + w * (self.states[i + 1] - self.states[i])


def on_branch(br: Branch, p: float, points: np.ndarray, tol: float, pad: float = PAD, stable: bool = False) -> bool:
    """True when one of ``points`` (phase-0 points of an orbit at p) lies on the branch (max-norm
    distance within tol * max(1, max |x|) of the branch interpolated at p, :meth:`Branch.states_at`);
    ``stable``: only on steps of changing p between two stable points."""
    scale = max(1.0, float(np.max(np.abs(br.states))))
    st = br.stable if stable else None
    return any(
        float(np.min(np.max(np.abs(points - x), axis=1))) <= tol * scale
        for i, x in br.states_at(p, pad)
        if st is None or (st[i] and st[i + 1] and br.p[i] != br.p[i + 1])
    )
