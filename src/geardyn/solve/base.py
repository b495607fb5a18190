"""The contract of the solver core: what a system must offer, how to integrate, what comes back.

The solver integrates one family of equations, the dimensionless 3-DOF form of a gear stage with
one backlash mesh (paper 1 Eq. 16, corrected)::

    x'' + C x' + K x + g (kappa(s) f(x2) + c_m x2') = p + (0, te sin(2 pi s + phi), 0)

with the mesh phase s = tau / T, a piecewise-quadratic stiffness kappa(s) on the two zones
[0, f] and [f, 1] of every mesh period (f = eps - floor(eps), one pair more on the first), and the dead zone f of
half width b.  Any
object that satisfies :class:`System` can be integrated; :class:`geardyn.khv.model.Coefficients`
is the one the KHV model family builds.

The numbers the compiled kernels read are packed in one flat array in the order of
:data:`LAYOUT`; every reader (the RK4 kernels, the DOP853 reference) uses the named indices
below, never a raw position.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, Protocol

import numpy as np

IntegratorName = Literal["rk4", "rk4_event", "dop853"]

#: Order of the flat coefficient array of :meth:`System.kernel_array` (names of the 3-DOF form).
LAYOUT: tuple[str, ...] = (
    "K11",
    "C11",
    "G1",
    "P1",  # row 1: x1 stiffness, damping, mesh coupling, load
    "K21",
    "C21",
    "K23",
    "C23",  # row 2: couplings of x2 to x1 and x3
    "K33",
    "C33",
    "G3",
    "P3",  # row 3
    "CM",
    "B",
    "TE",
    "PHI",
    "T",  # mesh damping, half backlash, TE forcing amplitude and phase, period
    "BACKLASH_ON",
    "EPS",  # 1.0 when the dead zone is active; contact ratio
)
(K11, C11, G1, P1, K21, C21, K23, C23, K33, C33, G3, P3, CM, B, TE, PHI, T, BACKLASH_ON, EPS) = range(len(LAYOUT))


class System(Protocol):
    """What the solver needs of a model (see :class:`geardyn.khv.model.Coefficients`)."""

    eps: float
    b: float
    phi: float
    backlash_on: bool
    stiffness_mode: str

    @property
    def period(self) -> float: ...

    @property
    def te_forcing(self) -> float: ...

    def kernel_array(self) -> np.ndarray: ...

    def stiffness_polys(self) -> np.ndarray: ...

    def static_state(self) -> np.ndarray: ...


@dataclass(frozen=True)
class SimulationSettings:
    """How to integrate.  Times in mesh periods; thresholds in units of b_c.

    steps_per_period: N (default 512 from the work-precision study, ``python -m benchmarks.bench``).
    aligned: False spreads N equal steps over the period regardless of the stiffness jumps
    (for demonstrations only; rk4 integrators).  rtol: only used by ``"dop853"``.
    divergence_threshold: a run has diverged when any |state_i| exceeds this many times the larger of 1
    and the same component of the static deflection (:func:`divergence_limits`), or is not finite.

    Used by the labeller (:mod:`geardyn.label`, through :func:`geardyn.solve.simulate_batch`), never by
    :func:`geardyn.solve.simulate` itself:

    early_stop: end the transient once the stroboscopic map has converged to a period-n cycle
    (return distance <= early_stop_tol_factor x the classifier's tolerance floor for
    early_stop_confirm consecutive periods, not before early_stop_min_periods); False: always the
    full ``transient_periods``.
    """

    integrator: IntegratorName = "rk4_event"
    steps_per_period: int = 512
    transient_periods: int = 500
    recorded_periods: int = 100
    divergence_threshold: float = 1.0e4
    aligned: bool = True
    rtol: float = 1.0e-12
    dense_stride: int = 1
    early_stop: bool = True
    early_stop_min_periods: int = 50
    early_stop_confirm: int = 10
    early_stop_tol_factor: float = 0.1

    def __post_init__(self) -> None:
        if self.integrator not in ("rk4", "rk4_event", "dop853"):
            raise ValueError(f"integrator {self.integrator!r}; allowed: 'rk4', 'rk4_event', 'dop853'")
        if self.steps_per_period < 2:
            raise ValueError("steps_per_period must be >= 2")
        if self.early_stop_confirm < 1 or self.early_stop_min_periods < 0 or not self.early_stop_tol_factor > 0:
            raise ValueError("early_stop_confirm >= 1, early_stop_min_periods >= 0, early_stop_tol_factor > 0")


@dataclass
class SimulationResult:
    """Output of :func:`geardyn.solve.simulate` (dimensionless; states ordered x1, x2, x3, v1, v2, v3
    with x = (X_DH, X_VH, X_VL) / b_c, v = dx / dtau).

    poincare: (n, 6) state at the end of each recorded mesh period (phase 0).
    final_state: (6,) state at the end of the run (phase 0): continue a sweep from it
    (after a divergence: the state at the period end where it was detected).
    diverged / diverged_period: the period (counted from the start, transient included)
    at which |state| first exceeded the threshold, else -1; poincare then holds only the
    points recorded before.
    tau, states: dense trajectory over the recorded periods (``dense=True``), on the step
    grid (nearly uniform; use :meth:`uniform` for spectra).
    growth, strobe: with a tangent vector (``tangent_periods > 0``), log of its growth over each of
    the last ``tangent_periods`` mesh periods (renormalised after each) and X_VH / b_c at the end of
    those periods (stroboscopic samples for the 0-1 test).
    monodromy: with ``monodromy_periods = n``, the (6, 6) derivative of the state after the last n
    periods with respect to the state n periods before the end (the monodromy matrix of a period-n
    orbit, when the run ends on it).
    transient_used: transient periods actually integrated (less than ``transient_periods`` after an
    early stop, :func:`geardyn.solve.simulate_batch`); tangent: the (renormalised) tangent vector at the end
    of a batch run that carried one (:func:`geardyn.solve.simulate_batch` continues it from there, the same
    numbers as one longer run); stop_period: the n of the period-n cycle the
    early stop saw (0: no early stop).  sums: the response measures' sums
    (:mod:`geardyn.solve._response`) over the run's last periods, where a batch run was asked for them
    (``sums_last`` of :func:`geardyn.solve.simulate_batch`; reduced by
    :func:`geardyn.solve.response.measures_of_sums`).
    """

    poincare: np.ndarray
    final_state: np.ndarray
    diverged: bool
    diverged_period: int
    n_events: int = 0
    tau: np.ndarray | None = None
    states: np.ndarray | None = None
    period: float = float("nan")
    settings: SimulationSettings | None = None
    growth: np.ndarray | None = None
    strobe: np.ndarray | None = None
    monodromy: np.ndarray | None = None
    transient_used: int = -1
    stop_period: int = 0
    tangent: np.ndarray | None = None
    sums: np.ndarray | None = None

    def uniform(self, samples_per_period: int) -> tuple[np.ndarray, np.ndarray]:
        """Dense trajectory resampled on a uniform grid (cubic spline) for FFTs."""

        if self.tau is None or self.states is None:
            raise ValueError("run simulate(..., dense=True) first")
        t, idx = np.unique(self.tau, return_index=True)
        from scipy.interpolate import CubicSpline  # noqa: PLC0415 - 0.1 s to import: only dense output needs it

        cs = CubicSpline(t, self.states[idx], axis=0)
        n = round((t[-1] - t[0]) / self.period * samples_per_period)
        tu = t[0] + np.arange(n + 1) * self.period / samples_per_period
        tu = tu[tu <= t[-1]]
        return tu, cs(tu)


def divergence_limits(system: System, settings: SimulationSettings) -> np.ndarray:
    """|state_i| above which a run has diverged, per state (6,): ``divergence_threshold`` times the larger
    of 1 and that displacement's static deflection (velocities: the largest static displacement, the
    dimensionless frequencies being of order 1).  A heavily loaded design (a large static deflection) is
    therefore not called diverged; growth by that factor is unbounded growth whatever the load."""
    static = np.abs(system.static_state())
    if not np.all(np.isfinite(static)):
        static = np.zeros(6)
    scale = np.maximum(1.0, static)
    scale[3:] = max(1.0, float(np.max(static[:3])))
    return settings.divergence_threshold * scale


def static_mesh_force(system: System) -> float:
    """F_s: the mesh force of the static deflection (mean stiffness, no TE), k_mean b_c units."""
    x2 = float(system.static_state()[1])
    b = system.b if system.backlash_on else 0.0
    return x2 - min(max(x2, -b), b)


def drive_side(static_force: float) -> float:
    """+1 or -1: the sign of the drive-side contact, that of the static mesh force (+1 for zero)."""
    return -1.0 if static_force < 0.0 else 1.0
