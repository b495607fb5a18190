"""Branches of periodic orbits along a sweep parameter and regime boundaries as two-parameter curves, by one
continuation engine: problems (a branch, a curve, a grazing curve) with one corrector, one tangent and one
settings class (docs/orbits.md, with the map of the package's modules)."""

from geardyn.runs.continuation.branch import Bifurcation, Branch, on_branch
from geardyn.runs.continuation.corrector import CURVES, ContinuationSettings, Point
from geardyn.runs.continuation.curve_maps import curves_from_branch
from geardyn.runs.continuation.curves import Codim2, Curve, continue_curve, line_points
from geardyn.runs.continuation.driver import OrbitSpec, label_agreement, label_check, seeds_from_cube, sweep_orbits
from geardyn.runs.continuation.family import KHVFamily, KHVPlane, PlaneLine, grazing_margin
from geardyn.runs.continuation.output import (
    bifurcation_rows,
    branch_dataset,
    branches_from_dataset,
    curve_dataset,
    rows_to_csv,
)
from geardyn.runs.continuation.stepping import continue_branch
from geardyn.runs.continuation.switching import switch_at_period_doubling

__all__ = [
    "CURVES",
    "Bifurcation",
    "Branch",
    "Codim2",
    "ContinuationSettings",
    "Curve",
    "KHVFamily",
    "KHVPlane",
    "OrbitSpec",
    "PlaneLine",
    "Point",
    "bifurcation_rows",
    "branch_dataset",
    "branches_from_dataset",
    "continue_branch",
    "continue_curve",
    "curve_dataset",
    "curves_from_branch",
    "grazing_margin",
    "label_agreement",
    "label_check",
    "line_points",
    "on_branch",
    "rows_to_csv",
    "seeds_from_cube",
    "sweep_orbits",
    "switch_at_period_doubling",
]
