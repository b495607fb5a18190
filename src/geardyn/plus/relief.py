"""Tip-relief optimisation of the p-d pair (paper 2, Sec. 4): scipy's differential evolution of the peak-to-peak
static TE (m) of :func:`geardyn.plus.ishikawa.design_te`, seeded, one worker, no polishing: deterministic."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import pandas as pd
from numpy.typing import NDArray
from scipy.optimize import differential_evolution

from .design import PlusDesign
from .ishikawa import MeshGrid, design_grid, design_te, pd_mesh_load

SHAPES = ("linear", "parabolic")
BOUND_SETS = ("paper", "physical")


@dataclass(frozen=True)
class ReliefOptimum:
    """Optimum of one relief shape within one set of bounds.  Lengths in m."""

    shape: str
    bounds: str
    amount: float
    length: float
    ptp: float
    ptp_unmodified: float
    nfev: int
    amount_bounds: tuple[float, float]
    length_bounds: tuple[float, float]

    @property
    def reduction(self) -> float:
        """Relative change of the peak-to-peak TE (negative = better), e.g. -0.2778 for the paper."""
        return self.ptp / self.ptp_unmodified - 1.0


def objective(design: PlusDesign, grid: MeshGrid, shape: str):
    """f(amount, length) = peak-to-peak TE in m (of the approach, free of the constant deviations), for
    differential evolution."""

    def f(p: NDArray) -> float:
        te = design_te(design, grid=grid, relief_amount=float(p[0]), relief_length=float(p[1]), relief_shape=shape)
        return float(np.ptp(te.approach))

    return f


def bounds_of(design: PlusDesign, which: str) -> tuple[tuple[float, float], tuple[float, float]]:
    if which not in BOUND_SETS:
        raise ValueError(f"unknown bound set {which!r}; allowed: {BOUND_SETS}")
    return getattr(design.relief, f"{which}_amount"), getattr(design.relief, f"{which}_length")


def optimise(
    design: PlusDesign, shape: str, which: str, *, points: int | None = None, grid: MeshGrid | None = None
) -> ReliefOptimum:
    """Differential-evolution optimum of ``shape`` relief within the ``which`` bounds."""
    if shape not in SHAPES:
        raise ValueError(f"unknown relief shape {shape!r}; allowed: {SHAPES}")
    f = objective(design, grid or design_grid(design, points), shape)
    ab, lb = bounds_of(design, which)
    r = design.relief
    settings = {"seed": r.seed, "popsize": r.popsize, "maxiter": r.maxiter, "tol": r.tol, "updating": "immediate"}
    res = differential_evolution(f, [ab, lb], polish=False, workers=1, **settings)
    amount, length = (float(v) for v in res.x)
    return ReliefOptimum(shape, which, amount, length, float(res.fun), f(np.zeros(2)), int(res.nfev), ab, lb)


def landscape(
    design: PlusDesign, shape: str, amounts: NDArray, lengths: NDArray, *, grid: MeshGrid | None = None
) -> NDArray:
    """Peak-to-peak TE (m) on the grid ``amounts x lengths`` (m), shape (len(amounts), len(lengths))."""
    f = objective(design, grid or design_grid(design), shape)
    return np.array([[f(np.array([a, L])) for L in lengths] for a in amounts])


def landscape_axes(design: PlusDesign, n: int | None = None) -> tuple[NDArray, NDArray]:
    """Axes covering both bound sets: amount 0..max, length 0..max (m)."""
    r, n = design.relief, n or design.relief.landscape_points
    amax, lmax = max(r.paper_amount[1], r.physical_amount[1]), max(r.paper_length[1], r.physical_length[1])
    return np.linspace(0.0, amax, n), np.linspace(0.0, lmax, n)


def load_study(
    design: PlusDesign, torques: tuple[float, ...], shape: str = "linear", points: int = 200
) -> pd.DataFrame:
    """For each sun torque (N m): the optimum within the paper's bounds and within wide bounds (amount from 0
    to the paper's upper bound, length from 0 to the physical one), in display units (N m, N, um, mm, %)."""
    rows = []
    for t in torques:
        d = replace(design, torque=float(t), torque_member="sun")
        wide_bounds = replace(
            d.relief,
            physical_amount=(0.0, d.relief.paper_amount[1]),
            physical_length=(0.0, d.relief.physical_length[1]),
        )
        d_wide = replace(d, relief=wide_bounds)
        grid = design_grid(d, points)
        paper = optimise(d, shape, "paper", grid=grid)
        wide = optimise(d_wide, shape, "physical", grid=grid)
        row = {
            "sun_torque_Nm": float(t),
            "pd_load_N": pd_mesh_load(d),
            "te_ptp_unmodified_um": paper.ptp_unmodified * 1e6,
        }
        for name, o in (("paper", paper), ("wide", wide)):
            row[f"{name}_bounds_amount_um"] = o.amount * 1e6
            row[f"{name}_bounds_length_mm"] = o.length * 1e3
            row[f"{name}_bounds_change_pct"] = 100 * (o.ptp / paper.ptp_unmodified - 1)
        rows.append(row)
    return pd.DataFrame(rows)
