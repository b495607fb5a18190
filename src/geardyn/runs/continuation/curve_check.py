"""The pixel check of regime-boundary curves against their map: every curve crossed with rows and columns of
the map, the curve's orbit shot at the pixels beside each crossing and the map's labels judged (docs/orbits.md,
section 5, "The pixel check": the samples left out, the table of what each side must show, the reasons)."""

from __future__ import annotations

import time
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import NamedTuple

import numpy as np
import xarray as xr

from geardyn.io import Var
from geardyn.jsontypes import Json
from geardyn.label.classify import LABELS
from geardyn.runs.continuation.branch import Bifurcation
from geardyn.runs.continuation.corrector import CURVES, ContinuationSettings, Point, correct
from geardyn.runs.continuation.curves import (
    RECORD_KINDS,
    BoundaryCurve,
    Curve,
    bounds_stable,
    crossings,
    segment_distance,
    shorter_period,
)
from geardyn.runs.continuation.family import KHVPlane, PlaneLine, cached
from geardyn.runs.continuation.output import index, quantity
from geardyn.runs.continuation.problem import CurveProblem
from geardyn.runs.continuation.stepping import continue_branch
from geardyn.runs.continuation.switching import switch_at_period_doubling
from geardyn.solve import bifurcations
from geardyn.solve.base import ShootingSettings
from geardyn.solve.bifurcations import CODES
from geardyn.solve.response import IMPACT_CLASSES, response_measures
from geardyn.solve.shooting import newton_shooting

_UNDETERMINED = LABELS["undetermined"]
#: Failures of a checked sample.
FAILURES = ("not_straddled", "stable_side", "other_side", "impact_class")
#: Samples left out of the fraction, each with its reason (module doc).
EXCLUDED = ("codim2", "crowded", "edge", "slow", "hysteresis", "coexistence")
#: Outcomes of a sample (``check_reason`` flags); the first is a pass.
REASONS = ("ok", *FAILURES, *EXCLUDED)
FORWARD = "the stable pixel's row reaches it without crossing the curve"
#: Criticality of a period doubling (``check_criticality`` flags; "untyped" for the other kinds).
CRITICALITY = ("untyped", "supercritical", "subcritical")
#: What a pixel just past a Neimark-Sacker curve may show: the torus, a phase-locked torus, or a record that still
#: grows away from the orbit toward the torus at the labeller's cap (``transient``).
_TORUS = (LABELS["quasi_periodic"], LABELS["long_period"], LABELS["transient"])


@dataclass(frozen=True)
class CheckSettings:
    """The numbers of the pixel check (docs/orbits.md, section 5): the samples (``every``, ``max_samples``), left
    out (``margin``, ``crowd`` pixels), the orbit at a pixel (Newton: ``shooting``, ``pushes`` along the
    fold eigenvector, within ``near``; else ``follow``, the probes' branches: about 8 steps over the way, none below
    1/512 of it, from ``follow_share`` of it; a period doubling's switched branch halves its steps down to
    ``switch_ds_min``), a pixel on the orbit (``mean_rtol``, ``mean_spread``, ``spread_rtol``)."""

    every: int = 5
    margin: float = 3.0
    crowd: float = 1.5
    max_samples: int = 80
    shooting: ShootingSettings = ShootingSettings(max_iter=12)
    pushes: tuple[float, ...] = (0.02, -0.02, 0.1, -0.1)
    near: float = 0.1
    follow: ContinuationSettings = ContinuationSettings(
        ds=0.125, ds_min=2e-3, ds_max=0.125, max_points=40, grazing=False, locate=False
    )
    switch_ds_min: float = 1e-7
    follow_share: float = 0.125
    mean_rtol: float = 1e-3
    mean_spread: float = 0.1
    spread_rtol: float = 1e-2


class Orbit(NamedTuple):
    """The curve's orbit at a pixel (:meth:`_Probe.at`): ``status`` stable, unstable or absent, its phase-0 state,
    of a stable orbit the mean of X_VH over its cycle, its grazing margin (grazing curves; else NaN), its impact
    class (:data:`~geardyn.solve.response.IMPACT_CLASSES`; -1: none) and the spread of X_VH, and its largest
    multiplier modulus (NaN: absent)."""

    status: str
    state: np.ndarray | None = None
    mean: float = float("nan")
    margin: float = float("nan")
    impact: int = -1
    spread: float = float("nan")
    rho: float = float("nan")


class Origin(NamedTuple):
    """A crossing (p, q) of a curve with a row (``along`` "p") or a column (``along`` "q")."""

    p: float
    q: float
    along: str


class Crossing(NamedTuple):
    """A row (``line`` "row", index ``idx`` of y) or a column (``line`` "column", index of x) that crosses a
    curve at the fraction ``w`` of its segment ``seg``."""

    line: str
    idx: int
    seg: int
    w: float


class Side(NamedTuple):
    """One pixel (row, column) beside a crossing and the curve's orbit there."""

    pixel: tuple[int, int]
    orbit: Orbit


@dataclass(frozen=True)
class Sample:
    """One crossing (x, y) of a curve: the two pixels ((row, column), the stable side first), their labels, the
    outcome (:data:`REASONS`), :data:`FORWARD`, the stable side's largest multiplier modulus, the criticality."""

    curve: int
    kind: str
    n: int
    x: float
    y: float
    pixels: tuple = ()
    labels: tuple[int, int] = (0, 0)
    reason: str = "ok"
    forward: bool = True
    modulus: float = float("nan")
    criticality: str = "untyped"

    @property
    def ok(self) -> bool:
        return self.reason == "ok"

    @property
    def checked(self) -> bool:
        return self.reason not in EXCLUDED


@dataclass
class PixelCheck:
    """The samples, and how many crossings lay where the curve bounds no stable orbit (``interior``)."""

    samples: list[Sample] = field(default_factory=list)
    every: int = 1
    seconds: float = 0.0
    interior: int = 0
    slow_margin: float = 0.0

    @property
    def checked(self) -> list[Sample]:
        return [s for s in self.samples if s.checked]

    @property
    def fraction(self) -> float:
        """The share of the checked samples that pass."""
        c = self.checked
        return sum(s.ok for s in c) / len(c) if c else float("nan")

    def by_kind(self) -> dict[str, tuple[int, int]]:
        out: dict[str, tuple[int, int]] = {}
        for s in self.checked:
            ok, n = out.get(s.kind, (0, 0))
            out[s.kind] = (ok + s.ok, n + 1)
        return out

    def tally(self, reasons: Sequence[str]) -> Counter:
        return Counter(f"{s.kind}: {s.reason}" for s in self.samples if s.reason in reasons)

    def attrs(self) -> dict[str, Json]:
        """Global attributes of the curves file."""

        def text(c: Counter) -> str:
            return "; ".join(f"{k} {v}" for k, v in sorted(c.items())) or "none"

        kinds = "; ".join(f"{k} {ok}/{n}" for k, (ok, n) in sorted(self.by_kind().items()))
        return {
            "pixel_check_fraction": round(self.fraction, 4) if self.checked else -1.0,
            "pixel_check_samples": len(self.checked),
            "pixel_check_passed": sum(s.ok for s in self.samples),
            "pixel_check_every": self.every,
            "pixel_check_by_kind": kinds or "none",
            "pixel_check_failures": text(self.tally(FAILURES)),
            "pixel_check_excluded": text(self.tally(EXCLUDED)),
            "pixel_check_interior": self.interior,
            "pixel_check_slow_margin": self.slow_margin,
        }

    def variables(self, names: tuple[str, str], kinds: Sequence[str]) -> list[tuple[Var, Json]]:
        """The samples as (row, values) of dimension ``check``."""
        s, C = self.samples, "check"
        pix = np.array([list(v.pixels[0]) + list(v.pixels[1]) if v.pixels else [-1] * 4 for v in s], np.int32)
        pixels = "row, column of the stable-side pixel, then the other (-1: none)"
        labels, modulus = (
            "map label at the stable-side pixel and the other",
            "largest multiplier modulus, stable-side orbit",
        )
        reason = Var(
            "check_reason", C, None, "outcome of the check", index(REASONS), attrs={"failures": " ".join(FAILURES)}
        )
        return [
            *[
                (Var(f"check_{n}", C, quantity(n)[0], f"{n} at the crossing"), [getattr(v, a) for v in s])
                for n, a in zip(names, "xy", strict=True)
            ],
            (Var("check_curve", C, "1", "index of the curve", dtype=np.int32), [v.curve for v in s]),
            (Var("check_kind", C, None, "curve kind", bifurcations.flags(kinds)), [CODES[v.kind] for v in s]),
            (Var("check_forward", C, None, FORWARD, index(("return", "forward"))), [v.forward for v in s]),
            (reason, [REASONS.index(v.reason) for v in s]),
            (Var("check_pixels", (C, "pixel_index"), "1", pixels), pix.reshape(len(s), 4)),
            (
                Var("check_labels", (C, "side"), "1", labels, dtype=np.int16),
                np.reshape([v.labels for v in s], (len(s), 2)),
            ),
            (Var("check_modulus", C, "1", modulus), np.array([v.modulus for v in s], float)),
            (
                Var("check_criticality", C, None, "criticality", index(CRITICALITY)),
                [CRITICALITY.index(v.criticality) for v in s],
            ),
        ]


class _Probe:
    """The curve's orbit at pixels (:meth:`at`): status (stable, unstable, absent), state, mean X_VH, margin,
    impact class, spread of X_VH, largest multiplier modulus; and the criticality of a period doubling."""

    def __init__(self, plane: KHVPlane, curve: Curve, check: CheckSettings):
        self.plane, self.curve, self.kind, self.n, self.check = plane, curve, curve.kind, curve.n, check
        self.cache: dict[tuple[float, float], Orbit] = {}

    def at(self, p: float, q: float, guesses: Sequence[np.ndarray], near: np.ndarray, origin: Origin) -> Orbit:
        """The orbit at (p, q), cached: Newton from each guess within ``near`` of the curve's state (the stable one
        nearest it), else :meth:`followed` from the crossing ``origin``."""
        return cached(self.cache, (p, q), lambda key: self._solve(key[0], key[1], guesses, near, origin))

    def _solve(self, p: float, q: float, guesses: Sequence[np.ndarray], near: np.ndarray, origin: Origin) -> Orbit:
        scale = max(1.0, float(np.max(np.abs(near))))
        found = []
        for g in guesses:
            sh = self.check.shooting
            r = newton_shooting(self.plane.flow(p, q, self.n), g, self.n, sh.tol, sh.max_iter)
            if r.converged and float(np.max(np.abs(r.state - near))) < self.check.near * scale:
                found.append((r.state, r.spectral_radius))
        found = found or self.followed(p, q, near, origin)
        found = [f for f in found if not shorter_period(self.plane, p, q, f[0], self.n)]
        if not found:
            return Orbit("absent")
        x, rho = min(found, key=lambda f: (f[1] >= 1.0, float(np.max(np.abs(f[0] - near)))))  # stable, nearest
        if rho >= 1.0:
            return Orbit("unstable", x, rho=rho)
        cyc = self.plane.cycle(p, q, x, self.n)
        system, s = self.plane.coefficients(p, q), self.plane.settings
        margin = self.plane.grazing(p, q, x, self.n) if self.kind == "grazing" else np.nan
        impact = IMPACT_CLASSES[response_measures(system, x, s, periods=self.n).impact_class]
        return Orbit("stable", x, float(np.mean(cyc[:, 1])), margin, impact, float(np.ptp(cyc[:, 1])), rho)

    def followed(self, p: float, q: float, x: np.ndarray, origin: Origin) -> list[tuple[np.ndarray, float]]:
        """The orbit at (p, q) on the branch along the crossing's line from ``follow_share`` of the way from
        ``origin`` (state x); none when the branch does not reach (p, q)."""
        along = origin.along
        t0, t1 = (origin.p, p) if along == "p" else (origin.q, q)
        line = PlaneLine(self.plane, along, q if along == "p" else p)
        ts = t0 + self.check.follow_share * (t1 - t0)
        lo, hi = min(ts, t1), max(ts, t1)
        br = continue_branch(line, ts, x, self.n, lo, hi, self.check.follow, ("up",) if t1 > ts else ("down",))
        if br is None or br.p[-1 if t1 > ts else 0] != t1:
            return []
        k = -1 if t1 > ts else 0
        return [(br.states[k], float(np.max(np.abs(br.multipliers[k]))))]

    def criticality(self, origin: Origin, ref: Point, state: np.ndarray, t_pair: tuple[float, float]) -> str:
        """A period doubling's criticality on the crossing's line: the period-2n branch switched at the curve's
        point solved on the line (from ``state`` and the curve point ``ref``) is ``supercritical`` when it reaches
        the other pixel of ``t_pair`` (stable side, other side) stable."""
        along, d = origin.along, state.size
        held = d + 1 if along == "p" else d
        prob = CurveProblem(self.plane, self.kind, self.n, d, self.curve.scales, CURVES)
        z = np.r_[state, origin.p, origin.q]
        pt = correct(prob, z, np.eye(d + 2)[held], z[held] / prob.scale[held], CURVES, ref)
        if pt is None:
            return "subcritical"
        at, t_cross = (pt.q, pt.p) if along == "p" else (pt.p, pt.q)
        bf = Bifurcation("period_doubling", t_cross, pt.x, pt.multipliers, -1.0, np.nan, -1, True, self.n)
        lo, hi = sorted(t_pair)
        t_other = t_pair[1]
        follow = replace(self.check.follow, ds_min=self.check.switch_ds_min)
        br = switch_at_period_doubling(PlaneLine(self.plane, along, at), bf, lo, hi, follow)
        reached = [] if br is None else [i for i, _ in br.states_at(t_other)]
        return (
            "supercritical"
            if br is not None and any(br.stable[i] and br.stable[i + 1] for i in reached)
            else "subcritical"
        )


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
        probe = _Probe(plane.back_flank() if bc.flank == "back" else plane, curve, check)
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
    base: Sample, curve: Curve, cross: Crossing, xs: np.ndarray, ys: np.ndarray, probe: _Probe, judge: _Judge
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
    probe: _Probe,
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
