"""The orbit and one tangent vector integrated together: the largest Lyapunov exponent.

Variational equation of the dimensionless KHV model (Eq. 16, corrected): w' = J(tau, y) w with

    J: dx = dv,  da = -K dx - C dv - g (kappa(s) f'(x2) dx2 + c_m dv2),
    f'(x2) = 1 in contact (|x2| > b, or no backlash), 0 inside the backlash.

The vector field is continuous across x2 = +-b (only its derivative jumps), so the saltation
matrix of a contact switch is the identity and the tangent vector needs no jump there.  The orbit
part of every step is the very same RK4 arithmetic as :func:`geardyn.integrators._run` (same
grid, same event location): the Poincaré points are bit-identical to :func:`integrators.simulate`.
The tangent vector is advanced with the same RK4 stages (f'(x2) of each stage state), i.e. it is
the derivative of the discrete flow; it is renormalised at the end of every mesh period and the
log of its growth is recorded.  Cost: about 1.6x a plain step (measured, see ``docs/classify.md``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from geardyn.integrators import (
    _A11, _A21, _A23, _A33, _B, _BON, _CM, _D11, _D21, _D23, _D33, _EPS, _G1, _G3, _T,
    SimulationSettings, _hermite_root, _kappa_at, _region, _rk4, _rk4_sub, _rhs, _te_at, default_initial_state,
    step_grid,
)
from geardyn.model import Coefficients


@njit(cache=True, inline="always")
def _slope(c, x2):
    if c[_BON] == 0.0:
        return 1.0
    b = c[_B]
    return 1.0 if (x2 > b or x2 < -b) else 0.0


@njit(cache=True, inline="always")
def _lin(c, w0, w1, w2, w3, w4, w5, ks):
    """Tangent accelerations for stiffness slope ks = kappa f'(x2)."""
    fm = ks * w1 + c[_CM] * w4
    a1 = -c[_A11] * w0 - c[_D11] * w3 - c[_G1] * fm
    a2 = -c[_A21] * w0 - c[_D21] * w3 - c[_A23] * w2 - c[_D23] * w5 - fm
    a3 = -c[_A33] * w2 - c[_D33] * w5 - c[_G3] * fm
    return a1, a2, a3


@njit(cache=True)
def _rk4v(c, y, w, h, k0, k1, k2, p0, p1, p2, yout, wout):
    """One RK4 step of the orbit (exactly :func:`_rk4`) and of the tangent vector w."""
    _rk4(c, y, h, k0, k1, k2, p0, p1, p2, yout)
    hh = 0.5 * h
    # x2 and v2 of the orbit's stage states (for f'(x2) at each stage)
    a1, a2, a3 = _rhs(c, y[0], y[1], y[2], y[3], y[4], y[5], k0, p0)
    x2_2 = y[1] + hh * y[4]
    b1, b2, b3 = _rhs(c, y[0] + hh * y[3], x2_2, y[2] + hh * y[5],
                      y[3] + hh * a1, y[4] + hh * a2, y[5] + hh * a3, k1, p1)
    x2_3 = y[1] + hh * (y[4] + hh * a2)
    x2_4 = y[1] + h * (y[4] + hh * b2)
    s1 = k0 * _slope(c, y[1])
    s2 = k1 * _slope(c, x2_2)
    s3 = k1 * _slope(c, x2_3)
    s4 = k2 * _slope(c, x2_4)
    w0, w1, w2, w3, w4, w5 = w[0], w[1], w[2], w[3], w[4], w[5]
    A1, A2, A3 = _lin(c, w0, w1, w2, w3, w4, w5, s1)
    B0, B1, B2 = w0 + hh * w3, w1 + hh * w4, w2 + hh * w5
    B3, B4, B5 = w3 + hh * A1, w4 + hh * A2, w5 + hh * A3
    Q1, Q2, Q3 = _lin(c, B0, B1, B2, B3, B4, B5, s2)
    C0, C1, C2 = w0 + hh * B3, w1 + hh * B4, w2 + hh * B5
    C3, C4, C5 = w3 + hh * Q1, w4 + hh * Q2, w5 + hh * Q3
    R1, R2, R3 = _lin(c, C0, C1, C2, C3, C4, C5, s3)
    D0, D1, D2 = w0 + h * C3, w1 + h * C4, w2 + h * C5
    D3, D4, D5 = w3 + h * R1, w4 + h * R2, w5 + h * R3
    S1, S2, S3 = _lin(c, D0, D1, D2, D3, D4, D5, s4)
    h6 = h / 6.0
    wout[0] = w0 + h6 * (w3 + 2.0 * B3 + 2.0 * C3 + D3)
    wout[1] = w1 + h6 * (w4 + 2.0 * B4 + 2.0 * C4 + D4)
    wout[2] = w2 + h6 * (w5 + 2.0 * B5 + 2.0 * C5 + D5)
    wout[3] = w3 + h6 * (A1 + 2.0 * Q1 + 2.0 * R1 + S1)
    wout[4] = w4 + h6 * (A2 + 2.0 * Q2 + 2.0 * R2 + S2)
    wout[5] = w5 + h6 * (A3 + 2.0 * Q3 + 2.0 * R3 + S3)


@njit(cache=True)
def _rk4v_sub(c, poly, seg, y, w, s0, dt, yout, wout):
    T = c[_T]
    eps1 = c[_EPS] - 1.0
    sm = s0 + 0.5 * dt / T
    se = s0 + dt / T
    _rk4v(c, y, w, dt,
          _kappa_at(poly, seg, eps1, s0), _kappa_at(poly, seg, eps1, sm), _kappa_at(poly, seg, eps1, se),
          _te_at(c, s0), _te_at(c, sm), _te_at(c, se), yout, wout)


@njit(cache=True)
def _run_tangent(c, tab_h, tab_s, tab_seg, tab_k, tab_p, poly, y0, n_trans, n_rec, n_tan, event, threshold,
                 poinc, growth, strobe, yfinal):
    """Like integrators._run (no dense output), plus a tangent vector over the last n_tan periods.

    growth[k] = log |w| at the end of tangent period k (w renormalised to 1 after each period);
    strobe[k] = x2 (X_VH) at the end of tangent period k (stroboscopic samples for the 0-1 test).
    Returns (status, last_period, n_events).
    """
    c = (c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7], c[8], c[9], c[10], c[11], c[12], c[13],
         c[14], c[15], c[16], c[17], c[18])
    nsteps = tab_h.shape[0]
    T = c[_T]
    b = c[_B]
    use_events = event and c[_BON] != 0.0 and b > 0.0
    y = y0.copy()
    ynew = np.empty(6)
    ytmp = np.empty(6)
    w = np.ones(6) / math.sqrt(6.0)
    wnew = np.empty(6)
    wtmp = np.empty(6)
    n_events = 0
    n_total = n_trans + n_rec
    tan_start = n_total - n_tan
    reg = _region(y[1], b)
    for per in range(n_total):
        tan = per >= tan_start
        for j in range(nsteps):
            h = tab_h[j]
            if tan:
                _rk4v(c, y, w, h, tab_k[j, 0], tab_k[j, 1], tab_k[j, 2], tab_p[j, 0], tab_p[j, 1], tab_p[j, 2],
                      ynew, wnew)
            else:
                _rk4(c, y, h, tab_k[j, 0], tab_k[j, 1], tab_k[j, 2], tab_p[j, 0], tab_p[j, 1], tab_p[j, 2], ynew)
            if use_events:
                rnew = _region(ynew[1], b)
                if rnew != reg:
                    s_cur = tab_s[j]
                    left = h
                    seg = tab_seg[j]
                    for _it in range(8):
                        if reg == 0:
                            target = b if rnew > 0 else -b
                        else:
                            target = b if reg > 0 else -b
                        th = _hermite_root(y[1], ynew[1], y[4], ynew[4], left, target)
                        if th <= 1e-12 * h or th >= left * (1.0 - 1e-12):
                            reg = rnew
                            break
                        if tan:
                            _rk4v_sub(c, poly, seg, y, w, s_cur, th, ytmp, wtmp)
                            for i in range(6):
                                w[i] = wtmp[i]
                        else:
                            _rk4_sub(c, poly, seg, y, s_cur, th, ytmp)  # the plain integrator's sub-step
                        n_events += 1
                        for i in range(6):
                            y[i] = ytmp[i]
                        if reg == 0:
                            reg = 1 if target > 0 else -1
                        else:
                            reg = 0
                        s_cur += th / T
                        left -= th
                        if tan:
                            _rk4v_sub(c, poly, seg, y, w, s_cur, left, ynew, wnew)
                        else:
                            _rk4_sub(c, poly, seg, y, s_cur, left, ynew)
                        rnew = _region(ynew[1], b)
                        if rnew == reg:
                            break
                    reg = rnew
            for i in range(6):
                y[i] = ynew[i]
            if tan:
                for i in range(6):
                    w[i] = wnew[i]
        bad = False
        for i in range(6):
            if not (abs(y[i]) <= threshold):
                bad = True
        if bad:
            for i in range(6):
                yfinal[i] = y[i]
            return 1, per, n_events
        if tan:
            nrm = 0.0
            for i in range(6):
                nrm += w[i] * w[i]
            nrm = math.sqrt(nrm)
            growth[per - tan_start] = math.log(nrm) if nrm > 0.0 else -np.inf
            strobe[per - tan_start] = y[1]
            for i in range(6):
                w[i] /= nrm
        if per >= n_trans:
            for i in range(6):
                poinc[per - n_trans, i] = y[i]
    for i in range(6):
        yfinal[i] = y[i]
    return 0, n_total, n_events


def tables(coeffs: Coefficients, n: int, aligned: bool = True):
    """The step tables of :func:`integrators._tables`, vectorised (same arithmetic, same values).

    ``integrators._tables`` loops in Python (about 14 ms at 512 steps, more than the integration
    of a sweep point); this builds identical arrays in about 0.3 ms.
    """
    c = coeffs.kernel_array()
    poly = coeffs.stiffness_polys()
    s, seg = step_grid(coeffs.eps, n, aligned)
    ds = np.diff(np.append(s, 1.0))
    e1 = coeffs.eps - 1.0
    sv = s[:, None] + np.array([0.0, 0.5, 1.0])[None, :] * ds[:, None]
    sg = np.broadcast_to(seg[:, None], sv.shape)
    if not aligned:
        sv_k = sv % 1.0
        sg = np.where(sv_k < e1, 0, 1)
    else:
        sv_k = sv
    # Horner, as np.polyval does for a scalar
    pa, pb, pc = poly[sg, 0], poly[sg, 1], poly[sg, 2]
    tab_k = (pa * sv_k + pb) * sv_k + pc
    te = coeffs.te_forcing
    tab_p = np.array([te * math.sin(2 * math.pi * v + coeffs.phi) for v in sv.ravel()]).reshape(sv.shape)
    return c, ds * coeffs.period, s, seg, tab_k, tab_p, poly


@dataclass
class TangentResult:
    """Orbit (as :class:`integrators.SimulationResult` without dense output) plus tangent growth.

    growth: (n,) log of the tangent vector's growth over each of the last ``n_tan`` mesh periods
    (fewer after a divergence); strobe: (n,) X_VH / b_c at the end of those periods.
    period: T in dimensionless time.
    """

    poincare: np.ndarray
    final_state: np.ndarray
    diverged: bool
    diverged_period: int
    n_events: int
    growth: np.ndarray
    strobe: np.ndarray
    period: float


def simulate_tangent(coeffs: Coefficients, settings: SimulationSettings, x0: np.ndarray | None = None,
                     tangent_periods: int | None = None) -> TangentResult:
    """Integrate like :func:`integrators.simulate` and carry a tangent vector over the last
    ``tangent_periods`` (default: the recorded periods; at most the whole run) mesh periods.

    Only the RK4 integrators are supported ("rk4", "rk4_event").
    """
    if settings.integrator not in ("rk4", "rk4_event"):
        raise ValueError("simulate_tangent supports the fixed-step integrators 'rk4' and 'rk4_event'")
    y0 = default_initial_state(coeffs) if x0 is None else np.asarray(x0, dtype=float).copy()
    c, tab_h, tab_s, tab_seg, tab_k, tab_p, poly = tables(coeffs, settings.steps_per_period, settings.aligned)
    n_trans, n_rec = settings.transient_periods, settings.recorded_periods
    n_tan = n_rec if tangent_periods is None else int(tangent_periods)
    n_tan = max(0, min(n_tan, n_trans + n_rec))
    poinc = np.full((n_rec, 6), np.nan)
    growth = np.full(n_tan, np.nan)
    strobe = np.full(n_tan, np.nan)
    final = np.empty(6)
    status, per, nev = _run_tangent(c, tab_h, tab_s, tab_seg, tab_k, tab_p, poly, y0, n_trans, n_rec, n_tan,
                                    settings.integrator == "rk4_event", settings.divergence_threshold,
                                    poinc, growth, strobe, final)
    diverged = status == 1
    npts = max(0, per - n_trans) if diverged else n_rec
    ngrowth = max(0, per - (n_trans + n_rec - n_tan)) if diverged else n_tan
    return TangentResult(poinc[:npts], final, diverged, int(per) if diverged else -1, int(nev),
                         growth[:ngrowth], strobe[:ngrowth], coeffs.period)
