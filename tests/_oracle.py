"""Test oracle: the rules applied to one plain run (no following, no shooting, no torus test).

This is the classifier's point-by-point path of earlier versions, kept here only to test against: a run
from the static deflection (or ``x0``) with a tangent vector over its last ``tangent_periods`` periods,
labelled by :func:`geardyn.classify.classify_point`.  The product labels through :mod:`geardyn.label`.
"""

from __future__ import annotations

import numpy as np

from geardyn import classify
from geardyn.solve import SimulationSettings, simulate


def rules_label(
    system,
    settings: SimulationSettings,
    cs: classify.ClassifierSettings = classify.ClassifierSettings(),
    x0: np.ndarray | None = None,
):
    """(SimulationResult, Classification) of one plain run."""
    res = simulate(system, settings, x0=x0, tangent_periods=cs.tangent_periods)
    return res, classify.classify_point(res.poincare, res.growth, res.period, res.diverged, cs, samples=res.strobe)
