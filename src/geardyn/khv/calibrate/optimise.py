"""The search: differential evolution over the unit cube, a local refinement, the verified choice."""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import numpy as np
from scipy.optimize import differential_evolution
from scipy.stats import qmc

from geardyn.jsontypes import Json
from geardyn.khv import point
from geardyn.khv.calibrate.evaluate import Evaluator, Problem
from geardyn.khv.calibrate.objective import Grids, ranked_score
from geardyn.khv.calibrate.records import Record
from geardyn.khv.calibrate.space import SearchSpace, interior
from geardyn.khv.design import KHVDesign
from geardyn.label import Policy
from geardyn.papers import paper_of


def refine(
    space: SearchSpace, evaluator: Evaluator, start: Record, steps: Sequence[float] = (0.1, 0.02), rounds: int = 2
) -> Record:
    """Deterministic local refinement: each round moves every unknown by +-step (:func:`perturbed`, evaluated
    together) and takes the best move if it raises :func:`ranked_score`, else tries the next smaller step; stops
    after ``rounds`` improvements or when no move improves."""
    best = start
    k, done = 0, 0
    steps = sorted(steps, reverse=True)
    rank = functools.partial(ranked_score, require=evaluator.problem.require)
    while k < len(steps) and done < rounds:
        cand = max(evaluator.records(space.one_at_a_time(best.values, (-steps[k], steps[k]))), key=rank)
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
) -> tuple[Record, Evaluator]:
    """Differential evolution over the unit cube of ``problem.space`` (``init`` in the initial population, the rest
    Latin-hypercube from ``seed``), then :func:`refine` from its best: (best record, evaluator); deterministic, so a
    rerun replays the cache."""
    dim = len(problem.space.unknowns)
    pop = qmc.LatinHypercube(d=dim, seed=seed).random(max(5, popsize * dim))
    for i, v in enumerate(init):
        pop[i] = np.clip(problem.space.unit(v), 0.0, 1.0)
    with Evaluator(problem, cache, workers) as ev:
        fixed = {"polish": False, "vectorized": True, "updating": "deferred", "tol": 0.0, "atol": 0.0}
        differential_evolution(ev, [(0.0, 1.0)] * dim, init=pop, maxiter=maxiter, seed=seed, **fixed)
        recs = ev.searched()
        best_rec = max(recs, key=lambda r: (ranked_score(r, problem.require), interior(r.unit)))
        if refine_rounds > 0 and refine_steps:
            best_rec = refine(problem.space, ev, best_rec, refine_steps, refine_rounds)
    return best_rec, ev


def verified_choice(
    search_records: Sequence[Record],
    verify: Callable[[list[list[float]]], list[Record]],
    top: int,
    require: str | None = None,
) -> tuple[Record, Record, list[tuple[Record, Record]]]:
    """Re-score the ``top`` best candidates with ``verify`` (the design's own settings) and choose by
    (verified, search :func:`ranked_score`, distance from the bounds: inside beats an equal one on the edge).
    Returns (search record, verified record, all pairs)."""
    order = sorted(search_records, key=lambda r: (-ranked_score(r, require), -interior(r.unit)))[: max(1, top)]
    pairs = list(zip(order, verify([r.unit for r in order]), strict=True))
    best_pair = max(
        pairs, key=lambda p: (ranked_score(p[1], require), ranked_score(p[0], require), interior(p[0].unit))
    )
    return best_pair[0], best_pair[1], pairs


def problem_from_config(design: KHVDesign, spec: Mapping[str, Json]) -> tuple[Problem, dict]:
    """The search problem and its budget (seed, popsize, maxiter) from a ``calibration`` entry."""
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
    return Problem(design, design.paper, space, grids, policy, dict(spec.get("fixed", {})), s.get("require")), budget  # type: ignore[arg-type]
