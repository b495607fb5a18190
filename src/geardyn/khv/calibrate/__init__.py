"""Calibration of a paper design's unknowns by a global search scored by the paper's own claims (docs/calibration.md):
the space (:mod:`.space`), a candidate's labels and score (:mod:`.objective`), the records (:mod:`.records`), evaluation
(:mod:`.evaluate`), the search (:mod:`.optimise`), its products (:mod:`.products`), robustness (:mod:`.robustness`)."""
