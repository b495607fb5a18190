"""Regime boundaries as curves: two-parameter continuation of the codimension-1 bifurcations of
period-n orbits in a plane of two parameters (p, q), with the codimension-2 points on the curves
(docs/orbits.md, "Regime boundaries as curves": the extended systems, the tests, the measured errors).

Unknowns z = (x, p, q); equations H(z) = (phi_n(x; p, q) - x, G) = 0, G the defining condition of the
kind (:func:`condition`; the critical multipliers tracked from point to point): fold mu_c - 1, period
doubling mu_c + 1, Neimark-Sacker mu_a mu_b - 1 (|mu|^2 - 1 of the pair), grazing g = min |x_VH| - b.
dH/dx has M - I from the variational equations, the other derivatives are forward differences.
Pseudo-arclength in u = (x / sx, p / sp, q / sq) (sp, sq: the sides of the box); a curve stops on
the box.  Codimension-2 points (:data:`CODIM2_TYPES`) are sign changes of :func:`tests` between
consecutive points, located by Brent on the arclength fraction (every trial point corrected).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np
import xarray as xr
from scipy.optimize import brentq

from geardyn import libm
from geardyn.khv import point
from geardyn.runs.continuation.branch import Branch
from geardyn.runs.continuation.events import fold_test, ns_product, pd_test
from geardyn.runs.continuation.family import KHVFamily, grazing_margin
from geardyn.solve.base import SimulationSettings
from geardyn.solve.shooting import FlowMap, khv_flow, sorted_multipliers

CURVE_KINDS = ("fold", "period_doubling", "neimark_sacker", "grazing")
CODIM2_TYPES = tuple(
    "cusp resonance_1_1 resonance_1_2 fold_flip fold_neimark_sacker flip_neimark_sacker double_neimark_sacker "
    "grazing_fold grazing_flip grazing_neimark_sacker".split()
)
_TARGET = {"fold": 1.0, "period_doubling": -1.0}
_TERMINAL = ("resonance_1_1", "resonance_1_2")
#: The codimension-2 tests of each kind of curve, in the order of :func:`tests`.
_TESTS = {
    "fold": tuple("cusp resonance_1_1 fold_flip fold_neimark_sacker grazing_fold".split()),
    "period_doubling": tuple("fold_flip resonance_1_2 flip_neimark_sacker grazing_flip".split()),
    "neimark_sacker": (*CODIM2_TYPES[1:3], *CODIM2_TYPES[4:7], "grazing_neimark_sacker"),
    "grazing": CODIM2_TYPES[7:],
}
_CHEAP = {"b": "b", "e": "e", "w": "omega"}  # overrides that are one coefficient field each


class PlaneFamily(Protocol):
    """What curve continuation needs of a two-parameter family of periodic systems."""

    box: tuple[float, float, float, float]  # p_lo, p_hi, q_lo, q_hi

    def flow(self, p: float, q: float, n: int) -> FlowMap: ...

    def grazing(self, p: float, q: float, x: np.ndarray, n: int) -> float: ...


class KHVPlane:
    """A KHV design over two control parameters ``names`` = (p, q) in ``box`` = (p_lo, p_hi, q_lo, q_hi),
    the other overrides ``fixed``.  When one of them is b, e or w (one coefficient field each), the
    coefficients along the other come from a :class:`KHVFamily` (``nodes`` as there; 0: direct) and
    that field is replaced, if a direct evaluation at the box corner agrees; otherwise
    :func:`geardyn.khv.point.point_coefficients` is called at every (p, q).  Cached by (p, q)."""

    def __init__(
        self,
        design: Any,
        names: tuple[str, str],
        fixed: Mapping[str, float],
        box: tuple[float, float, float, float],
        settings: SimulationSettings | None = None,
        nodes: int = 0,
    ):
        self.design, self.names, self.fixed = design, (names[0], names[1]), dict(fixed)
        self.box = tuple(float(v) for v in box)
        self.settings = settings or point.integration_settings(design)
        swap = self.names[0] in _CHEAP and self.names[1] not in _CHEAP
        self._swap, fast = swap, self.names[0 if swap else 1]
        self._field = _CHEAP.get(fast)
        self._cache: dict[tuple[float, float], Any] = {}
        if self._field is not None:
            lo, hi = self.box[2:] if swap else self.box[:2]
            mid = 0.5 * (self.box[0] + self.box[1]) if swap else 0.5 * (self.box[2] + self.box[3])
            self._line = KHVFamily(design, self.names[1 if swap else 0], {**self.fixed, fast: mid}, lo, hi, None, nodes)
            corner = self.coefficients(self.box[1], self.box[3]).as_dict()
            direct = self._direct(self.box[1], self.box[3]).as_dict()
            if any(abs(corner[k] - v) > 1e-9 * max(1.0, abs(v)) for k, v in direct.items() if isinstance(v, float)):
                self._field = None
            self._cache.clear()

    def _direct(self, p: float, q: float) -> Any:
        return point.point_coefficients(self.design, {**self.fixed, self.names[0]: p, self.names[1]: q})

    def coefficients(self, p: float, q: float) -> Any:
        key = (float(p), float(q))
        c = self._cache.get(key)
        if c is None:
            if self._field is None:
                c = self._direct(*key)
            else:
                slow, fast = (key[1], key[0]) if self._swap else key
                c = self._line.coefficients(slow).replace(**{self._field: fast})
            if len(self._cache) > 256:
                self._cache.clear()
            self._cache[key] = c
        return c

    def flow(self, p: float, q: float, n: int) -> FlowMap:
        return khv_flow(self.coefficients(p, q), n, self.settings)

    def grazing(self, p: float, q: float, x: np.ndarray, n: int) -> float:
        return grazing_margin(self.coefficients(p, q), x, n, self.settings)


@dataclass(frozen=True)
class CurveSettings:
    """Numbers of curve continuation (ds in the scaled arclength, box sides = 1).  tol: max |F| <=
    tol max(1, max |x|); test_tol: |G| for the multiplier conditions (grazing: as F).  fd_x, fd_p:
    forward-difference steps relative to sx and the box sides; fold_h: the step of the second
    difference of the cusp test, relative to sx."""

    ds: float = 0.01
    ds_min: float = 1e-6
    ds_max: float = 0.02
    tol: float = 1e-9
    test_tol: float = 1e-10
    max_corrector: int = 10
    fd_x: float = 1e-7
    fd_p: float = 1e-7
    fold_h: float = 1e-3
    max_points: int = 400
    grazing: bool = True
    locate_xtol: float = 1e-10


@dataclass(frozen=True)
class CurvePoint:
    """A point of a curve: z = (x, p, q), the sorted multipliers, the critical ones (crit),
    the others, the defining condition's value G, the unit tangent (scaled), the grazing margin, the
    fold coefficient a and its eigenvector v (fold curves), corrector evaluations."""

    z: np.ndarray
    multipliers: np.ndarray
    crit: tuple[complex, ...]
    others: np.ndarray
    G: float
    tangent: np.ndarray
    grazing: float
    fold_a: float
    v: np.ndarray | None
    iterations: int


@dataclass(frozen=True)
class Codim2:
    """A codimension-2 point on a curve of kind ``curve_kind`` (multipliers of the n-period map)."""

    kind: str
    curve_kind: str
    p: float
    q: float
    state: np.ndarray
    multipliers: np.ndarray
    located: bool
    n: int


@dataclass
class Curve:
    """A continued curve of codimension-1 points, ordered along its arclength; end_status: why each
    end stopped (``box``, ``resonance_1_1``, ``step_too_small``, ...)."""

    kind: str
    n: int
    points: list[CurvePoint]
    scales: tuple[float, float, float]
    end_status: dict[str, str] = field(default_factory=dict)
    codim2: list[Codim2] = field(default_factory=list)

    def __len__(self) -> int:
        return len(self.points)

    p = property(lambda self: np.array([c.z[-2] for c in self.points]), doc="p at every point")
    q = property(lambda self: np.array([c.z[-1] for c in self.points]), doc="q at every point")
    residual = property(lambda self: np.array([c.G for c in self.points]), doc="the defining condition G")


def _nearest(mu: np.ndarray, target: complex, skip: int = -1) -> int:
    return int(np.argmin(np.where(np.arange(mu.size) == skip, np.inf, libm.cabs(mu - target))))


def condition(kind: str, M: np.ndarray, ref: tuple[complex, ...]) -> tuple[float, tuple[complex, ...]]:
    """The defining condition G of a multiplier kind at monodromy M and its critical multipliers,
    tracked from ``ref`` (the last point's critical multipliers)."""
    mu = np.linalg.eigvals(M)
    i = _nearest(mu, ref[0])
    if kind == "neimark_sacker":
        j = _nearest(mu, np.conj(ref[0]), skip=i)
        return float((mu[i] * mu[j]).real) - 1.0, (complex(mu[i]), complex(mu[j]))
    return float(mu[i].real) - _TARGET[kind], (complex(mu[i]),)


def _others(mu: np.ndarray, crit: tuple[complex, ...]) -> np.ndarray:
    keep = np.ones(mu.size, bool)
    for c in crit:
        dist = np.where(keep, libm.cabs(mu - c), np.inf)
        keep[int(np.argmin(dist))] = False
    return mu[keep]


def _ns_count(mu: np.ndarray) -> int:
    return int(np.sum((libm.cabs(mu) > 1.0) & (np.abs(mu.imag) > 1e-8 * np.maximum(libm.cabs(mu), 1e-300))))


def tests(kind: str, pt: CurvePoint) -> dict[str, float]:
    """The codimension-2 tests of a point (docs/orbits.md, "Regime boundaries as curves"): the fold's
    normal-form coefficient, the NS pair's trace -+ 2, det(others -+ I), the others' complex pairs, g."""
    o = pt.multipliers if kind == "grazing" else pt.others
    tr = float(sum(pt.crit).real)
    pre = {"fold": [pt.fold_a], "neimark_sacker": [tr - 2.0, tr + 2.0]}.get(kind, [])
    post = [] if kind == "grazing" else [pt.grazing]
    return dict(zip(_TESTS[kind], [*pre, fold_test(o), pd_test(o), ns_product(o), *post], strict=True))


def _crossed(kind: str, name: str, a: CurvePoint, b: CurvePoint, ta: float, tb: float) -> bool:
    if not (np.isfinite(ta) and np.isfinite(tb)) or (ta > 0) == (tb > 0):
        return False
    if name.endswith("neimark_sacker") and not (kind == "neimark_sacker" and name != "double_neimark_sacker"):
        mu_a, mu_b = (a.multipliers, b.multipliers) if kind == "grazing" else (a.others, b.others)
        return abs(_ns_count(mu_a) - _ns_count(mu_b)) == 2
    return True


class Extended:
    """The extended system of one curve (kind, period n) of ``plane`` in the scaled variables."""

    def __init__(self, plane: PlaneFamily, kind: str, n: int, scales: tuple[float, float, float], cs: CurveSettings):
        if kind not in CURVE_KINDS:
            raise ValueError(f"curve kind {kind!r}; allowed: {CURVE_KINDS}")
        self.plane, self.kind, self.n, self.cs = plane, kind, n, cs
        self.scales = scales

    def scale(self, d: int) -> np.ndarray:
        return np.array([self.scales[0]] * d + [self.scales[1], self.scales[2]])

    def u(self, z: np.ndarray) -> np.ndarray:
        """The scaled point."""
        return z / self.scale(z.size - 2)

    def residual(self, z: np.ndarray, ref: tuple[complex, ...]) -> tuple[np.ndarray, float, np.ndarray, tuple] | None:
        """(F, G, M, critical multipliers) at z; None when the orbit diverged."""
        x, p, q = z[:-2], float(z[-2]), float(z[-1])
        phi, M = self.plane.flow(p, q, self.n)(x, True)
        if phi is None or not np.all(np.isfinite(M)):
            return None
        if self.kind == "grazing":
            return phi - x, float(self.plane.grazing(p, q, x, self.n)), M, ()
        G, crit = condition(self.kind, M, ref)
        return phi - x, G, M, crit

    def jacobian(self, z: np.ndarray, F: np.ndarray, G: float, M: np.ndarray, ref: tuple) -> np.ndarray | None:
        """dH/du (scaled columns): M - I from the variational equations, the rest by forward differences."""
        d = z.size - 2
        sc = self.scale(d)
        J = np.empty((d + 1, d + 2))
        J[:d, :d] = M - np.eye(d)
        for k in range(d + 2):
            h = (self.cs.fd_x if k < d else self.cs.fd_p) * sc[k]
            zk = z.copy()
            zk[k] += h
            r = self.residual(zk, ref)
            if r is None:
                return None
            if k >= d:
                J[:d, k] = (r[0] - F) / h
            J[d, k] = (r[1] - G) / h
        return J * sc

    def solve(self, z: np.ndarray, ref: tuple, row: np.ndarray, c: float) -> tuple[np.ndarray, np.ndarray, int] | None:
        """Newton on (H = 0, row . u = c) from z; (z, dH/du at the last iterate, evaluations) or None."""
        d = z.size - 2
        sc = self.scale(d)
        gtol = self.cs.tol * max(1.0, float(np.max(np.abs(z[:d])))) if self.kind == "grazing" else self.cs.test_tol
        J = None
        for it in range(self.cs.max_corrector):
            r = self.residual(z, ref)
            if r is None:
                return None
            F, G, M, _ = r
            lin = float(row @ (z / sc)) - c
            xs = max(1.0, float(np.max(np.abs(z[:d]))))
            if J is not None and np.max(np.abs(F)) <= self.cs.tol * xs and abs(G) <= gtol and abs(lin) < 1e-10:
                return z, J, it + 1
            J = self.jacobian(z, F, G, M, ref)
            if J is None or not np.all(np.isfinite(J)):
                return None
            try:
                du = np.linalg.solve(np.vstack([J, row]), -np.append(np.append(F, G), lin))
            except np.linalg.LinAlgError:
                return None
            if float(np.max(np.abs(du))) > 0.5:
                return None
            z = z + du * sc
        return None

    def describe(self, z: np.ndarray, J: np.ndarray, ref: tuple, v_ref: np.ndarray | None, t_ref, it: int):
        """The :class:`CurvePoint` at a converged z (critical multipliers tracked from ``ref``, the fold
        eigenvector oriented like ``v_ref``, the tangent like ``t_ref``)."""
        _, G, M, crit = self.residual(z, ref)
        mu = sorted_multipliers(M)
        t = _null(J, t_ref)
        a, v = float("nan"), None
        if self.kind == "fold":
            a, v = self._fold_coefficient(z, M, crit[0], v_ref)
        g = float(self.plane.grazing(float(z[-2]), float(z[-1]), z[:-2], self.n)) if self.cs.grazing else float("nan")
        return CurvePoint(z, mu, crit, _others(mu, crit), G, t, g, a, v, it)

    def corrected(self, z: np.ndarray, a: CurvePoint, row: np.ndarray, c: float) -> CurvePoint | None:
        """The point solved from z with the extra equation row . u = c, tracked from the point a."""
        out = self.solve(z, a.crit, row, c)
        return None if out is None else self.describe(out[0], out[1], a.crit, a.v, a.tangent, out[2])

    def _fold_coefficient(self, z: np.ndarray, M: np.ndarray, mu_c: complex, v_ref: np.ndarray | None):
        """a = w . (phi(x + h v) + phi(x - h v) - 2 phi(x)) / (2 h^2), v the unit eigenvector of mu_c
        (oriented like v_ref), w the left one with w . v = 1."""
        lam, V = np.linalg.eig(M)
        v = V[:, _nearest(lam, mu_c)].real
        v /= np.linalg.norm(v)
        if (v_ref is not None and float(v @ v_ref) < 0) or (v_ref is None and v[np.argmax(np.abs(v))] < 0):
            v = -v
        lam_t, W = np.linalg.eig(M.T)
        w = W[:, _nearest(lam_t, mu_c)].real
        w = w / float(w @ v)
        x, p, q = z[:-2], float(z[-2]), float(z[-1])
        h = self.cs.fold_h * self.scales[0]
        fl = self.plane.flow(p, q, self.n)
        ys = [fl(x + s * h * v, False)[0] for s in (1.0, -1.0, 0.0)]
        if any(y is None for y in ys):
            return float("nan"), v
        return float(w @ (ys[0] + ys[1] - 2.0 * ys[2])) / (2.0 * h * h), v


def _null(J: np.ndarray, t_ref: np.ndarray | None) -> np.ndarray:
    """Unit null vector of J (d+1, d+2), oriented like t_ref (or with its largest (p, q) part > 0)."""
    _, _, vt = np.linalg.svd(J)
    t = vt[-1]
    sign = float(t @ t_ref) if t_ref is not None else float(t[-2:][np.argmax(np.abs(t[-2:]))])
    return t if sign >= 0 else -t


def _on_arc(ext: Extended, a: CurvePoint, h: float) -> CurvePoint | None:
    """The corrected point at scaled arclength h from a along its tangent (pseudo-arclength)."""
    up = ext.u(a.z) + h * a.tangent
    return ext.corrected(up * ext.scale(a.z.size - 2), a, a.tangent, float(a.tangent @ up))


def _codim2(ext: Extended, name: str, pt: CurvePoint, located: bool) -> Codim2:
    z = pt.z
    return Codim2(name, ext.kind, float(z[-2]), float(z[-1]), z[:-2].copy(), pt.multipliers, located, ext.n)


def _events(ext: Extended, a: CurvePoint, b: CurvePoint) -> list[Codim2]:
    """The codimension-2 points between consecutive points a and b, located by Brent on the arclength."""
    ta, tb = tests(ext.kind, a), tests(ext.kind, b)
    h = float(np.linalg.norm(ext.u(b.z) - ext.u(a.z)))
    found = []
    for name in ta:
        if not _crossed(ext.kind, name, a, b, ta[name], tb[name]):
            continue
        cache: dict[float, CurvePoint] = {0.0: a, 1.0: b}

        def f(s: float, name: str = name, cache: dict = cache) -> float:
            if s not in cache:
                q = _on_arc(ext, a, s * h)
                if q is None:
                    raise RuntimeError("correction failed while locating")
                cache[s] = q
            v = tests(ext.kind, cache[s])[name]
            if not np.isfinite(v):
                raise RuntimeError("test function undefined")
            return v

        try:
            s = brentq(f, 0.0, 1.0, xtol=ext.cs.locate_xtol, rtol=1e-15, maxiter=60)
            found.append(_codim2(ext, name, cache[s], True))
        except (RuntimeError, ValueError):
            found.append(_codim2(ext, name, a if abs(ta[name]) < abs(tb[name]) else b, False))
    return found


def _box_end(ext: Extended, a: CurvePoint, z_pred: np.ndarray, box: Sequence[float]) -> CurvePoint | None:
    """The point on the side of the box that the step a -> z_pred crosses first."""
    fracs = []
    for k in (0, 1):
        v0, v1, lo, hi = a.z[-2 + k], z_pred[-2 + k], box[2 * k], box[2 * k + 1]
        bound = hi if v1 > hi else lo if v1 < lo else None
        if bound is not None:
            fracs.append(((bound - v0) / (v1 - v0), k, bound))
    frac, k, bound = min(fracs)
    return ext.corrected(a.z + frac * (z_pred - a.z), a, _row(a.z.size - 2, k), bound / ext.scales[1 + k])


def _row(d: int, k: int) -> np.ndarray:
    """The extra equation's row of the line on which coordinate k (0: p, 1: q) is held."""
    row = np.zeros(d + 2)
    row[d + k] = 1.0
    return row


def _inside(z: np.ndarray, box: Sequence[float]) -> bool:
    return box[0] <= z[-2] <= box[1] and box[2] <= z[-1] <= box[3]


def _march(ext: Extended, start: CurvePoint, box: Sequence[float]) -> tuple[list[CurvePoint], list[Codim2], str]:
    """Points along one direction from ``start`` (excluded), the codimension-2 points passed, the end."""
    cs = ext.cs
    pts: list[CurvePoint] = []
    found: list[Codim2] = []
    cur, ds = start, cs.ds
    u0 = ext.u(start.z)
    while len(pts) < cs.max_points:
        z_pred = (ext.u(cur.z) + ds * cur.tangent) * ext.scale(cur.z.size - 2)
        if not _inside(z_pred, box):
            end = _box_end(ext, cur, z_pred, box)
            if end is not None:
                found += _events(ext, cur, end)
                pts.append(end)
            return pts, found, "box"
        new = _on_arc(ext, cur, ds)
        if new is None:
            ds *= 0.5
            if ds < cs.ds_min:
                return pts, found, "step_too_small"
            continue
        ev = _events(ext, cur, new)
        found += ev
        term = [c.kind for c in ev if c.kind in _TERMINAL]
        if term:
            return pts, found, term[0]
        pts.append(new)
        cur = new
        if len(pts) > 10 and float(np.linalg.norm(ext.u(new.z) - u0)) < ds and float(new.tangent @ start.tangent) > 0:
            return pts, found, "closed_loop"
        if float(np.max(libm.cabs(new.multipliers))) > 1e8:
            return pts, found, "multipliers_too_large"
        if new.iterations <= 4:
            ds = min(ds * 1.3, cs.ds_max)
    return pts, found, "max_points"


def continue_curve(
    plane: PlaneFamily,
    kind: str,
    n: int,
    x0: np.ndarray,
    start: tuple[float, float],
    critical: complex = complex("nan"),
    cs: CurveSettings | None = None,
    along: str = "p",
) -> Curve | None:
    """The curve of ``kind`` (period n) through the codimension-1 point near (x0, start = (p0, q0)), both
    ways to the box ``plane.box``.  ``critical``: the critical multiplier there (the upper one of a
    Neimark-Sacker pair; default +1 / -1 for fold / period doubling).  The seed is corrected on the line
    through ``start`` along ``along`` (the other coordinate held); None when that fails."""
    cs, box = cs or CurveSettings(), tuple(plane.box)
    x0 = np.asarray(x0, dtype=float)
    if not _inside(np.asarray(start), box):
        return None
    ext = Extended(plane, kind, n, (max(1.0, float(np.max(np.abs(x0)))), box[1] - box[0], box[3] - box[2]), cs)
    ref = () if kind == "grazing" else (complex(critical if np.isfinite(critical) else _TARGET[kind]),)
    k = 1 if along == "p" else 0
    out = ext.solve(np.concatenate([x0, start]), ref, _row(x0.size, k), start[k] / ext.scales[1 + k])
    if out is None:
        return None
    z, J, _ = out
    seed = ext.describe(z, J, ref, None, None, 1)
    up, ev_up, end_up = _march(ext, seed, box)
    back = CurvePoint(**{**seed.__dict__, "tangent": -seed.tangent})
    down, ev_down, end_down = _march(ext, back, box) if end_up != "closed_loop" else ([], [], "closed_loop")
    down = [CurvePoint(**{**c.__dict__, "tangent": -c.tangent}) for c in reversed(down)]
    return Curve(kind, n, [*down, seed, *up], ext.scales, {"down": end_down, "up": end_up}, ev_down + ev_up)


def _on_curve(curve: Curve, kind: str, n: int, p: float, q: float, tol: float = 1e-3) -> bool:
    """True when (p, q) lies on ``curve`` of the same kind and period (scaled distance to its polyline)."""
    if curve.kind != kind or curve.n != n or len(curve) < 2:
        return False
    s = np.array(curve.scales[1:])
    pts = np.column_stack([curve.p, curve.q]) / s
    y = np.array([p, q]) / s
    a, b = pts[:-1], pts[1:]
    ab = b - a
    w = np.clip(np.sum((y - a) * ab, axis=1) / np.maximum(np.sum(ab * ab, axis=1), 1e-300), 0.0, 1.0)
    return float(np.min(np.linalg.norm(a + w[:, None] * ab - y, axis=1))) < tol


def curves_from_branch(
    plane: PlaneFamily,
    branch: Branch,
    axis: str,
    at: float,
    cs: CurveSettings | None = None,
    kinds: Sequence[str] = CURVE_KINDS,
    existing: Sequence[Curve] = (),
) -> list[Curve]:
    """A curve from every located bifurcation of ``branch`` whose kind is in ``kinds`` (the one-parameter
    branch runs along the plane's ``axis``, "p" or "q", with the other coordinate at ``at``).  A seed
    that lies on a curve already found (among them or ``existing``) starts none."""
    if axis not in ("p", "q"):
        raise ValueError(f"axis {axis!r}; allowed: 'p', 'q'")
    curves = list(existing)
    for bf in branch.bifurcations:
        if bf.kind not in kinds or not bf.located:
            continue
        p, q = (bf.p, at) if axis == "p" else (at, bf.p)
        if any(_on_curve(c, bf.kind, bf.n, p, q) for c in curves):
            continue
        c = continue_curve(plane, bf.kind, bf.n, bf.state, (p, q), bf.critical, cs, axis)
        if c is not None:
            curves.append(c)
    return curves[len(existing) :]


def curve_crossings(
    plane: PlaneFamily, curve: Curve, axis: str, value: float, cs: CurveSettings | None = None
) -> list[CurvePoint]:
    """The points where ``curve`` crosses the line ``axis`` ("p" or "q") = value, each solved on the
    extended system with the line as the extra equation (from the chord between the bracketing points)."""
    ext = Extended(plane, curve.kind, curve.n, curve.scales, cs or CurveSettings())
    k = 0 if axis == "p" else 1
    d = curve.points[0].z.size - 2
    out = []
    for a, b in zip(curve.points, [*curve.points[1:], curve.points[-1]], strict=True):
        va, vb = a.z[d + k] - value, b.z[d + k] - value
        if va == 0.0 or (vb != 0.0 and (va > 0) != (vb > 0)):
            w = va / (va - vb) if va != vb else 0.0
            pt = ext.corrected(a.z + w * (b.z - a.z), a, _row(d, k), value / ext.scales[1 + k])
            out += [pt] if pt is not None else []
    return out


def _attrs(name: str, units: Mapping[str, str] | None, long_names: Mapping[str, str] | None) -> dict[str, str]:
    if units and name in units:
        u = units[name]
    else:
        u = point.units_of(name) if name in point.CONTROLS or name in point.PARAMETER_UNITS else "1"
    ln = (long_names or {}).get(name) or (point.CONTROLS[name][1] if name in point.CONTROLS else name)
    return {"units": u, "long_name": ln}


def _flags(names: Sequence[str], long_name: str) -> dict[str, Any]:
    return dict(long_name=long_name, flag_values=np.arange(len(names), dtype=np.int8), flag_meanings=" ".join(names))


def curve_dataset(
    curves: Sequence[Curve],
    names: tuple[str, str],
    units: Mapping[str, str] | None = None,
    long_names: Mapping[str, str] | None = None,
) -> xr.Dataset:
    """The curves as one CF dataset: dimension ``point`` (every curve's points in order, ``curve_index``
    the curve's), ``curve`` (kind, period, first point, length; end statuses as attributes
    ``curve_<k>_end``) and ``codim2`` (type, curve, (p, q), multipliers, located)."""
    d = curves[0].points[0].z.size - 2 if curves and curves[0].points else 0
    rows = [(k, pt) for k, c in enumerate(curves) for pt in c.points]
    c2 = [(k, b) for k, c in enumerate(curves) for b in c.codim2]
    mu = np.array([pt.multipliers for _, pt in rows]).reshape(len(rows), d)
    mu2 = np.array([b.multipliers for _, b in c2]).reshape(len(c2), d)
    pa, qa = _attrs(names[0], units, long_names), _attrs(names[1], units, long_names)
    P, PM, C2, C2M = ("point",), ("point", "multiplier"), ("codim2",), ("codim2", "multiplier")
    g = "defining condition G (fold: mu - 1, period doubling: mu + 1, Neimark-Sacker: |mu|^2 - 1, grazing: g)"
    spec: list[tuple[str, tuple[str, ...], Any, Any]] = [
        ("curve_index", P, np.array([k for k, _ in rows], np.int32), "index of the curve"),
        (names[0], P, [pt.z[-2] for _, pt in rows], pa),
        (names[1], P, [pt.z[-1] for _, pt in rows], qa),
        ("orbit_state", ("point", "state"), np.reshape([pt.z[:-2] for _, pt in rows], (len(rows), d)), "orbit state"),
        ("multiplier_real", PM, mu.real, "Floquet multiplier, real part"),
        ("multiplier_imag", PM, mu.imag, "Floquet multiplier, imaginary part"),
        ("condition_residual", P, [pt.G for _, pt in rows], g),
        ("grazing_margin", P, [pt.grazing for _, pt in rows], "grazing margin min |x_VH| - b over the cycle"),
        ("curve_kind", ("curve",), [CURVE_KINDS.index(c.kind) for c in curves], _flags(CURVE_KINDS, "curve kind")),
        ("curve_period", ("curve",), np.array([c.n for c in curves], np.int16), "orbit period (mesh periods)"),
        ("curve_start", ("curve",), np.cumsum([0] + [len(c) for c in curves])[:-1], "index of the first point"),
        ("curve_length", ("curve",), [len(c) for c in curves], "number of points"),
        ("codim2_type", C2, [CODIM2_TYPES.index(b.kind) for _, b in c2], _flags(CODIM2_TYPES, "codim-2 type")),
        ("codim2_curve", C2, np.array([k for k, _ in c2], np.int32), "index of the curve"),
        (f"codim2_{names[0]}", C2, [b.p for _, b in c2], pa),
        (f"codim2_{names[1]}", C2, [b.q for _, b in c2], qa),
        ("codim2_multiplier_real", C2M, mu2.real, "Floquet multiplier, real part"),
        ("codim2_multiplier_imag", C2M, mu2.imag, "Floquet multiplier, imaginary part"),
        ("codim2_located", C2, [int(b.located) for _, b in c2], _flags(("bracketed", "located"), "located")),
    ]
    data = {}
    for name, dims, values, attrs in spec:
        a = attrs if isinstance(attrs, dict) else {"units": "1", "long_name": attrs}
        v = np.asarray(values, dtype=np.int8 if "flag_values" in a else None)
        data[name] = (dims, v.astype(np.int32) if v.dtype == np.int64 else v, a)
    ends = {f"curve_{k}_end": ", ".join(f"{s}={v}" for s, v in c.end_status.items()) for k, c in enumerate(curves)}
    return xr.Dataset(data, attrs={**ends, "curve_parameters": f"{names[0]} {names[1]}"})
