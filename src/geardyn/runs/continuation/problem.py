"""The problems of continuation, each stating its residual, its Jacobian blocks and its monodromy for the one
corrector: a branch (F, p), a curve (F, G, p, q), a grazing curve (F, g, p, q) (docs/orbits.md, section 2)."""

from __future__ import annotations

import numpy as np

from geardyn import libm
from geardyn.runs.continuation.branch import Branch
from geardyn.runs.continuation.corrector import ContinuationSettings, Evaluation, Point
from geardyn.runs.continuation.family import Family, Plane, flows
from geardyn.solve.bifurcations import CURVE_KINDS
from geardyn.solve.shooting import sorted_multipliers

#: The multiplier of a fold and of a period doubling.
TARGET = {"fold": 1.0, "period_doubling": -1.0}


def nearest(mu: np.ndarray, target: complex, skip: int = -1) -> int:
    """The index of the multiplier nearest ``target`` (but ``skip``)."""
    d = libm.cabs(mu - target)
    if skip >= 0:
        d[skip] = np.inf
    return int(np.argmin(d))


def condition(kind: str, M: np.ndarray, ref: tuple[complex, ...]) -> tuple[float, tuple[complex, ...]]:
    """The condition G of a multiplier kind at monodromy M and its critical multipliers, tracked from ``ref`` (the
    last point's): fold mu - 1, period doubling mu + 1, Neimark-Sacker mu mu' - 1 of the pair (|mu|^2 - 1)."""
    mu = np.linalg.eigvals(M)
    i = nearest(mu, ref[0])
    if kind == "neimark_sacker":
        j = nearest(mu, np.conj(ref[0]), skip=i)
        return float((mu[i] * mu[j]).real) - 1.0, (complex(mu[i]), complex(mu[j]))
    return float(mu[i].real) - TARGET[kind], (complex(mu[i]),)


def others(mu: np.ndarray, crit: tuple[complex, ...]) -> np.ndarray:
    """The multipliers but the critical ones."""
    keep = np.ones(mu.size, bool)
    for c in crit:
        keep[int(np.argmin(np.where(keep, libm.cabs(mu - c), np.inf)))] = False
    return mu[keep]


class BranchProblem:
    """The period-n orbits of a one-parameter ``family`` (module doc), scaled by sx (states) and sp (parameter)."""

    npar = 1

    def __init__(self, family: Family, n: int, d: int, sx: float, sp: float, cs: ContinuationSettings):
        self.family, self.n, self.sx, self.sp, self.cs = family, n, sx, sp, cs
        self.scale = np.array([sx] * d + [sp])

    @classmethod
    def of(cls, family: Family, br: Branch) -> BranchProblem:
        """The problem ``br`` was continued as (its scales and settings), on ``family``."""
        return cls(family, br.n, br.states.shape[1], br.sx, br.sp, br.settings)

    def evaluate(self, z: np.ndarray, last: Evaluation | None, ref: Point | None = None) -> Evaluation | None:
        x, p = z[:-1], float(z[-1])
        phi, M = self.family.flow(p, self.n)(x, True)
        if phi is None:
            return None
        if last is None:  # two flows: a batch of two saves less than its switch to one thread costs
            dp = self.cs.dp_rel * self.sp
            phi2, _ = self.family.flow(p + dp, self.n)(x, False)
            if phi2 is None:
                return None
            Fp = (phi2 - phi) / dp
        else:
            Fp = last.J[:, -1]
        return Evaluation(phi - x, M, np.column_stack([M - np.eye(x.size), Fp]))

    def jacobian(self, z: np.ndarray, ev: Evaluation, ref: Point) -> np.ndarray | None:
        """dH/dz, which comes with every evaluation (:meth:`evaluate`)."""
        return ev.J

    def converged(self, z: np.ndarray, ev: Evaluation) -> bool:
        return float(np.max(np.abs(ev.H))) <= self.cs.tol * max(1.0, float(np.max(np.abs(z[:-1]))))

    def point(self, z: np.ndarray, ev: Evaluation, t: np.ndarray, iterations: int, ref: Point | None = None) -> Point:
        return Point(z, sorted_multipliers(ev.M), t, iterations)


class CurveProblem:
    """The curve of ``kind`` (period n) of a two-parameter ``plane`` (module doc), scaled by ``scales`` = (sx, the
    box's sides)."""

    npar = 2

    def __init__(
        self, plane: Plane, kind: str, n: int, d: int, scales: tuple[float, float, float], cs: ContinuationSettings
    ):
        if kind not in CURVE_KINDS:
            raise ValueError(f"curve kind {kind!r}; allowed: {CURVE_KINDS}")
        self.plane, self.kind, self.n, self.scales, self.cs = plane, kind, n, scales, cs
        self.scale = np.array([scales[0]] * d + [scales[1], scales[2]])

    def evaluate(self, z: np.ndarray, last: Evaluation | None, ref: Point) -> Evaluation | None:
        phi, M = self.plane.flow(float(z[-2]), float(z[-1]), self.n)(z[:-2], True)
        return self._residual(z, phi, M, ref)

    def _residual(self, z: np.ndarray, phi: np.ndarray | None, M: np.ndarray | None, ref: Point) -> Evaluation | None:
        """The :class:`Evaluation` at z of the flow's (phi, M) there."""
        x, p, q = z[:-2], float(z[-2]), float(z[-1])
        if phi is None or M is None or not np.all(np.isfinite(M)):
            return None
        if self.kind == "grazing":
            return Evaluation(np.append(phi - x, float(self.plane.grazing(p, q, x, self.n))), M)
        G, crit = condition(self.kind, M, ref.crit)
        return Evaluation(np.append(phi - x, G), M, crit=crit)

    def jacobian(self, z: np.ndarray, ev: Evaluation, ref: Point) -> np.ndarray | None:
        """dH/dz: M - I from the variational equations, the other entries by forward differences."""
        d = z.size - 2
        J = np.empty((d + 1, d + 2))
        J[:d, :d] = ev.M - np.eye(d)
        hs = self.cs.dp_rel * self.scale
        zs = [z + np.eye(d + 2)[k] * hs[k] for k in range(d + 2)]
        # the d + 2 perturbed flows in one batch, each then the residual evaluate() would make of it
        runs = flows(
            self.plane, [(float(zk[-2]), float(zk[-1])) for zk in zs], [zk[:-2] for zk in zs], self.n, [True] * (d + 2)
        )
        for k, (zk, (phi, M)) in enumerate(zip(zs, runs, strict=True)):
            r = self._residual(zk, phi, M, ref)
            if r is None:
                return None
            if k >= d:
                J[:d, k] = (r.H[:d] - ev.H[:d]) / hs[k]
            J[d, k] = (r.H[d] - ev.H[d]) / hs[k]
        return J

    def converged(self, z: np.ndarray, ev: Evaluation) -> bool:
        xs = max(1.0, float(np.max(np.abs(z[:-2]))))
        gtol = self.cs.tol * xs if self.kind == "grazing" else self.cs.test_tol
        return float(np.max(np.abs(ev.H[:-1]))) <= self.cs.tol * xs and abs(float(ev.H[-1])) <= gtol

    def point(self, z: np.ndarray, ev: Evaluation, t: np.ndarray, iterations: int, ref: Point) -> Point:
        """The point (the fold eigenvector oriented like ``ref.v``), with its grazing margin."""
        a, v = float("nan"), None
        if self.kind == "fold":
            a, v = self.fold_coefficient(z, ev.M, ev.crit[0], ref.v)
        G = float(ev.H[-1])
        g = G if self.kind == "grazing" else float(self.plane.grazing(float(z[-2]), float(z[-1]), z[:-2], self.n))
        return Point(z, sorted_multipliers(ev.M), t, iterations, 0.0, 2, ev.crit, G, g, a, v)

    def fold_coefficient(self, z: np.ndarray, M: np.ndarray, mu_c: complex, v_ref: np.ndarray | None):
        """a = w . (phi(x + h v) + phi(x - h v) - 2 phi(x)) / (2 h^2), v the unit eigenvector of mu_c (oriented
        like v_ref), w the left one with w . v = 1."""
        lam, V = np.linalg.eig(M)
        v = V[:, nearest(lam, mu_c)].real
        v /= np.linalg.norm(v)
        if (v_ref is not None and float(v @ v_ref) < 0) or (v_ref is None and v[np.argmax(np.abs(v))] < 0):
            v = -v
        lam_t, W = np.linalg.eig(M.T)
        w = W[:, nearest(lam_t, mu_c)].real
        w = w / float(w @ v)
        x, p, q = z[:-2], float(z[-2]), float(z[-1])
        h = self.cs.fold_h * self.scales[0]
        ys = [
            y
            for y, _ in flows(self.plane, [(p, q)] * 3, [x + s * h * v for s in (1.0, -1.0, 0.0)], self.n, [False] * 3)
        ]
        if any(y is None for y in ys):
            return float("nan"), v
        return float(w @ (ys[0] + ys[1] - 2.0 * ys[2])) / (2.0 * h * h), v
