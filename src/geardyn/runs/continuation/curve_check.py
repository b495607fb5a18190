"""The pixel check of regime-boundary curves against their map (docs/orbits.md, "Regime boundaries as curves").

Every curve is crossed with every ``every``-th row and column of the map; at a crossing (at least ``margin``
pixels from every codimension-2 point) the two neighbouring pixels of that row or column on either side of
the curve are compared with what the curve predicts there.  The curve's orbit is shot at each pixel's own
parameter values (Newton from the curve's orbit at the crossing); the sample counts when it is a boundary of
a stable orbit there: the orbit is stable at exactly one of the two pixels (fold, period doubling,
Neimark-Sacker), or stable at both with margins of opposite sign (grazing).  Then the map must show, for a
curve of period n:

=================  ==============================  ===================================================
kind               stable side                     other side
=================  ==============================  ===================================================
period_doubling    P-n, on the orbit               P-2n
neimark_sacker     P-n, on the orbit               a torus: QP, a long period, or P-m, m not n or 2n
fold               P-n, on the orbit               another attractor: another label or a jump of the
                                                   mean Poincare X_VH (the orbit is gone)
grazing            P-n, on the orbit, both sides;  the impact class of the orbit (response measures of
back_grazing       the impact class of the orbit   the shot orbit): no impact | single-sided for grazing,
                                                   single-sided | double-sided for the back flank
=================  ==============================  ===================================================

"On the orbit": the pixel's mean Poincare X_VH within 1e-3 max(1, |x|) + 0.1 of the orbit's spread of the
orbit's mean.  A failure is typed (:data:`REASONS`): the stable side holds another attractor that its row
carried across the curve from the unstable side (``hysteresis``) or that the row started on
(``coexistence``), the other side's label is not the predicted one (``other_side``), or the impact class
differs (``impact_class``).
"""

from __future__ import annotations

import time
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import xarray as xr

from geardyn.classify import LABELS
from geardyn.khv import point
from geardyn.runs.continuation.curve_maps import Boundaries, back_margin, shorter_period
from geardyn.runs.continuation.curve_records import bounds_stable
from geardyn.runs.continuation.family import cycle_states
from geardyn.solve.response import IMPACT_CLASSES, response_measures
from geardyn.solve.shooting import newton_shooting

#: Outcomes of a sample (``check_reason`` flags); the first is a pass.
REASONS = ("ok", "slow_approach", "hysteresis", "coexistence", "other_side", "impact_class")
FORWARD = "the stable pixel's row reaches it without crossing the curve"
_TORUS = (LABELS["quasi_periodic"], LABELS["long_period"])


@dataclass(frozen=True)
class Sample:
    """One checked crossing: the curve, its kind and period, the crossing (x, y), the two pixels
    ((row, column) of the stable side first), their labels, the outcome (:data:`REASONS`); forward: the stable
    pixel's row reaches it without crossing the curve."""

    curve: int
    kind: str
    n: int
    x: float
    y: float
    pixels: tuple[tuple[int, int], tuple[int, int]]
    labels: tuple[int, int]
    reason: str
    forward: bool = True

    @property
    def ok(self) -> bool:
        return self.reason == "ok"


@dataclass
class PixelCheck:
    """The samples, and how many crossings were not boundaries of a stable orbit (``interior``), had no pair
    of pixels on either side (``unresolved``) or another curve within reach (``crowded``)."""

    samples: list[Sample] = field(default_factory=list)
    every: int = 1
    seconds: float = 0.0
    interior: int = 0
    unresolved: int = 0
    crowded: int = 0

    @property
    def fraction(self) -> float:
        """The share of samples that pass."""
        return _share(self.samples)

    @property
    def forward_fraction(self) -> float:
        """The share among the forward samples (the stable pixel's row reaches it without crossing the curve)."""
        return _share([s for s in self.samples if s.forward])

    def by_kind(self) -> dict[str, tuple[int, int]]:
        out: dict[str, tuple[int, int]] = {}
        for s in self.samples:
            ok, n = out.get(s.kind, (0, 0))
            out[s.kind] = (ok + s.ok, n + 1)
        return out

    def failures(self) -> Counter:
        return Counter(f"{s.kind}: {s.reason}{'' if s.forward else ' (return)'}" for s in self.samples if not s.ok)

    def attrs(self) -> dict[str, Any]:
        """Global attributes of the curves file."""
        kinds = "; ".join(f"{k} {ok}/{n}" for k, (ok, n) in sorted(self.by_kind().items()))
        fails = "; ".join(f"{k} {v}" for k, v in sorted(self.failures().items())) or "none"
        return {
            "pixel_check_fraction": round(self.fraction, 4) if self.samples else -1.0,
            "pixel_check_samples": len(self.samples),
            "pixel_check_every": self.every,
            "pixel_check_forward_fraction": round(self.forward_fraction, 4) if self.samples else -1.0,
            "pixel_check_forward_samples": sum(s.forward for s in self.samples),
            "pixel_check_by_kind": kinds or "none",
            "pixel_check_failures": fails,
            "pixel_check_interior": self.interior,
            "pixel_check_unresolved": self.unresolved,
            "pixel_check_crowded": self.crowded,
        }

    def variables(self, names: tuple[str, str], kinds: Sequence[str]) -> dict[str, Any]:
        """The samples as variables of dimension ``check``."""
        s = self.samples
        units = [point.units_of(n) if n in point.CONTROLS or n in point.PARAMETER_UNITS else "1" for n in names]

        def flags(values: Sequence[str], long_name: str) -> dict[str, Any]:
            return {
                "long_name": long_name,
                "flag_values": np.arange(len(values), dtype=np.int8),
                "flag_meanings": " ".join(values),
            }

        def var(values: list, dtype: Any, attrs: dict[str, Any]) -> tuple:
            return (("check",), np.array(values, dtype), attrs)

        return {
            f"check_{names[0]}": var(
                [v.x for v in s], float, {"units": units[0], "long_name": f"{names[0]} at the crossing"}
            ),
            f"check_{names[1]}": var(
                [v.y for v in s], float, {"units": units[1], "long_name": f"{names[1]} at the crossing"}
            ),
            "check_curve": var([v.curve for v in s], np.int32, {"units": "1", "long_name": "index of the curve"}),
            "check_kind": var([list(kinds).index(v.kind) for v in s], np.int8, flags(kinds, "curve kind")),
            "check_forward": var([v.forward for v in s], np.int8, flags(("return", "forward"), FORWARD)),
            "check_reason": var([REASONS.index(v.reason) for v in s], np.int8, flags(REASONS, "outcome of the check")),
        }


def _share(samples: Sequence[Sample]) -> float:
    return sum(s.ok for s in samples) / len(samples) if samples else float("nan")


def _boundary_segments(curve: Any, px: float, py: float) -> tuple[np.ndarray, np.ndarray]:
    """The segments (start, end; pixel units) of a curve between consecutive points that both bound a stable
    orbit: the parts of the curve that can change the map's labels."""
    flags = np.array([bounds_stable(curve.kind, pt.multipliers, pt.crit) for pt in curve.points])
    pts = np.column_stack([curve.p / px, curve.q / py])
    keep = flags[:-1] & flags[1:]
    return pts[:-1][keep], pts[1:][keep]


def _distance(segments: tuple[np.ndarray, np.ndarray], x: float, y: float) -> float:
    a, b = segments
    if not len(a):
        return np.inf
    pt, ab = np.array([x, y]), b - a
    w = np.clip(np.sum((pt - a) * ab, axis=1) / np.maximum(np.sum(ab * ab, axis=1), 1e-300), 0.0, 1.0)
    return float(np.min(np.linalg.norm(a + w[:, None] * ab - pt, axis=1)))


def _crossings(values: np.ndarray, line: float) -> list[tuple[int, float]]:
    """(segment i, fraction w) where the polyline coordinate ``values`` crosses ``line``."""
    d = values - line
    out = []
    for i in range(d.size - 1):
        if d[i] == 0.0 or (d[i + 1] != 0.0 and (d[i] > 0) != (d[i + 1] > 0)):
            out.append((i, d[i] / (d[i] - d[i + 1]) if d[i] != d[i + 1] else 0.0))
    return out


class _Probe:
    """The curve's orbit at pixels: status (stable, unstable, absent), state, mean X_VH, margin, impact class."""

    def __init__(self, plane: Any, kind: str, n: int, flank: str):
        self.plane, self.kind, self.n, self.flank = plane, kind, n, flank
        self.cache: dict[tuple[float, float], tuple] = {}

    def at(self, p: float, q: float, guesses: Sequence[np.ndarray], near: np.ndarray) -> tuple:
        key = (p, q)
        if key not in self.cache:
            self.cache[key] = self._solve(p, q, guesses, near)
        return self.cache[key]

    def _shorter(self, p: float, q: float, x: np.ndarray) -> bool:
        """True when the period-n orbit through x is one of a proper divisor of n (a shorter orbit repeated)."""
        return shorter_period(self.plane, p, q, x, self.n)

    def _solve(self, p: float, q: float, guesses: Sequence[np.ndarray], near: np.ndarray) -> tuple:
        scale = max(1.0, float(np.max(np.abs(near))))
        found = []
        for g in guesses:
            r = newton_shooting(self.plane.flow(p, q, self.n), g, self.n, 1e-9, max_iter=12)
            if r.converged and float(np.max(np.abs(r.state - near))) < 0.1 * scale and not self._shorter(p, q, r.state):
                found.append(r)
                if r.stable:
                    break
        if not found:
            return ("absent", None, np.nan, np.nan, -1, np.nan)
        r = next((f for f in found if f.stable), found[0])
        if not r.stable:
            return ("unstable", r.state, np.nan, np.nan, -1, np.nan)
        cyc = cycle_states(_Along(self.plane, q), p, r.state, self.n)
        system = self.plane.coefficients(p, q)
        s = self.plane.settings
        margin = np.nan
        if self.kind == "grazing":
            margin = (
                back_margin(system, r.state, self.n, s)
                if self.flank == "back"
                else self.plane.grazing(p, q, r.state, self.n)
            )
        impact = IMPACT_CLASSES[response_measures(system, r.state, s, periods=self.n).impact_class]
        return ("stable", r.state, float(np.mean(cyc[:, 1])), margin, impact, float(np.ptp(cyc[:, 1])))


class _Along:
    """The plane along p at fixed q (what :func:`cycle_states` needs)."""

    def __init__(self, plane: Any, q: float):
        self.plane, self.q = plane, q

    def flow(self, p: float, n: int):
        return self.plane.flow(p, self.q, n)


def _on_orbit(map_mean: float, st: tuple) -> bool:
    return bool(np.isfinite(map_mean) and abs(map_mean - st[2]) <= 1e-3 * max(1.0, abs(st[2])) + 0.1 * st[5])


def _other_ok(kind: str, n: int, lab: int, mean_u: float, mean_s: float, scale: float) -> bool:
    if kind == "period_doubling":
        return lab == 2 * n
    if kind == "neimark_sacker":
        return lab in _TORUS or (lab >= 1 and lab not in (n, 2 * n))
    return lab != n or not np.isfinite(mean_u) or abs(mean_u - mean_s) > 0.05 * scale  # fold: the orbit is gone


def _judge(kind: str, n: int, stable: tuple, other: tuple, maps: tuple, scale: float, forward: bool) -> str:
    """The outcome of one sample (:data:`REASONS`): the stable side (grazing: both sides) on the orbit with
    label P-n, the other side as predicted (module doc)."""
    lab, mean, spread, impact = maps
    sides = (stable, other) if kind in ("grazing", "back_grazing") else (stable,)
    for (j, i), st in sides:
        on = _on_orbit(mean[j, i], st)
        if not (int(lab[j, i]) == n and on):
            return _why(on, spread[j, i], scale, forward)
    (js, is_), (ju, iu) = stable[0], other[0]
    if kind in ("grazing", "back_grazing"):
        ok = impact is None or (int(impact[js, is_]) == stable[1][4] and int(impact[ju, iu]) == other[1][4])
        return "ok" if ok else "impact_class"
    return "ok" if _other_ok(kind, n, int(lab[ju, iu]), mean[ju, iu], mean[js, is_], scale) else "other_side"


def pixel_check(
    plane: Any,
    bd: Boundaries,
    map_ds: xr.Dataset,
    every: int = 5,
    margin: float = 3.0,
    crowd: float = 1.5,
    max_samples: int = 80,
) -> PixelCheck:
    """The pixel check (module doc) of the curves ``bd`` against their map; ``plane`` the curves' plane.
    Crossings within ``margin`` pixels of a codimension-2 point or ``crowd`` pixels of another curve are left
    out (the two pixels would not straddle this curve alone), at most ``max_samples`` per curve."""
    xs, ys = map_ds["x"].values, map_ds["y"].values
    lab, mean, spread = (map_ds[v].values for v in ("label", "x_vh_mean", "x_vh_spread"))
    impact = map_ds["impact_class"].values if "impact_class" in map_ds else None
    px, py = float(xs[1] - xs[0]), float(ys[1] - ys[0])
    c2 = [(b.p, b.q) for c in bd.curves for b in c.codim2]
    segs = [_boundary_segments(c, px, py) for c in bd.curves]
    t0 = time.perf_counter()
    out = PixelCheck(every=every)
    for k, curve in enumerate(bd.curves):
        kind = bd.file_kind(k)
        probe = _Probe(plane, curve.kind, curve.n, bd.flank[k])
        P, Q = curve.p, curve.q
        X = np.array([pt.z[:-2] for pt in curve.points])
        V = [pt.v for pt in curve.points]
        cands = [("row", j, seg, w) for j in range(0, ys.size, every) for seg, w in _crossings(Q, ys[j])]
        cands += [("column", i, seg, w) for i in range(0, xs.size, every) for seg, w in _crossings(P, xs[i])]
        if len(cands) > max_samples:
            cands = [cands[i] for i in np.linspace(0, len(cands) - 1, max_samples).round().astype(int)]
        for line, idx, seg, w in cands:
            x = P[seg] + w * (P[seg + 1] - P[seg]) if seg + 1 < P.size else P[seg]
            y = Q[seg] + w * (Q[seg + 1] - Q[seg]) if seg + 1 < Q.size else Q[seg]
            if any(np.hypot((x - a) / px, (y - b) / py) < margin for a, b in c2):
                continue
            if any(_distance(seg_m, x / px, y / py) < crowd for m, seg_m in enumerate(segs) if m != k):
                out.crowded += 1
                continue
            state = X[seg] + w * (X[min(seg + 1, len(X) - 1)] - X[seg])
            scale = max(1.0, float(np.max(np.abs(state))))
            guesses = [state]
            v = V[seg] if V[seg] is not None else None
            if v is not None:
                guesses += [state + a * scale * v for a in (0.02, -0.02, 0.1, -0.1)]
            sample = _sample(k, kind, curve.n, line, idx, x, y, xs, ys, probe, guesses, state)
            if sample is None:
                out.unresolved += 1
                continue
            if sample == "interior":
                out.interior += 1
                continue
            (js, is_), (ju, iu), sts, stu = sample
            fwd = kind in ("grazing", "back_grazing") or _forward(curve, (js, is_), (ju, iu), xs, ys, js == ju)
            maps = (lab, mean, spread, impact)
            reason = _judge(kind, curve.n, ((js, is_), sts), ((ju, iu), stu), maps, scale, fwd)
            labels = (int(lab[js, is_]), int(lab[ju, iu]))
            out.samples.append(Sample(k, kind, curve.n, float(x), float(y), ((js, is_), (ju, iu)), labels, reason, fwd))
    out.seconds = time.perf_counter() - t0
    return out


def _sample(k, kind, n, line, idx, x, y, xs, ys, probe: _Probe, guesses, state):
    """The pixel pair across the crossing (stable side first) with the orbit there, "interior" when the curve
    bounds no stable orbit there, None when no pair of pixels straddles it."""
    grid, c = (xs, x) if line == "row" else (ys, y)
    i0 = int(np.searchsorted(grid, c) - 1)
    for a in (i0, i0 - 1, i0 + 1):
        if a < 0 or a + 1 >= grid.size:
            continue
        pix = [(idx, a), (idx, a + 1)] if line == "row" else [(a, idx), (a + 1, idx)]
        st = [probe.at(float(xs[i]), float(ys[j]), guesses, state) for j, i in pix]
        status = [s[0] for s in st]
        if kind in ("grazing", "back_grazing"):
            if status != ["stable", "stable"]:
                if status.count("stable") == 1:
                    continue  # another bifurcation between them
                return "interior"
            if not np.sign(st[0][3]) != np.sign(st[1][3]):
                continue
            return pix[0], pix[1], st[0], st[1]
        if status.count("stable") == 1:
            s = status.index("stable")
            return pix[s], pix[1 - s], st[s], st[1 - s]
        if "stable" not in status and a == i0:
            return "interior"
    return None


def _forward(curve, stable_px, other_px, xs, ys, same_row: bool) -> bool:
    """True when the stable pixel's row reaches it without crossing the curve (x increases along a row): the
    curve alone then says what the map shows there."""
    js, is_ = stable_px
    if same_row:
        return is_ < other_px[1]
    p = curve.p
    return not any(
        p[seg] + w * (p[min(seg + 1, p.size - 1)] - p[seg]) < xs[is_] for seg, w in _crossings(curve.q, ys[js])
    )


def _why(on_orbit: bool, spread: float, scale: float, forward: bool) -> str:
    """Why the stable side shows another label: still spiralling onto the orbit (on it, a spread below 1e-3 of
    its size), another attractor carried across the curve by the row (hysteresis) or started on (coexistence)."""
    if on_orbit and np.isfinite(spread) and spread < 1e-3 * scale:
        return "slow_approach"
    return "coexistence" if forward else "hysteresis"
