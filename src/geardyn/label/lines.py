"""The labeller's one entry point: :func:`label_lines`, which follows the attractor along lines of systems,
batching the free lines' next points and growing waiting records together (``docs/classify.md``)."""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

import geardyn.label._stages as st
from geardyn import libm
from geardyn.label._follow import follow
from geardyn.label._nonperiodic import exponents, longer_record
from geardyn.label._record import integrate, slow_transients
from geardyn.label.policy import Policy
from geardyn.label.verdict import Verdict
from geardyn.solve.base import System
from geardyn.solve.run import LaneTables, full_batch, lane_tables

log = logging.getLogger("geardyn.label")

#: Whether this process has been checked against :func:`geardyn.libm.canonical_process` (once per process: its
#: math build and BLAS kernels do not change while it runs).
_checked = False


def _warn_unless_canonical() -> None:
    """Log a warning, once per process, when it computes with other bits than a build's jobs (glibc's fused
    math build or other OpenBLAS kernels): its labels may differ from the build's (``docs/reproducibility.md``,
    section 5)."""
    global _checked
    if _checked:
        return
    _checked = True
    if libm.canonical_process():
        return
    log.warning(
        "this process runs the C library's %s math build (OpenBLAS %s), not a build's: labels may differ from "
        "the build's; start it with geardyn.libm.restart_canonical() (docs/reproducibility.md, section 5)",
        libm.variant(),
        libm.blas_core(),
    )


#: The stages of a batch's first pass, in order: each takes the points still undecided and the policy,
#: decides what it can and returns the rest (the last returns the points whose record is to grow).
STAGES: tuple[Callable[[list[st.Point], Policy], list[st.Point]], ...] = (
    follow,
    integrate,
    slow_transients,
    exponents,
)


def _first_pass(points: list[st.Point], policy: Policy) -> list[st.Point]:
    """Every stage of :data:`STAGES` in turn on the points still undecided; returns the points whose record
    is to grow."""
    for stage in STAGES:
        points = stage(points, policy)
    return points


@dataclass
class _Line:
    """A line on its way: its systems, fixed start, the verdicts so far (the next point is the one after
    them), the verdicts the line goes on from (a check of doubt's finding is not followed: ``Point.handed``)
    and the point that waits in the pool (None: the line is free)."""

    systems: Sequence[System]
    start: np.ndarray | None
    out: list[Verdict]
    chain: list[Verdict] = field(default_factory=list)
    waiting: st.Point | None = None

    @property
    def free(self) -> bool:
        return self.waiting is None and len(self.out) < len(self.systems)

    def place(self, p: st.Point, waits: bool) -> None:
        """The line's current point either waits in the pool (its record grows) or is decided."""
        self.waiting = p if waits else None
        if not waits:
            self.out.append(p.verdict)
            self.chain.append(p.handed or p.verdict)

    def point(self, tables: LaneTables, row: int) -> st.Point:
        """The line's next point, row ``row`` of its batch's ``tables``."""
        prev = self.chain[-1] if self.chain else None
        return st.Point(
            self.systems[len(self.out)],
            None if prev is None or prev.diverged else prev,
            self.start,
            self.chain[-2] if len(self.chain) > 1 else None,
            tables,
            row,
        )


def _schedule(lines: list[_Line], policy: Policy, progress: str) -> None:
    """Advance every line to its end.  Each batch is either the next points of all free lines (when there
    are enough to fill the lanes, :func:`geardyn.solve.run.full_batch`, or no point waits), or the
    next piece of every waiting point's growing record, as long as the shortest round has left: all
    waiting points in one batch, whatever the lengths of their records."""
    total, t0, shown = sum(len(ln.systems) for ln in lines), time.perf_counter(), 0
    while True:
        free = [ln for ln in lines if ln.free]
        busy = [ln for ln in lines if ln.waiting is not None]
        if free and (len(free) >= full_batch() or not busy):
            tables = lane_tables([ln.systems[len(ln.out)] for ln in free], policy.integration)
            batch, points = free, [ln.point(tables, r) for r, ln in enumerate(free)]
            grow = {id(p) for p in _first_pass(points, policy)}
        elif busy:
            batch, points = busy, [ln.waiting for ln in busy]
            grow = {id(p) for p in longer_record(points, min(p.left for p in points), policy)}
        else:
            return
        for ln, p in zip(batch, points, strict=True):
            ln.place(p, id(p) in grow)
        done = sum(len(ln.out) for ln in lines)
        if progress and (done - shown >= max(1, total // 10) or done == total):
            shown, elapsed = done, time.perf_counter() - t0
            log.info(
                "%s: %d/%d points, %.1f s elapsed, %.1f s remaining",
                progress,
                done,
                total,
                elapsed,
                elapsed / max(done, 1) * (total - done),
            )


def label_lines(
    lines: Sequence[Sequence[System]],
    policy: Policy,
    starts: Sequence[np.ndarray | None] | None = None,
    progress: str = "",
) -> list[list[Verdict]]:
    """Label every point of every line: ``out[i][k]`` is the verdict of point k of line i, from ``starts[i]``
    (None: the static deflection); a verdict depends only on its line (``docs/classify.md``) and on the process's
    math build (a warning where it is not a build's: :func:`_warn_unless_canonical`)."""
    _warn_unless_canonical()
    starts = [None] * len(lines) if starts is None else list(starts)
    if policy.start == "fixed":  # every point a line of its own, from its line's start
        singles = [([s], x0) for line, x0 in zip(lines, starts, strict=True) for s in line]
        it = iter(
            label_lines([s for s, _ in singles], policy.with_start("follow"), [x0 for _, x0 in singles], progress)
        )
        return [[next(it)[0] for _ in line] for line in lines]
    state = [
        _Line(line, None if x0 is None else np.asarray(x0, float), []) for line, x0 in zip(lines, starts, strict=True)
    ]
    _schedule(state, policy, progress)
    return [ln.out for ln in state]


def label_points(
    systems: Sequence[System], policy: Policy, starts: Sequence[np.ndarray | None] | None = None
) -> list[Verdict]:
    """Label independent points, each from its fixed start (a line of one point each)."""
    return [v for (v,) in label_lines([[s] for s in systems], policy, starts)]
