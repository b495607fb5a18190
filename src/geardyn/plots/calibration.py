"""Figures of the calibration search: tornado chart of the best candidate and a 2-D score map."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import xarray as xr
from matplotlib.figure import Figure

from geardyn.plots import single_axes


def plot_tornado(oat: xr.Dataset, paper_leave_p1: float) -> Figure:
    """Score change and transition positions when each unknown moves by +-10 % and +-50 %; the paper's
    first x1 not P1 (``paper_leave_p1``) marked."""
    fig = Figure(figsize=(9.0, 4.8))
    ax1, ax2 = fig.subplots(1, 2, sharey=True)
    names = [str(n) for n in oat["unknown"].values]
    y = np.arange(len(names))
    base = float(oat.attrs["base_score"])
    steps = oat["step"].values
    for st, colour, h in ((0.5, "tab:red", 0.38), (0.1, "tab:blue", 0.22)):
        for sign, alpha in ((-1, 0.5), (1, 1.0)):
            j = np.argmin(np.abs(steps - sign * st))
            if abs(steps[j] - sign * st) > 1e-12:
                continue
            d = oat["score"].values[:, j] - base
            ax1.barh(y, d, height=h, color=colour, alpha=alpha, label=f"{'+' if sign > 0 else '-'}{100 * st:.0f} %")
            ax2.scatter(
                oat["leave_p1"].values[:, j], y, color=colour, alpha=alpha, marker="o" if sign > 0 else "s", s=18
            )
    ax1.axvline(0.0, color="k", lw=0.8)
    ax1.set_yticks(y, names)
    ax1.set_xlabel("score change from the best")
    ax1.legend(fontsize=7, loc="lower left")
    ax2.axvline(float(oat.attrs["base_leave_p1"]), color="k", lw=0.8, label="best")
    ax2.axvline(paper_leave_p1, color="tab:green", ls="--", lw=1.0, label=f"paper {paper_leave_p1:g}")
    ax2.set_xlabel("first x1 not P1 (inf: P1 throughout, not drawn)")
    ax2.legend(fontsize=7)
    fig.suptitle("Calibration: one-at-a-time sensitivity of the best candidate")
    fig.tight_layout()
    return fig


def plot_score_map(mp: xr.Dataset) -> Figure:
    """Score over the two unknowns that matter most, the best candidate marked."""
    x, y = mp.attrs["x"], mp.attrs["y"]
    xlabel, ylabel = f"{x} ({mp[x].attrs.get('units', '')})", f"{y} ({mp[y].attrs.get('units', '')})"
    fig, ax = single_axes((5.6, 4.6), "Calibration score map", xlabel, ylabel)
    pc = ax.pcolormesh(mp[x].values, mp[y].values, mp["score"].values, shading="nearest", cmap="viridis")
    fig.colorbar(pc, ax=ax, label="score (claims that agree + partial)")
    ax.plot([mp.attrs["best_x"]], [mp.attrs["best_y"]], "r*", ms=12, label="best")
    ax.legend(fontsize=7)
    fig.tight_layout()
    return fig


def caption_tornado(oat: xr.Dataset, fixed: Mapping[str, float], paper_leave_p1: float) -> str:
    """The caption of :func:`plot_tornado`; ``fixed``: the values held along the paper's main line."""
    at = ", ".join(f"{k} = {v:g}" for k, v in fixed.items())
    return (
        "One-at-a-time sensitivity of the best calibration candidate: left, the change of the score (claims "
        "that agree + 0.99 x partial credit, docs/calibration.md) when each searched unknown moves by +-10 % "
        "(blue) and +-50 % (red; lighter bars: downward moves; a phase moves by that fraction of 2 pi); "
        f"right, where the motion first leaves P1 along x1 at {at} (paper: {paper_leave_p1:g}). "
        f"Best score {float(oat.attrs['base_score']):.3f}."
    )


def caption_map(mp: xr.Dataset) -> str:
    return (
        f"Score of the calibration over {mp.attrs['x']} and {mp.attrs['y']} (each +-50 % around the best, "
        "the other unknowns at the best), the two unknowns whose moves change the score most in the "
        f"tornado chart. Highest score on the map {float(mp['score'].max()):.3f}; star: the best candidate."
    )
