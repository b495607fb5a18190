"""The constraint set of a spur pair as signed margins (>= 0 satisfied), the derived geometry of one design, and line 4
of the closed graph (the G_s = 0 boundary), on which the design point of an x1 lies."""

from __future__ import annotations

import dataclasses
import math
from typing import TypedDict, Unpack

import numpy as np
from numpy.typing import ArrayLike

from geardyn.gears import geometry as geo
from geardyn.gears import interference as itf

# --- Constraint set ---

#: name -> (units, long_name); filled for both internal and external role names.
_INFO: dict[str, tuple[str, str]] = {
    "contact_ratio_margin": ("1", "transverse contact ratio minus required minimum (eps - eps_min)"),
    "overlap_interference": ("rad", "tooth-profile overlap interference G_s"),
    "trimming_interference_annulus": ("rad", "shaper-cutter trimming (radial-feed) interference of the annulus"),
}
for _g in ("planet", "annulus", "pinion", "wheel"):
    _INFO[f"involute_interference_{_g}"] = ("mm", f"involute interference margin of the {_g}")
    _INFO[f"root_interference_{_g}"] = ("mm", f"root transition-curve interference margin of the {_g}")
    _INFO[f"undercut_{_g}"] = ("mm", f"undercut margin of the {_g} (rack-cut), rb tan aF")
    _INFO[f"tip_thickness_{_g}"] = ("mm", f"tip thickness of the {_g} minus required minimum")


#: Constraints that need the shaper cutter of the annulus (teeth, shift), which a paper may not give: a
#: design reports them always and enforces them only with ``admissible.enforce_cutter_constraints``.
CUTTER_DEPENDENT = ("root_interference_annulus", "trimming_interference_annulus")


def constraint_info(name: str) -> tuple[str, str]:
    """(units, long_name) of a constraint returned by :func:`constraints`."""
    return _INFO[name]


class Options(TypedDict, total=False):
    """The options of :func:`constraint_grid`, passed on by :func:`constraints` and :func:`describe`."""

    min_tip_thickness: float
    min_contact_ratio: float
    cutter: geo.ShaperCutter | None


def constraint_grid(
    pair: geo.GearPair,
    *,
    min_tip_thickness: float = 0.25,
    min_contact_ratio: float = 1.0,
    cutter: geo.ShaperCutter | None = None,
) -> dict[str, geo.FloatArray]:
    """All constraints as signed margins (>= 0 satisfied); shifts may be broadcasting arrays.  Keys: those
    of :func:`constraint_info` for the pair's role names (docs/geometry.md, "Lines 1-4 of Fig. 3")."""
    out: dict[str, geo.FloatArray] = {"contact_ratio_margin": itf.contact_ratio(pair) - min_contact_ratio}
    if pair.internal:
        out["overlap_interference"] = itf.overlap_interference(pair)
    smin = min_tip_thickness * pair.module
    per_gear = (  # each gear's margin (the annulus is shaper-cut: no undercut)
        ("involute_interference", itf.involute_interference(pair)),
        ("root_interference", itf.root_interference(pair, cutter)),
        ("undercut", itf.undercut_margin(pair)[: 1 if pair.internal else 2]),
        ("tip_thickness", tuple(sa - smin for sa in itf.tip_thickness(pair))),
    )
    out |= {f"{key}_{name}": v for key, values in per_gear for name, v in zip(pair.names, values, strict=False)}
    if pair.internal:
        out["trimming_interference_annulus"] = itf.trimming_interference(pair, cutter)
    shape = np.broadcast(*geo.shifts(pair)).shape
    return {k: np.broadcast_to(np.asarray(v, dtype=float), shape) for k, v in out.items()}


def constraints(pair: geo.GearPair, **kwargs: Unpack[Options]) -> dict[str, float]:
    """Every constraint of one design as a float margin (>= 0 satisfied); ``kwargs``: those of
    :func:`constraint_grid` (``min_tip_thickness`` is s_min in modules, 0.25 m or 0.4 m the usual choices)."""
    return {k: float(v) for k, v in constraint_grid(pair, **kwargs).items()}


def describe(pair: geo.GearPair, **kwargs: Unpack[Options]) -> dict[str, float]:
    """Derived geometry of one design for ``geardyn check-design`` (mm, deg, -)."""
    aw = float(geo.working_pressure_angle(pair))
    out: dict[str, float] = {
        "reference_centre_distance_mm": geo.reference_centre_distance(pair),
        "working_pressure_angle_deg": math.degrees(aw),
        "cos_working_pressure_angle": math.cos(aw),
        "working_centre_distance_mm": float(geo.working_centre_distance(pair)),
        "centre_distance_modification": float(geo.centre_distance_modification(pair)),
        "contact_ratio": float(itf.contact_ratio(pair)),
    }
    # tip, root and base diameters and tip thickness of each gear: da1_mm, da2_mm, df1_mm, ...
    per_gear: dict[str, tuple[float, float] | tuple[geo.FloatArray, geo.FloatArray]]
    per_gear = {"da": geo.tip_diameters(pair), "df": geo.root_diameters(pair), "db": geo.base_diameters(pair)}
    per_gear["sa"] = itf.tip_thickness(pair)
    out |= {f"{name}{i + 1}_mm": float(v[i]) for name, v in per_gear.items() for i in (0, 1)}
    if pair.internal:
        out["overlap_interference_Gs"] = float(itf.overlap_interference(pair))
        out["radial_interference_assembly"] = float(itf.radial_interference(pair))
    out.update({f"margin_{k}": v for k, v in constraints(pair, **kwargs).items()})
    return out


# --- Line 4: the G_s = 0 boundary ---


def _gs_scalar(base: geo.GearPair, x1: float, x2: float) -> float:
    return float(itf.overlap_interference(dataclasses.replace(base, x1=x1, x2=x2)))


def x2_on_overlap_boundary(x1: float, base: geo.GearPair, *, xtol: float = 1e-12) -> float:
    """Annulus shift x2 with G_s(x1, x2) = 0 ("line 4", the design point for a given x1): bracketed by stepping x2 up
    from x1 - 0.5, then brentq (docs/geometry.md, "Lines 1-4 of Fig. 3"); ``ValueError`` when no root exists."""
    if not base.internal:
        raise ValueError("the G_s = 0 boundary applies to internal pairs only")
    lo = float(x1) - 0.5
    g_lo = _gs_scalar(base, x1, lo)
    step = 0.25
    hi = lo
    for _ in range(200):
        hi = lo + step
        g_hi = _gs_scalar(base, x1, hi)
        if np.isfinite(g_hi) and g_hi > 0:
            break
        lo, g_lo = hi, g_hi
    else:
        raise ValueError(f"G_s has no sign change for x1 = {x1} between x2 = {x1 - 0.5} and {hi}")
    if not (np.isfinite(g_lo) and g_lo < 0):
        raise ValueError(
            f"G_s = {g_hi:.4g} > 0 already at x2 = {hi:.4g}, the first x2 at which it is defined for x1 = {x1}"
        )
    from scipy.optimize import brentq  # noqa: PLC0415 - 0.35 s to import: only the jobs that solve for x2

    return float(brentq(lambda x2: _gs_scalar(base, x1, x2), lo, hi, xtol=xtol, rtol=4 * np.finfo(float).eps))


def x2_on_overlap_boundary_many(x1: ArrayLike, base: geo.GearPair) -> geo.FloatArray:
    """Vectorised :func:`x2_on_overlap_boundary` (one brentq per x1 value)."""
    arr = np.asarray(x1, dtype=float)
    return np.array([x2_on_overlap_boundary(float(v), base) for v in arr.ravel()]).reshape(arr.shape)
