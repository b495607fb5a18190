"""A labelling policy: a frozen value built from a named preset of the config, holding every setting a
stage of the labeller reads (integration, classifier thresholds, the stages' numerics by group)."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Literal

from geardyn.jsontypes import Json
from geardyn.label.indicators import ClassifierSettings
from geardyn.solve.base import ShootingSettings, SimulationSettings

Start = Literal["follow", "fixed"]


@dataclass(frozen=True)
class Newton(ShootingSettings):
    """The labeller's Newton shooting (:class:`~geardyn.solve.base.ShootingSettings`, 12 iterations), and the
    cycle tolerance of a certified orbit's least period (``docs/classify.md``)."""

    max_iter: int = 12
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
    """The slow-transient check's numerics (:mod:`geardyn.label.settle`): shooting iterations, cycle tolerance,
    the approach tests on the record, the probe and the last continued run (``docs/classify.md``, "Slow transients")."""

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
    """The search for a cycle that a quasi-periodic record gathers about (:func:`geardyn.label._cycles.locked`):
    return tolerance, Newton iterations and growth stop, required falls, circled periods (measured values:
    ``docs/classify.md``)."""

    return_tol: float = 1e-2
    newton_max_iter: int = 4
    max_growth: float = 20.0
    fall_short: float = 0.95
    fall_long: float = 0.5
    circle_max_n: int = 2


@dataclass(frozen=True)
class Same:
    """When two runs reached the same attractor (:mod:`geardyn.label.compare`): the same label and, periodic,
    cycles within ``distance_tol`` max(1, size) (symmetric Hausdorff distance, max norm), else centroids and
    bounding boxes within ``chaotic_distance_tol`` max(1, size) (``docs/classify.md``)."""

    distance_tol: float = 1e-3
    chaotic_distance_tol: float = 0.2


@dataclass(frozen=True)
class GrowthSettings:
    """The growth test's numbers (:func:`geardyn.label.growth.growth_test`; measured false alarms and detections:
    ``docs/classify.md``, "Growing records"): ``blocks`` blocks of at least ``min_block`` periods, one-sided level
    ``alpha``, least rise ``min_rise`` of the envelope over the record; ``blocks`` = 0: off."""

    blocks: int = 16
    min_block: int = 8
    alpha: float = 1e-3
    min_rise: float = 0.05

    def __post_init__(self) -> None:
        if self.blocks < 0 or 0 < self.blocks < 4:
            raise ValueError(f"growth blocks = {self.blocks}; allowed: 0 (off) or >= 4")
        if not 0.0 < self.alpha < 1.0:
            raise ValueError(f"growth alpha = {self.alpha}; allowed: 0 < alpha < 1")
        if self.min_rise < 0.0:
            raise ValueError(f"growth min_rise = {self.min_rise}; allowed: >= 0")


@dataclass(frozen=True)
class Policy:
    """How the points of a study are labelled: integration, classifier thresholds, start (``"follow"`` or
    ``"fixed"``), coexistence, and the numerics of the stages (``docs/classify.md``)."""

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
    same: Same = Same()
    growth: GrowthSettings = GrowthSettings()
    extrapolate_min: int = 24
    torus_windows: int = 6
    cycle_repeats: int = 3
    gather_fall: float = 0.5
    return_fall: float = 0.95
    doubt_periods: int = 3200
    switch_step: float = 1e-4

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
    def from_spec(cls, integration: SimulationSettings, spec: Mapping[str, Json] | None = None) -> Policy:
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
