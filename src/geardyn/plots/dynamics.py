"""Figures 7-12 of paper 1: bifurcation diagrams and phase / Poincaré / spectrum panels."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import xarray as xr  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

_LABELS = {"x_vh": "X_VH / b_c", "v_vh": "dX_VH/dtau / b_c", "x_dh": "X_DH / b_c", "x_vl": "X_VL / b_c"}


def plot_bifurcation(cube: xr.Dataset, title: str, state: str = "x_vh") -> Figure:
    """Poincaré points of ``state`` against the control parameter; one panel per case and direction."""
    par = cube.attrs["control_parameter"]
    cases = list(cube["case"].values)
    directions = list(cube["direction"].values)
    n = len(cases) * len(directions)
    fig, axes = plt.subplots(n, 1, figsize=(7.0, 2.6 * n + 0.6), squeeze=False, sharex=True)
    for i, case in enumerate(cases):
        for j, direction in enumerate(directions):
            ax = axes[i * len(directions) + j, 0]
            sel = cube[state].sel(case=case, direction=direction)
            x = np.broadcast_to(sel[par].values[:, None], sel.shape)
            ax.plot(x.ravel(), sel.values.ravel(), ",", color="k", alpha=0.6, rasterized=True)
            div = cube["diverged"].sel(case=case, direction=direction).values == 1
            if div.any():
                ax.plot(sel[par].values[div], np.zeros(div.sum()), "|", color="r", label="diverged")
                ax.legend(loc="upper right", fontsize=7)
            label = f"({chr(97 + i)}) {case}" if len(cases) > 1 else case
            if direction != "none":
                label += f", sweep {direction}"
            ax.set_title(label, fontsize=9, loc="left")
            ax.set_ylabel(_LABELS.get(state, state))
    axes[-1, 0].set_xlabel(cube[par].attrs.get("long_name", par))
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_points(ds: xr.Dataset, title: str, fmax: float = 3.0) -> Figure:
    """Per case: phase trajectory (X_VH, V_VH), Poincaré map, amplitude spectrum (f / f_mesh)."""
    cases = list(ds["case"].values)
    fig, axes = plt.subplots(len(cases), 3, figsize=(10.0, 2.6 * len(cases) + 0.6), squeeze=False)
    for i, case in enumerate(cases):
        d = ds.sel(case=case)
        ax_t, ax_p, ax_s = axes[i]
        if int(d["diverged"]) == 1:
            ax_t.text(0.5, 0.5, "diverged", ha="center", transform=ax_t.transAxes, color="r")
        ax_t.plot(d["x_vh"], d["v_vh"], lw=0.4, color="k")
        ax_t.set_xlabel(_LABELS["x_vh"])
        ax_t.set_ylabel(_LABELS["v_vh"])
        ax_t.set_title(f"({chr(97 + i)}) {case}: trajectory", fontsize=9, loc="left")
        # the map on the trajectory's axes: a period-1 point is one dot, not a cloud of round-off
        ax_p.plot(d["x_vh"], d["v_vh"], lw=0.3, color="0.85")
        ax_p.plot(d["poincare_x_vh"], d["poincare_v_vh"], ".", ms=3, color="k")
        ax_p.set_xlim(ax_t.get_xlim())
        ax_p.set_ylim(ax_t.get_ylim())
        ax_p.set_xlabel(_LABELS["x_vh"])
        ax_p.set_title("Poincare map", fontsize=9, loc="left")
        f = d["frequency"].values
        keep = (f > 0) & (f <= fmax)
        ax_s.plot(f[keep], d["amplitude"].values[keep], lw=0.6, color="k")
        ax_s.set_xlabel("f / f_mesh")
        ax_s.set_ylabel("amplitude")
        ax_s.set_title("spectrum", fontsize=9, loc="left")
    fig.suptitle(title)
    fig.tight_layout()
    return fig
