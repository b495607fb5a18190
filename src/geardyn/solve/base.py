"""The contract of the solver core: what a system must offer, how to integrate, what comes back.

The dimensionless 3-DOF backlash equations, the :data:`LAYOUT` of the kernels' coefficient array and the
settings and results (equations and layout: ``docs/numerics.md``)."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Hashable
from dataclasses import dataclass
from typing import Literal, Protocol

import numpy as np

from geardyn.solve.precision import POINCARE_ERROR

IntegratorName = Literal["rk4", "rk4_event", "dop853"]

#: Order of the flat coefficient array of :meth:`System.kernel_array` (names of the 3-DOF form).
LAYOUT: tuple[str, ...] = (
    *("K11", "C11", "G1", "P1"),  # row 1: x1 stiffness, damping, mesh coupling, load
    *("K21", "C21", "K23", "C23"),  # row 2: couplings of x2 to x1 and x3
    *("K33", "C33", "G3", "P3"),  # row 3
    *("CM", "B", "TE", "PHI", "T"),  # mesh damping, half backlash, TE forcing amplitude and phase, period
    *("BACKLASH_ON", "EPS"),  # 1.0 when the dead zone is active; contact ratio
)
(K11, C11, G1, P1, K21, C21, K23, C23, K33, C33, G3, P3, CM, B, TE, PHI, T, BACKLASH_ON, EPS) = range(len(LAYOUT))


class System(Hashable, Protocol):
    """What the solver needs of a model (see :class:`geardyn.khv.model.Coefficients`): its scalars, read-only (the
    fields of a frozen dataclass), its tables and its static state."""

    @property
    def eps(self) -> float: ...

    @property
    def b(self) -> float: ...

    @property
    def phi(self) -> float: ...

    @property
    def backlash_on(self) -> bool: ...

    @property
    def stiffness_mode(self) -> str: ...

    @property
    def period(self) -> float: ...

    @property
    def te_forcing(self) -> float: ...

    @property
    def c_m(self) -> float: ...

    @property
    def c_DH(self) -> float: ...

    @property
    def c_VL(self) -> float: ...

    def kernel_array(self) -> np.ndarray: ...

    def stiffness_polys(self) -> np.ndarray: ...

    def static_state(self) -> np.ndarray: ...

    def as_dict(self) -> dict[str, float | str | int]: ...


@dataclass(frozen=True)
class ShootingSettings:
    """Newton shooting on the n-period map (:mod:`geardyn.solve.shooting`, ``docs/numerics.md``): converged when
    max |phi(x) - x| <= ``tol`` max(1, max |x|), at most ``max_iter`` iterations, each step capped at ``step_cap``
    max(1, max |x0|), stopped when the residual grows ``max_growth`` times over the previous iterate's (never by
    default)."""

    tol: float = 1e-9
    max_iter: int = 30
    step_cap: float = 10.0
    max_growth: float = math.inf


#: The shooting of every caller that does not name its own settings.
SHOOTING = ShootingSettings()


@dataclass(frozen=True)
class SimulationSettings:
    """How to integrate (times in mesh periods, thresholds in units of b_c); the early-stop fields are
    read by the labeller only (``docs/numerics.md``)."""

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


@dataclass(frozen=True)
class Tangent:
    """A renormalised tangent vector carried over the last ``periods`` periods of a run (at most all of them),
    from ``start`` (None: every component 1/sqrt(6)); its growth and strobe come back (``docs/numerics.md``)."""

    periods: int
    start: np.ndarray | None = None


@dataclass(frozen=True)
class Monodromy:
    """The monodromy matrix carried over the last ``periods`` periods of a run (at most all of them)."""

    periods: int


@dataclass(frozen=True)
class Sums:
    """The response measures' sums (:mod:`geardyn.solve.response`) added over the last ``last`` periods of a run,
    onto ``start`` (None: zeros); not in a batch whose lanes carry a :class:`Monodromy`."""

    last: int
    start: np.ndarray | None = None


@dataclass(frozen=True)
class Lane:
    """One point of a batch run (:func:`geardyn.solve.simulate_batch`): its system, start state (None: the
    static deflection), transient and recorded periods (None: the settings'), variational part and sums."""

    system: System
    start: np.ndarray | None = None
    transient_periods: int | None = None
    recorded_periods: int | None = None
    variational: Tangent | Monodromy | None = None
    sums: Sums | None = None


@dataclass
class SimulationResult:
    """Output of :func:`geardyn.solve.simulate` and :func:`geardyn.solve.simulate_batch` (dimensionless;
    states x1, x2, x3, v1, v2, v3): Poincare points, final state, divergence, dense output, tangent and
    monodromy records, early-stop and response sums (``docs/numerics.md``)."""

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
    """|state_i| above which a run has diverged (6,): ``divergence_threshold`` times the larger of 1 and the
    static deflection (reasons: ``docs/numerics.md``)."""
    static = [abs(float(v)) for v in system.static_state()]
    if not all(math.isfinite(v) for v in static):
        static = [0.0] * 6
    top = max(1.0, *static[:3])
    return settings.divergence_threshold * np.array([*(max(1.0, v) for v in static[:3]), top, top, top])


def static_mesh_force(system: System) -> float:
    """F_s: the mesh force of the static deflection (mean stiffness, no TE), k_mean b_c units."""
    x2 = float(system.static_state()[1])
    b = system.b if system.backlash_on else 0.0
    return x2 - min(max(x2, -b), b)


def drive_side(static_force: float) -> float:
    """+1 or -1: the sign of the drive-side contact, that of the static mesh force (+1 for zero)."""
    return -1.0 if static_force < 0.0 else 1.0


@dataclass(frozen=True)
class EarlyStop:
    """Early stop of the transient (see :mod:`geardyn.solve._batch`): from ``min_periods`` on, stop
    once a return distance d_n (n <= max_n) stays <= tol = max(atol max(|p|, 1), floor) for ``confirm``
    consecutive mesh periods, the smallest such n, with d_m > separation * tol for m < n."""

    min_periods: int = 50
    confirm: int = 10
    max_n: int = 12
    floor: float = POINCARE_ERROR[128]  # the measured Poincare error at 128 steps per period
    atol: float = 1e-7
    separation: float = 10.0

    def as_kernel_args(self) -> tuple[int, int, int, float, float, float]:
        """The early-stop tuple of the compiled loops (``es`` of :func:`geardyn.solve._kernel.run`)."""
        v = dataclasses.astuple(self)
        return (*map(int, v[:3]), *map(float, v[3:]))  # type: ignore[return-value]
