"""A labelling policy: a frozen value, built from a named preset of the config (sweep, map, points,
calibration), never a row of switches on a function.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Literal

from geardyn.classify import ClassifierSettings
from geardyn.solve.base import SimulationSettings

Start = Literal["follow", "fixed"]


@dataclass(frozen=True)
class Policy:
    """How the points of a study are labelled.

    integration: the integrator settings (steps per period, transient and recorded periods, early stop of
    the transient).  classifier: the thresholds of the rules (:class:`geardyn.classify.ClassifierSettings`).
    start: ``"follow"``: along a line, each point starts from the attractor of the previous point (Newton
    shooting from its orbit, or a run from its final state); ``"fixed"``: every point starts from the fixed
    initial state (the static deflection), as a line of one point.  coexistence: also label every point
    from the fixed start and report where the two end on different attractors.
    follow_transient_periods: the transient of a run that starts from the previous point's (non-periodic)
    attractor; a line's first point and every ``fixed`` start use ``integration.transient_periods``.
    newton_tol, newton_max_iter: Newton shooting (residual relative to max(1, |x|)).  newton_max_growth: the
    shooting gives up when its residual grows more than this many times in one iteration (inf: never; the
    labeller's searches for cycles that may not exist set it, :mod:`geardyn.label._nonperiodic`).
    chord_max_iter: the follow stage's chord iterations with the previous orbit's monodromy before full
    Newton takes over.  deflation_max_iter: deflated Newton iterations past an unstable orbit found.
    settle_newton_max_iter: Newton iterations of the slow-transient check (:mod:`geardyn.label.settle`).
    locked_return, locked_newton_max_iter, locked_max_growth: the search for a cycle that a quasi-periodic
    record gathers about: the largest return distance after n periods, relative to the attractor's size
    (measured on map_x1_e: the certified cycles 5e-4 median, 6e-3 at most), the Newton iterations (where
    the cycle exists Newton finds it in a few: 89 of the 94 cycles found with 12 on 20 rows of map_x1_e), and
    the growth of the residual in one iteration at which it gives up (measured on all of map_x1_e without
    the stop: of 933 cycles found in 3556 attempts, 928 had a residual that never grew more than 1.6 times
    in one iteration, 5 grew 2-19 times and converged; attempts that found none mostly grew 15-90 times at
    the first iteration; with 20 no cycle of that map is lost and the attempts cost 0.76 of their
    integrations).  extrapolate_min: records shorter than this are tested without the torus test's
    extrapolation (its six windows need a few points each).
    """

    integration: SimulationSettings
    classifier: ClassifierSettings = ClassifierSettings()
    start: Start = "follow"
    coexistence: bool = False
    follow_transient_periods: int = 100
    newton_tol: float = 1e-9
    newton_max_iter: int = 12
    newton_max_growth: float = math.inf
    chord_max_iter: int = 8
    deflation_max_iter: int = 20
    settle_newton_max_iter: int = 15
    locked_return: float = 1e-2
    locked_newton_max_iter: int = 4
    locked_max_growth: float = 20.0
    extrapolate_min: int = 24

    def __post_init__(self) -> None:
        if self.start not in ("follow", "fixed"):
            raise ValueError(f"start {self.start!r}; allowed: 'follow', 'fixed'")
        if self.follow_transient_periods < 0:
            raise ValueError("follow_transient_periods must be >= 0")
        if self.integration.integrator == "dop853":
            raise ValueError("the labeller integrates with 'rk4' or 'rk4_event' (DOP853 carries no variational part)")

    @property
    def stability_margin(self) -> float:
        """A periodic orbit is certified stable when max|mu| < 1 - margin: the margin is the classifier's
        ``error_floor``, the integration error of the Poincare points at these steps per period (the
        multipliers of the discrete map differ from the flow's by errors of that order)."""
        return self.classifier.error_floor

    def with_start(self, start: Start) -> Policy:
        return dataclasses.replace(self, start=start)

    @classmethod
    def from_spec(cls, integration: SimulationSettings, spec: Mapping[str, Any] | None = None) -> Policy:
        """The policy of a study entry of the config (a sweep, map, points run or calibration): its
        ``classifier`` block, ``start_from`` (follow or fixed; not ``start``, which a sweep uses for its range)
        and ``coexistence`` keys (presets already resolved by the validator)."""
        spec = dict(spec or {})
        return cls(
            integration=integration,
            classifier=ClassifierSettings.from_mapping(dict(spec.get("classifier") or {})),
            start=spec.get("start_from", "follow"),
            coexistence=bool(spec.get("coexistence", False)),
        )
