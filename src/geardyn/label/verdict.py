"""The typed record the labeller returns for every point: :class:`Verdict`."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

import geardyn.label.vocabulary as vocabulary
from geardyn.solve.bifurcations import CODES
from geardyn.solve.response import ResponseMeasures

#: Which stage decided a verdict (cube variable ``stage``; codes and meanings).
STAGES = {
    "follow": 1,  # Newton shooting from the previous point's orbit: a stable orbit, certified by its multipliers
    "period_test": 2,  # the run returns within tolerance (rule 3); Newton shooting certifies the orbit
    "shooting": 3,  # a slow transient: a stable orbit found by shooting that the run approaches
    "exponent": 4,  # the tangent exponent with the 0-1 test, the spectrum and the torus test (chaos)
    "torus": 5,  # weighted Birkhoff averages converge: a torus (quasi-periodic)
    "undecided": 6,  # the indicators disagree (the reason says how)
    "diverged": 7,  # unbounded growth
    "growing": 8,  # the record's amplitude still grows at the record cap: a transient (geardyn.label.growth)
}
STAGE_NAMES = {v: k for k, v in STAGES.items()}

#: How the followed orbit lost stability at this point (cube variable ``bifurcation``; codes of the one vocabulary,
#: :mod:`geardyn.solve.bifurcations`): a real multiplier left the unit circle through +1 or -1, a complex pair left
#: it, or Newton shooting found no orbit near the previous one (a fold or a jump).
BIFURCATIONS = {k: CODES[k] for k in ("none", "fold", "period_doubling", "neimark_sacker", "orbit_lost")}

#: How the exponent was obtained (cube variable ``exponent_method``).
EXPONENT_METHODS = {"none": 0, "floquet": 1, "tangent": 2}


@dataclass(frozen=True, eq=False)
class Verdict:
    """One point's label and how it was obtained: label and period, exponent and method, multiplier, stage,
    bifurcation, reason, indicators, the attractor's points and final state, the response measures on it, and for a
    quasi-periodic verdict the longest period its long-cycle search excluded, ``period_searched`` (a torus or a
    cycle longer than that; ``docs/classify.md``)."""

    label: int
    period: int
    exponent: float
    exponent_sigma: float
    exponent_method: str
    stage: str
    reason: str
    final_state: np.ndarray
    poincare: np.ndarray
    multiplier: float = float("nan")
    bifurcation: str = "none"
    k01: float = float("nan")
    flatness: float = float("nan")
    torus_digits: float = float("nan")
    crosscheck: int = -1
    transient_used: int = 0
    n_events: int = -1
    diverged_period: int = -1
    period_searched: int = 0
    monodromy: np.ndarray | None = None
    response: ResponseMeasures | None = None

    @property
    def diverged(self) -> bool:
        return self.label == vocabulary.LABELS["diverged"]

    @property
    def periodic(self) -> bool:
        return self.period > 0
