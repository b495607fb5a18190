"""The corrector: Newton on the pseudo-arclength system in scaled variables u = (x / sx, p / sp),
the unit tangent of the branch, and the test for a period-n orbit that is already a fixed point of
a shorter map.  Its results are named records (:class:`Evaluation`, :class:`BranchPoint`)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from geardyn.runs.continuation.branch import ContinuationSettings
from geardyn.runs.continuation.family import Family
from geardyn.solve.shooting import FlowMap, sorted_multipliers


@dataclass(frozen=True)
class Evaluation:
    """F = phi_nT(x) - x, A = dF/dx = M - I, Fp = dF/dp and the monodromy M at one (x, p)."""

    F: np.ndarray
    A: np.ndarray
    Fp: np.ndarray
    M: np.ndarray


@dataclass(frozen=True)
class BranchPoint:
    """A point of a branch: the orbit's state x at phase 0, the parameter p, the sorted multipliers, the unit
    tangent in the scaled variables (oriented along the march; None where singular), the corrector
    evaluations, and u, the arclength fraction of the step it lies on (event location)."""

    x: np.ndarray
    p: float
    multipliers: np.ndarray
    tangent: np.ndarray | None
    iterations: int = 0
    u: float = 0.0


class Corrector:
    """Newton on the augmented system in scaled variables u = (x / sx, p / sp) for the period-n
    orbits of ``family``; ``evals`` counts the flow-map evaluations with monodromy."""

    def __init__(self, family: Family, n: int, sx: float, sp: float, cs: ContinuationSettings):
        self.family, self.n, self.sx, self.sp, self.cs = family, n, sx, sp, cs
        self.evals = 0

    def evaluate(self, x: np.ndarray, p: float, Fp: np.ndarray | None = None) -> Evaluation | None:
        """F, dF/dx (= M - I), dF/dp, M at (x, p); None when the orbit diverged.  dF/dp by a forward
        difference unless ``Fp`` is given (the corrector reuses the one of its first iterate: a chord
        step in the parameter column, which saves one new system per iteration)."""
        phi, M = self.family.flow(p, self.n)(x, True)
        self.evals += 1
        if phi is None:
            return None
        if Fp is None:
            dp = self.cs.dp_rel * self.sp
            phi2, _ = self.family.flow(p + dp, self.n)(x, False)
            if phi2 is None:
                return None
            Fp = (phi2 - phi) / dp
        F = phi - x
        return Evaluation(F, M - np.eye(x.size), Fp, M)

    def scaled(self, q: Any) -> np.ndarray:
        """The scaled point u = (x / sx, p / sp) of a point q with fields x and p."""
        return np.append(q.x / self.sx, q.p / self.sp)

    def predict(self, q: Any, h: float) -> tuple[np.ndarray, float]:
        """The predicted point (x, p) at scaled arclength h from q along its tangent."""
        u = self.scaled(q) + h * q.tangent
        return u[:-1] * self.sx, u[-1] * self.sp

    def jacobian(self, A: np.ndarray, Fp: np.ndarray, t: np.ndarray) -> np.ndarray:
        """[[A sx, Fp sp], [t]]: the Jacobian of (F, t . u) in the scaled variables."""
        d = A.shape[0]
        J = np.zeros((d + 1, d + 1))
        J[:d, :d] = A * self.sx
        J[:d, d] = Fp * self.sp
        J[d] = t
        return J

    def tangent(self, A: np.ndarray, Fp: np.ndarray, t_prev: np.ndarray) -> np.ndarray:
        """Unit null vector of [A sx, Fp sp] oriented like t_prev."""
        d = A.shape[0]
        rhs = np.zeros(d + 1)
        rhs[d] = 1.0
        t = np.linalg.solve(self.jacobian(A, Fp, t_prev), rhs)
        t /= np.linalg.norm(t)
        return t if float(t @ t_prev) >= 0 else -t

    def point(self, x: np.ndarray, p: float, ev: Evaluation, t_prev: np.ndarray, iterations: int) -> BranchPoint:
        """The point (x, p) of the evaluation ``ev``, its tangent oriented like t_prev (None when singular)."""
        try:
            t = self.tangent(ev.A, ev.Fp, t_prev)
        except np.linalg.LinAlgError:
            t = None
        return BranchPoint(x, p, sorted_multipliers(ev.M), t, iterations)

    def correct(self, x: np.ndarray, p: float, t: np.ndarray) -> BranchPoint | None:
        """Newton from the predicted point (x, p) on (F = 0, t . (u - u_pred) = 0), the point with its
        tangent; None when it diverges, leaves the prediction by more than 0.5 (scaled) in one step, or
        does not converge within ``max_corrector`` evaluations."""
        d = x.size
        u_pred = np.append(x / self.sx, p / self.sp)
        last = np.inf
        Fp = None
        for it in range(self.cs.max_corrector):
            ev = self.evaluate(x, p, Fp)
            if ev is None:
                return None
            Fp = ev.Fp
            res = float(np.max(np.abs(ev.F)))
            if not np.isfinite(res):
                return None
            if res <= self.cs.tol * max(1.0, float(np.max(np.abs(x)))) and last < 1e-6:
                return self.point(x, p, ev, t, it + 1)
            g = np.append(ev.F, float(t @ (np.append(x / self.sx, p / self.sp) - u_pred)))
            try:
                du = np.linalg.solve(self.jacobian(ev.A, Fp, t), -g)
            except np.linalg.LinAlgError:
                return None
            last = float(np.max(np.abs(du)))
            if last > 0.5:  # far off the predicted point: let the step control shorten ds
                return None
            x = x + du[:d] * self.sx
            p = p + du[d] * self.sp
        return None


def merged_period(flow_of: Callable[[int], FlowMap], x: np.ndarray, n: int, tol: float | None = None) -> int:
    """The smallest proper divisor m of n for which x is already a fixed point of the m-period map
    ``flow_of(m)`` within ``tol`` (default 1e-6 max(1, max |x|)), else 0: the period-n orbit is one of
    period m traversed n / m times (a period-2n branch that reaches a second period doubling merges there
    into the period-n orbit and would otherwise continue along it)."""
    tol = 1e-6 * max(1.0, float(np.max(np.abs(x)))) if tol is None else tol
    for m in range(1, n):
        if n % m:
            continue
        y, _ = flow_of(m)(x, False)
        if y is not None and float(np.max(np.abs(y - x))) <= tol:
            return m
    return 0
