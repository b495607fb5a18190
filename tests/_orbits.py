"""The continued P1 branch of the calibrated design over x1 in [0.70, 0.78] (b = 2, e = 5), shared by the
continuation and attractor tests (computed once per test process), and the crossings of a curve with a line
(the curve tests' measure of where a curve lies), and a family of any model from plain functions."""

from collections.abc import Callable
from functools import cache
from pathlib import Path

import numpy as np

from geardyn.khv import design
from geardyn.runs import continuation as C
from geardyn.runs.continuation.curves import Extended, _row, crossings
from geardyn.solve import SimulationSettings, simulate
from geardyn.solve.shooting import FlowMap

ROOT = Path(__file__).resolve().parents[1]


@cache
def calibrated_branch():
    d = design.load(ROOT / "tests" / "data" / "li2013_w07.yaml")
    fam = C.KHVFamily(d, "x1", {"b": 2.0, "e": 5.0}, 0.70, 0.78, nodes=17)
    c = fam.coefficients(0.71)
    r = simulate(c, SimulationSettings(transient_periods=2000, recorded_periods=1))
    br = C.continue_branch(
        fam, 0.71, r.final_state, 1, 0.70, 0.78, C.ContinuationSettings(ds=5e-3, ds_max=5e-3, grazing=False)
    )
    return d, fam, br


def curve_crossings(
    plane: C.PlaneFamily, curve: C.Curve, axis: str, value: float, cs: C.CurveSettings | None = None
) -> list[C.CurvePoint]:
    """The points where ``curve`` crosses the line ``axis`` ("p" or "q") = value, each solved on the
    extended system with the line as the extra equation (from the chord between the bracketing points)."""
    ext = Extended(plane, curve.kind, curve.n, curve.scales, cs or C.CurveSettings())
    k = 0 if axis == "p" else 1
    d = curve.points[0].z.size - 2
    along = curve.p if axis == "p" else curve.q
    out = []
    for i, w in crossings(np.append(along, along[-1:]), value):  # the last point counts too
        a, b = curve.points[i], curve.points[min(i + 1, len(curve) - 1)]
        pt = ext.corrected(a.z + w * (b.z - a.z), a, _row(d, k), value / ext.scales[1 + k])
        out += [pt] if pt is not None else []
    return out


class CallableFamily:
    """A family from plain functions: ``flow_of(p, n) -> FlowMap`` (no grazing)."""

    def __init__(self, flow_of: Callable[[float, int], FlowMap]):
        self._flow_of = flow_of

    def flow(self, p: float, n: int) -> FlowMap:
        return self._flow_of(p, n)

    def grazing(self, p: float, x: np.ndarray, n: int) -> float:
        return float("nan")
