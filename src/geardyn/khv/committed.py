"""How far a calibration search's optimum lies from the committed calibrated design: each unknown's distance in
the search's unit cube and the score difference, compared as conclusions, not as bytes (docs/calibration.md)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

from geardyn.io import markdown_table
from geardyn.jsontypes import Json
from geardyn.khv.calibrate.space import SearchSpace

#: Largest distance of one unknown, as a fraction of its search range, for "the same optimum": well
#: below the 15-76 % that separate paper 1's two committed optima (its search and its route search),
#: wider than the +-2 % moves that change a verdict (docs/calibration.md, "Reproducing a calibration").
UNIT_TOLERANCE = 0.05
#: Largest score difference for "the same optimum": less than one claim.
SCORE_TOLERANCE = 0.99


@dataclass(frozen=True)
class Comparison:
    """A search's optimum against the committed one."""

    search: str
    unknowns: tuple[tuple[str, float, float, float], ...]  # name, committed, found, |unit distance|
    committed_score: float
    found_score: float
    only_committed: tuple[str, ...]  # claims agreeing at the committed optimum only
    only_found: tuple[str, ...]

    @property
    def max_unit_distance(self) -> float:
        return max((d for *_, d in self.unknowns), default=0.0)

    @property
    def score_difference(self) -> float:
        return self.found_score - self.committed_score

    @property
    def same_optimum(self) -> bool:
        return self.max_unit_distance <= UNIT_TOLERANCE and abs(self.score_difference) <= SCORE_TOLERANCE

    def markdown(self) -> str:
        verdict = "the same optimum" if self.same_optimum else "a different optimum"
        lines = [
            f"# Search `{self.search}` against the committed design",
            "",
            f"**{verdict}**: largest distance {100 * self.max_unit_distance:.1f} % of a search range (tolerance "
            f"{100 * UNIT_TOLERANCE:.0f} %), score {self.found_score:.3f} found against {self.committed_score:.3f} "
            f"committed ({self.score_difference:+.3f}; tolerance {SCORE_TOLERANCE:g}).",
            "",
            "The committed design file is what every build uses; this search is the pipeline's own rerun of "
            'it (docs/calibration.md, "Reproducing a calibration").',
            "",
            markdown_table(
                ("unknown", "committed", "found", "distance (fraction of search range)"),
                [(n, f"{c:.6g}", f"{f:.6g}", f"{d:.3f}") for n, c, f, d in self.unknowns],
            ),
            "",
            f"Claims agreeing only at the committed optimum: {', '.join(self.only_committed) or 'none'}.",
            f"Claims agreeing only at the found optimum: {', '.join(self.only_found) or 'none'}.",
        ]
        return "\n".join(lines) + "\n"


def compare(committed: Mapping[str, Json], found: Mapping[str, Json], space: SearchSpace) -> Comparison:
    """Compare two search results (``calibrate.result_of`` or ``calibrate.search_result``) over ``space``.

    Raises ``ValueError`` when they searched different unknowns (not comparable)."""
    cv, fv = committed["values"], found["values"]
    if set(cv) != set(fv) or set(cv) != set(space.names):
        raise ValueError(
            f"the results searched different unknowns: committed {sorted(cv)}, found {sorted(fv)}, "
            f"search space {sorted(space.names)}"
        )
    pairs = [(u, float(cv[u.name]), float(fv[u.name])) for u in space.unknowns]
    rows = [(u.name, c, f, abs(u.to_unit(f) - u.to_unit(c))) for u, c, f in pairs]
    if not all(math.isfinite(d) for *_, d in rows):
        raise ValueError("a searched value lies outside its (log) search range")
    a, b = set(committed.get("agreeing", ())), set(found.get("agreeing", ()))
    return Comparison(
        str(found.get("search", committed.get("search", "?"))),
        tuple(rows),
        float(committed["score"]),
        float(found["score"]),
        tuple(sorted(a - b)),
        tuple(sorted(b - a)),
    )
