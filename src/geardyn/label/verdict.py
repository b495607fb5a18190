"""The typed record the labeller returns for every point: :class:`Verdict`.

A verdict says what the point's attractor is (``label``, ``period``), how sure that is (``stage``: which
stage of the labeller decided it, and ``reason``), its largest exponent and how that was obtained
(``exponent_method``), where the followed orbit lost stability (``bifurcation``), the points that a figure
draws (``poincare``: points on the attractor, never a transient) and the state the next point of a line
starts from (``final_state``) and the response measures on the attractor (``response``), from the
labeller's own runs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from geardyn import classify
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
}
STAGE_NAMES = {v: k for k, v in STAGES.items()}

#: How the followed orbit lost stability at this point (cube variable ``bifurcation``).
BIFURCATIONS = {
    "none": 0,
    "fold": 1,  # a real multiplier left the unit circle through +1
    "period_doubling": 2,  # a real multiplier left through -1
    "neimark_sacker": 3,  # a complex pair left the unit circle
    "orbit_lost": 4,  # Newton shooting found no orbit near the previous one (a fold or a jump)
}

#: How the exponent was obtained (cube variable ``exponent_method``).
EXPONENT_METHODS = {"none": 0, "floquet": 1, "tangent": 2}


@dataclass(frozen=True, eq=False)
class Verdict:
    """One point's label and how it was obtained.

    label: code of :data:`geardyn.classify.LABELS` or n >= 1 (period-n, n the least period).
    period: the least period n (0 when not periodic).
    exponent, exponent_sigma: largest exponent per unit dimensionless time tau and its uncertainty;
    ``exponent_method`` ``"floquet"`` (log max|mu| / (n T) of the certified orbit, sigma 0), ``"tangent"``
    (a tangent vector over the record) or ``"none"``.
    multiplier: max |mu| of the orbit's Floquet multipliers over its least period (NaN: no orbit).
    stage: key of :data:`STAGES`; bifurcation: key of :data:`BIFURCATIONS` (how the orbit followed from the
    previous point of the line lost stability here; ``"none"`` otherwise).
    reason: short text.  k01, flatness, torus_digits: the 0-1 statistic, spectral flatness and the digits of
    agreement of the weighted Birkhoff averages (NaN where not computed).
    crosscheck: 1 when the 0-1 test and the spectrum both agree with a QP or chaos label, 0 when one does,
    -1 when not applicable.
    final_state: (6,) state at phase 0 the next point of a line starts from (a point of the orbit for
    periodic verdicts).  poincare: (m, 6) points on the attractor at phase 0 (the cycle repeated for a
    periodic verdict).  transient_used: transient periods integrated before the record (0 when followed).
    n_events: contact switches located in the run that recorded ``poincare``.
    diverged_period: mesh period of divergence (-1: bounded).  monodromy: (6, 6) over n periods at
    ``final_state`` for a periodic verdict (the next point's chord iteration reuses it).
    response: the :class:`~geardyn.solve.response.ResponseMeasures` on the attractor, summed in the
    labeller's own runs: over one cycle (``period`` mesh periods) from ``final_state`` for a periodic verdict
    (the run that builds its cycle), over the last ``recorded_periods`` of the record that ends at
    ``final_state`` for another (fewer where a round of a growing record is shorter), not computed for a
    diverged one.
    """

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
    monodromy: np.ndarray | None = None
    response: ResponseMeasures | None = None

    @property
    def diverged(self) -> bool:
        return self.label == classify.LABELS["diverged"]

    @property
    def periodic(self) -> bool:
        return self.period > 0

    @property
    def decided(self) -> bool:
        return self.label != classify.LABELS["undetermined"]
