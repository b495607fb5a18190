"""Floquet analysis of the linear case (b = 0: the dead zone vanishes, f(x) = x).

The model is then y' = A(tau) y + q(tau) with period T.  The monodromy matrix Phi (one mesh
period of the homogeneous system) and the particular solution y_p(T) from y(0) = 0 are
integrated with DOP853 (rtol 1e-12, zone by zone, see :mod:`geardyn.solve.reference`), so

* the T-periodic orbit is y* = (I - Phi)^-1 y_p(T) (Poincare point at phase 0),
* it is asymptotically stable iff every Floquet multiplier (eigenvalue of Phi) has |mu| < 1;
  max |mu| > 1 is parametric instability (growth per period).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from geardyn import libm
from geardyn.solve.reference import integrate_period


@dataclass(frozen=True)
class FloquetResult:
    monodromy: np.ndarray  # (6, 6)
    multipliers: np.ndarray  # (6,) complex
    periodic_state: np.ndarray  # (6,) Poincare point of the T-periodic orbit

    @property
    def spectral_radius(self) -> float:
        return float(np.max(libm.cabs(self.multipliers)))

    @property
    def stable(self) -> bool:
        return self.spectral_radius < 1.0


#: A multiplier is complex when its imaginary part exceeds this fraction of its modulus (a real multiplier
#: computed from a real monodromy matrix can carry a rounding-level imaginary part).
COMPLEX_RTOL = 1e-8


def is_complex(mu: np.ndarray) -> np.ndarray:
    """Which of the multipliers ``mu`` are complex (:data:`COMPLEX_RTOL`), element by element."""
    mu = np.asarray(mu)
    return np.abs(mu.imag) > COMPLEX_RTOL * np.maximum(libm.cabs(mu), 1e-300)


def bifurcation_type(multipliers: np.ndarray) -> str:
    """How the leading multiplier of an orbit leaves (or reaches) the unit circle: ``neimark_sacker`` (a
    complex pair), ``period_doubling`` (real, through -1) or ``fold`` (real, through +1)."""
    mu = np.asarray(multipliers)[:1]
    if bool(is_complex(mu)[0]):
        return "neimark_sacker"
    return "period_doubling" if mu[0].real < 0 else "fold"


def linear_part(coeffs):
    """The linear (b = 0) model of the same coefficients."""
    return coeffs.replace(b=0.0, backlash_on=False)


def floquet(coeffs, rtol: float = 1e-12) -> FloquetResult:
    """Monodromy, multipliers and periodic orbit of the b = 0 model (backlash ignored)."""
    lin = linear_part(coeffs)
    hom = lin.replace(P_D=0.0, P_L=0.0, e=0.0)
    phi = np.empty((6, 6))
    for i in range(6):
        e = np.zeros(6)
        e[i] = 1.0
        phi[:, i], _, _ = integrate_period(hom, e, 0, rtol, atol=rtol * 1e-2)
    yp, _, _ = integrate_period(lin, np.zeros(6), 0, rtol)
    ystar = np.linalg.solve(np.eye(6) - phi, yp)
    return FloquetResult(phi, np.linalg.eigvals(phi), ystar)
