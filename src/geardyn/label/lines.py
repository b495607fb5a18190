"""The labeller's one entry point: :func:`label_lines`.

A *line* is a sequence of systems along which the attractor is followed: a sweep case in one direction,
or one row of a regime map.  All lines of a batch advance together, point k of every line at once, so the
stages integrate one point per line in lockstep (:mod:`geardyn.label._stages` and the modules of its
stages).  The first point of a line starts from the line's fixed start (the static deflection unless
given); each next point starts from the verdict of the previous one.  With ``policy.start == "fixed"``
every point is a line of its own.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Sequence

import numpy as np

import geardyn.label._stages as st
from geardyn.label._follow import follow
from geardyn.label._nonperiodic import exponents
from geardyn.label._record import integrate, slow_transients
from geardyn.label.policy import Policy
from geardyn.label.verdict import Verdict
from geardyn.solve.base import System
from geardyn.solve.simulate import lane_tables

log = logging.getLogger("geardyn.label")


def _step(points: list[st.Point], policy: Policy) -> list[Verdict]:
    """Every stage in turn on the points still undecided."""
    left = follow(points, policy)
    left = integrate(left, policy)
    left = slow_transients(left, policy)
    exponents(left, policy)
    return [p.verdict for p in points]  # type: ignore[misc]


def label_lines(
    lines: Sequence[Sequence[System]],
    policy: Policy,
    starts: Sequence[np.ndarray | None] | None = None,
    progress: str = "",
) -> list[list[Verdict]]:
    """Label every point of every line: ``out[i][k]`` is the :class:`~geardyn.label.verdict.Verdict` of point
    k of line i.

    ``starts[i]``: the fixed initial state (6,) of line i (None: the static deflection of its first
    system).  With ``policy.start == "fixed"`` every point is a line of its own starting from its line's
    fixed start.  A verdict depends only on its line (its systems, in order, and its start), not on the other
    lines of the batch or on the number of threads.  ``progress``: a name for the log.
    """
    starts = [None] * len(lines) if starts is None else list(starts)
    if policy.start == "fixed":
        flat = [(i, k) for i, line in enumerate(lines) for k in range(len(line))]
        single = label_lines(
            [[lines[i][k]] for i, k in flat], policy.with_start("follow"), [starts[i] for i, _ in flat], progress
        )
        out: list[list[Verdict]] = [[None] * len(line) for line in lines]  # type: ignore[list-item]
        for (i, k), (v,) in zip(flat, single, strict=True):
            out[i][k] = v
        return out
    out = [[None] * len(line) for line in lines]  # type: ignore[list-item]
    prev: list[Verdict | None] = [None] * len(lines)
    prev2: list[Verdict | None] = [None] * len(lines)
    length = max((len(line) for line in lines), default=0)
    total, t0 = sum(len(line) for line in lines), time.perf_counter()
    for k in range(length):
        idx = [i for i, line in enumerate(lines) if k < len(line)]
        systems = [lines[i][k] for i in idx]
        tables = lane_tables(systems, policy.integration)  # every stage's runs of this step share them
        points = [
            st.Point(
                systems[r],
                None if prev[i] is None or prev[i].diverged else prev[i],
                None if starts[i] is None else np.asarray(starts[i], float),
                prev2[i],
                tables,
                r,
            )
            for r, i in enumerate(idx)
        ]
        for i, v in zip(idx, _step(points, policy), strict=True):
            out[i][k] = v
            prev2[i] = prev[i]
            prev[i] = v
        if progress and ((k + 1) % max(1, length // 10) == 0 or k + 1 == length):
            done = sum(min(k + 1, len(line)) for line in lines)
            elapsed = time.perf_counter() - t0
            log.info(
                "%s: %d/%d points, %.1f s elapsed, %.1f s remaining",
                progress,
                done,
                total,
                elapsed,
                elapsed / done * (total - done),
            )
    return out


def label_points(
    systems: Sequence[System], policy: Policy, starts: Sequence[np.ndarray | None] | None = None
) -> list[Verdict]:
    """Label independent points, each from its fixed start (a line of one point each)."""
    return [v for (v,) in label_lines([[s] for s in systems], policy, starts)]
