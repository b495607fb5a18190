"""Motion labelling: systems, starts and a policy in, typed verdicts out.

One entry point, :func:`label_lines` (and :func:`label_points` for independent points): every consumer
(sweeps, maps, point runs, the attractor search, the calibration, the claims and the captions) labels
through it.  The stages are in :mod:`geardyn.label._follow`, :mod:`~geardyn.label._record` and
:mod:`~geardyn.label._nonperiodic` (what they share in :mod:`geardyn.label._stages`); the torus test
in :mod:`geardyn.label.torus`.
"""

from geardyn.label.lines import label_lines, label_points
from geardyn.label.policy import Policy
from geardyn.label.verdict import BIFURCATIONS, EXPONENT_METHODS, STAGE_NAMES, STAGES, Verdict

__all__ = [
    "BIFURCATIONS",
    "EXPONENT_METHODS",
    "STAGES",
    "STAGE_NAMES",
    "Policy",
    "Verdict",
    "label_lines",
    "label_points",
]
