"""Independent forms of the models, kept beside the tests that check the library against them.

None of these is used by the library or the workflow: each is a second, plainly written statement of
something the library computes another way (the 4-DOF form of Eq. (2) against the 3-DOF relative
form the solver integrates, the exact LTI steady state, a cutter fitted to a trimming limit, the
direct-solve damping matrix of modal damping, the rigid-body ratio of a plus set).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import scipy.linalg
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import brentq

from geardyn.gears import constraints, interference
from geardyn.gears import geometry as geo
from geardyn.gears.backlash import backlash as _backlash
from geardyn.khv.model import Coefficients
from geardyn.plus import modal
from geardyn.plus.design import PlusDesign


def rhs3(coeffs: Coefficients, tau: float, y: np.ndarray) -> np.ndarray:
    """Right-hand side of the dimensionless 3-DOF system (NumPy)."""
    m = coeffs.matrices()
    kap = float(coeffs.kappa(tau / coeffs.period))
    x, v = y[:3], y[3:]
    fm = kap * float(_backlash(x[1], coeffs.b)) + coeffs.c_m * v[1]
    te = m["te"] * math.sin(coeffs.omega * tau + coeffs.phi)
    a = m["p"] - m["K"] @ x - m["C"] @ v - m["g"] * fm + np.array([0.0, te, 0.0])
    return np.concatenate([v, a])


def rhs4(coeffs: Coefficients, tau: float, z: np.ndarray) -> np.ndarray:
    """Dimensionless 4-DOF form of Eq. (2): z = (X_D, X_H, X_V, X_L, velocities) / b_c (docs/model.md),
    same scaling as the 3-DOF form (masses / M_VH, forces / k_mean b_c, time * w_n)."""
    c = coeffs
    XD, XH, XV, XL, VD, VH, VV, VL = z
    kap = float(c.kappa(tau / c.period))
    e = c.e * math.sin(c.omega * tau + c.phi)
    de = c.e * c.omega * math.cos(c.omega * tau + c.phi)
    fm = kap * float(_backlash(XV - XH - e, c.b)) + c.c_m * (VV - VH - de)
    fdh = c.k_DH * (XD - XH) + c.c_DH * (VD - VH)
    fvl = c.k_VL * (XV - XL) + c.c_VL * (VV - VL)
    return np.array([VD, VH, VV, VL, (c.P_D - fdh) / c.mu_D, (fdh + fm) / c.mu_H, (-fvl - fm) / c.mu_V,
                     (fvl - c.P_L) / c.mu_L])  # fmt: skip


def to_relative(coeffs: Coefficients, tau: np.ndarray, z: np.ndarray) -> np.ndarray:
    """4-DOF states z (..., 8) at times tau as 3-DOF relative states (..., 6), Eq. (3)."""
    z, tau = np.asarray(z, dtype=float), np.asarray(tau, dtype=float)
    e = coeffs.e * np.sin(coeffs.omega * tau + coeffs.phi)
    de = coeffs.e * coeffs.omega * np.cos(coeffs.omega * tau + coeffs.phi)
    XD, XH, XV, XL, VD, VH, VV, VL = np.moveaxis(z, -1, 0)
    return np.stack([XD - XH, XV - XH - e, XV - XL, VD - VH, VV - VH - de, VV - VL], axis=-1)


def from_relative(coeffs: Coefficients, tau: float, y: np.ndarray) -> np.ndarray:
    """One 4-DOF state with X_H = 0, X_H' = 0 that maps to the relative state y at time tau."""
    e = coeffs.e * math.sin(coeffs.omega * tau + coeffs.phi)
    de = coeffs.e * coeffs.omega * math.cos(coeffs.omega * tau + coeffs.phi)
    x1, x2, x3, v1, v2, v3 = y
    XV, VV = x2 + e, v2 + de
    return np.array([x1, 0.0, XV, XV - x3, v1, 0.0, VV, VV - v3])


def lti_response(coeffs: Coefficients, tau: np.ndarray) -> np.ndarray:
    """Exact steady state of the linear time-invariant case (kappa = 1, b = 0), states (..., 6):
    x(tau) = x_static + Im[X exp(i (omega tau + phi))], (-omega^2 I + i omega (C + c_m g e2^T)
    + K + g e2^T) X = (0, e_bar omega^2, 0)."""
    m = coeffs.matrices()
    K = m["K"] + np.outer(m["g"], [0.0, 1.0, 0.0])
    C = m["C"] + coeffs.c_m * np.outer(m["g"], [0.0, 1.0, 0.0])
    w = coeffs.omega
    X = np.linalg.solve(-(w**2) * np.eye(3) + 1j * w * C + K, np.array([0.0, m["te"], 0.0]))
    ph = np.exp(1j * (w * np.asarray(tau, dtype=float)[..., None] + coeffs.phi))
    return np.concatenate([np.linalg.solve(K, m["p"]) + np.imag(X * ph), np.imag(1j * w * X * ph)], axis=-1)


def cutter_shift_for_trimming_limit(
    base: geo.GearPair, x1_limit: float, teeth: int, addendum: float | None = None
) -> geo.ShaperCutter:
    """Shaper cutter (given z0, ha0*) whose trimming limit on line 4 falls at ``x1_limit``: solves
    trimming_interference(x1_limit, x2_line4(x1_limit); z0, x0, ha0*) = 0 for x0 (docs/geometry.md:
    the hypothesis that the paper's M is a cutter-trimming limit; a fit, not a datum of the paper)."""
    pair = geo.with_shifts(base, x1_limit, constraints.x2_on_overlap_boundary(x1_limit, base))

    def f(x0: float) -> float:
        return float(interference.trimming_interference(pair, geo.ShaperCutter(teeth, x0, addendum)))

    return geo.ShaperCutter(teeth, float(brentq(f, -1.0, 1.5, xtol=1e-12)), addendum)


def modal_damping_matrix(mass: ArrayLike, omega2: ArrayLike, shapes: ArrayLike, zeta: float) -> NDArray:
    """Physical damping matrix C = M Phi diag(2 zeta w_r) Phi^T M of modal damping: with it the direct
    solve (K - w^2 M + i w C) X = F equals :func:`geardyn.plus.forced.modal_frf`."""
    mp = np.asarray(mass, dtype=float) @ np.asarray(shapes, dtype=float)
    return mp @ np.diag(2 * zeta * np.sqrt(np.asarray(omega2, dtype=float))) @ mp.T


def kinematic_ratio_carrier_fixed(design: PlusDesign) -> float:
    """theta_r / theta_s of the rigid-body mode with the carrier fixed (+z_s/z_r for a plus set)."""
    mat = modal.matrices(design, "I")
    rigid = scipy.linalg.eigh(mat.K, mat.M)[1][:, 0]
    return float(rigid[mat.coords.index("theta_r")] / rigid[mat.coords.index("theta_s")])


def read_provenance_text(text: str) -> dict[str, str]:
    """The ``key: value`` pairs of the provenance comment that ``geardyn.io.write_text`` put in a table."""
    start = text.rfind("<!-- provenance\n")
    if start < 0:
        return {}
    body = text[start + len("<!-- provenance\n") : text.find("-->", start)]
    return dict(line.split(": ", 1) for line in body.splitlines() if ": " in line)


# Moved from geardyn (used only by tests)


def energy(coeffs: Coefficients, y: np.ndarray, kappa: float = 1.0) -> np.ndarray:
    """Mechanical energy of the relative motion in units of k_mean b_c^2.

    Kinetic energy of the 4 masses minus that of the centre of mass (conserved separately
    when no external torque acts), plus shaft and mesh potentials (mesh: kappa/2 f(x2)^2,
    valid for constant kappa; TE must be off for this to be a conserved quantity).
    """
    y = np.asarray(y, dtype=float)
    x1, x2, x3, u1, u2, u3 = np.moveaxis(y, -1, 0)
    muD, muH, muV, muL = coeffs.mu_D, coeffs.mu_H, coeffs.mu_V, coeffs.mu_L
    # velocities relative to the carrier: D = u1, H = 0, V = u2, L = u2 - u3
    vD, vV, vL = u1, u2, u2 - u3
    mtot = muD + muH + muV + muL
    p = muD * vD + muV * vV + muL * vL
    kin = 0.5 * (muD * vD**2 + muV * vV**2 + muL * vL**2) - 0.5 * p**2 / mtot
    pot = 0.5 * coeffs.k_DH * x1**2 + 0.5 * coeffs.k_VL * x3**2
    pot = pot + 0.5 * kappa * _backlash(x2, coeffs.b) ** 2
    return kin + pot


def violations(pair: geo.GearPair, **kwargs: Any) -> list[str]:
    """Names of the constraints that fail (margin < 0 or not a number)."""
    return [k for k, v in constraints.constraints(pair, **kwargs).items() if not v >= 0.0]


def working_pitch_diameters(pair: geo.GearPair) -> tuple[geo.FloatArray, geo.FloatArray]:
    """Working pitch diameters d' = d cos a / cos a', mm."""
    d1, d2 = geo.pitch_diameters(pair)
    r = math.cos(pair.alpha) / np.cos(geo.working_pressure_angle(pair))
    return d1 * r, d2 * r
