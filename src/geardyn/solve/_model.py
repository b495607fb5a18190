"""The model's equations, stated once: accelerations, linearisation, one RK4 step of orbit and tangent, the
contact region of x2 and the crossing of a region's boundary within a step.
Private to :mod:`geardyn.solve`; inlined into the scalar loop and the SIMD lanes, so both run the same
bits (the dead zone's form: ``docs/numerics.md``)."""

from __future__ import annotations

from numba import njit

import geardyn.solve._cache as _cache
from geardyn.solve.base import C11, C21, C23, C33, CM, G1, G3, K11, K21, K23, K33, P1, P3

#: The safeguarded Newton for a root u in [lo, hi] stops when a step is below this (a few hundred units of the
#: double's resolution at u of order 1).
ROOT_STEP = 1e-14

_cache.renew_once()  # before the loops: numba's cache renewed when any kernel source changed


@njit(cache=True, inline="always")
def accel(k, b, x1, x2, x3, v1, v2, v3, kap, pe):
    """Accelerations (a1, a2, a3) at stiffness kap and TE forcing pe."""
    fm = kap * (x2 - min(max(x2, -b), b)) + k[CM] * v2
    a1 = k[P1] - k[K11] * x1 - k[C11] * v1 - k[G1] * fm
    a2 = pe - k[K21] * x1 - k[C21] * v1 - k[K23] * x3 - k[C23] * v3 - fm
    a3 = k[P3] - k[K33] * x3 - k[C33] * v3 - k[G3] * fm
    return a1, a2, a3


@njit(cache=True, inline="always")
def lin(k, w0, w1, w2, w3, w4, w5, ks):
    """Tangent accelerations of the column (w0 .. w5) for the stiffness slope ks = kappa f'(x2)."""
    fm = ks * w1 + k[CM] * w4
    a1 = -k[K11] * w0 - k[C11] * w3 - k[G1] * fm
    a2 = -k[K21] * w0 - k[C21] * w3 - k[K23] * w2 - k[C23] * w5 - fm
    a3 = -k[K33] * w2 - k[C33] * w5 - k[G3] * fm
    return a1, a2, a3


@njit(cache=True, inline="always")
def slope(on, b, x2):
    """f'(x2): 1 in contact (or without backlash, ``on == 0``), 0 inside the backlash."""
    return 1.0 if (on == 0.0 or x2 > b or x2 < -b) else 0.0


@njit(cache=True, inline="always")
def rk4(k, b, h, k0, k1, k2, p0, p1, p2, x1, x2, x3, v1, v2, v3):
    """One RK4 step of size h from (x1 .. v3), kappa k0, k1, k2 and TE p0, p1, p2 at the stage times
    (start, middle, end).  Returns the new state (6 numbers) and x2 at stages 2, 3, 4 (for the
    slopes of the tangent step)."""
    hh = 0.5 * h
    a1, a2, a3 = accel(k, b, x1, x2, x3, v1, v2, v3, k0, p0)
    X2 = x2 + hh * v2
    V1 = v1 + hh * a1
    V2 = v2 + hh * a2
    V3 = v3 + hh * a3
    b1, b2, b3 = accel(k, b, x1 + hh * v1, X2, x3 + hh * v3, V1, V2, V3, k1, p1)
    sx1, sx2, sx3 = v1 + 2.0 * V1, v2 + 2.0 * V2, v3 + 2.0 * V3
    sv1, sv2, sv3 = a1 + 2.0 * b1, a2 + 2.0 * b2, a3 + 2.0 * b3
    W1 = v1 + hh * b1
    W2 = v2 + hh * b2
    W3 = v3 + hh * b3
    Z2 = x2 + hh * V2
    c1, c2, c3 = accel(k, b, x1 + hh * V1, Z2, x3 + hh * V3, W1, W2, W3, k1, p1)
    sx1 += 2.0 * W1
    sx2 += 2.0 * W2
    sx3 += 2.0 * W3
    sv1 += 2.0 * c1
    sv2 += 2.0 * c2
    sv3 += 2.0 * c3
    U1 = v1 + h * c1
    U2 = v2 + h * c2
    U3 = v3 + h * c3
    Q2 = x2 + h * W2
    d1, d2, d3 = accel(k, b, x1 + h * W1, Q2, x3 + h * W3, U1, U2, U3, k2, p2)
    h6 = h / 6.0
    return (
        x1 + h6 * (sx1 + U1),
        x2 + h6 * (sx2 + U2),
        x3 + h6 * (sx3 + U3),
        v1 + h6 * (sv1 + d1),
        v2 + h6 * (sv2 + d2),
        v3 + h6 * (sv3 + d3),
        X2,
        Z2,
        Q2,
    )


@njit(cache=True, inline="always")
def rk4_tangent(k, h, s1, s2, s3, s4, w0, w1, w2, w3, w4, w5):
    """The RK4 step of size h of one tangent column (w0 .. w5), stiffness slopes s1 .. s4 = kappa f'(x2)
    at the orbit's four stage states: the derivative of the discrete flow of :func:`rk4`."""
    hh = 0.5 * h
    A1, A2, A3 = lin(k, w0, w1, w2, w3, w4, w5, s1)
    B0, B1, B2 = w0 + hh * w3, w1 + hh * w4, w2 + hh * w5
    B3, B4, B5 = w3 + hh * A1, w4 + hh * A2, w5 + hh * A3
    Q1, Q2, Q3 = lin(k, B0, B1, B2, B3, B4, B5, s2)
    C0, C1, C2 = w0 + hh * B3, w1 + hh * B4, w2 + hh * B5
    C3, C4, C5 = w3 + hh * Q1, w4 + hh * Q2, w5 + hh * Q3
    R1, R2, R3 = lin(k, C0, C1, C2, C3, C4, C5, s3)
    D0, D1, D2 = w0 + h * C3, w1 + h * C4, w2 + h * C5
    D3, D4, D5 = w3 + h * R1, w4 + h * R2, w5 + h * R3
    S1, S2, S3 = lin(k, D0, D1, D2, D3, D4, D5, s4)
    h6 = h / 6.0
    return (
        w0 + h6 * (w3 + 2.0 * B3 + 2.0 * C3 + D3),
        w1 + h6 * (w4 + 2.0 * B4 + 2.0 * C4 + D4),
        w2 + h6 * (w5 + 2.0 * B5 + 2.0 * C5 + D5),
        w3 + h6 * (A1 + 2.0 * Q1 + 2.0 * R1 + S1),
        w4 + h6 * (A2 + 2.0 * Q2 + 2.0 * R2 + S2),
        w5 + h6 * (A3 + 2.0 * Q3 + 2.0 * R3 + S3),
    )


@njit(cache=True, inline="always")
def rk4_tangent_at(k, h, s1, s2, s3, s4, A, read, write, stride, q):
    """:func:`rk4_tangent` of the column held in the flat buffer ``A`` at ``A[(read + i) stride + q]``,
    i = 0 .. 5, its new value written at ``A[(write + i) stride + q]`` (the buffers of the compiled loops:
    one offset per component, ``stride`` columns or lanes apart)."""
    # fmt: off
    w = rk4_tangent(k, h, s1, s2, s3, s4, A[read * stride + q], A[(read + 1) * stride + q],
                    A[(read + 2) * stride + q], A[(read + 3) * stride + q], A[(read + 4) * stride + q],
                    A[(read + 5) * stride + q])
    # fmt: on
    A[write * stride + q] = w[0]
    A[(write + 1) * stride + q] = w[1]
    A[(write + 2) * stride + q] = w[2]
    A[(write + 3) * stride + q] = w[3]
    A[(write + 4) * stride + q] = w[4]
    A[(write + 5) * stride + q] = w[5]


@njit(cache=True, inline="always")
def region(x, b):
    """The contact region of x2 = x for half backlash b: 1 (x > b), 0 (inside), -1 (x < -b)."""
    if x > b:
        return 1
    if x < -b:
        return -1
    return 0


@njit(cache=True, inline="always")
def hermite_root(x0, x1, d0, d1, h, target):
    """Root in (0, h) of the cubic Hermite interpolant of x (values x0, x1, slopes d0, d1) = target, by
    safeguarded Newton (``docs/numerics.md``)."""
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
        if abs(un - u) < ROOT_STEP:
            u = un
            break
        u = un
    return u * h
