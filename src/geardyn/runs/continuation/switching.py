"""Branch switching: the period-2n branch born at a located period-doubling point of a period-n
branch, and the distinct branches through a set of seeds with those born at their period doublings."""

from __future__ import annotations

import logging
import math

import numpy as np

from geardyn import libm
from geardyn.runs.continuation.branch import Bifurcation, Branch, on_branch
from geardyn.runs.continuation.corrector import ContinuationSettings
from geardyn.runs.continuation.family import Family, KHVFamily
from geardyn.runs.continuation.stepping import continue_branch
from geardyn.solve.shooting import newton_shooting

#: The smallest parameter span of a branch that scales a distance (a branch of one point has none).
SPAN_FLOOR = 1e-12

log = logging.getLogger("geardyn.continuation")


def switch_at_period_doubling(
    family: Family, bf: Bifurcation, lo: float, hi: float, cs: ContinuationSettings = ContinuationSettings()
) -> Branch | None:
    """The period-2n branch born at a period-doubling point of a period-n branch: shot from the bifurcating
    orbit pushed along the eigenvector of the multiplier -1 a little past the point and continued away from it
    only (docs/orbits.md, section 3, "Branch switching"); None when none is found."""
    n = bf.n
    flow = family.flow(bf.p, n)
    phi, M = flow(bf.state, True)
    if phi is None:
        return None
    mu, vecs = np.linalg.eig(M)
    k = int(np.argmin(libm.cabs(mu + 1.0)))
    v = np.real(vecs[:, k])
    v /= float(np.max(np.abs(v)))
    scale = max(1.0, float(np.max(np.abs(bf.state))))
    span = hi - lo
    for frac in cs.switch_steps:
        for side in (1.0, -1.0):
            p = bf.p + side * frac * span
            if not lo <= p <= hi:
                continue
            for amp in cs.switch_amplitudes:
                x0 = bf.state + amp * scale * math.sqrt(frac) * v
                r = newton_shooting(family.flow(p, 2 * n), x0, 2 * n, cs.tol)
                if not r.converged:
                    continue
                back, _ = family.flow(p, n)(r.state, False)
                if back is None or float(np.max(np.abs(back - r.state))) < cs.merge_tol * scale:
                    continue  # the period-n orbit itself
                return continue_branch(family, p, r.state, 2 * n, lo, hi, cs, ("up",) if side > 0 else ("down",))
    return None


def add_branch(
    family: KHVFamily,
    p: float,
    x: np.ndarray,
    n: int,
    known: list[Branch],
    cs: ContinuationSettings,
    max_period: int = 0,
) -> Branch | None:
    """Continue the period-n orbit through x at p over the family's range unless it lies on a branch of
    ``known`` (within ``cs.seed_tol``); append it to ``known`` with the branches of its period doublings
    (:func:`doubled_branches`).  Returns the new branch."""
    cyc = family.cycle(p, x, n)
    if any(b.n == n and on_branch(b, p, cyc, cs.seed_tol) for b in known):
        return None
    br = continue_branch(family, p, x, n, family.lo, family.hi, cs)
    if br is not None:
        known.append(br)
        known.extend(doubled_branches(family, br, known, cs, max_period))
    return br


def doubled_branches(
    family: KHVFamily,
    br: Branch,
    known: list[Branch],
    cs: ContinuationSettings,
    max_period: int = 0,
    depth: int = 0,
) -> list[Branch]:
    """The period-2n branches born at the located period doublings of ``br`` (recursively, 2n <= max_period,
    five levels); a doubling whose orbit lies on a known period-2n branch (``cs.doubled_tol``, ``cs.touch_tol``:
    :func:`touches`) starts none."""
    out: list[Branch] = []
    for bf in br.bifurcations:
        if bf.kind != "period_doubling" or not bf.located or 2 * br.n > max_period:
            continue
        pts = family.cycle(bf.p, bf.state, br.n)
        seen = (b for b in known + out if b.n == 2 * br.n)
        if any(on_branch(b, bf.p, pts, cs.doubled_tol) or touches(b, bf.p, pts, cs.touch_tol) for b in seen):
            continue
        new = switch_at_period_doubling(family, bf, family.lo, family.hi, cs)
        if new is None:
            log.info("no period-%d branch found at the period doubling at %g", 2 * br.n, bf.p)
            continue
        log.info("P%d branch switched at %g: %d points, %d bifurcations", new.n, bf.p, len(new), len(new.bifurcations))
        out.append(new)
        if depth < 4:
            out.extend(doubled_branches(family, new, known + out, cs, max_period, depth + 1))
    return out


def touches(br: Branch, p: float, points: np.ndarray, tol: float) -> bool:
    """True when a point of ``br`` lies within ``tol`` (scaled: the branch's range, max(1, max |x|)) of one of
    ``points`` at p: a branch that ends at (or was cut just short of) a period doubling it was born at."""
    if tol <= 0.0:
        return False
    span = max(float(np.ptp(br.p)), SPAN_FLOOR)
    scale = max(1.0, float(np.max(np.abs(br.states))))
    dp = np.abs(br.p - p)[:, None] / span
    dx = np.max(np.abs(br.states[:, None, :] - points[None, :, :]), axis=2) / scale
    return bool(np.min(np.maximum(dp, dx)) < tol)
