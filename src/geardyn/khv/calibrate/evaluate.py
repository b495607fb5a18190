"""Evaluation of candidates: one candidate's record, and many on a process pool with a resumable cache."""

from __future__ import annotations

import functools
import json
import multiprocessing as mp
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING

import numpy as np

from geardyn.khv import point
from geardyn.khv.calibrate.objective import Grids, candidate_labels, ranked_score, score_labels
from geardyn.khv.calibrate.records import Record, cache_key, read_cache
from geardyn.khv.calibrate.space import SearchSpace
from geardyn.khv.design import KHVDesign
from geardyn.label import Policy
from geardyn.papers import paper_of
from geardyn.solve import warm_up

if TYPE_CHECKING:  # for the annotations only
    from geardyn.claims import Track


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


def evaluate_candidate(problem: Problem, unit: Sequence[float]) -> Record:
    """One candidate: its values, labels along every sweep, score and claims verdicts."""
    paper = paper_of(problem.paper) if isinstance(problem.paper, str) else problem.paper
    values = problem.space.values(unit)
    lab = candidate_labels(problem.design, {**problem.fixed, **values}, problem.grids, problem.policy)
    return Record(
        key=cache_key(unit),
        unit=[float(x) for x in unit],
        values=values,
        labels={role: _label_lists(lines) for role, lines in lab.items()},
        **score_labels(paper, lab),
    )


def _label_lists(lines: Track | Mapping[float, Track]) -> list[int] | dict[str, list[int]]:
    """The labels of a line as a list, of a family of lines as {f"{case:g}": list}."""
    if isinstance(lines, Mapping):
        return {f"{k:g}": [int(x) for x in t.labels] for k, t in lines.items()}
    return [int(x) for x in lines.labels]


def warm_worker(design: KHVDesign) -> None:
    """Compile the kernels in a worker (or in this process) before its first candidate."""
    warm_up(point.point_coefficients(design))


class Evaluator:
    """Evaluate many candidates: cached ones from the cache file, the others on a process pool
    (``workers``, forked; each task carries the problem, :func:`evaluate_candidate` bound to it), each new
    record appended to the cache as soon as it is done."""

    def __init__(self, problem: Problem, cache: str | Path, workers: int = 1):
        self.problem = problem
        self.cache_path = Path(cache)
        self.cache = read_cache(cache)
        self.workers = max(1, int(workers))
        self.pool, self.new, self.reused = None, 0, 0
        self.seen: dict[str, None] = {}

    def __enter__(self):
        if self.workers > 1:
            self.pool = mp.get_context("fork").Pool(self.workers, warm_worker, (self.problem.design,))
        else:
            warm_worker(self.problem.design)
        return self

    def __exit__(self, *exc):
        if self.pool is not None:
            self.pool.terminate()
            self.pool.join()

    def records(self, units: Sequence[Sequence[float]]) -> list[Record]:
        keys = [cache_key(u) for u in units]
        self.seen.update(dict.fromkeys(keys))
        todo = list({k: list(u) for k, u in zip(keys, units, strict=True) if k not in self.cache}.items())
        self.reused += len(units) - len(todo)
        if todo:
            evaluate = functools.partial(evaluate_candidate, self.problem)
            pending = [u for _, u in todo]
            it = self.pool.imap(evaluate, pending) if self.pool is not None else map(evaluate, pending)
            self.cache_path.parent.mkdir(parents=True, exist_ok=True)
            with open(self.cache_path, "a") as fh:
                for rec in it:
                    self.cache[rec.key] = rec
                    fh.write(json.dumps(rec.to_json()) + "\n")
                    fh.flush()
                    os.fsync(fh.fileno())
                    self.new += 1
        return [self.cache[k] for k in keys]

    def searched(self) -> list[Record]:
        """The records this evaluator was asked for, in the order first asked (the cache may hold others)."""
        return [self.cache[k] for k in self.seen]

    def __call__(self, x: np.ndarray) -> np.ndarray:
        """The vectorised objective of differential_evolution: x (N, S) -> -score (S,)."""
        units = np.atleast_2d(x.T) if x.ndim == 2 else x[None, :]
        recs = self.records([list(u) for u in units])
        return -np.array([ranked_score(r, self.problem.require) for r in recs])
