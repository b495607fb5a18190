"""Branches of periodic orbits along a sweep parameter: pseudo-arclength continuation, Floquet
multipliers per point, typed bifurcation points.

A *family* gives, for a parameter value p, the n-period stroboscopic map with its monodromy
(:class:`KHVFamily` for a KHV design: the parameter enters through
:func:`geardyn.khv.point.point_coefficients`).  :func:`continue_branch` follows the fixed points of
that map, F(x, p) = phi_nT(x; p) - x = 0, in both directions from a seed:

* predictor: a step ds along the unit tangent of the branch in the scaled variables
  u = (x / x_scale, p / p_scale) (p_scale: the sweep's range, x_scale: max(1, max |x|) at the seed);
* corrector: Newton on (F(x, p) = 0, t . (u - u_pred) = 0) with dF/dx = M - I from the
  variational equations and dF/dp by a forward difference; the extra equation lets the corrector
  pass folds, where M - I is singular;
* step control: ds grows by 1.3 after a corrector that needed at most 3 evaluations, halves after a
  failure, and never exceeds ``ds_max`` (in units of the sweep range), so a branch of the sweep's
  range has about 1 / ds_max points.

Bifurcation points (test functions between consecutive points, then located):

=================  ==========================================  ===============================
type               test function changes sign                  located by
=================  ==========================================  ===============================
period_doubling    det(M + I) (a real multiplier crosses -1)    Brent on the arclength fraction
neimark_sacker     |mu| - 1 of the complex pair that crosses    Brent; rotation number
                   (the count of complex |mu| > 1 changes by 2)  arg(mu) / (2 pi) at the point
fold               dp/ds (the branch turns; a multiplier        cubic Hermite extremum of p(s),
                   crosses +1)                                  then bracketing on dp/ds = 0
branch_point       det(M - I) without a turn of p               Brent
grazing            g = min over the cycle of |x_VH| - b          Brent (dense run of the cycle
                   (g < 0: contact is lost during the cycle)     at each trial)
=================  ==========================================  ===============================

Every trial point of a location is a pseudo-arclength correction from the left point along its
tangent (so it stays on this branch even next to a fold), so the located parameter is accurate to
the shooting tolerance, not to the step size.

The modules of the package:

==========  ==================================================================================
family      the model adapter: :class:`Family`, :class:`KHVFamily` (system at a parameter value,
            spline cache), :func:`grazing_margin`, :func:`cycle_states`
branch      the records: :class:`ContinuationSettings`, :class:`Branch` (with the one interpolation
            of a branch at a parameter value), :class:`Bifurcation`, :func:`on_branch`
corrector   Newton on the pseudo-arclength system, the tangent, the merged-period test
stepping    :class:`~geardyn.runs.continuation.stepping.ContState`, the march of one direction
            (predictor, step control, end tests), :func:`continue_branch`
events      the test functions and the location of typed bifurcation points
switching   :func:`switch_at_period_doubling`
spec        :class:`OrbitSpec` (an ``orbits:`` entry) and :func:`seeds_from_cube`
output      :func:`branch_dataset` (netCDF), :func:`bifurcation_rows` / :func:`rows_to_csv` (CSV),
            :func:`branches_from_dataset`
driver      :func:`sweep_orbits`: seeds, branches, switching, outputs, and :func:`label_check`
            (the cross-check of the sweep's labels)
==========  ==================================================================================
"""

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
    KHVPlane,
    PlaneFamily,
    continue_curve,
    curve_crossings,
    curve_dataset,
    curves_from_branch,
)
from geardyn.runs.continuation.driver import label_agreement, label_check, sweep_branches, sweep_orbits
from geardyn.runs.continuation.events import detect_bifurcations, fold_test, ns_pair, ns_product, pd_test
from geardyn.runs.continuation.family import CallableFamily, Family, KHVFamily, cycle_states, grazing_margin
from geardyn.runs.continuation.output import (
    TABLE_COLUMNS,
    bifurcation_rows,
    branch_dataset,
    branches_from_dataset,
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
    "CallableFamily",
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
    "curve_crossings",
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
