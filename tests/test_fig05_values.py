"""Paper 1 Fig. 5 points: eps, k_C and mean stiffness against an independent calculation.

The independent calculation below uses only the formulas of docs/geometry.md ("Formulas": internal
pair, Chinese sign convention) and ISO 6336-1's constants, written out here
with scipy's root finder; it shares no code with geardyn.geometry or geardyn.stiffness.
"""

import math
from pathlib import Path

import pytest
from scipy.optimize import brentq

from geardyn.khv import design

Z1, Z2, M, HA, ALPHA, B = 30, 33, 3.5, 0.8, math.radians(20.0), 20.0


def inv(a):
    return math.tan(a) - a


def independent(x1):
    def angles(x2):
        inv_w = 2 * (x2 - x1) * math.tan(ALPHA) / (Z2 - Z1) + inv(ALPHA)
        aw = brentq(lambda a: inv(a) - inv_w, 1e-6, 1.5)
        a = M * (Z2 - Z1) / 2
        aw_dist = a * math.cos(ALPHA) / math.cos(aw)
        ra1 = (M * Z1 + 2 * (HA + x1) * M) / 2
        ra2 = (M * Z2 - 2 * (HA - x2) * M) / 2
        rb1, rb2 = M * Z1 * math.cos(ALPHA) / 2, M * Z2 * math.cos(ALPHA) / 2
        aa1, aa2 = math.acos(rb1 / ra1), math.acos(rb2 / ra2)
        d1 = math.acos((ra2**2 - ra1**2 - aw_dist**2) / (2 * ra1 * aw_dist))
        d2 = math.acos((ra2**2 - ra1**2 + aw_dist**2) / (2 * ra2 * aw_dist))
        gs = Z1 * (inv(aa1) + d1) - Z2 * (inv(aa2) + d2) + (Z2 - Z1) * inv(aw)
        eps = (Z1 * (math.tan(aa1) - math.tan(aw)) - Z2 * (math.tan(aa2) - math.tan(aw))) / (2 * math.pi)
        return gs, eps

    x2 = brentq(lambda v: angles(v)[0], x1 + 0.01, x1 + 0.5)
    eps = angles(x2)[1]
    # ISO 6336-1 method B for an internal gear: z_n2 -> infinity, x2 in ISO sign (= -x2 here)
    xi = -x2
    q = 0.04723 + 0.15551 / Z1 - 0.00635 * x1 - 0.11654 * x1 / Z1 - 0.00193 * xi + 0.00529 * x1**2 + 0.00182 * xi**2
    k_c = 0.8 * B / q * 1e6  # N/m
    return x2, eps, k_c, 8.0 / 9.0 * eps * k_c  # mean of the corrected k(t): (4/3) eps k'


@pytest.mark.parametrize("x1", [0.416, 0.626, 0.835])
def test_fig05_points_match_independent_calculation(x1):
    spec = design.load(Path(__file__).resolve().parents[1] / "config" / "designs" / "li2013.yaml")
    props = design.mesh_properties(spec, x1)
    x2, eps, k_c, k_mean = independent(x1)
    # required: within 0.5 %; both are exact formulas, so they agree far closer
    assert props.x2 == pytest.approx(x2, rel=1e-6)
    assert props.contact_ratio == pytest.approx(eps, rel=5e-3)
    assert props.k_c == pytest.approx(k_c, rel=5e-3)
    assert props.k_mean == pytest.approx(k_mean, rel=5e-3)
    assert props.contact_ratio == pytest.approx(eps, rel=1e-9)


def test_mean_stiffness_falls_along_m_n():
    # paper 1 Sec. 4.1: "the meshing stiffness becomes small" as x1 grows
    means = [independent(x1)[3] for x1 in (0.416, 0.626, 0.835)]
    assert means[0] > means[1] > means[2]
