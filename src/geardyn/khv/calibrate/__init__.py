"""Calibration of a paper design's unknowns: a global search scored by the paper's own claims.

The unknowns of a paper's design (for paper 1: mesh frequency, carrier radius, shaft stiffnesses, damping
ratios, TE phase, planet mass; ``docs/calibration.md``) span a search space with bounds given in the config
(``calibration.<name>.search``).  A candidate is one vector of them; it is scored by
:func:`geardyn.claims.evaluate`, the function that writes ``claims.md``, applied to the labels the
candidate produces along the paper's lines (its ``CLAIM_LINES``: for paper 1 along x1 at the Fig. 7
values of b and e, and along b and e at the paper's three x1), each on the grid the config gives for its
parameter:

    score = (claims that agree) + 0.5 * (borderline claims) + 0.99 * partial,   partial in [0, 1]

(a borderline claim is a fraction within its statistical uncertainty of its threshold,
:func:`geardyn.claims.fraction_verdict`, the rule ``claims.md`` uses)

with partial credit, along the paper's main line (``CALIBRATION["line"]``), for where the motion leaves P1
and where chaos starts (where the paper's ``SEQUENCE`` places them, :func:`paper_transitions`) and for the
order of the regimes (longest common subsequence with the paper's, e.g. P1 -> QP -> Pn -> chaos -> Pn ->
chaos).  The partial credit never outweighs one claim.

Labels come from the one labeller, :func:`geardyn.label.label_lines`, along the candidate's own lines
(each point follows the attractor of the previous one, as in the sweeps), so the figures, ``claims.md``
and the calibration score the same labels.

The optimiser is :func:`scipy.optimize.differential_evolution` (seeded, ``vectorized``, deferred
updating); every evaluated candidate is appended to a cache file keyed by its vector, so a rerun
with the same seed replays the cached evaluations and resumes where it stopped.

The package in parts: the search space (:mod:`.space`), a candidate's labels and its score
(:mod:`.objective`), the evaluated candidates and their cache (:mod:`.records`), evaluation on a
process pool (:mod:`.evaluate`), the search itself (:mod:`.optimise`), its products (:mod:`.products`)
and the robustness study of the best candidate (:mod:`.robustness`).
"""

from geardyn.khv.calibrate.evaluate import Evaluator, Problem, evaluate_candidate, warm_worker
from geardyn.khv.calibrate.objective import (
    REQUIREMENTS,
    TRANSITION_SCALE,
    CandidateLabels,
    Grids,
    Line,
    Score,
    candidate_labels,
    label_tracks,
    lcs,
    paper_regime_string,
    paper_transitions,
    ranked_score,
    regime_string,
    requirement_text,
    route_in,
    score_labels,
    shows_route,
    transitions,
)
from geardyn.khv.calibrate.optimise import problem_from_config, refine, search, verified_choice
from geardyn.khv.calibrate.products import (
    RESULT_PREFIX,
    design_text_from_file,
    design_values,
    records_dataset,
    search_design_text,
    search_result,
    search_table,
)
from geardyn.khv.calibrate.records import Record, cache_key, read_cache
from geardyn.khv.calibrate.robustness import sensitivity
from geardyn.khv.calibrate.space import SearchSpace, Unknown, interior, perturbed

__all__ = [
    "REQUIREMENTS",
    "RESULT_PREFIX",
    "TRANSITION_SCALE",
    "CandidateLabels",
    "Evaluator",
    "Grids",
    "Line",
    "Problem",
    "Record",
    "Score",
    "SearchSpace",
    "Unknown",
    "cache_key",
    "candidate_labels",
    "design_text_from_file",
    "design_values",
    "evaluate_candidate",
    "interior",
    "label_tracks",
    "lcs",
    "paper_regime_string",
    "paper_transitions",
    "perturbed",
    "problem_from_config",
    "ranked_score",
    "read_cache",
    "records_dataset",
    "refine",
    "regime_string",
    "requirement_text",
    "route_in",
    "score_labels",
    "search",
    "search_design_text",
    "search_result",
    "search_table",
    "sensitivity",
    "shows_route",
    "transitions",
    "verified_choice",
    "warm_worker",
]
