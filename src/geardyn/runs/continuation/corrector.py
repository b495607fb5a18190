"""The engine of every continuation (BifurcationKit's ``ContinuationPar``, ``ContState``, ``newton``): one
settings class, one point record, the predictor, one bordered Newton corrector and one tangent for every
:mod:`~geardyn.runs.continuation.problem` (docs/orbits.md, section 2)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Protocol

import numpy as np

from geardyn.config import settings_from
from geardyn.jsontypes import Json
from geardyn.label.compare import least_period
from geardyn.solve.base import SHOOTING, ShootingSettings


@dataclass(frozen=True)
class ContinuationSettings:
    """Every number of continuation; the defaults are a branch's, :data:`CURVES` a two-parameter curve's.  Steps
    ds in the scaled arclength (x / sx, each parameter over its range); residuals max |F| <= tol max(1, max |x|)
    (``tol``: the ``shooting`` tolerance, which also shoots a branch's seed),
    |G| <= test_tol (a multiplier condition; a grazing margin as F).  The corrector: converged after a step below
    ``step_tol`` with the arclength equation within ``constraint_tol``, failed by a step above ``max_step`` or
    after ``max_corrector`` evaluations; forward differences of step ``dp_rel`` of the scales.  Step control: ds
    grows by ``ds_grow`` after at most ``grow_at`` evaluations, halves after a failure down to ``ds_min``.  A period-n
    point is of period m | n when its m-th cycle point returns within ``merge_tol`` sx (``merge_tol_fold`` at a
    fold); a seed within ``on_curve_tol`` (box sides = 1) of a curve of its kind starts none, one within ``seed_tol``
    sx of a branch of its period too.  Branch switching (docs/orbits.md, section 3) tries the steps ``switch_steps``
    of the range and the amplitudes ``switch_amplitudes``; a period doubling on a known period-2n branch (within
    ``doubled_tol`` sx, or ``touch_tol`` of a point of it, sx and the range scaled to 1) starts none."""

    ds: float = 1e-3
    ds_min: float = 1e-7
    ds_max: float = 1e-3
    shooting: ShootingSettings = SHOOTING
    test_tol: float = 1e-10
    constraint_tol: float = 1e-10
    step_tol: float = 1e-6
    max_step: float = 0.5
    max_corrector: int = 8
    grow_at: int = 3
    ds_grow: float = 1.3
    dp_rel: float = 1e-6
    fold_h: float = 1e-3
    max_points: int = 5000
    max_multiplier: float = 1e8
    grazing: bool = True
    locate: bool = True
    locate_xtol: float = 1e-9
    merge_tol: float = 1e-6
    merge_tol_fold: float = 1e-4
    on_curve_tol: float = 5e-3
    switch_steps: tuple[float, ...] = (1e-3, 1e-2)
    seed_tol: float = 1e-3
    switch_amplitudes: tuple[float, ...] = (1e-2, 1e-1, 1.0)
    doubled_tol: float = 1e-2
    touch_tol: float = 0.0

    @property
    def tol(self) -> float:
        """The residual tolerance of a point: the shooting's."""
        return self.shooting.tol

    @classmethod
    def from_mapping(cls, spec: Mapping[str, Json] | None) -> ContinuationSettings:
        """The settings of a config entry; its ``tol`` is the shooting's tolerance."""
        values = dict(spec or {})
        if "tol" in values:
            values["shooting"] = replace(SHOOTING, tol=float(values.pop("tol")))
        return settings_from(cls, values, "continuation settings")


#: The settings of a two-parameter curve: steps of the plane with both box sides 1, converged on the first
#: residual within tolerance after a step.
CURVES = ContinuationSettings(
    ds=0.01,
    ds_min=1e-6,
    ds_max=0.02,
    step_tol=math.inf,
    max_corrector=10,
    grow_at=4,
    dp_rel=1e-7,
    max_points=400,
    locate_xtol=1e-10,
)


@dataclass(frozen=True)
class Point:
    """A point of a branch or a curve: z = (x, parameters) with ``npar`` parameters, the multipliers by decreasing
    modulus, the unit tangent in the scaled variables (oriented along the march), the corrector's evaluations,
    the arclength fraction u of the step it was located on; a curve's point also its critical multipliers, its
    condition G, its grazing margin and a fold curve's normal-form coefficient with its eigenvector."""

    z: np.ndarray
    multipliers: np.ndarray
    tangent: np.ndarray | None
    iterations: int = 0
    u: float = 0.0
    npar: int = 1
    crit: tuple[complex, ...] = ()
    G: float = float("nan")
    grazing: float = float("nan")
    fold_a: float = float("nan")
    v: np.ndarray | None = None

    x = property(lambda self: self.z[: -self.npar], doc="the orbit's state at phase 0")
    p = property(lambda self: float(self.z[-self.npar]), doc="the (first) parameter")
    q = property(lambda self: float(self.z[-1]), doc="the second parameter")


@dataclass(frozen=True)
class Evaluation:
    """A problem's residual H at one z, the monodromy M there, its Jacobian dH/dz (unscaled) when it comes with
    the residual (else the problem's :meth:`Problem.jacobian` makes it), and the critical multipliers."""

    H: np.ndarray
    M: np.ndarray
    J: np.ndarray | None = None
    crit: tuple[complex, ...] = ()


class Problem(Protocol):
    """What the corrector needs of a problem: the scales of z, its residual (reusing what the last evaluation
    allows), its Jacobian, its convergence test and the point record of a solution."""

    npar: int
    scale: np.ndarray

    def evaluate(self, z: np.ndarray, last: Evaluation | None, ref: Point) -> Evaluation | None: ...

    def jacobian(self, z: np.ndarray, ev: Evaluation, ref: Point) -> np.ndarray | None: ...  # when ev.J is None

    def converged(self, z: np.ndarray, ev: Evaluation) -> bool: ...

    def point(self, z: np.ndarray, ev: Evaluation, t: np.ndarray, iterations: int, ref: Point) -> Point: ...


def tangent(J: np.ndarray, npar: int, ref: np.ndarray | None = None) -> np.ndarray:
    """The unit null vector of the scaled Jacobian J (m, m + 1), oriented like ``ref`` (none: with its largest
    parameter component positive, the last ``npar`` entries)."""
    t = np.linalg.svd(J)[2][-1]
    sign = float(t @ ref) if ref is not None else float(t[-npar:][np.argmax(np.abs(t[-npar:]))])
    return t if sign >= 0 else -t


def correct(
    problem: Problem, z: np.ndarray, row: np.ndarray, c: float, cs: ContinuationSettings, ref: Point
) -> Point | None:
    """Newton on (H(z) = 0, row . u = c), u = z / scale, from z; the point with its tangent oriented like
    ``ref.tangent`` (``ref``: the point it was predicted from), or None (module doc, :class:`ContinuationSettings`).
    The tangent takes the newest Jacobian known without a new evaluation."""
    sc = problem.scale
    ev, J, last = None, None, math.inf
    for it in range(cs.max_corrector):
        ev = problem.evaluate(z, ev, ref)
        if ev is None or not np.all(np.isfinite(ev.H)):
            return None
        lin = float(row @ (z / sc)) - c
        if last < cs.step_tol and abs(lin) < cs.constraint_tol and problem.converged(z, ev):
            t = tangent((ev.J if ev.J is not None else J) * sc, problem.npar, ref.tangent)
            return problem.point(z, ev, t, it + 1, ref)
        J = ev.J if ev.J is not None else problem.jacobian(z, ev, ref)
        if J is None or not np.all(np.isfinite(J)):
            return None
        try:
            du = np.linalg.solve(np.vstack([J * sc, row]), -np.append(ev.H, lin))
        except np.linalg.LinAlgError:
            return None
        last = float(np.max(np.abs(du)))
        if last > cs.max_step:  # far off the predicted point: the step control shortens ds
            return None
        z = z + du * sc
    return None


def predict(problem: Problem, pt: Point, h: float) -> tuple[np.ndarray, float]:
    """The point at scaled arclength h from ``pt`` along its tangent, and the arclength equation's right side."""
    u = pt.z / problem.scale + h * pt.tangent
    return u * problem.scale, float(pt.tangent @ u)


def step(problem: Problem, pt: Point, h: float, cs: ContinuationSettings) -> Point | None:
    """Predictor and corrector: the point at scaled arclength h from ``pt`` (pseudo-arclength), or None."""
    z, c = predict(problem, pt, h)
    return correct(problem, z, pt.tangent, c, cs, pt)


def merged(cycle: np.ndarray, n: int, tol: float) -> int:
    """m when the period-n orbit of the n points ``cycle`` is one of period m (a proper divisor of n) traversed
    n / m times, within ``tol`` (:func:`geardyn.label.compare.least_period`), else 0 (also for a cycle cut short
    by divergence)."""
    if cycle.shape[0] < n or not np.all(np.isfinite(cycle)):
        return 0
    m = least_period(cycle[:n], tol)
    return m if m < n else 0
