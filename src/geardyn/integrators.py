"""Fixed-step RK4 kernels (numba) for the dimensionless KHV model, and :func:`simulate`.

Method (MODEL_NOTES "Numerics"):

* The step grid is aligned to the stiffness jumps: each mesh period [0, 1) (phase s) is split
  into the double-contact zone [0, eps-1] with N1 = max(1, round(N (eps-1))) steps and the
  single-contact zone [eps-1, 1] with N - N1 steps.  No RK4 stage ever sees a jump.
* Stiffness kappa and TE forcing repeat every period: they are tabulated per step at the
  three RK4 stage times (start+, middle, end-), so a step costs four right-hand sides and
  no transcendental function.
* ``"rk4"``: plain RK4 on that grid.  The dead zone f(x2) has a kinked derivative, so the
  order drops when a step straddles a contact switch.
* ``"rk4_event"``: after each step, a change of contact region (x2 < -b, |x2| <= b, x2 > b)
  means a crossing of x2 = +-b inside the step; it is located as the root of the cubic
  Hermite interpolant of x2 (values and x2' = v2 at both ends; Illinois iterations), the
  step is redone up to the crossing and continued from there to the grid point.  The error
  of the crossing time is O(h^4) and enters the solution only at second order (the vector
  field is continuous there), so 4th order is recovered.
* Divergence: checked once per mesh period; any |state| > threshold or non-finite value
  stops the run and sets ``diverged``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Literal

import numpy as np
from numba import njit

from geardyn.model import Coefficients, static_deflection

IntegratorName = Literal["rk4", "rk4_event", "dop853"]

# indices into Coefficients.kernel_array()
_A11, _D11, _G1, _P1, _A21, _D21, _A23, _D23, _A33, _D33, _G3, _P3 = range(12)
_CM, _B, _TE, _PHI, _T, _BON, _EPS = range(12, 19)


@dataclass(frozen=True)
class SimulationSettings:
    """How to integrate.  Times in mesh periods; thresholds in units of b_c.

    steps_per_period: N (default 512 from the work-precision study, ``python -m geardyn.bench``).
    aligned: False spreads N equal steps over the period regardless of the stiffness jumps
    (for demonstrations only; rk4 integrators).  rtol: only used by ``"dop853"``.
    """

    integrator: IntegratorName = "rk4_event"
    steps_per_period: int = 512
    transient_periods: int = 500
    recorded_periods: int = 100
    divergence_threshold: float = 1.0e4
    aligned: bool = True
    rtol: float = 1.0e-12
    dense_stride: int = 1

    def __post_init__(self) -> None:
        if self.integrator not in ("rk4", "rk4_event", "dop853"):
            raise ValueError(f"integrator {self.integrator!r}; allowed: 'rk4', 'rk4_event', 'dop853'")
        if self.steps_per_period < 2:
            raise ValueError("steps_per_period must be >= 2")


@dataclass
class SimulationResult:
    """Output of :func:`simulate` (dimensionless; states ordered x1, x2, x3, v1, v2, v3 with
    x = (X_DH, X_VH, X_VL) / b_c, v = dx / dtau).

    poincare: (n, 6) state at the end of each recorded mesh period (phase 0).
    final_state: (6,) state at the end of the run (phase 0): continue a sweep from it
    (after a divergence: the state at the period end where it was detected).
    diverged / diverged_period: the period (counted from the start, transient included)
    at which |state| first exceeded the threshold, else -1; poincare then holds only the
    points recorded before.
    tau, states: dense trajectory over the recorded periods (``dense=True``), on the step
    grid (nearly uniform; use :meth:`uniform` for spectra).
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

    def uniform(self, samples_per_period: int) -> tuple[np.ndarray, np.ndarray]:
        """Dense trajectory resampled on a uniform grid (cubic spline) for FFTs."""
        from scipy.interpolate import CubicSpline

        if self.tau is None or self.states is None:
            raise ValueError("run simulate(..., dense=True) first")
        t, idx = np.unique(self.tau, return_index=True)
        cs = CubicSpline(t, self.states[idx], axis=0)
        n = int(round((t[-1] - t[0]) / self.period * samples_per_period))
        tu = t[0] + np.arange(n + 1) * self.period / samples_per_period
        tu = tu[tu <= t[-1]]
        return tu, cs(tu)


# ----------------------------------------------------------------------------------------
# numba kernels
# ----------------------------------------------------------------------------------------


@njit(cache=True, inline="always")
def _fdead(x, b, on):
    if on == 0.0:
        return x
    if x > b:
        return x - b
    if x < -b:
        return x + b
    return 0.0


@njit(cache=True, inline="always")
def _rhs(c, x1, x2, x3, v1, v2, v3, kap, pe):
    fm = kap * _fdead(x2, c[_B], c[_BON]) + c[_CM] * v2
    a1 = c[_P1] - c[_A11] * x1 - c[_D11] * v1 - c[_G1] * fm
    a2 = pe - c[_A21] * x1 - c[_D21] * v1 - c[_A23] * x3 - c[_D23] * v3 - fm
    a3 = c[_P3] - c[_A33] * x3 - c[_D33] * v3 - c[_G3] * fm
    return a1, a2, a3


@njit(cache=True, inline="always")
def _rk4(c, y, h, k0, k1, k2, p0, p1, p2, out):
    """One RK4 step of size h from y (6,) into out (6,), with stage values of kappa and TE."""
    x1, x2, x3, v1, v2, v3 = y[0], y[1], y[2], y[3], y[4], y[5]
    hh = 0.5 * h
    a1, a2, a3 = _rhs(c, x1, x2, x3, v1, v2, v3, k0, p0)
    # stage 2
    X1 = x1 + hh * v1
    X2 = x2 + hh * v2
    X3 = x3 + hh * v3
    V1 = v1 + hh * a1
    V2 = v2 + hh * a2
    V3 = v3 + hh * a3
    b1, b2, b3 = _rhs(c, X1, X2, X3, V1, V2, V3, k1, p1)
    sx1, sx2, sx3 = v1 + 2.0 * V1, v2 + 2.0 * V2, v3 + 2.0 * V3
    sv1, sv2, sv3 = a1 + 2.0 * b1, a2 + 2.0 * b2, a3 + 2.0 * b3
    # stage 3
    W1 = v1 + hh * b1
    W2 = v2 + hh * b2
    W3 = v3 + hh * b3
    c1, c2, c3 = _rhs(c, x1 + hh * V1, x2 + hh * V2, x3 + hh * V3, W1, W2, W3, k1, p1)
    sx1 += 2.0 * W1
    sx2 += 2.0 * W2
    sx3 += 2.0 * W3
    sv1 += 2.0 * c1
    sv2 += 2.0 * c2
    sv3 += 2.0 * c3
    # stage 4
    U1 = v1 + h * c1
    U2 = v2 + h * c2
    U3 = v3 + h * c3
    d1, d2, d3 = _rhs(c, x1 + h * W1, x2 + h * W2, x3 + h * W3, U1, U2, U3, k2, p2)
    h6 = h / 6.0
    out[0] = x1 + h6 * (sx1 + U1)
    out[1] = x2 + h6 * (sx2 + U2)
    out[2] = x3 + h6 * (sx3 + U3)
    out[3] = v1 + h6 * (sv1 + d1)
    out[4] = v2 + h6 * (sv2 + d2)
    out[5] = v3 + h6 * (sv3 + d3)


@njit(cache=True, inline="always")
def _kappa_at(poly, seg, eps1, s):
    """kappa at phase s (0 <= s <= 1 + tiny) on segment seg (0, 1), or the global function if seg < 0."""
    if seg < 0:
        s = s - math.floor(s)
        seg = 0 if s < eps1 else 1
    return (poly[seg, 0] * s + poly[seg, 1]) * s + poly[seg, 2]


@njit(cache=True, inline="always")
def _te_at(c, s):
    return c[_TE] * math.sin(2.0 * math.pi * s + c[_PHI])


@njit(cache=True, inline="always")
def _region(x, b):
    if x > b:
        return 1
    if x < -b:
        return -1
    return 0


@njit(cache=True)
def _rk4_sub(c, poly, seg, y, s0, dt, out):
    """RK4 substep of length dt (time) starting at phase s0, kappa/TE evaluated on the fly."""
    T = c[_T]
    eps1 = c[_EPS] - 1.0
    sm = s0 + 0.5 * dt / T
    se = s0 + dt / T
    _rk4(c, y, dt,
         _kappa_at(poly, seg, eps1, s0), _kappa_at(poly, seg, eps1, sm), _kappa_at(poly, seg, eps1, se),
         _te_at(c, s0), _te_at(c, sm), _te_at(c, se), out)


@njit(cache=True)
def _hermite_root(x0, x1, d0, d1, h, target):
    """Root in (0, h) of the cubic Hermite interpolant of x (values x0, x1, slopes d0, d1) = target.

    Safeguarded Newton on the cubic (bisection when a Newton step leaves the bracket);
    converges in 3-5 iterations to |dt| < 1e-14 h.
    """
    # cubic in u = t / h: p(u) = x0 + c1 u + c2 u^2 + c3 u^3
    dx = x1 - x0
    c1 = h * d0
    c2 = 3.0 * dx - h * (2.0 * d0 + d1)
    c3 = -2.0 * dx + h * (d0 + d1)
    f0 = x0 - target
    lo, hi = 0.0, 1.0
    flo = f0
    u = f0 / (f0 - (x1 - target))  # secant start
    for _ in range(40):
        fu = f0 + u * (c1 + u * (c2 + u * c3))
        if fu == 0.0:
            break
        if (fu > 0.0) == (flo > 0.0):
            lo, flo = u, fu
        else:
            hi = u
        du = c1 + u * (2.0 * c2 + 3.0 * u * c3)
        un = u - fu / du if du != 0.0 else 0.5 * (lo + hi)
        if not (lo < un < hi):
            un = 0.5 * (lo + hi)
        if abs(un - u) < 1e-14:
            u = un
            break
        u = un
    return u * h


@njit(cache=True)
def _run(c, tab_h, tab_s, tab_seg, tab_k, tab_p, poly, y0, n_trans, n_rec, event, threshold,
         stride, poinc, dense_t, dense_y, yfinal):
    """Integrate n_trans + n_rec mesh periods from y0 (phase 0).

    Returns (status, last_period, n_events, n_dense): status 0 ok, 1 diverged.
    poinc (n_rec, 6) gets the state at the end of each recorded period; dense_t/dense_y
    (if their length > 0) get every ``stride``-th step of the recorded periods.
    """
    # coefficients as a tuple: numba keeps them in registers instead of reloading the array
    c = (c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7], c[8], c[9], c[10], c[11], c[12], c[13],
         c[14], c[15], c[16], c[17], c[18])
    nsteps = tab_h.shape[0]
    T = c[_T]
    b = c[_B]
    use_events = event and c[_BON] != 0.0 and b > 0.0
    y = y0.copy()
    ynew = np.empty(6)
    ytmp = np.empty(6)
    n_events = 0
    n_dense = 0
    ndmax = dense_t.shape[0]
    reg = _region(y[1], b)
    for per in range(n_trans + n_rec):
        for j in range(nsteps):
            h = tab_h[j]
            _rk4(c, y, h, tab_k[j, 0], tab_k[j, 1], tab_k[j, 2], tab_p[j, 0], tab_p[j, 1], tab_p[j, 2], ynew)
            if use_events:
                rnew = _region(ynew[1], b)
                if rnew != reg:
                    # locate crossings inside the step and restart there
                    s_cur = tab_s[j]
                    left = h
                    seg = tab_seg[j]
                    for _it in range(8):
                        if reg == 0:
                            target = b if rnew > 0 else -b
                        else:
                            target = b if reg > 0 else -b
                        # slopes at both ends: x2' = v2
                        th = _hermite_root(y[1], ynew[1], y[4], ynew[4], left, target)
                        if th <= 1e-12 * h or th >= left * (1.0 - 1e-12):
                            # crossing at an end point: accept the step as it is
                            reg = rnew
                            break
                        _rk4_sub(c, poly, seg, y, s_cur, th, ytmp)
                        n_events += 1
                        for i in range(6):
                            y[i] = ytmp[i]
                        # new region: entering from the dead zone or leaving a contact side
                        if reg == 0:
                            reg = 1 if target > 0 else -1
                        else:
                            reg = 0
                        s_cur += th / T
                        left -= th
                        _rk4_sub(c, poly, seg, y, s_cur, left, ynew)
                        rnew = _region(ynew[1], b)
                        if rnew == reg:
                            break
                    reg = rnew
            for i in range(6):
                y[i] = ynew[i]
            if per >= n_trans and ndmax > 0 and (j % stride) == stride - 1 and n_dense < ndmax:
                dense_t[n_dense] = (per + tab_s[j]) * T + h
                for i in range(6):
                    dense_y[n_dense, i] = y[i]
                n_dense += 1
        bad = False
        for i in range(6):
            if not (abs(y[i]) <= threshold):
                bad = True
        if bad:
            for i in range(6):
                yfinal[i] = y[i]
            return 1, per, n_events, n_dense
        if per >= n_trans:
            for i in range(6):
                poinc[per - n_trans, i] = y[i]
    for i in range(6):
        yfinal[i] = y[i]
    return 0, n_trans + n_rec, n_events, n_dense


# ----------------------------------------------------------------------------------------
# tables
# ----------------------------------------------------------------------------------------


def step_grid(eps: float, n: int, aligned: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """Step start phases s_j (n,) and segment ids (n,) of one mesh period.

    Aligned: N1 = max(1, round(n (eps - 1))) equal steps on [0, eps - 1], n - N1 on [eps - 1, 1].
    Not aligned: n equal steps, segment id -1 (kappa evaluated by its global definition).
    """
    e1 = eps - 1.0
    if not aligned:
        return np.arange(n) / n, np.full(n, -1, dtype=np.int64)
    n1 = min(max(1, int(round(n * e1))), n - 1)
    s = np.concatenate([np.arange(n1) * (e1 / n1), e1 + np.arange(n - n1) * ((1.0 - e1) / (n - n1))])
    seg = np.concatenate([np.zeros(n1, dtype=np.int64), np.ones(n - n1, dtype=np.int64)])
    return s, seg


@lru_cache(maxsize=64)
def _tables(coeffs: Coefficients, n: int, aligned: bool):
    c = coeffs.kernel_array()
    poly = coeffs.stiffness_polys()
    s, seg = step_grid(coeffs.eps, n, aligned)
    ds = np.diff(np.append(s, 1.0))
    T = coeffs.period
    e1 = coeffs.eps - 1.0

    def kap(sv, sg):
        if sg < 0:
            sv = sv % 1.0
            sg = 0 if sv < e1 else 1
        return np.polyval(poly[sg], sv)

    tab_k = np.empty((n, 3))
    tab_p = np.empty((n, 3))
    for j in range(n):
        for q, frac in enumerate((0.0, 0.5, 1.0)):
            sv = s[j] + frac * ds[j]
            tab_k[j, q] = kap(sv, seg[j])
            tab_p[j, q] = coeffs.te_forcing * math.sin(2 * math.pi * sv + coeffs.phi)
    for a in (c, poly, tab_k, tab_p):
        a.setflags(write=False)
    return c, ds * T, s, seg, tab_k, tab_p, poly


def default_initial_state(coeffs: Coefficients) -> np.ndarray:
    """Static deflection under the mean load (no TE), at rest: the default x0."""
    return static_deflection(coeffs)


def simulate(
    coeffs: Coefficients,
    settings: SimulationSettings = SimulationSettings(),
    x0: np.ndarray | None = None,
    dense: bool = False,
) -> SimulationResult:
    """Integrate the dimensionless 3-DOF KHV model; see :class:`SimulationResult`.

    x0: initial state (6,) at phase 0 (default :func:`default_initial_state`).
    Never raises on divergence: it returns ``diverged=True``.
    """
    y0 = default_initial_state(coeffs) if x0 is None else np.asarray(x0, dtype=float).copy()
    if settings.integrator == "dop853":
        from geardyn.reference import simulate_reference

        return simulate_reference(coeffs, settings, y0, dense=dense)
    n = settings.steps_per_period
    c, tab_h, tab_s, tab_seg, tab_k, tab_p, poly = _tables(coeffs, n, settings.aligned)
    nrec = settings.recorded_periods
    poinc = np.full((nrec, 6), np.nan)
    stride = max(1, settings.dense_stride)
    nd = (nrec * n) // stride if dense else 0
    dt = np.empty(nd)
    dy = np.empty((nd, 6))
    final = np.empty(6)
    status, per, nev, ndense = _run(
        c, tab_h, tab_s, tab_seg, tab_k, tab_p, poly, y0, settings.transient_periods, nrec,
        settings.integrator == "rk4_event", settings.divergence_threshold, stride, poinc, dt, dy, final,
    )
    diverged = status == 1
    npts = max(0, per - settings.transient_periods) if diverged else nrec
    poinc = poinc[:npts]
    return SimulationResult(
        poincare=poinc,
        final_state=final,
        diverged=diverged,
        diverged_period=int(per) if diverged else -1,
        n_events=int(nev),
        tau=dt[:ndense] if dense else None,
        states=dy[:ndense] if dense else None,
        period=coeffs.period,
        settings=settings,
    )


def warm_up() -> None:
    """Compile (or load from the numba cache) the kernels once per process."""
    from geardyn.model import KHVParameters, dimensionless

    c = dimensionless(KHVParameters(eps=1.3, k_c=3.1e8))
    for integ in ("rk4", "rk4_event"):
        simulate(c, SimulationSettings(integrator=integ, steps_per_period=16, transient_periods=1,
                                       recorded_periods=1), dense=True)


def largest_lyapunov(
    coeffs: Coefficients,
    settings: SimulationSettings = SimulationSettings(),
    x0: np.ndarray | None = None,
    n_periods: int = 500,
    d0: float = 1e-7,
) -> tuple[float, np.ndarray]:
    """Largest Lyapunov exponent (per unit dimensionless time) by two nearby trajectories.

    Benettin's method: a companion started d0 away (all 6 states, Euclidean norm) is
    renormalised back to distance d0 at the end of every mesh period.  Starts after
    ``settings.transient_periods``.  Returns (lambda, running estimate per period).
    Positive: chaos (or parametric instability); ~0: quasi-periodic; negative: periodic.
    """
    one = SimulationSettings(integrator=settings.integrator, steps_per_period=settings.steps_per_period,
                             transient_periods=0, recorded_periods=1,
                             divergence_threshold=settings.divergence_threshold, aligned=settings.aligned)
    y = default_initial_state(coeffs) if x0 is None else np.asarray(x0, dtype=float)
    if settings.transient_periods > 0:
        tr = SimulationSettings(integrator=settings.integrator, steps_per_period=settings.steps_per_period,
                                transient_periods=settings.transient_periods - 1, recorded_periods=1,
                                divergence_threshold=settings.divergence_threshold, aligned=settings.aligned)
        r = simulate(coeffs, tr, y)
        if r.diverged:
            return float("inf"), np.array([np.inf])
        y = r.final_state
    rng = np.random.default_rng(0)
    d = rng.standard_normal(6)
    z = y + d0 * d / np.linalg.norm(d)
    acc = 0.0
    est = np.empty(n_periods)
    for k in range(n_periods):
        ry = simulate(coeffs, one, y)
        rz = simulate(coeffs, one, z)
        if ry.diverged or rz.diverged:
            return float("inf"), est[:k]
        y, z = ry.final_state, rz.final_state
        dist = np.linalg.norm(z - y)
        acc += math.log(dist / d0)
        z = y + (z - y) * (d0 / dist)
        est[k] = acc / ((k + 1) * coeffs.period)
    return float(est[-1]), est
