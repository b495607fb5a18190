"""Branches of periodic orbits along a sweep parameter (pseudo-arclength continuation, Floquet multipliers,
typed bifurcation points) and regime boundaries as two-parameter curves (docs/orbits.md, sections 2, 3 and 9,
with the table of the package's modules at the top)."""

from geardyn.runs.continuation.branch import (
    BIFURCATION_TYPES,
    TYPE_CODES,
    Bifurcation,
    Branch,
    ContinuationSettings,
    on_branch,
)
from geardyn.runs.continuation.curves import (
    CODIM2_TYPES,
    CURVE_KINDS,
    Codim2,
    Curve,
    CurvePoint,
    CurveSettings,
    continue_curve,
    curves_from_branch,
)
from geardyn.runs.continuation.driver import label_agreement, label_check, sweep_branches, sweep_orbits
from geardyn.runs.continuation.events import detect_bifurcations, fold_test, ns_pair, ns_product, pd_test
from geardyn.runs.continuation.family import (
    Family,
    KHVFamily,
    KHVPlane,
    PlaneFamily,
    cycle_states,
    grazing_margin,
)
from geardyn.runs.continuation.output import (
    TABLE_COLUMNS,
    bifurcation_rows,
    branch_dataset,
    branches_from_dataset,
    curve_dataset,
    rows_to_csv,
)
from geardyn.runs.continuation.spec import STATE_VARS, OrbitSpec, seeds_from_cube
from geardyn.runs.continuation.stepping import continue_branch
from geardyn.runs.continuation.switching import switch_at_period_doubling

__all__ = [
    "BIFURCATION_TYPES",
    "CODIM2_TYPES",
    "CURVE_KINDS",
    "STATE_VARS",
    "TABLE_COLUMNS",
    "TYPE_CODES",
    "Bifurcation",
    "Branch",
    "Codim2",
    "ContinuationSettings",
    "Curve",
    "CurvePoint",
    "CurveSettings",
    "Family",
    "KHVFamily",
    "KHVPlane",
    "OrbitSpec",
    "PlaneFamily",
    "bifurcation_rows",
    "branch_dataset",
    "branches_from_dataset",
    "continue_branch",
    "continue_curve",
    "curve_dataset",
    "curves_from_branch",
    "cycle_states",
    "detect_bifurcations",
    "fold_test",
    "grazing_margin",
    "label_agreement",
    "label_check",
    "ns_pair",
    "ns_product",
    "on_branch",
    "pd_test",
    "rows_to_csv",
    "seeds_from_cube",
    "sweep_branches",
    "sweep_orbits",
    "switch_at_period_doubling",
]
