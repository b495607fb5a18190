"""A candidate's labels along the paper's sweeps and its score: the claims that agree plus the partial credit."""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from types import ModuleType
from typing import Any

import numpy as np

from geardyn import claims as claims_mod
from geardyn import classify
from geardyn.khv import point
from geardyn.khv.calibrate.records import Record
from geardyn.khv.design import KHVDesign
from geardyn.label import Policy, label_lines

P1, QP, CHAOS = 1, classify.LABELS["quasi_periodic"], classify.LABELS["chaotic"]


@dataclass(frozen=True)
class Grids:
    """Where a candidate is labelled: x1 at the Fig. 7 values of b and e; b (at the Fig. 9 e) and e
    (at the Fig. 11 b) at each of the paper's three x1."""

    x1: np.ndarray
    b: np.ndarray
    e: np.ndarray
    fixed07: Mapping[str, float]
    fixed09: Mapping[str, float]
    fixed11: Mapping[str, float]
    case_x1: tuple[float, ...]

    @classmethod
    def from_config(cls, spec: Mapping[str, Any], paper: ModuleType) -> Grids:
        def lin(r):
            return np.linspace(float(r["start"]), float(r["stop"]), int(r["num"]))

        return cls(
            lin(spec["x1"]),
            lin(spec["b"]),
            lin(spec["e"]),
            dict(paper.FIG07_FIXED),
            {"e": float(paper.FIG07_FIXED["e"])},
            {"b": float(paper.FIG07_FIXED["b"])},
            tuple(float(v) for v in paper.CASE_X1),
        )

    @property
    def n_points(self) -> int:
        return self.x1.size + len(self.case_x1) * (self.b.size + self.e.size)


def label_tracks(
    design: KHVDesign, tracks: Sequence[tuple[Mapping[str, float], str, Sequence[float]]], policy: Policy
) -> list[claims_mod.Track]:
    """Labels along each track (overrides, swept parameter, values): every track is a line of the one
    labeller (:func:`geardyn.label.label_lines`), all tracks advancing together; each point's label
    depends only on its own track."""
    lines = [
        [point.point_coefficients(design, {**over, par: float(v)}) for v in values] for over, par, values in tracks
    ]
    out = label_lines(lines, policy)
    return [
        claims_mod.Track(
            np.asarray(values, float),
            np.array([v.label for v in vs], np.int16),
            np.array([v.exponent for v in vs], float),
            np.array([v.exponent_sigma for v in vs], float),
        )
        for (_, _, values), vs in zip(tracks, out, strict=True)
    ]


@dataclass
class CandidateLabels:
    fig07: claims_mod.Track
    fig09: dict[float, claims_mod.Track]
    fig11: dict[float, claims_mod.Track]


def candidate_labels(design: KHVDesign, values: Mapping[str, float], grids: Grids, policy: Policy) -> CandidateLabels:
    """The labelled sweeps of one candidate (overrides ``values``)."""
    base = dict(values)
    x1s = list(grids.case_x1)
    tracks = (
        [({**base, **grids.fixed07}, "x1", grids.x1)]
        + [({**base, **grids.fixed09, "x1": x1}, "b", grids.b) for x1 in x1s]
        + [({**base, **grids.fixed11, "x1": x1}, "e", grids.e) for x1 in x1s]
    )
    got = label_tracks(design, tracks, policy)
    f07 = got[0]
    f09 = dict(zip(x1s, got[1 : 1 + len(x1s)], strict=True))
    f11 = dict(zip(x1s, got[1 + len(x1s) :], strict=True))
    return CandidateLabels(f07, f09, f11)


#: regime classes for the order credit: P1, QP, chaos, and "periodic n > 1"
_ORDER = {P1: "1", QP: "Q", CHAOS: "C"}


def regime_string(labels: np.ndarray) -> str:
    """Run-length compressed regime classes along a sweep (undetermined and diverged left out)."""
    out = []
    for lab in labels:
        c = _ORDER.get(int(lab), "n" if int(lab) > 1 else "")
        if c and (not out or out[-1] != c):
            out.append(c)
    return "".join(out)


def shows_route(labels: np.ndarray) -> bool:
    """Whether labels along x1 go from period-1 through non-period-1 motion (quasi-periodic or period
    n > 1) into chaos: the regime string (:func:`regime_string`) begins ``1``, then ``Q`` / ``n`` and then
    ``C`` (a return to P1 before the first chaos does not count)."""
    return re.match(r"1[Qn]+C", regime_string(np.asarray(labels))) is not None


#: Requirements a search can place on a candidate besides its score (``search.require``): a name ->
#: (test of a record's labels, the sentence the calibrated design's header states).
REQUIREMENTS: dict[str, tuple[Callable[[Record], bool], str]] = {
    "route": (
        lambda rec: shows_route(np.asarray(rec.fig07)),
        "Fig. 7 (x1 sweep, b = 2, e = 5) goes from period-1 through non-period-1 motion into chaos",
    ),
}

#: what a candidate that fails the requirement loses from its score (more than any score can be)
_UNMET = 100.0


def ranked_score(record: Record, require: str | None = None) -> float:
    """The score the search ranks by: the claims score, less 100 when the record fails ``require``
    (:data:`REQUIREMENTS`), so a candidate that meets it beats every one that does not, and among
    those that meet it the claims decide."""
    if require is None:
        return float(record.score)
    return float(record.score) - (0.0 if REQUIREMENTS[require][0](record) else _UNMET)


def paper_regime_string(paper: ModuleType) -> str:
    return regime_string(
        np.array(
            [
                claims_mod.code(lab) if not isinstance(claims_mod.code(lab), tuple) else claims_mod.code(lab)[0]
                for _, _, lab in paper.SEQUENCE
            ]
        )
    )


def lcs(a: str, b: str) -> int:
    """Length of the longest common subsequence."""
    prev = [0] * (len(b) + 1)
    for ca in a:
        cur = [0]
        for j, cb in enumerate(b):
            cur.append(prev[j] + 1 if ca == cb else max(prev[j + 1], cur[j]))
        prev = cur
    return prev[-1]


def transitions(values: np.ndarray, labels: np.ndarray) -> dict[str, float]:
    """Where the motion along x1 first leaves P1 and where chaos first appears (inf if never)."""
    lab = np.asarray(labels)
    leave = np.nonzero(lab != P1)[0]
    chaos = np.nonzero(lab == CHAOS)[0]
    return {
        "leave_p1": float(values[leave[0]]) if leave.size else float("inf"),
        "first_chaos": float(values[chaos[0]]) if chaos.size else float("inf"),
    }


#: the paper's positions of the two transitions above (Sec. 4.1), and the distance that earns nothing
PAPER_TRANSITIONS = {"leave_p1": 0.565, "first_chaos": 0.593}
TRANSITION_SCALE = 0.1


@dataclass
class Score:
    score: float
    agree: int
    partial: float
    transitions: dict[str, float]
    order: str
    rows: list = field(default_factory=list)


def score_labels(paper: ModuleType, lab: CandidateLabels) -> Score:
    """Score of a candidate's labels: claims that agree (:func:`geardyn.claims.evaluate`) plus the
    partial credit (module docstring)."""
    rows = claims_mod.evaluate(paper, lab.fig07, lab.fig09, lab.fig11)
    agree = sum(r.verdict == "agree" for r in rows)
    # a borderline claim (a fraction within its statistical uncertainty of the threshold,
    # geardyn.claims.fraction_verdict) is worth half an agreeing one: one point cannot flip the search
    half = sum(claims_mod.credit(r.verdict) for r in rows if r.verdict == "borderline")
    tr = transitions(lab.fig07.values, lab.fig07.labels)
    credit = [
        max(0.0, 1.0 - abs(tr[k] - PAPER_TRANSITIONS[k]) / TRANSITION_SCALE) if np.isfinite(tr[k]) else 0.0
        for k in PAPER_TRANSITIONS
    ]
    ours, want = regime_string(lab.fig07.labels), paper_regime_string(paper)
    credit.append(lcs(ours, want) / len(want))
    partial = float(np.mean(credit))
    return Score(agree + half + 0.99 * partial, agree, partial, tr, ours, rows)
