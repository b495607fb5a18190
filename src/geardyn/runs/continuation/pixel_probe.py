"""The curve's orbit at the pixels beside a crossing of the pixel check (:class:`Probe`): shot by Newton from
the curve's state, else followed along the crossing's line; and the criticality of a period doubling there
(docs/orbits.md, section 5, "The pixel check")."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from typing import NamedTuple

import numpy as np

from geardyn.runs.continuation.branch import Bifurcation
from geardyn.runs.continuation.corrector import CURVES, Point, correct
from geardyn.runs.continuation.curves import Curve, shorter_period
from geardyn.runs.continuation.family import KHVPlane, PlaneLine, cached
from geardyn.runs.continuation.pixel_samples import CheckSettings
from geardyn.runs.continuation.problem import CurveProblem
from geardyn.runs.continuation.stepping import continue_branch
from geardyn.runs.continuation.switching import switch_at_period_doubling
from geardyn.solve.response import IMPACT_CLASSES, response_measures
from geardyn.solve.shooting import newton_shooting


class Orbit(NamedTuple):
    """The curve's orbit at a pixel (:meth:`Probe.at`): ``status`` stable, unstable or absent, its phase-0 state,
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


class Side(NamedTuple):
    """One pixel (row, column) beside a crossing and the curve's orbit there."""

    pixel: tuple[int, int]
    orbit: Orbit


class Probe:
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
