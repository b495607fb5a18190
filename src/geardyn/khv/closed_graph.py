"""Closed graph of paper 1 (Li et al. 2013, Fig. 3) on an (x1, x2) grid as an :class:`xarray.Dataset`: lines 1-4
(:data:`LINES`), line 4 being G_s = 0, not a line of constant a' (docs/geometry.md, "Lines 1-4 of Fig. 3")."""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike

from geardyn import io
from geardyn.gears import constraints, interference
from geardyn.gears import geometry as geo
from geardyn.io import Var
from geardyn.jsontypes import Json

#: Each constraint of the graph: the paper's line it belongs to (0: drawn but not one of lines 1-4) and its
#: short label in the figure (K the annulus, V the planet; * cutter-dependent), in the figure's drawing order.
LINES: dict[str, tuple[int, str]] = {
    "contact_ratio_margin": (1, "eps=1"),
    "overlap_interference": (4, "G_s=0"),
    "involute_interference_planet": (2, "inv. int. V"),
    "involute_interference_annulus": (2, "inv. int. K"),
    "root_interference_planet": (2, "root int. V"),
    "root_interference_annulus": (2, "root int. K*"),
    "tip_thickness_planet": (3, "s_a V"),
    "tip_thickness_annulus": (3, "s_a K"),
    "trimming_interference_annulus": (3, "trimming K*"),
    "undercut_planet": (0, "undercut V"),
}

#: Constraints that need the shaper cutter of the annulus (the figure and the scaffold read them here).
CUTTER_DEPENDENT = constraints.CUTTER_DEPENDENT

#: Tolerance on G_s (rad) when testing points that lie on line 4 by construction.
_ON_LINE_TOL = 1e-9


#: The pair's fields stored as attributes of the dataset: attribute -> (GearPair field, type).
_PAIR_ATTRS: dict[str, tuple[str, type]] = {
    "z1": ("z1", int),
    "z2": ("z2", int),
    "module_mm": ("module", float),
    "pressure_angle_deg": ("pressure_angle_deg", float),
    "addendum_coefficient": ("addendum", float),
    "clearance_coefficient": ("clearance", float),
}


def closed_graph(
    base: geo.GearPair,
    x1: ArrayLike,
    x2: ArrayLike,
    *,
    min_tip_thickness: float = 0.25,
    min_contact_ratio: float = 1.0,
    cutter: geo.ShaperCutter | None = None,
    reference_points: Mapping[str, tuple[float, float]] | None = None,
) -> xr.Dataset:
    """All constraints of an internal pair (``base``; its own shifts ignored) on the (x1, x2) grid as signed
    margins, the feasibility flags, line 4 (G_s = 0) with the constraints on it, and ``reference_points``
    (a paper's printed (x1, x2)) against ours along dim ``point`` (docs/geometry.md, "The closed graph dataset")."""
    if not base.internal:
        raise ValueError("the closed graph of paper 1 is for an internal pair")
    x1a, x2a = np.asarray(x1, dtype=float), np.asarray(x2, dtype=float)
    if x1a.ndim != 1 or x2a.ndim != 1:
        raise ValueError("x1 and x2 must be 1-D grids")
    kw = {"min_tip_thickness": min_tip_thickness, "min_contact_ratio": min_contact_ratio, "cutter": cutter}

    grid_pair = geo.with_shifts(base, x1a[np.newaxis, :], x2a[:, np.newaxis])
    margins = constraints.constraint_grid(grid_pair, **kw)  # type: ignore[arg-type]
    values = {"x1": x1a, "x2": x2a, **_grid_values(grid_pair, margins), **_line4_values(base, x1a, kw)}
    if reference_points:
        values |= _point_values(base, reference_points)
    ds = io.dataset([v for v in variables(margins) if v.name in values], values)
    feas_x1 = x1a[values["feasible_line4"]]
    cut = cutter if cutter is not None else interference.default_cutter(base)
    ha0 = cut.addendum if cut.addendum is not None else base.addendum + base.clearance
    ds.attrs.update(
        {
            "title": "Closed graph of profile-shift coefficients, computed",
            "source": "geardyn.khv.closed_graph.closed_graph",
            "conventions_note": "every constraint is a signed margin, >= 0 satisfied; x2 in the Chinese convention",
            "line4_definition": "G_s = 0 (tooth-profile overlap interference); the working pressure angle a' varies "
            "along it",
            **{attr: getattr(base, field) for attr, (field, _) in _PAIR_ATTRS.items()},
            "min_tip_thickness_modules": min_tip_thickness,
            "min_contact_ratio": min_contact_ratio,
            "cutter_teeth": int(cut.teeth),
            "cutter_shift": float(cut.shift),
            "cutter_addendum": float(ha0),
            "cutter_source": "configured" if cutter is not None else "assumed (interference.default_cutter)",
            "line4_feasible_x1_min": float(feas_x1.min()) if feas_x1.size else math.nan,
            "line4_feasible_x1_max": float(feas_x1.max()) if feas_x1.size else math.nan,
        }
    )
    return ds


_GRID = ("x2", "x1")
#: The feasibility flags' codes.
FEASIBLE = {"infeasible": 0, "feasible": 1}


def variables(margins: Iterable[str]) -> list[Var]:
    """The variables of the closed graph dataset; ``margins``: the constraints' names."""
    ok = FEASIBLE
    return [
        Var("x1", "x1", "1", "planet profile-shift coefficient x1"),
        Var("x2", "x2", "1", "annulus profile-shift coefficient x2 (Chinese sign convention)"),
        Var("point", "point", None, "printed limit point"),
        *(_margin(name) for name in margins),
        *_mesh_vars("", _GRID, ""),
        Var("feasible", _GRID, "1", "all constraints satisfied", ok),
        Var("feasible_cutter_free", _GRID, "1", "all constraints satisfied except the cutter-dependent ones", ok),
        Var("x2_line4", "x1", "1", "annulus shift x2 on line 4 (G_s = 0)"),
        *_mesh_vars("_line4", "x1", " on line 4"),
        Var("feasible_line4", "x1", "1", "line-4 point satisfying every other constraint", ok),
        Var("feasible_line4_cutter_free", "x1", "1", "line-4 point satisfying every cutter-independent constraint", ok),
        Var("paper_x1", "point", "1", "x1 of the printed limit point"),
        Var("paper_x2", "point", "1", "x2 of the printed limit point"),
        Var("computed_x2", "point", "1", "computed x2 on G_s = 0 at the paper's x1"),
        Var("residual_x2", "point", "1", "computed minus paper x2"),
        *_mesh_vars("_point", "point", " at the computed point"),
        Var("working_centre_distance_point", "point", "mm", "working centre distance a' at the computed point"),
    ]


def _margin(name: str) -> Var:
    line, dependent = LINES.get(name, (0, ""))[0], int(name in CUTTER_DEPENDENT)
    attrs = {"closed_graph_line": line, "cutter_dependent": dependent, "sign_convention": ">= 0 satisfied"}
    return Var(name, _GRID, *constraints.constraint_info(name), dtype=float, attrs=attrs)


def _mesh_vars(suffix: str, dims: str | tuple[str, ...], where: str) -> list[Var]:
    return [
        Var(f"contact_ratio{suffix}", dims, "1", f"transverse contact ratio{where}"),
        Var(f"working_pressure_angle{suffix}", dims, "degree", f"working pressure angle a'{where}"),
    ]


def _mesh_values(pair: geo.GearPair, suffix: str) -> dict[str, Json]:
    """The contact ratio and working pressure angle of ``pair`` (``contact_ratio<suffix>``, ...)."""
    aw = np.degrees(geo.working_pressure_angle(pair))
    return {f"contact_ratio{suffix}": interference.contact_ratio(pair), f"working_pressure_angle{suffix}": aw}


def _grid_values(grid_pair: geo.GearPair, margins: Mapping[str, np.ndarray]) -> dict[str, Json]:
    """Every constraint's margin on the (x2, x1) grid, the contact ratio, the working pressure angle and the
    feasibility flags (all constraints; the cutter-independent ones)."""
    stack = np.stack([np.asarray(v, float) for v in margins.values()])
    free = np.stack([np.asarray(v, float) for n, v in margins.items() if n not in CUTTER_DEPENDENT])
    ok = {"feasible": np.all(stack >= 0.0, axis=0), "feasible_cutter_free": np.all(free >= 0.0, axis=0)}
    return {**margins, **_mesh_values(grid_pair, ""), **ok}


def _line4_values(base: geo.GearPair, x1a: np.ndarray, kw: Mapping[str, Json]) -> dict[str, Json]:
    """Line 4 (G_s = 0) along the x1 grid, with the other constraints evaluated on it: where a line-4 point
    satisfies every other constraint (``feasible_line4``), every cutter-independent one."""
    x2_l4 = constraints.x2_on_overlap_boundary_many(x1a, base)
    line_pair = geo.with_shifts(base, x1a, x2_l4)
    on_line = constraints.constraint_grid(line_pair, **kw)
    others = np.stack([v for k, v in on_line.items() if k != "overlap_interference"])
    ok_line = np.all(others >= 0.0, axis=0) & (np.abs(on_line["overlap_interference"]) < _ON_LINE_TOL)
    others_free = np.stack([v for k, v in on_line.items() if k not in (*CUTTER_DEPENDENT, "overlap_interference")])
    ok = {"feasible_line4": ok_line, "feasible_line4_cutter_free": np.all(others_free >= 0.0, axis=0)}
    return {"x2_line4": x2_l4, **_mesh_values(line_pair, "_line4"), **ok}


def _point_values(base: geo.GearPair, points: Mapping[str, tuple[float, float]]) -> dict[str, Json]:
    """Printed points (x1, x2) and ours on G_s = 0 at the same x1, with residuals, along ``point``."""
    px1, px2 = (np.array([p[k] for p in points.values()]) for k in (0, 1))
    cx2 = constraints.x2_on_overlap_boundary_many(px1, base)
    pt_pair = geo.with_shifts(base, px1, cx2)
    values = {"point": np.array(list(points)), "paper_x1": px1, "paper_x2": px2, "computed_x2": cx2}
    values |= {"residual_x2": cx2 - px2, "working_centre_distance_point": geo.working_centre_distance(pt_pair)}
    return values | _mesh_values(pt_pair, "_point")


def line4_crossings(ds: xr.Dataset, name: str) -> list[float]:
    """x1 values (linear interpolation on the grid) where constraint ``name`` changes sign on line 4,
    re-evaluated along ``x2_line4`` from the dataset attributes."""
    base = geo.GearPair(x1=0.0, x2=0.0, **{field: kind(ds.attrs[attr]) for attr, (field, kind) in _PAIR_ATTRS.items()})
    cutter = geo.ShaperCutter(
        int(ds.attrs["cutter_teeth"]), float(ds.attrs["cutter_shift"]), float(ds.attrs["cutter_addendum"])
    )
    x1 = ds["x1"].values
    pair = geo.with_shifts(base, x1, ds["x2_line4"].values)
    v = constraints.constraint_grid(
        pair,
        min_tip_thickness=float(ds.attrs["min_tip_thickness_modules"]),
        min_contact_ratio=float(ds.attrs["min_contact_ratio"]),
        cutter=cutter,
    )[name]
    changes = [i for i in range(len(x1) - 1) if np.sign(v[i]) != np.sign(v[i + 1]) and np.isfinite(v[i : i + 2]).all()]
    return [float(x1[i] - v[i] * (x1[i + 1] - x1[i]) / (v[i + 1] - v[i])) for i in changes]
