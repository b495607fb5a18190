"""Motion labelling: systems, starts and a policy in, typed verdicts out, through one entry point,
:func:`label_lines` (and :func:`label_points`); names loaded on first use (PEP 562) so that a job that
only reads verdicts does not import the compiled loops."""

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
