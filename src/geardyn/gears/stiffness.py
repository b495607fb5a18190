"""Mesh stiffness of a spur pair: ISO 6336-1 method B and the parabolic k(t) of paper 1 (Eqs. 7-10), in N/m over
mesh periods; the paper's two misprints (C1, the swapped intervals of Eq. 9) and every formula: docs/stiffness.md."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

#: ISO 6336-1:2006 Table 8 (method B), coefficients of q' in mm um / N.
ISO_C: tuple[float, ...] = (0.04723, 0.15551, 0.25791, -0.00635, -0.11654, -0.00193, -0.24188, 0.00529, 0.00182)
#: The same as printed in paper 1, Eq. (8): C1 = 0.04732 (a transposition).
PRINTED_C: tuple[float, ...] = (0.04732, *ISO_C[1:])

QVariant = Literal["iso", "paper"]
KForm = Literal["corrected", "printed"]

#: Paper 1, Eq. (7): k_C = 0.8 B / q' (the product of ISO's C_M C_R C_B cos(beta) = 0.8).
ISO_REDUCTION = 0.8


def flexibility_q(
    z1: int,
    z2: int,
    x1: ArrayLike,
    x2: ArrayLike,
    *,
    internal: bool = True,
    variant: QVariant = "iso",
    constants: tuple[float, ...] = ISO_C,
) -> NDArray[np.float64]:
    """Minimum single-tooth flexibility q' in mm um / N (ISO 6336-1 method B; paper 1 Eq. 8); ``x2`` in the
    Chinese convention, ``variant`` "iso" (z_n2 -> infinity) or "paper" (z_n2 = z2): docs/stiffness.md."""
    c = constants
    x1, x2 = np.asarray(x1, dtype=float), np.asarray(x2, dtype=float)
    if not internal:
        inv_z2, x2_eff = 1.0 / z2, x2
    elif variant == "iso":
        inv_z2, x2_eff = 0.0, -x2
    elif variant == "paper":
        inv_z2, x2_eff = 1.0 / z2, -x2
    else:
        raise ValueError(f"unknown stiffness variant {variant!r}; allowed: 'iso', 'paper'")
    return (
        c[0]
        + c[1] / z1
        + c[2] * inv_z2
        + c[3] * x1
        + c[4] * x1 / z1
        + c[5] * x2_eff
        + c[6] * x2_eff * inv_z2
        + c[7] * x1**2
        + c[8] * x2_eff**2
    )


def pitch_point_stiffness(q: ArrayLike, facewidth_mm: float) -> NDArray[np.float64]:
    """Single-pair stiffness at the pitch point k_C in N/m (paper 1 Eq. 7: 0.8e3 B / q N/mm)."""
    return ISO_REDUCTION * facewidth_mm / np.asarray(q, dtype=float) * 1e6


def tip_stiffness(k_c: ArrayLike) -> NDArray[np.float64]:
    """Stiffness k' at the start and end of a tooth's engagement, k' = k_C / 1.5 (paper 1 Sec. 3.3)."""
    return np.asarray(k_c, dtype=float) / 1.5


def single_tooth_stiffness(s: ArrayLike, eps: float, k_prime: float) -> NDArray[np.float64]:
    """Stiffness of one tooth pair at engagement time ``s`` (mesh periods), zero outside [0, eps]: the
    parabola k'(1 + 2u(1 - u)), u = s / eps (paper 1 Fig. 4)."""
    u = np.asarray(s, dtype=float) / eps
    return np.where((u >= 0.0) & (u <= 1.0), k_prime * (1.0 + 2.0 * u * (1.0 - u)), 0.0)


@dataclass(frozen=True)
class ParabolicStiffness:
    """Paper 1 Eq. (9): k(t) as the sum of the single-pair parabolas of the pairs in contact (corrected) or
    with the printed intervals (1 <= eps < 2 only); docs/stiffness.md."""

    eps: float
    k_prime: float
    form: KForm = "corrected"

    def __post_init__(self) -> None:
        if self.form not in ("corrected", "printed"):
            raise ValueError(f"unknown stiffness form {self.form!r}; allowed: 'corrected', 'printed'")
        if not self.eps >= 1.0:
            raise ValueError(f"contact ratio eps={self.eps:.4g} below 1: the gears do not mesh continuously")
        if self.form == "printed" and not self.eps < 2.0:
            raise ValueError(f"contact ratio eps={self.eps:.4g}: the printed Eq. (9) is stated for 1 <= eps < 2 only")

    @property
    def pairs(self) -> int:
        """n = floor(eps): pairs in contact on the second zone [f, 1) (n + 1 on the first)."""
        return math.floor(self.eps)

    @property
    def fraction(self) -> float:
        """f = eps - floor(eps): the length of the first zone (one pair more) in mesh periods."""
        return self.eps - math.floor(self.eps)

    def zone_poly(self, m: int) -> tuple[float, float, float]:
        """(a, b, c) of a s^2 + b s + c: the sum of the single-pair parabolas of m pairs at t = s + j."""
        # the single-pair parabola of Eq. (9): A = -2k'/eps^2, B = 2k'/eps, C = k'
        a, b, c = -2.0 * self.k_prime / self.eps**2, 2.0 * self.k_prime / self.eps, self.k_prime
        sj = m * (m - 1) / 2.0
        sj2 = (m - 1) * m * (2 * m - 1) / 6.0
        return (m * a, 2 * a * sj + m * b, a * sj2 + b * sj + m * c)

    def zone_polys(self) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
        """The polynomials of the first zone [0, f) and the second [f, 1) (swapped in the printed form)."""
        more, fewer = self.zone_poly(self.pairs + 1), self.zone_poly(self.pairs)
        return (more, fewer) if self.form == "corrected" else (fewer, more)

    def __call__(self, t: ArrayLike) -> NDArray[np.float64]:
        """k(t) in N/m, periodic with period 1; right-continuous at the jumps."""
        tau = np.mod(np.asarray(t, dtype=float), 1.0)
        (a1, b1, c1), (a2, b2, c2) = self.zone_polys()
        return np.where(tau < self.fraction, a1 * tau**2 + b1 * tau + c1, a2 * tau**2 + b2 * tau + c2)

    def mean(self) -> float:
        """Exact mean of k(t) over one period (closed form of the piecewise polynomial)."""
        e1 = self.fraction

        def integral(p: tuple[float, float, float], lo: float, hi: float) -> float:
            a, b, c = p
            return a * (hi**3 - lo**3) / 3 + b * (hi**2 - lo**2) / 2 + c * (hi - lo)

        first, second = self.zone_polys()
        return integral(first, 0.0, e1) + integral(second, e1, 1.0)

    def minimum(self) -> float:
        """Smallest value over a period (negative values make the model meaningless)."""
        return float(np.min(self(np.concatenate([np.linspace(0.0, 1.0, 4001), [self.fraction]]))))
