"""The compiled accumulator of the response measures (private to :mod:`geardyn.solve`; use
:func:`geardyn.solve.response.response_measures`).

It integrates whole mesh periods with the very step of the solver's loop (:func:`geardyn.solve._kernel.step`,
the RK4 stage of :mod:`geardyn.solve._model`, contact switches located and the step restarted there when
``event``), so its orbit is the one :func:`geardyn.solve.simulate` integrates from the same state.  Along
the way it accumulates, at the integration's resolution:

* the time integrals of the mesh force F = kappa f(x2) + c_m x2' and of x2 (trapezoidal rule on the step
  grid, which is aligned to the stiffness jumps: each step uses kappa's one-sided values at its ends), and of
  their squares, shifted by their values at the start (no cancellation in the variance);
* the largest drive-side force s F (s = +-1, the side of the static contact) and the extremes of x2 on the
  grid;
* the time in each contact region (x2 beyond +b, between -b and +b, beyond -b): a step whose end points lie
  in different regions is cut at the crossings of x2 = +-b, located on the cubic Hermite interpolant of x2
  (values and slopes x2' at both ends, :func:`geardyn.solve._kernel.hermite_root`).
"""

from __future__ import annotations

import numpy as np
from numba import njit

import geardyn.solve._cache as _cache
from geardyn.solve._kernel import diverged, hermite_root, locate_switches, region, step
from geardyn.solve.base import BACKLASH_ON, CM, B, T

#: Layout of the accumulator's output (one float64 each).
(
    TIME,
    SUM_F,
    SUM_F2,
    MAX_SF,
    SUM_X,
    SUM_X2,
    MAX_X,
    MIN_X,
    T_POS,
    T_ZERO,
    T_NEG,
    F_REF,
    X_REF,
    STATUS,
    N_SWITCH,
) = range(15)
N_OUT = 15


_cache.renew_once()  # before the loops: numba's cache renewed when any kernel source changed


@njit(cache=True, inline="always")
def mesh_force(kap, cm, b, x, v):
    """kappa f(x) + c_m x' with the dead zone f of half width b (the force of :func:`geardyn.solve._model.accel`)."""
    return kap * (x - min(max(x, -b), b)) + cm * v


@njit(cache=True)
def region_times(x0, x1, v0, v1, h, b, times):
    """Add the time a step of size h spends in each contact region to ``times`` (index 0: x2 > b, 1: inside,
    2: x2 < -b): cut at the roots of the cubic Hermite interpolant of x2 = +-b between the regions of its
    end points (one root per boundary passed)."""
    r0, r1 = region(x0, b), region(x1, b)
    if r0 == r1:
        times[1 - r0] += h
        return 0
    t_prev = 0.0
    r = r0
    step_dir = 1 if r1 > r0 else -1
    n = 0
    while r != r1:
        nxt = r + step_dir
        target = b if (r + nxt) > 0 else -b
        t = hermite_root(x0, x1, v0, v1, h, target)
        t = min(max(t, t_prev), h)
        times[1 - r] += t - t_prev
        t_prev = t
        r = nxt
        n += 1
    times[1 - r1] += h - t_prev
    return n


@njit(cache=True, nogil=True)
def accumulate(c, tabs, y0, n_periods, event, limits, sgn, out):
    """Integrate ``n_periods`` mesh periods from y0 (phase 0) and fill ``out`` (:data:`N_OUT`,) with the
    sums named by the layout above; ``sgn``: +1 or -1, the side of the static contact.  ``out[STATUS]``:
    0 bounded, 1 diverged (the sums then cover the periods before).  tabs: the step tables of
    :func:`geardyn.solve._kernel.run`."""
    tab_h, tab_s, tab_seg, tab_k, tab_p, poly = tabs
    nsteps = tab_h.shape[0]
    on = c[BACKLASH_ON]
    b = c[B] if on != 0.0 else 0.0
    cm = c[CM]
    use_events = event and on != 0.0 and b > 0.0
    y = y0.copy()
    ynew = np.empty(6)
    W = np.empty((6, 0))
    Wnew = np.empty((6, 0))
    times = np.zeros(3)
    for i in range(N_OUT):
        out[i] = 0.0
    f_ref = mesh_force(tab_k[0, 0], cm, b, y[1], y[4])
    x_ref = y[1]
    out[F_REF], out[X_REF] = f_ref, x_ref
    out[MAX_SF] = sgn * f_ref
    out[MAX_X], out[MIN_X] = x_ref, x_ref
    reg = region(y[1], b)
    for _per in range(n_periods):
        for j in range(nsteps):
            h = tab_h[j]
            xs, vs = y[1], y[4]
            fs = mesh_force(tab_k[j, 0], cm, b, xs, vs) - f_ref
            # the step of _kernel.run, spelled as there: a shared inline helper made that loop ~2x slower (measured)
            k0, k1, k2 = tab_k[j, 0], tab_k[j, 1], tab_k[j, 2]
            step(c, y, W, 0, h, k0, k1, k2, tab_p[j, 0], tab_p[j, 1], tab_p[j, 2], ynew, Wnew, -1.0)
            if use_events:
                rnew = region(ynew[1], b)
                if rnew != reg:
                    reg, _nev = locate_switches(
                        c, poly, y, ynew, W, Wnew, 0, h, tab_s[j], tab_seg[j], reg, rnew, b, c[T]
                    )
            for i in range(6):
                y[i] = ynew[i]
            xe, ve = y[1], y[4]
            fe = mesh_force(tab_k[j, 2], cm, b, xe, ve) - f_ref
            out[TIME] += h
            out[SUM_F] += 0.5 * h * (fs + fe)
            out[SUM_F2] += 0.5 * h * (fs * fs + fe * fe)
            dxs, dxe = xs - x_ref, xe - x_ref
            out[SUM_X] += 0.5 * h * (dxs + dxe)
            out[SUM_X2] += 0.5 * h * (dxs * dxs + dxe * dxe)
            out[MAX_SF] = max(out[MAX_SF], sgn * (fe + f_ref))
            out[MAX_X] = max(out[MAX_X], xe)
            out[MIN_X] = min(out[MIN_X], xe)
            out[N_SWITCH] += region_times(xs, xe, vs, ve, h, b, times)
        if diverged(y, limits):
            out[STATUS] = 1.0
            break
    out[T_POS], out[T_ZERO], out[T_NEG] = times[0], times[1], times[2]
