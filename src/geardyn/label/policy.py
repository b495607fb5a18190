"""A labelling policy: a frozen value, built from a named preset of the config (sweep, map, points,
calibration), never a row of switches on a function.  It holds every setting a stage of the labeller
reads: the integration and the classifier's thresholds, and the numerics of the stages by group
(:class:`Newton`, :class:`Deflation`, :class:`Chord`, :class:`Settle`, :class:`Locked`).  The defaults are
the measured values the labeller has always used.
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
class Newton:
    """Newton shooting (:func:`geardyn.solve.shooting.newton_shooting_batch`): ``tol`` and ``max_iter`` (the
    residual relative to max(1, |x|)); ``max_growth``: it gives up when its residual grows more than this many
    times in one iteration (inf: never; the searches for cycles that may not exist set it, :class:`Locked`);
    ``step_cap``: a step is capped at this times max(1, |x|).  ``cycle_tol_factor``: the points of a certified
    orbit's cycle return to its state within this times ``tol`` (relative), which makes its least period."""

    tol: float = 1e-9
    max_iter: int = 12
    max_growth: float = math.inf
    step_cap: float = 10.0
    cycle_tol_factor: float = 1e3


@dataclass(frozen=True)
class Deflation:
    """Deflated Newton shooting past an unstable orbit found (:func:`geardyn.label._stages.certify`): at most
    ``max_iter`` iterations, the deflation factor 1 / |x - r|^2 + ``shift``."""

    max_iter: int = 20
    shift: float = 1.0


@dataclass(frozen=True)
class Chord:
    """The follow stage's chord iteration with the previous orbit's monodromy: at most ``max_iter`` iterations,
    the residual falling by ``fall`` at each (else full Newton takes over); the converged state is certified
    within ``tol_factor`` times the Newton tolerance (its monodromy run)."""

    max_iter: int = 8
    fall: float = 0.5
    tol_factor: float = 2.0


@dataclass(frozen=True)
class Settle:
    """The slow-transient check (:mod:`geardyn.label.settle`): ``newton_max_iter``, the shooting's iterations;
    ``cycle_rtol``, how close the n-th point of a shot cycle returns to make its least period;
    ``min_points``, ``rate_share``, ``record_fall``: a record of at least that many points approaches an
    orbit when its distance falls at least at that share of the rate the multiplier predicts, and by that
    factor over the record; ``rho_max``: the largest multiplier the approach is computed with (1 would never
    show it); ``probe_fall``, ``probe_min_periods``: the run continued as long as the multiplier needs to
    shrink a distance by that factor (at least that many periods); ``horizon_fall``, ``run_fall``: last, the
    run continued as long as the multiplier needs to shrink a distance by the first factor, and the distance
    must fall by the second, or below ``reached_rtol`` of the orbit's size."""

    newton_max_iter: int = 15
    cycle_rtol: float = 1e-6
    min_points: int = 20
    rate_share: float = 0.5
    record_fall: float = 0.5
    rho_max: float = 1.0 - 1e-6
    probe_fall: float = 0.25
    probe_min_periods: int = 20
    horizon_fall: float = 0.01
    run_fall: float = 0.1
    reached_rtol: float = 1e-7


@dataclass(frozen=True)
class Locked:
    """The search for a cycle that a quasi-periodic record gathers about (:mod:`geardyn.label._nonperiodic`):
    ``return_tol``, the largest return distance after n periods, relative to the attractor's size (measured
    on map_x1_e: the certified cycles 5e-4 median, 6e-3 at most); ``newton_max_iter``, the Newton iterations
    (where the cycle exists Newton finds it in a few: 89 of the 94 cycles found with 12 on 20 rows of
    map_x1_e); ``max_growth``, the growth of the residual in one iteration at which it gives up (measured on
    all of map_x1_e without the stop: of 933 cycles found in 3556 attempts, 928 had a residual that never grew
    more than 1.6 times in one iteration, 5 grew 2-19 times and converged; attempts that found none mostly grew
    15-90 times at the first iteration; with 20 no cycle of that map is lost and the attempts cost 0.76 of
    their integrations); ``fall_short``, ``fall_long``: the fall of the return distance along the record that
    a short (n <= max_n) and a long cycle must show; ``circle_max_n``: the periods n = 1 .. circle_max_n of
    the orbits a quasi-periodic record is checked to circle at the unit circle (the record is then undecided:
    a point at the orbit's Neimark-Sacker bifurcation, to the labeller's accuracy)."""

    return_tol: float = 1e-2
    newton_max_iter: int = 4
    max_growth: float = 20.0
    fall_short: float = 0.95
    fall_long: float = 0.5
    circle_max_n: int = 2


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
    newton, deflation, chord, settle, locked: the numerics of the stages (the classes above).  extrapolate_min: records
    shorter than this are tested without the torus test's extrapolation (its ``torus_windows`` windows need a
    few points each).  cycle_repeats: a record is searched for a period-n cycle only when it holds this many
    cycles (its return distances are read over the oldest and the newest of as many parts); gather_fall: a
    record gathers about a short cycle when its newest return distance is below this share of its oldest.
    return_fall: a record's return distance after n periods falls when the mean of its last quarter is below
    this share of the mean of its first (:func:`geardyn.classify.falling_return_distances`): which periods
    the slow-transient check shoots for, and which short cycles the search for locked cycles tries (0.95
    skips only transients slower than about 0.9993 per period on a 100-point record).
    """

    integration: SimulationSettings
    classifier: ClassifierSettings = ClassifierSettings()
    start: Start = "follow"
    coexistence: bool = False
    follow_transient_periods: int = 100
    newton: Newton = Newton()
    deflation: Deflation = Deflation()
    chord: Chord = Chord()
    settle: Settle = Settle()
    locked: Locked = Locked()
    extrapolate_min: int = 24
    torus_windows: int = 6
    cycle_repeats: int = 3
    gather_fall: float = 0.5
    return_fall: float = 0.95

    def __post_init__(self) -> None:
        if self.start not in ("follow", "fixed"):
            raise ValueError(f"start {self.start!r}; allowed: 'follow', 'fixed'")
        if self.follow_transient_periods < 0:
            raise ValueError("follow_transient_periods must be >= 0")
        if self.integration.integrator == "dop853":
            raise ValueError("the labeller integrates with 'rk4' or 'rk4_event' (DOP853 carries no variational part)")

    @property
    def newton_tol(self) -> float:
        """The Newton shooting's tolerance (:class:`Newton`)."""
        return self.newton.tol

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
