"""Continued branches drawn over a simulated bifurcation diagram (docs/orbits.md, section 4): the sweep's
Poincaré points grey, each branch's phase-0 points solid where stable and dashed where unstable, the typed
bifurcation points marked."""

from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib.figure import Figure

from geardyn.solve.bifurcations import decode, legend

#: Marker and colour of each bifurcation type (the legend text of the one vocabulary).
MARKERS = {
    "period_doubling": ("v", "#d62728"),
    "neimark_sacker": ("D", "#9467bd"),
    "fold": ("o", "#2ca02c"),
    "branch_point": ("X", "#8c564b"),
    "grazing": ("^", "#ff7f0e"),
}
_BRANCH_COLOURS = ["#1f77b4", "#17becf", "#393b79", "#637939", "#e377c2", "#7f7f7f"]


def plot_branches(cube: xr.Dataset | None, branches: xr.Dataset, title: str) -> Figure:
    """One panel per case: sweep dots (if ``cube``), branches, bifurcation points."""
    par = branches.attrs["control_parameter"]
    cases = [str(c) for c in branches["case"].values]
    fig = Figure(figsize=(9, 3.6 * len(cases)))
    axes = fig.subplots(len(cases), 1, squeeze=False)
    types = decode(branches["bifurcation_type"].attrs)
    for k, case in enumerate(cases):
        ax = axes[k, 0]
        if cube is not None and "x_vh" in cube:
            xs = np.asarray(cube[par].values, dtype=float)
            y = cube["x_vh"].isel(case=k, direction=0).values
            ax.plot(np.repeat(xs, y.shape[1]), y.ravel(), ",", color="0.6", alpha=0.6, rasterized=True)
        ids = np.unique(branches["branch"].values[branches["case_index"].values == k])
        for j, b in enumerate(ids):
            m = branches["branch"].values == b
            p = branches["parameter"].values[m]
            stable = branches["stable"].values[m].astype(bool)
            near = np.convolve(~stable, np.ones(3))[1:-1] > 0  # the unstable points and their neighbours
            cyc = branches["cycle_x_vh"].values[m]
            n = int(branches["orbit_period"].values[m][0])
            colour = _BRANCH_COLOURS[j % len(_BRANCH_COLOURS)]
            for c in range(n):
                yc, name = cyc[:, c], f"P{n} branch {int(b)}"
                label = f"{name} stable" if c == 0 else None
                ax.plot(p, np.where(stable, yc, np.nan), "-", color=colour, lw=1.4, label=label)
                label = f"{name} unstable" if c == 0 and (~stable).any() else None
                ax.plot(p, np.where(near, yc, np.nan), "--", color=colour, lw=1.0, label=label)
        bsel = np.isin(branches["bifurcation_branch"].values, ids)
        for code, kind in types.items():
            mk = bsel & (branches["bifurcation_type"].values == code)
            if mk.any():
                marker, colour = MARKERS.get(kind, ("s", "k"))
                at = (branches["bifurcation_parameter"].values[mk], branches["bifurcation_x_vh"].values[mk])
                ax.plot(*at, marker, color=colour, ms=7, mec="k", mew=0.6, ls="none", label=legend(kind))
        ax.set(xlabel=par, ylabel="X_VH / b_c (phase 0)")
        ax.set_title(f"{title} ({case})" if len(cases) > 1 or case != "base" else title, fontsize=10)
        ax.legend(fontsize=7, loc="best", ncol=2)
    fig.tight_layout()
    return fig
