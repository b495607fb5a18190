"""Motion labelling: systems, starts and a policy in, typed verdicts out.

One entry point, :func:`label_lines` (and :func:`label_points` for independent points): every consumer
(sweeps, maps, point runs, the attractor search, the calibration, the claims and the captions) labels
through it.  The stages are in :mod:`geardyn.label._follow`, :mod:`~geardyn.label._record` and
:mod:`~geardyn.label._nonperiodic` (what they share in :mod:`geardyn.label._stages`); the torus test
in :mod:`geardyn.label.torus`.

The names below are loaded on first use (PEP 562): a job that only reads verdicts (figures, captions,
tables) imports :mod:`~geardyn.label.verdict` and not the compiled loops.
"""

from typing import TYPE_CHECKING

from geardyn._lazy import lazy_attributes

if TYPE_CHECKING:
    from geardyn.label.lines import label_lines, label_points
    from geardyn.label.policy import Policy
    from geardyn.label.verdict import BIFURCATIONS, EXPONENT_METHODS, STAGE_NAMES, STAGES, Verdict

_HOME = {
    "BIFURCATIONS": "verdict",
    "EXPONENT_METHODS": "verdict",
    "STAGES": "verdict",
    "STAGE_NAMES": "verdict",
    "Verdict": "verdict",
    "Policy": "policy",
    "label_lines": "lines",
    "label_points": "lines",
}

__getattr__ = lazy_attributes(__name__, _HOME)


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
