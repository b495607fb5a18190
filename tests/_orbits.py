"""The continued P1 branch of the calibrated design over x1 in [0.70, 0.78] (b = 2, e = 5), shared by the
continuation and attractor tests (computed once per test process)."""

from functools import cache
from pathlib import Path

from geardyn.khv import design
from geardyn.runs import continuation as C
from geardyn.solve import SimulationSettings, simulate

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
