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
    """

    integration: SimulationSettings
    classifier: ClassifierSettings = ClassifierSettings()
    start: Start = "follow"
    coexistence: bool = False
    follow_transient_periods: int = 100
    newton_tol: float = 1e-9
    newton_max_iter: int = 12
    newton_max_growth: float = math.inf

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
