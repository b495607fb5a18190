"""A candidate's labels along the paper's lines and its score: the claims that agree plus the partial credit."""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import ModuleType

import numpy as np

from geardyn import claims as claims_mod
from geardyn.claims import CHAOS, P1, QP
from geardyn.claims.verdicts import credit
from geardyn.jsontypes import Json
from geardyn.khv import point
from geardyn.khv.calibrate.records import Record
from geardyn.khv.design import KHVDesign
from geardyn.khv.model import Coefficients
from geardyn.label import Policy, label_lines


@dataclass(frozen=True)
class Line:
    """One labelled line of a candidate (a role of the paper's ``CLAIM_LINES``): ``parameter`` swept over ``values``
    with ``fixed`` held; a family (``cases``) has one line per value of ``case_parameter``."""

    parameter: str
    values: np.ndarray
    fixed: Mapping[str, float]
    case_parameter: str | None = None
    cases: tuple[float, ...] = ()


@dataclass(frozen=True)
class Grids:
    """Where a candidate is labelled: the paper's lines (``CLAIM_LINES``, by role) on the config's grids,
    and ``main``, the role of the line whose transitions and regime order earn partial credit (the paper's
    ``CALIBRATION["line"]``)."""

    lines: Mapping[str, Line]
    main: str

    @classmethod
    def from_config(cls, spec: Mapping[str, Json], paper: ModuleType) -> Grids:
        """The paper's lines, each on the grid ``spec[<its parameter>]`` ({start, stop, num})."""

        def lin(r):
            return np.linspace(float(r["start"]), float(r["stop"]), int(r["num"]))

        lines = {
            role: Line(
                line["parameter"],
                lin(spec[line["parameter"]]),
                {k: float(v) for k, v in line["fixed"].items()},
                line.get("case_parameter"),
                tuple(float(v) for v in line.get("cases", ())),
            )
            for role, line in paper.CLAIM_LINES.items()
        }
        return cls(lines, paper.CALIBRATION["line"])

    @property
    def n_points(self) -> int:
        return sum(line.values.size * max(1, len(line.cases)) for line in self.lines.values())


#: A candidate's labelled lines, by role: a :class:`~geardyn.claims.Track`, or {case value: Track} for a
#: family of lines (what :func:`geardyn.claims.evaluate` reads).
CandidateLabels = dict


def candidate_labels(design: KHVDesign, values: Mapping[str, float], grids: Grids, policy: Policy) -> CandidateLabels:
    """The labelled lines of one candidate (overrides ``values``): every line is a line of the one labeller
    (:func:`geardyn.label.label_lines`), all advancing together; each point's label depends only on its own line."""
    where: list[tuple[str, float | None, np.ndarray]] = []
    lines: list[list[Coefficients]] = []
    for role, line in grids.lines.items():
        for case in line.cases or (None,):
            over: dict[str, float] = {
                **values,
                **line.fixed,
                **({line.case_parameter: case} if case is not None else {}),  # type: ignore[dict-item]  # cases have one
            }
            lines.append([point.point_coefficients(design, {**over, line.parameter: float(v)}) for v in line.values])
            where.append((role, case, line.values))
    out: CandidateLabels = {}
    for (role, case, x), vs in zip(where, label_lines(lines, policy), strict=True):
        track = claims_mod.Track(
            np.asarray(x, float),
            np.array([v.label for v in vs], np.int16),
            np.array([v.exponent for v in vs], float),
            np.array([v.exponent_sigma for v in vs], float),
        )
        if case is None:
            out[role] = track
        else:
            out.setdefault(role, {})[case] = track
    return out


#: regime classes for the order credit: P1, QP, chaos, and "periodic n > 1"
_ORDER = {P1: "1", QP: "Q", CHAOS: "C"}


def regime_string(labels: np.ndarray) -> str:
    """Run-length compressed regime classes along a sweep (undetermined and diverged left out)."""
    out: list[str] = []
    for lab in labels:
        c = _ORDER.get(int(lab), "n" if int(lab) > 1 else "")
        if c and (not out or out[-1] != c):
            out.append(c)
    return "".join(out)


def route_in(order: str) -> bool:
    """Whether a regime string (:func:`regime_string`) goes from period-1 through non-period-1 motion
    (quasi-periodic or period n > 1) into chaos: it begins ``1``, then ``Q`` / ``n`` and then ``C`` (a
    return to P1 before the first chaos does not count)."""
    return re.match(r"1[Qn]+C", order) is not None


#: Requirements a search can place on a candidate besides its score (``search.require``): name -> (test of a
#: record, the sentence of the calibrated design's header, ``{line}`` the main line's ``CLAIM_LINES`` text).
REQUIREMENTS: dict[str, tuple[Callable[[Record], bool], str]] = {
    "route": (lambda rec: route_in(rec.order), "{line} goes from period-1 through non-period-1 motion into chaos"),
}


def requirement_text(require: str, paper: ModuleType) -> str:
    """The sentence of requirement ``require`` for ``paper`` (its main line named as the paper names it)."""
    return REQUIREMENTS[require][1].format(line=paper.CLAIM_LINES[paper.CALIBRATION["line"]]["text"])


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
    """The regime string of the paper's ``SEQUENCE`` (a label with several codes counts by its first)."""
    codes = [claims_mod.code(lab) for _, _, lab in paper.SEQUENCE]
    return regime_string(np.array([c[0] if isinstance(c, tuple) else c for c in codes]))


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
    """Where the motion along a line first leaves P1 and where chaos first appears (inf if never)."""
    lab = np.asarray(labels)
    leave, chaos = np.nonzero(lab != P1)[0], np.nonzero(lab == CHAOS)[0]
    return {
        "leave_p1": float(values[leave[0]]) if leave.size else float("inf"),
        "first_chaos": float(values[chaos[0]]) if chaos.size else float("inf"),
    }


def paper_transitions(paper: ModuleType) -> dict[str, float]:
    """Where the paper's regime sequence (its ``SEQUENCE`` along the main line) first leaves P1 and where
    its chaos starts: the lower ends of the first entries that are not P1 and that are chaotic."""
    lows = [(lo, claims_mod.code(lab)) for lo, _, lab in paper.SEQUENCE]
    return {
        "leave_p1": next((lo for lo, c in lows if c != P1), float("inf")),
        "first_chaos": next((lo for lo, c in lows if c == CHAOS), float("inf")),
    }


#: The distance from the paper's transition that earns no partial credit.
TRANSITION_SCALE = 0.1


def score_labels(paper: ModuleType, lab: CandidateLabels) -> dict[str, Json]:
    """Score of a candidate's labels, the scored fields of a :class:`Record`: claims that agree
    (:func:`geardyn.claims.evaluate`) plus the partial credit along the paper's main line (``CALIBRATION["line"]``)."""
    rows = claims_mod.evaluate(paper, lab)
    agree = sum(r.verdict == "agree" for r in rows)
    # a borderline claim (a fraction within its statistical uncertainty of the threshold,
    # geardyn.claims.fraction_verdict) is worth half an agreeing one: one point cannot flip the search
    half = sum(credit(r.verdict) for r in rows if r.verdict == "borderline")
    main = lab[paper.CALIBRATION["line"]]
    tr, want_tr = transitions(main.values, main.labels), paper_transitions(paper)
    parts = [max(0.0, 1.0 - abs(tr[k] - want_tr[k]) / TRANSITION_SCALE) if np.isfinite(tr[k]) else 0.0 for k in want_tr]
    ours, want = regime_string(main.labels), paper_regime_string(paper)
    parts.append(lcs(ours, want) / len(want))
    partial = float(np.mean(parts))
    verdicts = {r.id: r.verdict for r in rows}
    return dict(
        score=agree + half + 0.99 * partial, agree=agree, partial=partial, transitions=tr, order=ours, verdicts=verdicts
    )
