"""Every checkable statement of a paper (data: a paper module's ``CLAIMS``) against our results, for designs that
name the paper.  The engine (:mod:`geardyn.claims.engine`) hands each claim to its rule: the rules on a KHV drive's
labelled sweeps (:mod:`geardyn.claims.sweep`) and on a model family's products (:mod:`geardyn.claims.data`); the
verdicts and the claims table: :mod:`geardyn.claims.verdicts`.  The rules, the keys of a claim and the
thresholds: docs/claims.md."""

from geardyn.claims.data import (
    DATA_KEYS,
    DATA_RULES,
    Measured,
    Quantity,
    data_claim,
    data_claims,
    format_value,
    matches_verdict,
    tolerance_text,
    within_verdict,
)
from geardyn.claims.engine import claims, evaluate, lines_of_runs, note, sweep_claim
from geardyn.claims.sweep import CHAOS, P1, QP, SWEEP_RULES, Track, code, first_non, track_of_cube
from geardyn.claims.verdicts import Claim, fraction_verdict

__all__ = [
    "CHAOS",
    "DATA_KEYS",
    "DATA_RULES",
    "P1",
    "QP",
    "SWEEP_RULES",
    "Claim",
    "Measured",
    "Quantity",
    "Track",
    "claims",
    "code",
    "data_claim",
    "data_claims",
    "evaluate",
    "first_non",
    "format_value",
    "fraction_verdict",
    "lines_of_runs",
    "matches_verdict",
    "note",
    "sweep_claim",
    "tolerance_text",
    "track_of_cube",
    "within_verdict",
]
