"""The pixel check of regime-boundary curves against their map: every curve crossed with rows and columns of
the map, the curve's orbit shot at the pixels beside each crossing and the map's labels judged (docs/orbits.md,
section 5, "The pixel check": the samples left out, the table of what each side must show, the reasons)."""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import replace

import numpy as np
import xarray as xr

from geardyn.label.vocabulary import LABELS
from geardyn.runs.continuation.curves import (
    RECORD_KINDS,
    BoundaryCurve,
    Curve,
    bounds_stable,
    crossings,
    segment_distance,
)
from geardyn.runs.continuation.family import KHVPlane
from geardyn.runs.continuation.pixel_probe import Orbit, Origin, Probe, Side
from geardyn.runs.continuation.pixel_samples import (
    CheckSettings,
    Crossing,
    PixelCheck,
    Sample,
)

_UNDETERMINED = LABELS["undetermined"]
#: What a pixel just past a Neimark-Sacker curve may show: the torus, a phase-locked torus, or a record that still
#: grows away from the orbit toward the torus at the labeller's cap (``transient``).
_TORUS = (LABELS["quasi_periodic"], LABELS["long_period"], LABELS["transient"])


def slow_margin(map_ds: xr.Dataset) -> float:
    """1 - |mu| below which the map cannot show a stable orbit its record does not start on: the larger of the
    labeller's ``stability_margin`` and 1 / T, T its longest run on a record (slower, an approach looks a torus)."""
    a = map_ds.attrs
    return max(float(a.get("stability_margin", 0.0)), 1.0 / float(a.get("classifier_torus_max_periods", np.inf)))


def _on_orbit(mean: float, spread: float, orbit: Orbit, check: CheckSettings) -> bool:
    """Whether a pixel's mean and spread of X_VH are those of ``orbit``."""
    scale = max(1.0, abs(orbit.mean))
    near = np.isfinite(mean) and abs(mean - orbit.mean) <= check.mean_rtol * scale + check.mean_spread * orbit.spread
    return bool(near and np.isfinite(spread) and spread <= orbit.spread + check.spread_rtol * scale)


def _other_ok(kind: str, n: int, lab: int, moved: bool, supercritical: bool) -> bool:
    """The other side's label as predicted (module doc); moved: its attractor is not the orbit."""
    if kind == "period_doubling" and supercritical:
        return lab == 2 * n
    if kind == "neimark_sacker":
        return lab in _TORUS or (lab >= 1 and lab not in (n, 2 * n)) or (moved and lab != 2 * n)
    return lab != n or moved  # a jump


class _Judge:
    """The outcome of one sample against the map (module doc)."""

    def __init__(self, map_ds: xr.Dataset, slow: float, check: CheckSettings):
        self.lab, self.mean, self.spread = (map_ds[v].values for v in ("label", "x_vh_mean", "x_vh_spread"))
        self.impact = map_ds["impact_class"].values if "impact_class" in map_ds else None
        self.slow, self.check = slow, check

    def stable_side(self, side: Side, n: int, forward: bool) -> str:
        px = side.pixel
        lab, on = int(self.lab[px]), _on_orbit(self.mean[px], self.spread[px], side.orbit, self.check)
        if lab == n and on:
            return "ok"
        if on:
            return "slow" if side.orbit.rho >= 1.0 - self.slow else "stable_side"
        return "coexistence" if forward else "hysteresis"

    def __call__(self, kind: str, n: int, stable: Side, other: Side, forward: bool, supercritical: bool) -> str:
        ps, pu = stable.pixel, other.pixel
        graze = kind in ("grazing", "back_grazing")
        for side in (stable, other) if graze else (stable,):
            why = self.stable_side(side, n, forward)
            if why != "ok":
                return why
        if graze:
            ok = self.impact is None or (
                int(self.impact[ps]) == stable.orbit.impact and int(self.impact[pu]) == other.orbit.impact
            )
            return "ok" if ok else "impact_class"
        if int(self.lab[pu]) == _UNDETERMINED and other.orbit.rho <= 1.0 + self.slow:
            return "slow"  # the labeller resolves no attractor within the margin past the bifurcation either
        moved = not _on_orbit(self.mean[pu], self.spread[pu], stable.orbit, self.check)
        return "ok" if _other_ok(kind, n, int(self.lab[pu]), moved, supercritical) else "other_side"


def pixel_check(
    plane: KHVPlane, curves: Sequence[BoundaryCurve], map_ds: xr.Dataset, check: CheckSettings = CheckSettings()
) -> PixelCheck:
    """The pixel check (module doc) of ``curves`` against their map; ``plane`` the curves' plane."""
    xs, ys = map_ds["x"].values, map_ds["y"].values
    px, py = float(xs[1] - xs[0]), float(ys[1] - ys[0])
    c2 = [(b.p, b.q) for bc in curves for b in bc.curve.codim2]
    stable = [
        np.array([bounds_stable(bc.curve.kind, pt.multipliers, pt.crit) for pt in bc.curve.points]) for bc in curves
    ]
    segs = []  # (start, end) in pixels of the segments that bound a stable orbit: those that change the labels
    for f, c in zip(stable, (bc.curve for bc in curves), strict=True):
        pts, keep = np.column_stack([c.p / px, c.q / py]), f[:-1] & f[1:]
        segs.append((pts[:-1][keep], pts[1:][keep]))
    t0 = time.perf_counter()
    out = PixelCheck(every=check.every, slow_margin=slow_margin(map_ds))
    judge = _Judge(map_ds, out.slow_margin, check)
    for k, bc in enumerate(curves):
        curve, kind = bc.curve, bc.kind
        probe = Probe(plane.back_flank() if bc.flank == "back" else plane, curve, check)
        flags = stable[k]
        own = np.column_stack([curve.p / px, curve.q / py])
        others = [
            m for m, bc in enumerate(curves) if m != k and (kind not in RECORD_KINDS or bc.curve.kind != "grazing")
        ]
        steep = np.abs(np.diff(curve.q)) / py >= np.abs(np.diff(curve.p)) / px  # rows cross it, else columns
        every = check.every
        rows = [Crossing("row", j, g, w) for j in range(0, ys.size, every) for g, w in crossings(curve.q, ys[j])]
        cands = [c for c in rows if steep[c.seg]]
        cands += [Crossing("column", i, g, w) for i in range(0, xs.size, every) for g, w in crossings(curve.p, xs[i])]
        cands = [c for c in cands if c.line == "row" or not steep[min(c.seg, steep.size - 1)]]
        bound = [c for c in cands if flags[c.seg] and flags[min(c.seg + 1, flags.size - 1)]]
        out.interior += len(cands) - len(bound)
        cands = bound
        if len(cands) > check.max_samples:
            cands = [cands[i] for i in np.linspace(0, len(cands) - 1, check.max_samples).round().astype(int)]
        for cross in cands:
            x, y = float(_lerp(curve.p, cross.seg, cross.w)), float(_lerp(curve.q, cross.seg, cross.w))
            base = Sample(k, kind, curve.n, float(x), float(y))
            if any(np.hypot((x - a) / px, (y - b) / py) < check.margin for a, b in c2):
                out.samples.append(replace(base, reason="codim2"))
            elif any(segment_distance(*segs[m], np.array([x / px, y / py])) < check.crowd for m in others) or (
                _self_crowded(own, cross.seg, x / px, y / py, check.crowd)
            ):
                out.samples.append(replace(base, reason="crowded"))
            else:
                out.samples.append(_probe_sample(base, curve, cross, xs, ys, probe, judge))
    out.seconds = time.perf_counter() - t0
    return out


def _self_crowded(pts: np.ndarray, seg: int, x: float, y: float, crowd: float, skip: int = 3) -> bool:
    """True when the curve itself, more than ``skip`` segments away along it from segment ``seg``, passes within
    ``crowd`` pixels of (x, y): a curve folded back on itself (the two folds near a cusp) narrower than that."""
    far = np.r_[0 : max(0, seg - skip), seg + skip + 1 : len(pts) - 1]
    return segment_distance(pts[far], pts[far + 1], np.array([x, y])) < crowd if far.size else False


def _lerp(values: np.ndarray, seg: int, w: float) -> np.ndarray:
    """``values`` at the fraction w of segment seg (of the last point past the end)."""
    return values[seg] + w * (values[min(seg + 1, len(values) - 1)] - values[seg])


def _probe_sample(
    base: Sample, curve: Curve, cross: Crossing, xs: np.ndarray, ys: np.ndarray, probe: Probe, judge: _Judge
) -> Sample:
    """The sample at one crossing: the orbit shot at the pixels beside it, the map judged (module doc)."""
    seg, row = cross.seg, cross.line == "row"
    state = _lerp(np.array([pt.x for pt in curve.points]), seg, cross.w)
    scale = max(1.0, float(np.max(np.abs(state))))
    v = curve.points[seg].v
    guesses = [state] + ([state + a * scale * v for a in probe.check.pushes] if v is not None else [])
    probe.cache.clear()
    origin = Origin(base.x, base.y, "p" if row else "q")
    grid, c = (xs, origin.p) if row else (ys, origin.q)
    i0 = int(np.searchsorted(grid, c) - 1)
    if i0 < 0 or i0 + 1 >= grid.size:
        return replace(base, reason="edge")
    pair = _pair(base.kind, cross, i0, origin, xs, ys, probe, guesses, state)
    if pair is None:
        return replace(base, reason="not_straddled")
    stable, other = pair
    ps, pu = stable.pixel, other.pixel
    graze = base.kind in ("grazing", "back_grazing")
    fwd = graze or _forward(curve, ps, pu, xs, ys, row)
    crit = "untyped"
    if base.kind == "period_doubling" and other.orbit.state is not None:
        t_pair = (float(xs[ps[1]]), float(xs[pu[1]])) if row else (float(ys[ps[0]]), float(ys[pu[0]]))
        crit = probe.criticality(origin, curve.points[seg], state, t_pair)
    reason = judge(base.kind, curve.n, stable, other, fwd, crit == "supercritical")
    labels = (int(judge.lab[ps]), int(judge.lab[pu]))
    rho = stable.orbit.rho
    return replace(base, pixels=(ps, pu), labels=labels, reason=reason, forward=fwd, modulus=rho, criticality=crit)


def _pair(
    kind: str,
    cross: Crossing,
    i0: int,
    origin: Origin,
    xs: np.ndarray,
    ys: np.ndarray,
    probe: Probe,
    guesses: Sequence[np.ndarray],
    state: np.ndarray,
) -> tuple[Side, Side] | None:
    """(stable side, other side) across the crossing, from the pixels i0, i0 + 1 of its line around it or one pixel
    either way; None when no pair straddles a change of the orbit's stability (grazing: of the margin's sign on a
    stable orbit)."""
    size, idx = (xs if cross.line == "row" else ys).size, cross.idx
    for a in (i0, i0 - 1, i0 + 1):
        if a < 0 or a + 1 >= size:
            continue
        pix = [(idx, a), (idx, a + 1)] if cross.line == "row" else [(a, idx), (a + 1, idx)]
        sides = [Side(px, probe.at(float(xs[px[1]]), float(ys[px[0]]), guesses, state, origin)) for px in pix]
        status = [s.orbit.status for s in sides]
        if kind in ("grazing", "back_grazing"):
            if status == ["stable", "stable"] and np.sign(sides[0].orbit.margin) != np.sign(sides[1].orbit.margin):
                return sides[0], sides[1]
        elif status.count("stable") == 1:
            s = status.index("stable")
            return sides[s], sides[1 - s]
    return None


def _forward(
    curve: Curve, stable_px: tuple[int, int], other_px: tuple[int, int], xs: np.ndarray, ys: np.ndarray, same_row: bool
) -> bool:
    """True when the stable pixel's row reaches it without crossing the curve (x increases along a row): the
    curve alone then says what the map shows there."""
    js, is_ = stable_px
    if same_row:
        return is_ < other_px[1]
    return not any(_lerp(curve.p, seg, w) < xs[is_] for seg, w in crossings(curve.q, ys[js]))
