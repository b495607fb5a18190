"""Regime boundaries as curves: two-parameter continuation of the codimension-1 bifurcations of period-n
orbits in a plane (p, q), with the codimension-2 points on them (docs/orbits.md, section 9: the extended
systems H(z) = (phi_n(x; p, q) - x, G) = 0, the tests, the measured errors)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import partial

import numpy as np

from geardyn import libm
from geardyn.runs.continuation.branch import Branch
from geardyn.runs.continuation.events import brent_on_step, fold_test, ns_product, pd_test, unstable_counts
from geardyn.runs.continuation.family import PlaneFamily
from geardyn.runs.continuation.stepping import both_ways, march
from geardyn.solve.shooting import sorted_multipliers

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


@dataclass(frozen=True)
class CurveSettings:
    """Numbers of curve continuation (ds in the scaled arclength, box sides = 1).  tol: max |F| <=
    tol max(1, max |x|); test_tol: |G| for the multiplier conditions (grazing: as F).  fd: the
    forward-difference step relative to sx and the box sides; fold_h: the step of the second
    difference of the cusp test, relative to sx."""

    ds: float = 0.01
    ds_min: float = 1e-6
    ds_max: float = 0.02
    tol: float = 1e-9
    test_tol: float = 1e-10
    max_corrector: int = 10
    fd: float = 1e-7
    fold_h: float = 1e-3
    max_points: int = 400
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
        return abs(unstable_counts(mu_a)[1] - unstable_counts(mu_b)[1]) == 2
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
            h = self.cs.fd * sc[k]
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
        g = float(self.plane.grazing(float(z[-2]), float(z[-1]), z[:-2], self.n))
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
        q = brent_on_step(
            lambda s: _on_arc(ext, a, s * h), lambda pt, name=name: tests(ext.kind, pt)[name], a, b, ext.cs.locate_xtol
        )
        bracketed = a if abs(ta[name]) < abs(tb[name]) else b
        found.append(_codim2(ext, name, q, True) if q is not None else _codim2(ext, name, bracketed, False))
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


def _advance(
    ext: Extended, box: Sequence[float], found: list[Codim2], cur: CurvePoint, ds: float
) -> tuple[list[CurvePoint], str] | None:
    """One step of a curve (:func:`~geardyn.runs.continuation.stepping.march`): ends on the box (the last
    point solved on its side) or at a 1:1 or 1:2 resonance; the codimension-2 points passed go to ``found``."""
    z_pred = (ext.u(cur.z) + ds * cur.tangent) * ext.scale(cur.z.size - 2)
    if not _inside(z_pred, box):
        end = _box_end(ext, cur, z_pred, box)
        found += _events(ext, cur, end) if end is not None else []
        return ([end] if end is not None else []), "box"
    new = _on_arc(ext, cur, ds)
    if new is None:
        return None
    ev = _events(ext, cur, new)
    found += ev
    term = [c.kind for c in ev if c.kind in _TERMINAL]
    return ([], term[0]) if term else ([new], "")


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
    found: list[list[Codim2]] = []  # per march: up, then down

    def run(start: CurvePoint) -> tuple[list[CurvePoint], str]:
        found.append([])
        return march(start, partial(_advance, ext, box, found[-1]), lambda pt: ext.u(pt.z), cs, 4)

    pts, ends = both_ways(run, ext.describe(z, J, ref, None, None, 1))
    return Curve(kind, n, pts, ext.scales, ends, [c for events in reversed(found) for c in events])


def _on_curve(curve: Curve, kind: str, n: int, p: float, q: float, tol: float = 1e-3) -> bool:
    """True when (p, q) lies on ``curve`` of the same kind and period (scaled distance to its polyline)."""
    if curve.kind != kind or curve.n != n or len(curve) < 2:
        return False
    return polyline_distance(curve, p, q, *curve.scales[1:]) < tol


def polyline_distance(curve: Curve, x: float, y: float, px: float, py: float) -> float:
    """Distance of (x, y) from the curve's polyline in units of (px, py) (e.g. the map's pixel)."""
    pts = np.column_stack([curve.p / px, curve.q / py])
    pt = np.array([x / px, y / py])
    return float(np.linalg.norm(pts[0] - pt)) if len(pts) == 1 else segment_distance(pts[:-1], pts[1:], pt)


def segment_distance(a: np.ndarray, b: np.ndarray, pt: np.ndarray) -> float:
    """Distance of pt from the nearest of the segments a[i] -> b[i] (inf without segments)."""
    if not len(a):
        return np.inf
    ab = b - a
    w = np.clip(np.sum((pt - a) * ab, axis=1) / np.maximum(np.sum(ab * ab, axis=1), 1e-300), 0.0, 1.0)
    return float(np.min(np.linalg.norm(a + w[:, None] * ab - pt, axis=1)))


def crossings(values: np.ndarray, line: float) -> list[tuple[int, float]]:
    """(segment i, fraction w) where the polyline coordinate ``values`` crosses ``line``."""
    d = values - line
    out = []
    for i in range(d.size - 1):
        if d[i] == 0.0 or (d[i + 1] != 0.0 and (d[i] > 0) != (d[i + 1] > 0)):
            out.append((i, d[i] / (d[i] - d[i + 1]) if d[i] != d[i + 1] else 0.0))
    return out


def bounds_stable(kind: str, multipliers: np.ndarray, crit: Sequence[complex]) -> bool:
    """True when every multiplier but the critical ones lies inside the unit circle (for grazing: all): the
    curve is a boundary of a stable orbit there."""
    mu = np.asarray(multipliers)
    return bool(np.all(libm.cabs(mu if kind == "grazing" else _others(mu, tuple(crit))) < 1.0))


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
