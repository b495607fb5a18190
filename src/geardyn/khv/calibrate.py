"""Calibration of a paper design's unknowns: a global search scored by the paper's own claims.

The unknowns of paper 1 (mesh frequency, carrier radius, shaft stiffnesses, damping ratios, TE
phase, planet mass; ``docs/calibration.md``) span a search space with bounds given in the config
(``calibration.<name>.search``).  A candidate is one vector of them; it is scored by
:func:`geardyn.claims.evaluate`, the function that writes ``claims.md``, applied to the labels the
candidate produces along x1 (Fig. 7) and along b and e at the paper's three x1 (Figs. 9, 11):

    score = (claims that agree) + 0.5 * (borderline claims) + 0.99 * partial,   partial in [0, 1]

(a borderline claim is a fraction within its statistical uncertainty of its threshold,
:func:`geardyn.claims.fraction_verdict`, the rule ``claims.md`` uses)

with partial credit for where the motion leaves P1 and where chaos starts along x1 (paper: 0.565,
0.593) and for the order of the regimes along x1 (longest common subsequence with the paper's
P1 -> QP -> Pn -> chaos -> Pn -> chaos).  The partial credit never outweighs one claim.

Labels come from the one labeller, :func:`geardyn.label.label_lines`, along the candidate's own x1, b
and e lines (each point follows the attractor of the previous one, as in the sweeps), so the figures,
``claims.md`` and the calibration score the same labels.

The optimiser is :func:`scipy.optimize.differential_evolution` (seeded, ``vectorized``, deferred
updating); every evaluated candidate is appended to a cache file keyed by its vector, so a rerun
with the same seed replays the cached evaluations and resumes where it stopped.
"""

from __future__ import annotations

import functools
import json
import math
import os
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np
import xarray as xr

from geardyn import claims as claims_mod
from geardyn import classify
from geardyn.khv import point
from geardyn.khv.design import KHVDesign
from geardyn.label import Policy, label_lines

P1, QP, CHAOS = 1, classify.LABELS["quasi_periodic"], classify.LABELS["chaotic"]
UNDET = classify.LABELS["undetermined"]

# ----------------------------------------------------------------------------------------------
# search space
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Unknown:
    """One searched unknown: an override name (``w`` or a KHVParameters field, SI), its bounds and
    whether it is searched on a log scale."""

    name: str
    low: float
    high: float
    log: bool = False

    def from_unit(self, u: float) -> float:
        if self.log:
            return float(math.exp(math.log(self.low) + u * (math.log(self.high) - math.log(self.low))))
        return float(self.low + u * (self.high - self.low))

    def to_unit(self, v: float) -> float:
        if self.log:
            return (math.log(v) - math.log(self.low)) / (math.log(self.high) - math.log(self.low))
        return (v - self.low) / (self.high - self.low)


@dataclass(frozen=True)
class SearchSpace:
    unknowns: tuple[Unknown, ...]

    @classmethod
    def from_config(cls, bounds: Mapping[str, Mapping[str, Any]]) -> SearchSpace:
        out = []
        for name, b in bounds.items():
            lo, hi = float(b["low"]), float(b["high"])
            if not lo < hi:
                raise ValueError(f"calibration bound of {name}: low {lo} must be below high {hi}")
            log = b.get("scale", "linear") == "log"
            if log and lo <= 0:
                raise ValueError(f"calibration bound of {name}: a log scale needs low > 0")
            out.append(Unknown(name, lo, hi, log))
        return cls(tuple(out))

    @property
    def names(self) -> list[str]:
        return [u.name for u in self.unknowns]

    def values(self, unit: Sequence[float]) -> dict[str, float]:
        """Overrides of a candidate given in the unit cube (each coordinate in [0, 1])."""
        return {u.name: u.from_unit(float(x)) for u, x in zip(self.unknowns, unit, strict=True)}

    def unit(self, values: Mapping[str, float]) -> np.ndarray:
        return np.array([u.to_unit(float(values[u.name])) for u in self.unknowns])


# ----------------------------------------------------------------------------------------------
# labels of one candidate
# ----------------------------------------------------------------------------------------------


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


# ----------------------------------------------------------------------------------------------
# objective: the claims
# ----------------------------------------------------------------------------------------------

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
REQUIREMENTS: dict[str, tuple[Callable[[Mapping[str, Any]], bool], str]] = {
    "route": (
        lambda rec: shows_route(np.asarray(rec["fig07"])),
        "Fig. 7 (x1 sweep, b = 2, e = 5) goes from period-1 through non-period-1 motion into chaos",
    ),
}

#: what a candidate that fails the requirement loses from its score (more than any score can be)
_UNMET = 100.0


def ranked_score(record: Mapping[str, Any], require: str | None = None) -> float:
    """The score the search ranks by: the claims score, less 100 when the record fails ``require``
    (:data:`REQUIREMENTS`), so a candidate that meets it beats every one that does not, and among
    those that meet it the claims decide."""
    if require is None:
        return float(record["score"])
    return float(record["score"]) - (0.0 if REQUIREMENTS[require][0](record) else _UNMET)


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


# ----------------------------------------------------------------------------------------------
# the search
# ----------------------------------------------------------------------------------------------


def cache_key(unit: Sequence[float]) -> str:
    return ",".join(f"{float(x):.12g}" for x in unit)


def read_cache(path: str | Path) -> dict[str, dict]:
    """Evaluations stored so far ({key: record}); a torn last line (interrupted write) is ignored."""
    out: dict[str, dict] = {}
    p = Path(path)
    if not p.exists():
        return out
    for line in p.read_text().splitlines():
        try:
            rec = json.loads(line)
        except json.JSONDecodeError:
            continue
        out[rec["key"]] = rec
    return out


@dataclass
class Problem:
    """Everything one evaluation needs (picklable, for a process pool)."""

    design: KHVDesign
    paper: ModuleType | str
    space: SearchSpace
    grids: Grids
    policy: Policy
    fixed: Mapping[str, float] = field(default_factory=dict)
    require: str | None = None  # a key of REQUIREMENTS: ranks by ranked_score


def evaluate_candidate(problem: Problem, unit: Sequence[float]) -> dict:
    """One candidate: its values, labels along every sweep, score and claims verdicts (a JSON record)."""
    from geardyn.papers import paper_of

    paper = paper_of(problem.paper) if isinstance(problem.paper, str) else problem.paper
    values = problem.space.values(unit)
    lab = candidate_labels(problem.design, {**problem.fixed, **values}, problem.grids, problem.policy)
    sc = score_labels(paper, lab)
    return {
        "key": cache_key(unit),
        "unit": [float(x) for x in unit],
        "values": values,
        "score": sc.score,
        "agree": sc.agree,
        "partial": sc.partial,
        "transitions": sc.transitions,
        "order": sc.order,
        "verdicts": {r.id: r.verdict for r in sc.rows},
        "fig07": [int(x) for x in lab.fig07.labels],
        "fig09": {f"{k:g}": [int(x) for x in t.labels] for k, t in lab.fig09.items()},
        "fig11": {f"{k:g}": [int(x) for x in t.labels] for k, t in lab.fig11.items()},
    }


_PROBLEM: Problem | None = None


def _init_worker(problem: Problem) -> None:
    global _PROBLEM
    _PROBLEM = problem
    from geardyn.solve import warm_up

    warm_up(point.point_coefficients(problem.design))


def _worker(unit: Sequence[float]) -> dict:
    assert _PROBLEM is not None
    return evaluate_candidate(_PROBLEM, unit)


class Evaluator:
    """Evaluate many candidates: cached ones from the cache file, the others on a process pool
    (``workers``), each new record appended to the cache as soon as it is done."""

    def __init__(self, problem: Problem, cache: str | Path, workers: int = 1):
        self.problem = problem
        self.cache_path = Path(cache)
        self.cache = read_cache(cache)
        self.workers = max(1, int(workers))
        self.pool = None
        self.new = 0
        self.reused = 0
        self.seen: dict[str, None] = {}

    def __enter__(self):
        if self.workers > 1:
            import multiprocessing as mp

            self.pool = mp.get_context("fork").Pool(self.workers, _init_worker, (self.problem,))
        else:
            _init_worker(self.problem)
        return self

    def __exit__(self, *exc):
        if self.pool is not None:
            self.pool.terminate()
            self.pool.join()

    def records(self, units: Sequence[Sequence[float]]) -> list[dict]:
        keys = [cache_key(u) for u in units]
        self.seen.update(dict.fromkeys(keys))
        todo = [(k, list(u)) for k, u in zip(keys, units, strict=True) if k not in self.cache]
        todo = list(dict(todo).items())
        self.reused += len(units) - len(todo)
        if todo:
            it = (
                self.pool.imap(_worker, [u for _, u in todo])
                if self.pool is not None
                else map(_worker, [u for _, u in todo])
            )
            self.cache_path.parent.mkdir(parents=True, exist_ok=True)
            with open(self.cache_path, "a") as fh:
                for rec in it:
                    self.cache[rec["key"]] = rec
                    fh.write(json.dumps(rec) + "\n")
                    fh.flush()
                    os.fsync(fh.fileno())
                    self.new += 1
        return [self.cache[k] for k in keys]

    def __call__(self, x: np.ndarray) -> np.ndarray:
        """The vectorised objective of differential_evolution: x (N, S) -> -score (S,)."""
        units = np.atleast_2d(x.T) if x.ndim == 2 else x[None, :]
        recs = self.records([list(u) for u in units])
        return -np.array([ranked_score(r, self.problem.require) for r in recs])


def refine(
    space: SearchSpace, evaluator: Evaluator, start: dict, steps: Sequence[float] = (0.1, 0.02), rounds: int = 2
) -> dict:
    """Deterministic local refinement after the global search: in each round every unknown is moved by
    +-step (:func:`perturbed`, all moves of a round evaluated together); the best move is taken if it
    raises the score (:func:`ranked_score`), else the next smaller step is tried; stops after ``rounds``
    improvements or when no move improves."""
    best = start
    k, done = 0, 0
    steps = sorted(steps, reverse=True)
    rank = functools.partial(ranked_score, require=evaluator.problem.require)
    while k < len(steps) and done < rounds:
        units = []
        for u in space.unknowns:
            for sign in (-1.0, 1.0):
                v = dict(best["values"])
                v[u.name] = perturbed(v[u.name], u, sign * steps[k])
                units.append(list(space.unit(v)))
        recs = evaluator.records(units)
        cand = max(recs, key=rank)
        if rank(cand) > rank(best):
            best, done = cand, done + 1
        else:
            k += 1
    return best


def search(
    problem: Problem,
    cache: str | Path,
    seed: int = 1,
    popsize: int = 6,
    maxiter: int = 4,
    workers: int = 1,
    init: Sequence[Mapping[str, float]] = (),
    refine_steps: Sequence[float] = (0.1, 0.02),
    refine_rounds: int = 2,
) -> tuple[dict, Evaluator]:
    """Differential evolution over the unit cube of ``problem.space``, then :func:`refine` from its best;
    returns (best record, evaluator).  Only the candidates this run asked for count (the cache may hold
    others, e.g. of a sensitivity study).

    ``init``: candidates (values) placed in the initial population (e.g. the design's current
    values), the rest Latin-hypercube from ``seed``.  Deterministic: same seed, same candidates, so
    a rerun replays the cache.
    """
    from scipy.optimize import differential_evolution
    from scipy.stats import qmc

    dim = len(problem.space.unknowns)
    n_pop = max(5, popsize * dim)
    pop = qmc.LatinHypercube(d=dim, seed=seed).random(n_pop)
    for i, v in enumerate(init):
        pop[i] = np.clip(problem.space.unit(v), 0.0, 1.0)
    with Evaluator(problem, cache, workers) as ev:
        differential_evolution(
            ev,
            [(0.0, 1.0)] * dim,
            init=pop,
            maxiter=maxiter,
            seed=seed,
            polish=False,
            vectorized=True,
            updating="deferred",
            tol=0.0,
            atol=0.0,
        )
        recs = [ev.cache[k] for k in ev.seen]
        best_rec = max(recs, key=lambda r: (ranked_score(r, problem.require), interior(r["unit"])))
        if refine_rounds > 0 and refine_steps:
            best_rec = refine(problem.space, ev, best_rec, refine_steps, refine_rounds)
    return best_rec, ev


def interior(unit: Sequence[float]) -> float:
    """Distance of a unit vector from the nearest bound (0 on an edge, 0.5 at the centre)."""
    u = np.clip(np.asarray(unit, float), 0.0, 1.0)
    return float(np.min(np.minimum(u, 1.0 - u)))


def verified_choice(
    search_records: Sequence[dict],
    verify: Callable[[list[list[float]]], list[dict]],
    top: int,
    require: str | None = None,
) -> tuple[dict, dict, list[tuple[dict, dict]]]:
    """Re-score the ``top`` best candidates of the search with ``verify`` (the design's own integration
    settings and the default classifier) and choose by (verified score, search score, distance from
    the bounds): an optimum inside the region beats an equal one on its edge.  Scores are ranked by
    :func:`ranked_score`: with ``require``, a candidate must meet it at the design's settings too.
    Returns (search record, verified record, all pairs)."""
    order = sorted(search_records, key=lambda r: (-ranked_score(r, require), -interior(r["unit"])))[: max(1, top)]
    checked = verify([r["unit"] for r in order])
    pairs = list(zip(order, checked, strict=True))
    best_pair = max(
        pairs, key=lambda p: (ranked_score(p[1], require), ranked_score(p[0], require), interior(p[0]["unit"]))
    )
    return best_pair[0], best_pair[1], pairs


def records_dataset(records: Sequence[dict], space: SearchSpace, grids: Grids) -> xr.Dataset:
    """All evaluated candidates as a dataset (candidate order: order of evaluation)."""
    n = len(records)
    data: dict = {
        "score": (
            "candidate",
            np.array([r["score"] for r in records]),
            {"units": "1", "long_name": "claims that agree + 0.99 * partial credit"},
        ),
        "agree": (
            "candidate",
            np.array([r["agree"] for r in records], np.int16),
            {"units": "1", "long_name": "claims that agree (of those the labels decide)"},
        ),
        "partial": (
            "candidate",
            np.array([r["partial"] for r in records]),
            {"units": "1", "long_name": "partial credit: transition positions and regime order"},
        ),
        "leave_p1": (
            "candidate",
            np.array([r["transitions"]["leave_p1"] for r in records]),
            {"units": "1", "long_name": "first x1 not P1"},
        ),
        "first_chaos": (
            "candidate",
            np.array([r["transitions"]["first_chaos"] for r in records]),
            {"units": "1", "long_name": "first chaotic x1"},
        ),
        "label": (
            ("candidate", "x1"),
            np.array([r["fig07"] for r in records], np.int16).reshape(n, grids.x1.size),
            {
                "units": "1",
                "long_name": "motion label along x1 after the slow-transient check (geardyn.classify codes)",
            },
        ),
    }
    for k, u in enumerate(space.unknowns):
        data[u.name] = (
            "candidate",
            np.array([r["values"][u.name] for r in records]),
            {
                "units": point.units_of(u.name),
                "long_name": f"candidate value of {u.name}",
                "search_low": u.low,
                "search_high": u.high,
                "search_scale": "log" if u.log else "linear",
            },
        )
    coords = {
        "candidate": ("candidate", np.arange(n), {"units": "1", "long_name": "candidate (evaluation order)"}),
        "x1": ("x1", grids.x1, {"units": "1", "long_name": "planet profile-shift coefficient x1"}),
    }
    return xr.Dataset(data, coords=coords)


RegimeSequence = Sequence[tuple[float, float, "int | str"]]


def _with_values(
    source: str, name: str, values: Mapping[str, float], note: str = "calibrated"
) -> tuple[dict[str, Any], str | None]:
    """The source design (YAML text) renamed, titled "(calibrated)", with ``values`` written into its
    ``dynamics.parameters`` (w and speed as omega_bar and input_speed_rpm; b, e and x1 stay run values).
    Returns the design dict and the source design's name."""
    import yaml

    data = yaml.safe_load(source)
    source_name = data.get("name")
    data["name"] = name
    data["title"] = f"{data.get('title', '')} ({note})"
    params = data.setdefault("dynamics", {}).setdefault("parameters", {})
    renames = {"w": "omega_bar", "speed": "input_speed_rpm"}
    for key, value in values.items():
        if key in ("b", "e", "x1"):
            continue
        params[renames.get(key, key)] = float(value)
    return data, source_name


# ----------------------------------------------------------------------------------------------
# products of a search: the calibrated design file, tables, sensitivity
# ----------------------------------------------------------------------------------------------

#: the header line that carries the search result in a calibrated design file (machine-readable)
RESULT_PREFIX = "# search-result: "


def search_result(
    record: Mapping[str, Any],
    spec_name: str,
    n_evaluations: int,
    verified: Mapping[str, Any] | None = None,
    require: str | None = None,
) -> dict:
    """The part of a best record a calibrated design file stores (enough to regenerate it); ``verified``:
    the same candidate re-scored at the design's own settings."""
    out = {
        "search": spec_name,
        "evaluations": int(n_evaluations),
        "score": round(float(record["score"]), 6),
        "agree": int(record["agree"]),
        "agreeing": sorted(k for k, v in record["verdicts"].items() if v == "agree"),
        "values": {k: float(f"{v:.6g}") for k, v in record["values"].items()},
    }
    if require is not None:
        out["require"] = require
        out["meets_requirement"] = bool(REQUIREMENTS[require][0](record))
    if verified is not None:
        out["verified_score"] = round(float(verified["score"]), 6)
        out["verified_agreeing"] = sorted(k for k, v in verified["verdicts"].items() if v == "agree")
    return out


def search_design_text(source: str, name: str, result: Mapping[str, Any]) -> str:
    """A calibrated design file: the source design with the searched values written into it, and a
    header that says it is calibrated, what it was fitted to, and the search result (one JSON line
    from which this text is regenerated: :func:`design_text_from_file`)."""
    import yaml

    note = "calibrated" + (f", {result['require']} required" if result.get("require") else "")
    data, source_name = _with_values(source, name, result["values"], note)
    header = (
        f"# GENERATED by the calibration search '{result['search']}' from design '{source_name}'; do not edit.\n"
        "# CALIBRATED: the values in the search result below are fitted to the paper, not taken from it.\n"
        "# Fitted to paper 1's claims (geardyn.claims.evaluate on the labels along x1 at b = 2, e = 5 and\n"
        "# along b and e at x1 = 0.5, 0.761, 0.83; reduced integration settings, docs/calibration.md).\n"
        + (
            f"# Required: {REQUIREMENTS[result['require']][1]}; among the candidates that meet it the claims\n"
            "# decide, so it may agree on fewer claims than a search without the requirement.\n"
            if result.get("require")
            else ""
        )
        + f"# Best of {result['evaluations']} evaluated candidates: score {result['score']:.3f}, "
        f"{result['agree']} claims agree during the search: {', '.join(result['agreeing'])}.\n"
        + (
            f"# Verified at the design's own settings: score {result['verified_score']:.3f}, "
            f"{len(result['verified_agreeing'])} agree: {', '.join(result['verified_agreeing'])}.\n"
            if "verified_score" in result
            else ""
        )
        + RESULT_PREFIX
        + json.dumps(result, sort_keys=True)
        + "\n"
    )
    return header + yaml.safe_dump(data, sort_keys=False)


def design_text_from_file(text: str, source: str) -> str:
    """Regenerate a calibrated design file from its own search-result line and the source design."""
    import yaml

    line = next(ln for ln in text.splitlines() if ln.startswith(RESULT_PREFIX))
    result = json.loads(line[len(RESULT_PREFIX) :])
    name = yaml.safe_load(text)["name"]
    return search_design_text(source, name, result)


def design_values(design: KHVDesign, space: SearchSpace) -> dict[str, float]:
    """The values a design has for the searched unknowns (the start of a search, a reference)."""
    phys, _, _ = point.point_model(design, {})
    out = {}
    for u in space.unknowns:
        out[u.name] = float(phys.omega_bar) if u.name == "w" else float(getattr(phys, u.name))
    return out


def search_table(
    records: Sequence[dict],
    space: SearchSpace,
    paper: ModuleType,
    best_rec: dict,
    cost: Mapping[str, float],
    top: int = 10,
    verified: dict | None = None,
    pairs: Sequence[tuple[dict, dict]] = (),
) -> str:
    """Markdown: the best candidates, the best one's bands along x1 beside the paper's, its claims."""
    order = sorted(range(len(records)), key=lambda i: -records[i]["score"])[:top]
    names = space.names
    lines = [
        f"# Calibration search: {len(records)} candidates scored by paper 1's claims",
        "",
        "Score = claims that agree + 0.99 x partial credit (transition positions, regime order); docs/calibration.md.",
        "",
        "Cost: " + ", ".join(f"{k} {v:.3g}" for k, v in cost.items()),
        "",
        "| rank | " + " | ".join(names) + " | agree | partial | leave P1 | first chaos | order | score |",
        "|---|" + "---|" * len(names) + "---|---|---|---|---|---|",
    ]
    for rank, i in enumerate(order, 1):
        r = records[i]
        vals = " | ".join(f"{r['values'][n]:.4g}" for n in names)
        lines.append(
            f"| {rank} | {vals} | {r['agree']} | {r['partial']:.3f} | {r['transitions']['leave_p1']:.4g} | "
            f"{r['transitions']['first_chaos']:.4g} | {r['order']} | {r['score']:.3f} |"
        )
    if pairs:
        lines += [
            "",
            "Verification of the best at the design's own settings (512 steps, 500 + 100 periods, default "
            "classifier with the slow-transient check); the chosen one has the highest verified score (ties: search score, then "
            "distance from the bounds):",
            "",
            "| " + " | ".join(names) + " | search score | verified score | verified agree | distance from bounds |",
            "|" + "---|" * (len(names) + 4),
        ]
        for a, b in pairs:
            lines.append(
                "| "
                + " | ".join(f"{a['values'][n]:.4g}" for n in names)
                + f" | {a['score']:.3f} | {b['score']:.3f} | {b['agree']} | {interior(a['unit']):.3f} |"
            )
    rec = verified if verified is not None else best_rec
    lines += [
        "",
        f"Paper's transitions along x1: {', '.join(f'{t:g}' for t in paper.TRANSITIONS)}; "
        f"paper's regime order {paper_regime_string(paper)} (1 = P1, Q = QP, n = period > 1, C = chaos).",
        "",
        f"Chosen candidate: leaves P1 at x1 = {rec['transitions']['leave_p1']:.4g}, first chaos at "
        f"{rec['transitions']['first_chaos']:.4g}, regime order {rec['order']}.",
        "",
        "Chosen candidate's claims verdicts (search settings; verified settings; static claims and those that "
        "need dense runs are not evaluated here):",
        "",
        "| claim | search | verified |",
        "|---|---|---|",
    ]
    lines += [
        f"| {k} | {v} | {(verified or {}).get('verdicts', {}).get(k, '-')} |" for k, v in best_rec["verdicts"].items()
    ]
    return "\n".join(lines) + "\n"


def perturbed(value: float, unknown: Unknown, step: float) -> float:
    """``value`` moved by the relative ``step`` (e.g. -0.1); a phase (or any value at 0) moves by
    ``step`` times its search range."""
    if unknown.name == "te_phase" or value == 0.0:
        return float(value + step * (unknown.high - unknown.low))
    return float(value * (1.0 + step))


def problem_from_config(design: KHVDesign, spec: Mapping[str, Any]) -> tuple[Problem, dict]:
    """The search problem and its budget (seed, popsize, maxiter) from a ``calibration`` entry."""
    from geardyn.papers import paper_of

    paper = paper_of(design.paper)
    s = spec["search"]
    space = SearchSpace.from_config(s["bounds"])
    grids = Grids.from_config(spec, paper)
    policy = Policy.from_spec(point.integration_settings(design, **spec.get("integration", {})), spec)
    budget = dict(s["thorough_budget"] if s.get("thorough") else s["budget"])
    budget.setdefault("seed", int(s.get("seed", 1)))
    ref = s.get("refine", {})
    budget["refine_steps"] = tuple(ref.get("steps", (0.1, 0.02)))
    budget["refine_rounds"] = int(ref.get("rounds", 2))
    return Problem(design, design.paper, space, grids, policy, dict(spec.get("fixed", {})), s.get("require")), budget


def sensitivity(
    problem: Problem,
    evaluator: Evaluator,
    best_values: Mapping[str, float],
    steps: Sequence[float],
    map_points: int = 7,
) -> tuple[xr.Dataset, xr.Dataset, str]:
    """Robustness and sensitivity of the best candidate.

    One-at-a-time moves of each unknown by +-step (:func:`perturbed`) give the score, the number of
    agreeing claims and the transitions along x1 (tornado); the smallest move that changes any claim
    verdict, or any label along x1, is the distance to the nearest label change.  Then a 2-D map of
    the score over the two unknowns whose moves change the score most (+-50 %, ``map_points`` per
    axis).  Returns (one-at-a-time dataset, map dataset, Markdown summary).
    """
    space = problem.space
    base_unit = space.unit(best_values)
    base = evaluator.records([list(base_unit)])[0]
    steps = sorted(float(s) for s in steps)
    signed = [-s for s in reversed(steps)] + steps
    units, where = [], []
    for u in space.unknowns:
        for st in signed:
            v = dict(best_values)
            v[u.name] = perturbed(best_values[u.name], u, st)
            units.append(list(space.unit(v)))
            where.append((u.name, st))
    recs = evaluator.records(units)
    names = space.names
    shape = (len(names), len(signed))

    def grid(key, fn):
        return np.array([fn(r) for r in recs], float).reshape(shape)

    oat = xr.Dataset(
        {
            "score": (("unknown", "step"), grid("score", lambda r: r["score"]), {"units": "1", "long_name": "score"}),
            "agree": (
                ("unknown", "step"),
                grid("agree", lambda r: r["agree"]),
                {"units": "1", "long_name": "claims that agree"},
            ),
            "leave_p1": (
                ("unknown", "step"),
                grid("l", lambda r: r["transitions"]["leave_p1"]),
                {"units": "1", "long_name": "first x1 not P1"},
            ),
            "first_chaos": (
                ("unknown", "step"),
                grid("c", lambda r: r["transitions"]["first_chaos"]),
                {"units": "1", "long_name": "first chaotic x1"},
            ),
            "verdicts_changed": (
                ("unknown", "step"),
                grid("v", lambda r: float(r["verdicts"] != base["verdicts"])),
                {"units": "1", "long_name": "1 when any claim verdict differs from the best's"},
            ),
            "labels_changed": (
                ("unknown", "step"),
                grid("x", lambda r: float(r["fig07"] != base["fig07"])),
                {"units": "1", "long_name": "1 when any label along x1 differs from the best's"},
            ),
        },
        coords={
            "unknown": ("unknown", names, {"units": "1", "long_name": "searched unknown"}),
            "step": ("step", np.array(signed), {"units": "1", "long_name": "relative move of the unknown"}),
        },
        attrs={
            "base_score": base["score"],
            "base_agree": base["agree"],
            "base_leave_p1": base["transitions"]["leave_p1"],
            "base_first_chaos": base["transitions"]["first_chaos"],
        },
    )
    # the two unknowns that matter most
    impact = np.nanmax(np.abs(oat["score"].values - base["score"]), axis=1)
    order = np.argsort(-impact, kind="stable")
    a, b = space.unknowns[order[0]], space.unknowns[order[1]]
    rel = np.linspace(-0.5, 0.5, map_points)
    va = [perturbed(best_values[a.name], a, r) for r in rel]
    vb = [perturbed(best_values[b.name], b, r) for r in rel]
    units = []
    for y in vb:
        for x in va:
            v = dict(best_values)
            v[a.name], v[b.name] = x, y
            units.append(list(space.unit(v)))
    mrecs = evaluator.records(units)
    mshape = (map_points, map_points)
    mp = xr.Dataset(
        {
            "score": (
                (b.name, a.name),
                np.array([r["score"] for r in mrecs]).reshape(mshape),
                {"units": "1", "long_name": "score"},
            ),
            "agree": (
                (b.name, a.name),
                np.array([r["agree"] for r in mrecs]).reshape(mshape),
                {"units": "1", "long_name": "claims that agree"},
            ),
            "leave_p1": (
                (b.name, a.name),
                np.array([r["transitions"]["leave_p1"] for r in mrecs]).reshape(mshape),
                {"units": "1", "long_name": "first x1 not P1"},
            ),
        },
        coords={
            a.name: (
                a.name,
                np.array(va),
                {"units": point.units_of(a.name), "long_name": f"{a.name} (searched unknown)"},
            ),
            b.name: (
                b.name,
                np.array(vb),
                {"units": point.units_of(b.name), "long_name": f"{b.name} (searched unknown)"},
            ),
        },
        attrs={"x": a.name, "y": b.name, "best_x": best_values[a.name], "best_y": best_values[b.name]},
    )
    # summary
    lines = [
        "# Calibration: robustness and sensitivity of the best candidate",
        "",
        f"Best: score {base['score']:.3f}, {base['agree']} claims agree, leaves P1 at x1 = "
        f"{base['transitions']['leave_p1']:.4g}, first chaos at {base['transitions']['first_chaos']:.4g}.",
        "",
        "| unknown | value | bounds | position in bounds | smallest move changing a verdict | smallest move "
        "changing a label along x1 | max score change |",
        "|---|---|---|---|---|---|---|",
    ]
    for k, u in enumerate(space.unknowns):
        vc = oat["verdicts_changed"].values[k]
        lc = oat["labels_changed"].values[k]
        dv = min((abs(s) for s, c in zip(signed, vc, strict=True) if c), default=None)
        dl = min((abs(s) for s, c in zip(signed, lc, strict=True) if c), default=None)
        pos = u.to_unit(best_values[u.name])
        lines.append(
            f"| {u.name} | {best_values[u.name]:.4g} | [{u.low:g}, {u.high:g}]{' log' if u.log else ''} | "
            f"{pos:.2f}{' (edge)' if min(pos, 1 - pos) < 0.05 else ''} | "
            f"{'> ' + format(max(steps), 'g') if dv is None else '+-' + format(dv, 'g')} | "
            f"{'> ' + format(max(steps), 'g') if dl is None else '+-' + format(dl, 'g')} | {impact[k]:.3f} |"
        )
    lines += [
        "",
        f"2-D map over {a.name} and {b.name} (the two with the largest score change): best score on the map "
        f"{float(mp['score'].max()):.3f}, at the centre {base['score']:.3f}.",
    ]
    return oat, mp, "\n".join(lines) + "\n"
