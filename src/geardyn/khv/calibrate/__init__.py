"""Calibration of a paper design's unknowns by a global search scored by the paper's own claims (docs/calibration.md):
the space (:mod:`.space`), a candidate's labels and score (:mod:`.objective`), the records (:mod:`.records`), evaluation
(:mod:`.evaluate`), the search (:mod:`.optimise`), its products (:mod:`.products`), robustness (:mod:`.robustness`)."""

from geardyn.khv.calibrate.evaluate import Evaluator, Problem
from geardyn.khv.calibrate.objective import (
    Grids,
    lcs,
    paper_regime_string,
    paper_transitions,
    ranked_score,
    regime_string,
    requirement_text,
    route_in,
    score_labels,
    transitions,
)
from geardyn.khv.calibrate.optimise import problem_from_config, search, verified_choice
from geardyn.khv.calibrate.products import (
    RESULT_PREFIX,
    design_text_from_file,
    design_values,
    records_dataset,
    result_of,
    search_design_text,
    search_result,
    search_table,
)
from geardyn.khv.calibrate.records import Record, cache_key, read_cache
from geardyn.khv.calibrate.robustness import sensitivity
from geardyn.khv.calibrate.space import SearchSpace, Unknown, interior, perturbed

__all__ = [
    "RESULT_PREFIX",
    "Evaluator",
    "Grids",
    "Problem",
    "Record",
    "SearchSpace",
    "Unknown",
    "cache_key",
    "design_text_from_file",
    "design_values",
    "interior",
    "lcs",
    "paper_regime_string",
    "paper_transitions",
    "perturbed",
    "problem_from_config",
    "ranked_score",
    "read_cache",
    "records_dataset",
    "regime_string",
    "requirement_text",
    "result_of",
    "route_in",
    "score_labels",
    "search",
    "search_design_text",
    "search_result",
    "search_table",
    "sensitivity",
    "transitions",
    "verified_choice",
]
