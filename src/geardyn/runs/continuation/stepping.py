"""The one stepper of continuation (:func:`march`, for branches and curves, :func:`both_ways`, :func:`box_end`)
and :func:`continue_branch`, which shoots a seed, marches both ways and types the branch's points."""

from __future__ import annotations

import logging
from collections.abc import Callable, Sequence
from dataclasses import replace
from functools import partial

import numpy as np

from geardyn import libm
from geardyn.runs.continuation.branch import Branch
from geardyn.runs.continuation.corrector import (
    ContinuationSettings,
    Point,
    Problem,
    correct,
    merged,
    predict,
    tangent,
)
from geardyn.runs.continuation.events import detect_bifurcations
from geardyn.runs.continuation.family import Family
from geardyn.runs.continuation.problem import BranchProblem
from geardyn.solve.shooting import newton_shooting, sorted_multipliers

log = logging.getLogger("geardyn.continuation")


def march(
    start: Point,
    advance: Callable[[Point, float], tuple[list[Point], str] | None],
    scale: np.ndarray,
    cs: ContinuationSettings,
) -> tuple[list[Point], str]:
    """(points, end status) along one direction from ``start`` (excluded), with the step control of ``cs``.
    ``advance(cur, ds)`` steps once: None when the corrector failed, else the points to add and a status that ends
    the march ("" to go on); the march also ends back at its start (``closed_loop``: an isola)."""
    pts: list[Point] = []
    cur, ds = start, cs.ds
    u_start = start.z / scale
    while len(pts) < cs.max_points:
        out = advance(cur, ds)
        if out is None:
            ds *= 0.5
            if ds < cs.ds_min:
                return pts, "step_too_small"
            continue
        new, end = out
        pts += new
        if end:
            return pts, end
        cur = new[0]
        back = float(np.linalg.norm(cur.z / scale - u_start)) < ds and float(cur.tangent @ start.tangent) > 0
        if len(pts) > 10 and back:
            return pts, "closed_loop"
        if cur.iterations <= cs.grow_at:
            ds = min(ds * cs.ds_grow, cs.ds_max)
        if float(np.max(libm.cabs(cur.multipliers))) > cs.max_multiplier:
            return pts, "multipliers_too_large"
    return pts, "max_points"


def both_ways(
    run: Callable[[Point], tuple[list[Point], str]], seed: Point, directions: tuple[str, ...] = ("down", "up")
) -> tuple[list[Point], dict[str, str]]:
    """The points of the marches ``run`` from ``seed`` in ``directions`` (``up``: along its tangent) in order
    along the tangent, the seed between, the down march's tangents flipped; the end statuses."""
    up, end_up = run(seed) if "up" in directions else ([], "not_followed")
    down: list[Point]
    if end_up == "closed_loop":
        down, end_down = [], "closed_loop"  # the up march went round the whole isola
    else:
        down, end_down = run(replace(seed, tangent=-seed.tangent)) if "down" in directions else ([], "not_followed")
    down = [replace(q, tangent=-q.tangent) for q in reversed(down)]
    return [*down, seed, *up], {"down": end_down, "up": end_up}


def box_end(
    problem: Problem, a: Point, z_pred: np.ndarray, box: Sequence[float], cs: ContinuationSettings
) -> Point | None:
    """The point where the step from ``a`` to the prediction ``z_pred`` leaves ``box`` (lo, hi of each parameter):
    solved on the side it crosses first, from the prediction shortened to it; None when ``a`` is on that side
    already (within ``cs.locate_xtol`` of the step) or the corrector fails."""
    k0 = a.z.size - problem.npar
    fracs = []
    for k in range(problem.npar):
        v0, v1, lo, hi = a.z[k0 + k], z_pred[k0 + k], box[2 * k], box[2 * k + 1]
        bound = hi if v1 > hi else lo if v1 < lo else None
        if bound is not None:
            fracs.append(((bound - v0) / (v1 - v0), k, bound))
    frac, k, bound = min(fracs)
    if frac <= cs.locate_xtol:
        return None
    return correct(problem, a.z + frac * (z_pred - a.z), np.eye(a.z.size)[k0 + k], bound / problem.scale[k0 + k], cs, a)


def inside(z: np.ndarray, box: Sequence[float], npar: int) -> bool:
    """Whether the parameters of z lie in ``box``."""
    return all(box[2 * k] <= z[z.size - npar + k] <= box[2 * k + 1] for k in range(npar))


def _advance(prob: BranchProblem, box: tuple[float, float], cur: Point, ds: float) -> tuple[list[Point], str] | None:
    """One step of a branch within ``box`` (:func:`march`): ends on the bound (``range``) or when the point is one
    of a shorter period (``merged_into_period_<m>``)."""
    z, c = predict(prob, cur, ds)
    if not inside(z, box, 1):
        end = box_end(prob, cur, z, box, prob.cs)
        return ([] if end is None else [end]), "range"
    out = correct(prob, z, cur.tangent, c, prob.cs, cur)
    if out is None:
        return None
    m = merged(prob.family.cycle(out.p, out.x, prob.n), prob.n, prob.cs.merge_tol * prob.sx) if prob.n > 1 else 0
    return ([], f"merged_into_period_{m}") if m else ([out], "")


def continue_branch(
    family: Family,
    p0: float,
    x0: np.ndarray,
    n: int,
    lo: float,
    hi: float,
    cs: ContinuationSettings = ContinuationSettings(),
    directions: tuple[str, ...] = ("down", "up"),
) -> Branch | None:
    """Shoot the period-n orbit at p0 from x0, then continue it within [lo, hi] in ``directions`` (``up``: the
    direction of increasing p at the seed).  None when the shooting at p0 does not converge.  Bifurcations are
    detected (and located when ``cs.locate``) on the returned branch."""
    r = newton_shooting(family.flow(p0, n), x0, n, cs.tol)
    if not r.converged:
        log.info("seed at p = %g (period %d) not converged: %s", p0, n, r.status)
        return None
    sx = max(1.0, float(np.max(np.abs(r.state))))
    prob = BranchProblem(family, n, r.state.size, sx, (hi - lo) if hi > lo else 1.0, cs)
    z0 = np.append(r.state, p0)
    ev = prob.evaluate(z0, None)
    if ev is None:
        return None
    seed = Point(z0, sorted_multipliers(ev.M), tangent(ev.J * prob.scale, 1), r.iterations)
    run = partial(march, advance=partial(_advance, prob, (lo, hi)), scale=prob.scale, cs=cs)
    pts, ends = both_ways(run, seed, directions)
    br = _assemble(prob, pts, ends)
    return _cut_at_merge(prob, br, pts, next(i for i, q in enumerate(pts) if q is seed), ends) if n > 1 else br


def _cut_at_merge(prob: BranchProblem, br: Branch, pts: list[Point], seed: int, ends: dict[str, str]) -> Branch:
    """A fold of a period-n branch on a period-m orbit (m | n) is where the branch was born at (or merges back
    into) a period doubling of the period-m orbit: beyond it lies the same orbit shifted by m periods.  Cut the
    branch there (the period doubling is a point of the period-m branch); ``seed``: the seed's index in ``pts``."""
    tol = prob.cs.merge_tol_fold * prob.sx
    for bf in br.bifurcations:
        m = merged(prob.family.cycle(bf.p, bf.state, prob.n), prob.n, tol) if bf.kind == "fold" else 0
        if m:
            if bf.index >= seed:
                pts, ends["up"] = pts[: bf.index + 1], f"merged_into_period_{m}"
            else:
                pts, ends["down"] = pts[bf.index + 1 :], f"merged_into_period_{m}"
            return _assemble(prob, pts, ends)
    return br


def _assemble(prob: BranchProblem, pts: list[Point], ends: dict[str, str]) -> Branch:
    """The branch of the points in order: multipliers, arclength, grazing margins, bifurcations."""
    z = np.array([q.z for q in pts])
    u = z / prob.scale
    graz = [prob.family.grazing(q.p, q.x, prob.n) for q in pts] if prob.cs.grazing else np.full(len(pts), np.nan)
    br = Branch(
        n=prob.n,
        p=z[:, -1].copy(),
        states=z[:, :-1].copy(),
        multipliers=np.array([q.multipliers for q in pts]),
        arclength=np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(u, axis=0), axis=1))]),
        grazing=np.asarray(graz, dtype=float),
        iterations=np.array([q.iterations for q in pts], dtype=np.int32),
        end_status=dict(ends),
        tangents=np.array([q.tangent for q in pts]),
        sx=prob.sx,
        sp=prob.sp,
        settings=prob.cs,
    )
    br.bifurcations = detect_bifurcations(prob, br)
    return br
