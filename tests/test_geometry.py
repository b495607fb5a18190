"""Gear geometry against numbers from outside the code: paper 1, published tables, hand derivations
(docs/paper1.md, "Geometry and closed graph")."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import _model_oracle as oracle
from geardyn.gears import constraints, interference
from geardyn.gears import geometry as geo

#: Paper 1, Table 1: planet V z = 30, annulus K z = 33, m = 3.5 mm, ha* = 0.8, B = 20 mm.
KHV = geo.GearPair(z1=30, z2=33, module=3.5, x1=0.0, x2=0.0, addendum=0.8, facewidth=20.0)


def at(x1: float, x2: float, base: geo.GearPair = KHV) -> geo.GearPair:
    return dataclasses.replace(base, x1=x1, x2=x2)


# ------------------------------------------------------------------------------------------
# Paper 1 (Sec. 3.2, Eq. 10) and docs/paper1.md, "Geometry and closed graph"
# ------------------------------------------------------------------------------------------


def test_reference_centre_distance_khv() -> None:
    # a = m (z2 - z1) / 2 = 3.5 x 3 / 2 = 5.25 mm (exact arithmetic).
    assert geo.reference_centre_distance(KHV) == pytest.approx(5.25, abs=1e-12)


@pytest.mark.parametrize(
    ("x1", "paper_x2", "computed_x2"),
    [(0.416, 0.601, 0.60095), (0.835, 0.995, 0.99443)],  # paper M and N; G_s = 0 to 5 decimals (docs/paper1.md)
)
def test_paper_points_on_overlap_boundary(x1: float, paper_x2: float, computed_x2: float) -> None:
    x2 = constraints.x2_on_overlap_boundary(x1, KHV)
    # Requirement: within 0.002 of the paper's 3-decimal values.
    assert abs(x2 - paper_x2) < 0.002
    # The 5-decimal values of docs/paper1.md ("M and N lie on G_s = 0"): half a unit in the last digit.
    assert x2 == pytest.approx(computed_x2, abs=5e-6)
    # By construction G_s = 0 there (brentq xtol 1e-12 in x2, dG_s/dx2 ~ 10).
    assert float(interference.overlap_interference(at(x1, x2))) == pytest.approx(0.0, abs=1e-9)


def test_eq10_constant_is_cos_working_angle_at_n() -> None:
    # The constant 0.866268 of paper Eq. (10) equals cos a' at N (cos 29.9722 deg); printed to 6 digits.
    x2 = constraints.x2_on_overlap_boundary(0.835, KHV)
    assert math.cos(float(geo.working_pressure_angle(at(0.835, x2)))) == pytest.approx(0.866268, abs=5e-7)


def test_working_angle_along_line4_is_not_constant() -> None:
    # a' falls from 30.996 deg (M) to 29.972 deg (N), so line 4 is not a constant-a' line; eps 1.298 -> 1.171
    # (docs/paper1.md, "Line 4 is not a constant-a' line").
    pm = at(0.416, constraints.x2_on_overlap_boundary(0.416, KHV))
    pn = at(0.835, constraints.x2_on_overlap_boundary(0.835, KHV))
    assert math.degrees(float(geo.working_pressure_angle(pm))) == pytest.approx(31.0, abs=0.05)
    assert math.degrees(float(geo.working_pressure_angle(pn))) == pytest.approx(29.97, abs=0.005)
    assert float(interference.contact_ratio(pm)) == pytest.approx(1.30, abs=0.005)
    assert float(interference.contact_ratio(pn)) == pytest.approx(1.17, abs=0.005)


def test_internal_tip_diameters_have_no_shortening() -> None:
    # Chinese convention, no tip shortening for internal pairs: da1 = d1 + 2 (ha* + x1) m,
    # da2 = d2 - 2 (ha* - x2) m; exact arithmetic.
    da1, da2 = geo.tip_diameters(at(0.5, 0.7))
    assert float(da1) == pytest.approx(105.0 + 2 * 1.3 * 3.5, abs=1e-12)
    assert float(da2) == pytest.approx(115.5 - 2 * 0.1 * 3.5, abs=1e-12)


def test_paper_points_feasible_with_a_trimming_cutter_and_boundary_violations_named() -> None:
    # With the cutter fitted to M (docs/geometry.md) both printed points satisfy every constraint
    # (they lie 5e-5 and 6e-4 above G_s = 0).
    cutter = geo.ShaperCutter(teeth=28, shift=-0.1096, addendum=1.25)
    assert oracle.violations(at(0.416, 0.601), cutter=cutter) == []
    assert oracle.violations(at(0.835, 0.995), cutter=cutter) == []
    assert "overlap_interference" in oracle.violations(at(0.416, 0.5), cutter=cutter)
    assert "contact_ratio_margin" in oracle.violations(at(0.0, 1.2), cutter=cutter)


def test_describe_has_check_design_fields() -> None:
    d = constraints.describe(at(0.416, 0.601))
    for key in (
        "working_pressure_angle_deg",
        "working_centre_distance_mm",
        "contact_ratio",
        "overlap_interference_Gs",
        "da1_mm",
        "da2_mm",
        "sa1_mm",
        "sa2_mm",
    ):
        assert math.isfinite(d[key])
    assert all(isinstance(v, float) for v in d.values())


# ------------------------------------------------------------------------------------------
# Published internal-gear table: SDP/SI-KHK "Elements of Metric Gear Technology", Table 5-4
# (Sec. 5.3, page T-46, http://www.sdp-si.com/D785/HTML1/D785T043_4.html):
# z2 = 50, x1 = 0, alpha = 20 deg, m = 1 (a printed in modules), full-depth teeth.
# ------------------------------------------------------------------------------------------

KHK_TABLE_5_4 = [
    # z1, x2, a_w (deg), a (mm at m = 1), eps  -- as printed
    (49, 1.00, 61.0605, 0.971, 1.105),
    (48, 0.60, 46.0324, 1.354, 1.512),
    (47, 0.40, 37.4155, 1.775, 1.726),
    (46, 0.30, 32.4521, 2.227, 1.835),
    (45, 0.20, 28.2019, 2.666, 1.933),
    (44, 0.11, 24.5356, 3.099, 2.014),
    (43, 0.06, 22.3755, 3.557, 2.053),
    (42, 0.01, 20.3854, 4.010, 2.088),
]


@pytest.mark.parametrize(("z1", "x2", "aw_deg", "a_w", "eps"), KHK_TABLE_5_4)
def test_khk_table_5_4_to_printed_digits(z1: int, x2: float, aw_deg: float, a_w: float, eps: float) -> None:
    pair = geo.GearPair(z1=z1, z2=50, module=1.0, x1=0.0, x2=x2)
    # Each tolerance is half a unit in the last printed digit.
    assert math.degrees(float(geo.working_pressure_angle(pair))) == pytest.approx(aw_deg, abs=5e-5)
    assert float(geo.working_centre_distance(pair)) == pytest.approx(a_w, abs=5e-4)
    assert float(interference.contact_ratio(pair)) == pytest.approx(eps, abs=5e-4)


@pytest.mark.parametrize(("z1", "x2"), [(r[0], r[1]) for r in KHK_TABLE_5_4])
def test_khk_table_5_4_interference_statements(z1: int, x2: float) -> None:
    # SDP/SI Sec. 5.3: "All combinations above will not cause involute interference or trochoid
    # interference, but trimming interference is still there."
    pair = geo.GearPair(z1=z1, z2=50, module=1.0, x1=0.0, x2=x2)
    assert float(interference.overlap_interference(pair)) > 0.0  # trochoid, KHK Eq. (5-6) = G_s / z2
    assert all(float(m) > 0.0 for m in interference.involute_interference(pair))
    assert float(interference.radial_interference(pair)) < 0.0  # KHK Eq. (5-9)


def test_khk_trochoid_equation_equals_gs_over_z2() -> None:
    # KHK Eqs. (5-6)/(5-7) written out independently: theta1 z1/z2 + inv a_w - inv a_a2 - theta2.
    pair = geo.GearPair(z1=45, z2=50, module=1.0, x1=0.0, x2=0.2)
    aw = float(geo.working_pressure_angle(pair))
    a = float(geo.working_centre_distance(pair))
    ra1, ra2 = (float(d) / 2 for d in geo.tip_diameters(pair))
    rb1, rb2 = (d / 2 for d in geo.base_diameters(pair))
    aa1, aa2 = math.acos(rb1 / ra1), math.acos(rb2 / ra2)

    def inv(t: float) -> float:
        return math.tan(t) - t

    th1 = math.acos((ra2**2 - ra1**2 - a**2) / (2 * a * ra1)) + inv(aa1) - inv(aw)
    th2 = math.acos((a**2 + ra2**2 - ra1**2) / (2 * a * ra2))
    khk = th1 * 45 / 50 + inv(aw) - inv(aa2) - th2
    # Same formula rearranged: agreement to rounding (1e-12 rad).
    assert float(interference.overlap_interference(pair)) / 50 == pytest.approx(khk, abs=1e-12)


#: SDP/SI Table 5-3a (page T-45, http://www.sdp-si.com/D785/HTML1/D785T043_3.html): smallest
#: annulus tooth count z2 that a z_c-tooth pinion cutter cuts without trimming interference,
#: alpha = 20 deg, x_c = x2 = 0 (standard cutter, addendum 1.25 m).
KHK_TABLE_5_3A = [
    (15, 34),
    (16, 34),
    (17, 35),
    (18, 36),
    (19, 37),
    (20, 38),
    (21, 39),
    (22, 40),
    (24, 42),
    (25, 43),
    (27, 45),
    (28, 46),
    (30, 48),
    (31, 49),
    (32, 50),
    (33, 51),
    (34, 52),
    (35, 53),
    (38, 56),
    (40, 58),
    (42, 60),
    (44, 62),
    (48, 66),
    (50, 68),
    (56, 74),
    (60, 78),
    (64, 82),
    (66, 84),
    (80, 98),
    (96, 114),
    (100, 118),
]


@pytest.mark.parametrize(("zc", "z2"), KHK_TABLE_5_3A)
def test_khk_trimming_limits_table_5_3a(zc: int, z2: int) -> None:
    cutter = geo.ShaperCutter(teeth=zc, shift=0.0, addendum=1.25)

    def margin(z: int) -> float:
        return float(interference.trimming_interference(geo.GearPair(z1=zc, z2=z, module=1.0, x1=0.0, x2=0.0), cutter))

    assert margin(z2) >= 0.0  # the printed z2 is free of trimming
    # One tooth fewer trims (margin < 0), or for z2 = 34 the annulus tip falls inside its base
    # circle (NaN: SDP/SI notes involute interference for z_c = 15-22), which also fails.
    assert not margin(z2 - 1) >= 0.0


# ------------------------------------------------------------------------------------------
# External pair: KHK profile-shifted spur example (m = 3, z = 12/24, x = 0.6/0.36), as printed on
# http://bolsover.com/utilitiesforalibre/profile-shifted-external-spur-gears.html
# ------------------------------------------------------------------------------------------


def test_external_profile_shifted_example() -> None:
    pair = geo.GearPair(z1=12, z2=24, module=3.0, x1=0.6, x2=0.36, internal=False)
    # That page takes a' = 56.500 mm as an input and derives a_w = 26.0888 deg and inv a_w = 0.034317
    # from it; from x1 + x2 = 0.96 exactly, a' = 56.49987 and a_w = 26.08856 deg.  The 1.3e-4 mm
    # difference moves inv a_w by 1e-6, so a_w is compared to 3 decimals (5e-4) and inv a_w to 5e-6.
    assert math.degrees(float(geo.working_pressure_angle(pair))) == pytest.approx(26.0888, abs=5e-4)
    assert float(geo.involute(geo.working_pressure_angle(pair))) == pytest.approx(0.034317, abs=5e-6)
    # The page takes a' = 56.500 as input; from the shifts a' = 56.49987: 3 decimals.
    assert float(geo.working_centre_distance(pair)) == pytest.approx(56.500, abs=5e-4)
    assert float(geo.centre_distance_modification(pair)) == pytest.approx(0.8333, abs=5e-5)
    d1, d2 = geo.pitch_diameters(pair)
    db1, db2 = geo.base_diameters(pair)
    dw1, dw2 = oracle.working_pitch_diameters(pair)
    da1, da2 = geo.tip_diameters(pair)
    df1, df2 = geo.root_diameters(pair)
    printed = {  # value: (ours, printed, half a unit in the last printed digit)
        "d1": (d1, 36.000, 5e-4),
        "d2": (d2, 72.000, 5e-4),
        "db1": (db1, 33.8289, 5e-5),
        "db2": (db2, 67.6579, 5e-5),
        "dw1": (dw1, 37.667, 5e-4),
        "dw2": (dw2, 75.333, 5e-4),
        "ha1": ((da1 - d1) / 2, 4.420, 5e-4),
        "ha2": ((da2 - d2) / 2, 3.700, 5e-4),
        "h": ((da1 - df1) / 2, 6.370, 5e-4),
        "da1": (da1, 44.840, 5e-4),
        "da2": (da2, 79.400, 5e-4),
        "df1": (df1, 32.100, 5e-4),
        "df2": (df2, 66.660, 5e-4),
        "eps": (interference.contact_ratio(pair), 1.202, 5e-4),
    }
    for name, (ours, value, tol) in printed.items():
        assert float(ours) == pytest.approx(value, abs=tol), name


def test_paper2_external_pair_standard_geometry() -> None:
    # Paper 2 sun 32 / planet 19, m = 4, alpha = 25 deg, ha* = 1, unshifted: a' = a = 102 mm and
    # eps from the textbook formula written out here.
    pair = geo.GearPair(z1=19, z2=32, module=4.0, x1=0.0, x2=0.0, pressure_angle_deg=25.0, internal=False)
    a = math.radians(25.0)
    ra1, ra2 = 38.0 + 4.0, 64.0 + 4.0
    rb1, rb2 = 38.0 * math.cos(a), 64.0 * math.cos(a)
    length = math.sqrt(ra1**2 - rb1**2) + math.sqrt(ra2**2 - rb2**2) - 102.0 * math.sin(a)
    eps = length / (math.pi * 4.0 * math.cos(a))
    assert float(geo.working_centre_distance(pair)) == pytest.approx(102.0, abs=1e-12)
    assert float(interference.contact_ratio(pair)) == pytest.approx(eps, rel=1e-12)  # rounding only


def test_internal_and_iso_signed_external_formula_agree() -> None:
    # ISO 21771: an annulus is an external gear with negative z and x_iso = -x2 (Chinese).  The
    # contact ratio written with signed quantities must equal ours.
    pair = at(0.5, 0.7)
    z1, z2 = 30, -33
    a = math.radians(20.0)
    aw = float(geo.working_pressure_angle(pair))
    inv_iso = 2 * (0.5 + (-0.7)) * math.tan(a) / (z1 + z2) + math.tan(a) - a
    assert math.tan(aw) - aw == pytest.approx(inv_iso, abs=1e-14)


# ------------------------------------------------------------------------------------------
# Vectorisation
# ------------------------------------------------------------------------------------------


def test_grid_evaluation_equals_scalar_evaluation() -> None:
    x1 = np.array([0.2, 0.6, 1.0])
    x2 = np.array([0.5, 0.9])
    grid = constraints.constraint_grid(geo.with_shifts(KHV, x1[None, :], x2[:, None]))
    for i, b in enumerate(x2):
        for j, a in enumerate(x1):
            scalar = constraints.constraints(at(float(a), float(b)))
            for k, v in scalar.items():
                # same arithmetic; NaN where a' does not exist (x2 < x1 - 0.06)
                assert grid[k][i, j] == pytest.approx(v, rel=1e-13, abs=1e-13, nan_ok=True), k


def test_x2_boundary_vectorised() -> None:
    x1 = np.array([0.416, 0.835])
    np.testing.assert_allclose(
        constraints.x2_on_overlap_boundary_many(x1, KHV),
        [constraints.x2_on_overlap_boundary(v, KHV) for v in x1],
        rtol=0,
        atol=1e-12,
    )


def test_invalid_pairs_rejected() -> None:
    with pytest.raises(ValueError, match="z2 - z1"):
        geo.GearPair(z1=30, z2=30, module=3.5, x1=0, x2=0)
    with pytest.raises(ValueError, match="module"):
        geo.GearPair(z1=30, z2=33, module=0.0, x1=0, x2=0)
    with pytest.raises(ValueError, match="pressure angle"):
        geo.GearPair(z1=30, z2=33, module=1.0, x1=0, x2=0, pressure_angle_deg=45.0)


# ------------------------------------------------------------------------------------------
# Properties (Hypothesis)
# ------------------------------------------------------------------------------------------


@settings(max_examples=200, deadline=None)
@given(st.floats(min_value=1e-3, max_value=1.55))
def test_involute_round_trip(alpha: float) -> None:
    # Newton to ~1 ulp; the relative conditioning of inv near 0 is 3 (inv ~ a^3/3): 1e-12 relative.
    assert float(geo.inverse_involute(geo.involute(alpha))) == pytest.approx(alpha, rel=1e-12)


@settings(max_examples=200, deadline=None)
@given(st.floats(min_value=-20.0, max_value=20.0))
def test_inverse_involute_solves(v: float) -> None:
    a = float(geo.inverse_involute(v))
    assert abs(a) < math.pi / 2
    assert float(geo.involute(a)) == pytest.approx(v, rel=1e-12, abs=1e-15)


def test_inverse_involute_of_an_array_is_each_value_alone_bit_for_bit() -> None:
    # Each value of an array stops on its own step, so the array path (numpy) and the one-value path (Python
    # floats, used by the root solvers) give the same bits; a NaN among the values leaves the rest alone.
    rng = np.random.default_rng(7)
    v = np.concatenate([rng.uniform(-0.3, 0.3, 3000), 10 ** rng.uniform(-12, 1, 1000)])
    v = np.concatenate([v, [0.0, -0.0, 5e-324, np.inf, -np.inf, np.nan, 0.01, -0.01]])
    rng.shuffle(v)
    arr = geo.inverse_involute(v.reshape(-1, 8))
    one = np.array([geo.inverse_involute(x) for x in v]).reshape(-1, 8)
    assert arr.shape == (v.size // 8, 8)
    assert np.array_equal(arr.view(np.int64), one.view(np.int64))
    assert np.isnan(geo.inverse_involute(np.array([np.nan, 0.01]))[0])
    assert float(geo.involute(geo.inverse_involute(np.array([np.nan, 0.01]))[1])) == pytest.approx(0.01, rel=1e-14)


@settings(max_examples=25, deadline=None)
@given(st.floats(0.416, 0.835), st.floats(0.416, 0.835))
def test_eps_decreases_along_line4(xa: float, xb: float) -> None:
    lo, hi = sorted((xa, xb))
    if hi - lo < 1e-3:
        return
    e_lo = float(interference.contact_ratio(at(lo, constraints.x2_on_overlap_boundary(lo, KHV))))
    e_hi = float(interference.contact_ratio(at(hi, constraints.x2_on_overlap_boundary(hi, KHV))))
    assert e_lo > e_hi


@settings(max_examples=60, deadline=None)
@given(st.floats(0.0, 1.2), st.floats(0.0, 1.0), st.floats(1e-3, 0.5))
def test_gs_monotone_in_x2(x1: float, dx: float, step: float) -> None:
    # Claimed for x2 >= x1 (a' >= a, the side of the graph where line 4 lies) and where the two
    # tip circles intersect (|ra2 - ra1| < a'), i.e. where teeth can meet; beyond that the clipped
    # formula has no physical meaning.  (For x2 < x1 - 0.06, a' would be negative: NaN.)
    x2 = x1 + dx
    for b in (x2, x2 + step):
        ra1, ra2 = (float(d) / 2 for d in geo.tip_diameters(at(x1, b)))
        assume(abs(ra2 - ra1) < float(geo.working_centre_distance(at(x1, b))))
    g0 = float(interference.overlap_interference(at(x1, x2)))
    g1 = float(interference.overlap_interference(at(x1, x2 + step)))
    assert g1 >= g0 - 1e-12  # non-decreasing (flat once the tip circles stop intersecting)


@settings(max_examples=60, deadline=None)
@given(st.integers(8, 80), st.integers(1, 80), st.floats(-0.5, 1.0))
def test_equal_shifts_internal_keep_reference_angle(z1: int, dz: int, x: float) -> None:
    pair = geo.GearPair(z1=z1, z2=z1 + dz, module=2.0, x1=x, x2=x)
    assert float(geo.working_pressure_angle(pair)) == pytest.approx(math.radians(20.0), abs=1e-12)
    assert float(geo.working_centre_distance(pair)) == pytest.approx(dz, abs=1e-10)


@settings(max_examples=60, deadline=None)
@given(
    st.integers(10, 80),
    st.integers(10, 80),
    st.floats(-0.4, 0.8),
    st.floats(-0.4, 0.8),
    st.sampled_from([20.0, 25.0]),
    st.booleans(),
)
def test_external_swap_symmetry(z1: int, z2: int, x1: float, x2: float, alpha: float, shorten: bool) -> None:
    p = geo.GearPair(
        z1=z1, z2=z2, module=4.0, x1=x1, x2=x2, pressure_angle_deg=alpha, internal=False, tip_shortening=shorten
    )
    q = geo.GearPair(
        z1=z2, z2=z1, module=4.0, x1=x2, x2=x1, pressure_angle_deg=alpha, internal=False, tip_shortening=shorten
    )

    # Rounding-level tolerances; NaN (no working angle for strongly negative shifts) on both sides.
    def same(u: object, v: object, tol: float) -> None:
        assert float(u) == pytest.approx(float(v), rel=tol, abs=tol, nan_ok=True)  # type: ignore[arg-type]

    same(geo.working_pressure_angle(q), geo.working_pressure_angle(p), 1e-13)
    same(geo.working_centre_distance(q), geo.working_centre_distance(p), 1e-13)
    same(interference.contact_ratio(q), interference.contact_ratio(p), 1e-12)
    sp, sq = interference.tip_thickness(p), interference.tip_thickness(q)
    same(sq[0], sp[1], 1e-12)


@settings(max_examples=40, deadline=None)
@given(st.integers(8, 60))
def test_large_difference_standard_annulus_behaves_like_rack(z1: int) -> None:
    # Zero shifts: a' = a for any teeth, and as z2 -> infinity the internal contact ratio tends to
    # the pinion-rack value eps = [z1 (tan aa1 - tan a) + 4 ha* / sin 2a] / (2 pi).
    pair = geo.GearPair(z1=z1, z2=z1 + 20000, module=1.0, x1=0.0, x2=0.0)
    assert float(geo.working_pressure_angle(pair)) == pytest.approx(math.radians(20.0), abs=1e-12)
    a = math.radians(20.0)
    aa1 = math.acos(z1 * math.cos(a) / (z1 + 2.0))
    rack = (z1 * (math.tan(aa1) - math.tan(a)) + 4.0 / math.sin(2 * a)) / (2 * math.pi)
    # O(1/z2) approach to the limit: 1e-3 absolute at z2 - z1 = 20000.
    assert float(interference.contact_ratio(pair)) == pytest.approx(rack, abs=1e-3)
