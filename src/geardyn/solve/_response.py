"""The response measures' sums, added step by step in the batch's lanes and the scalar loop (private to
:mod:`geardyn.solve`; use :func:`geardyn.solve.response.response_measures`; the sums: ``docs/response.md``)."""

from __future__ import annotations

from numba import njit

import geardyn.solve._cache as _cache
from geardyn.solve._model import hermite_root, region

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


@njit(cache=True, inline="always")
def region_times(x0, x1, v0, v1, h, b, times, base):
    """Add the time a step of size h spends in each contact region to ``times[base:base + 3]`` (index 0:
    x2 > b, 1: inside, 2: x2 < -b): cut at the roots of the cubic Hermite interpolant of x2 = +-b between
    the regions of its end points (one root per boundary passed).  Returns the number of boundaries passed."""
    r0, r1 = region(x0, b), region(x1, b)
    if r0 == r1:
        times[base + 1 - r0] += h
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
        times[base + 1 - r] += t - t_prev
        t_prev = t
        r = nxt
        n += 1
    times[base + 1 - r1] += h - t_prev
    return n


@njit(cache=True, inline="always")
def start_sums(out, k0, cm, b, x, v, sgn):
    """Reset the sums ``out`` (:data:`N_OUT`,) at the start state (x2 = x, x2' = v; kappa = k0 there)."""
    for i in range(N_OUT):
        out[i] = 0.0
    f_ref = mesh_force(k0, cm, b, x, v)
    out[F_REF], out[X_REF] = f_ref, x
    out[MAX_SF] = sgn * f_ref
    out[MAX_X], out[MIN_X] = x, x


@njit(cache=True, inline="always")
def add_step(out, h, k0, k2, cm, b, sgn, xs, vs, xe, ve):
    """Add one step of size h from (x2, x2') = (xs, vs) (kappa = k0) to (xe, ve) (kappa = k2) to the sums
    ``out``: the one statement of the accumulation."""
    f_ref, x_ref = out[F_REF], out[X_REF]
    fs = mesh_force(k0, cm, b, xs, vs) - f_ref
    fe = mesh_force(k2, cm, b, xe, ve) - f_ref
    out[TIME] += h
    out[SUM_F] += 0.5 * h * (fs + fe)
    out[SUM_F2] += 0.5 * h * (fs * fs + fe * fe)
    dxs, dxe = xs - x_ref, xe - x_ref
    out[SUM_X] += 0.5 * h * (dxs + dxe)
    out[SUM_X2] += 0.5 * h * (dxs * dxs + dxe * dxe)
    out[MAX_SF] = max(out[MAX_SF], sgn * (fe + f_ref))
    out[MAX_X] = max(out[MAX_X], xe)
    out[MIN_X] = min(out[MIN_X], xe)
    out[N_SWITCH] += region_times(xs, xe, vs, ve, h, b, out, T_POS)
