"""The continued P1 branch of the calibrated design over x1 in [0.70, 0.78] (b = 2, e = 5), shared by the
continuation and attractor tests (computed once per test process), and a family of any model from plain
functions (its cycle by repeated one-period maps, independent of the package's cycle builder)."""

from collections.abc import Callable
from functools import cache
from pathlib import Path

import numpy as np

from geardyn.khv import design
from geardyn.runs import continuation as C
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


class CallableFamily:
    """A family from plain functions: ``flow_of(p, n) -> FlowMap`` (no grazing)."""

    def __init__(self, flow_of: Callable[[float, int], FlowMap]):
        self._flow_of = flow_of

    def flow(self, p: float, n: int) -> FlowMap:
        return self._flow_of(p, n)

    def cycle(self, p: float, x: np.ndarray, n: int) -> np.ndarray:
        return cycle_of(self.flow(p, 1), x, n)

    def grazing(self, p: float, x: np.ndarray, n: int) -> float:
        return float("nan")


def cycle_of(flow: FlowMap, x: np.ndarray, n: int) -> np.ndarray:
    """The n phase-0 points of the orbit through x by n - 1 applications of the one-period map ``flow``."""
    pts = [np.asarray(x, dtype=float)]
    for _ in range(n - 1):
        pts.append(flow(pts[-1], False)[0])
    return np.array(pts)
