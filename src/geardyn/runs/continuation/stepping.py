"""The one stepper of continuation: the march of one direction with its step control and end tests
(:func:`march`, for branches and for curves), both directions from a seed (:func:`both_ways`), and
:func:`continue_branch`, which shoots the seed, marches both ways and assembles the
:class:`~geardyn.runs.continuation.branch.Branch` with its bifurcation points."""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import replace
from functools import partial
from typing import Any, TypeVar

import numpy as np

from geardyn import libm
from geardyn.runs.continuation.branch import Branch, ContinuationSettings
from geardyn.runs.continuation.corrector import BranchPoint, Corrector, merged_period
from geardyn.runs.continuation.events import detect_bifurcations
from geardyn.runs.continuation.family import Family
from geardyn.solve.shooting import newton_shooting, sorted_multipliers

log = logging.getLogger("geardyn.continuation")
P = TypeVar("P")


def _at_bound(
    corr: Corrector, st: BranchPoint, xp: np.ndarray, pp: float, lo: float, hi: float, cs: ContinuationSettings
) -> list[BranchPoint]:
    """The prediction (xp, pp) left [lo, hi]: the last point exactly on the bound, by fixed-p Newton
    from the prediction shortened to the bound (none when the branch runs along the bound, is
    already on it, or the shooting fails)."""
    d = st.x.size
    bound = hi if pp > hi else lo
    if abs(st.tangent[d]) < 1e-12:
        return []
    frac = (bound - st.p) / (pp - st.p)
    if frac <= 1e-9:
        return []
    xs = st.x + frac * (xp - st.x)
    r = newton_shooting(corr.family.flow(bound, corr.n), xs, corr.n, cs.tol)
    ev = corr.evaluate(r.state, bound) if r.converged else None
    pt = None if ev is None else corr.point(r.state, bound, ev, st.tangent, r.iterations + 1)
    return [] if pt is None or pt.tangent is None else [pt]


def march(
    start: P,
    advance: Callable[[P, float], tuple[list[P], str] | None],
    u_of: Callable[[P], np.ndarray],
    cs: Any,
    grow_at: int,
) -> tuple[list[P], str]:
    """Points along one direction from ``start`` (excluded); returns (points, end status).  ``advance(cur,
    ds)`` predicts and corrects one step: None when the corrector failed (ds halves, down to ``cs.ds_min``),
    else the points to add and a status that ends the march ("" to go on).  ds grows by 1.3 after a
    corrector of at most ``grow_at`` evaluations, never beyond ``cs.ds_max``; the march ends back at
    its start (``closed_loop``: an isola), past multipliers of modulus 1e8 or after ``cs.max_points``."""
    pts: list[P] = []
    cur, ds = start, cs.ds
    u_start = u_of(start)
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
        if len(pts) > 10 and float(np.linalg.norm(u_of(cur) - u_start)) < ds and float(cur.tangent @ start.tangent) > 0:
            return pts, "closed_loop"
        if cur.iterations <= grow_at:
            ds = min(ds * 1.3, cs.ds_max)
        if float(np.max(libm.cabs(cur.multipliers))) > 1e8:
            return pts, "multipliers_too_large"
    return pts, "max_points"


def both_ways(
    run: Callable[[P], tuple[list[P], str]], seed: P, directions: tuple[str, ...] = ("down", "up")
) -> tuple[list[P], dict[str, str]]:
    """The points of the marches ``run`` from ``seed`` in ``directions`` (``up``: along its tangent) in
    order along the tangent, the seed between, the down march's tangents flipped; the end statuses."""
    up, end_up = run(seed) if "up" in directions else ([], "not_followed")
    if end_up == "closed_loop":
        down, end_down = [], "closed_loop"  # the up march went round the whole isola
    else:
        down, end_down = run(replace(seed, tangent=-seed.tangent)) if "down" in directions else ([], "not_followed")
    down = [replace(q, tangent=-q.tangent) for q in reversed(down)]
    return [*down, seed, *up], {"down": end_down, "up": end_up}


def _advance(
    corr: Corrector, lo: float, hi: float, cur: BranchPoint, ds: float
) -> tuple[list[BranchPoint], str] | None:
    """One step of a branch within [lo, hi] (:func:`march`): ends on the bound (``range``), when the point
    is one of a shorter period (``merged_into_period_<m>``) or its tangent is singular."""
    xp, pp = corr.predict(cur, ds)
    if pp > hi or pp < lo:
        return _at_bound(corr, cur, xp, pp, lo, hi, corr.cs), "range"
    out = corr.correct(xp, pp, cur.tangent)
    if out is None:
        return None
    merged = merged_period(partial(corr.family.flow, out.p), out.x, corr.n, 1e-6 * corr.sx)
    if merged:
        return [], f"merged_into_period_{merged}"
    return ([], "singular_tangent") if out.tangent is None else ([out], "")


def _seed_tangent(A: np.ndarray, Fp: np.ndarray, sx: float, sp: float) -> np.ndarray:
    """Unit tangent at the seed: (dx/dp, 1) from A dx = -Fp in scaled variables ((0, 1) when A is
    singular), pointing towards increasing p."""
    d = A.shape[0]
    try:
        dxdp = np.linalg.solve(A, -Fp)
        t0 = np.append(dxdp * sp / sx, 1.0)
    except np.linalg.LinAlgError:
        t0 = np.zeros(d + 1)
        t0[d] = 1.0
    return t0 / np.linalg.norm(t0)


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
    """Shoot the period-n orbit at p0 from x0, then continue it within [lo, hi] in ``directions``
    (``up``: the direction of increasing p at the seed).

    Returns None when the shooting at p0 does not converge.  Bifurcations are detected (and located
    when ``cs.locate``) on the returned branch.
    """
    r = newton_shooting(family.flow(p0, n), x0, n, cs.tol)
    if not r.converged:
        log.info("seed at p = %g (period %d) not converged: %s", p0, n, r.status)
        return None
    sx = max(1.0, float(np.max(np.abs(r.state))))
    sp = (hi - lo) if hi > lo else 1.0
    corr = Corrector(family, n, sx, sp, cs)
    ev = corr.evaluate(r.state, p0)
    if ev is None:
        return None
    t0 = _seed_tangent(ev.A, ev.Fp, sx, sp)
    seed = BranchPoint(r.state, p0, sorted_multipliers(ev.M), t0, r.iterations)
    run = partial(march, advance=partial(_advance, corr, lo, hi), u_of=corr.scaled, cs=cs, grow_at=3)
    pts, ends = both_ways(run, seed, directions)
    down = next(i for i, q in enumerate(pts) if q is seed)
    br = _assemble(corr, pts, ends)
    return _cut_at_merge(corr, br, pts, down, ends) if n > 1 else br


def _cut_at_merge(corr: Corrector, br: Branch, pts: list[BranchPoint], seed: int, ends: dict[str, str]) -> Branch:
    """A fold of a period-n branch on a period-m orbit (m | n) is where the branch was born at (or
    merges back into) a period doubling of the period-m orbit: beyond it lies the same orbit shifted
    by m periods.  Cut the branch there (the period doubling is a point of the period-m branch);
    ``seed``: the index of the seed point in ``pts``."""
    for bf in br.bifurcations:
        m = merged_period(partial(corr.family.flow, bf.p), bf.state, corr.n, 1e-4 * corr.sx) if bf.kind == "fold" else 0
        if m:
            if bf.index >= seed:
                pts, ends["up"] = pts[: bf.index + 1], f"merged_into_period_{m}"
            else:
                pts, ends["down"] = pts[bf.index + 1 :], f"merged_into_period_{m}"
            return _assemble(corr, pts, ends)
    return br


def _assemble(corr: Corrector, pts: list[BranchPoint], ends: dict[str, str]) -> Branch:
    """The branch of the points in order: multipliers, arclength, grazing margins, bifurcations."""
    family, n, sx, sp, cs = corr.family, corr.n, corr.sx, corr.sp, corr.cs
    states = np.array([q.x for q in pts])
    ps = np.array([q.p for q in pts])
    mult = np.array([q.multipliers for q in pts])
    tang = np.array([q.tangent for q in pts])
    u = np.column_stack([states / sx, ps / sp])
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(u, axis=0), axis=1))])
    graz = np.array([family.grazing(q.p, q.x, n) for q in pts]) if cs.grazing else np.full(len(pts), np.nan)
    br = Branch(
        n=n,
        p=ps,
        states=states,
        multipliers=mult,
        arclength=arc,
        grazing=graz,
        iterations=np.array([q.iterations for q in pts], dtype=np.int32),
        end_status=dict(ends),
        tangents=tang,
    )
    br.bifurcations = detect_bifurcations(corr, br)
    return br
