"""Figures of the response measures (``docs/response.md``): the frequency response (RMS DTE and K_v against
the mesh frequency, up and down, jumps, hysteresis, impact classes, natural frequencies) and the K_v and
impact-class layers of a regime map."""

from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib.axes import Axes
from matplotlib.colors import BoundaryNorm, ListedColormap, LogNorm
from matplotlib.figure import Figure

from geardyn.solve.response import IMPACT_CLASSES

#: Shading of the impact classes (light, so the curves stay readable).
IMPACT_COLOURS = {"no_impact": "#ffffff", "single_sided": "#fde0a6", "double_sided": "#f4a6a6"}
IMPACT_LABELS = {"no_impact": "no impact", "single_sided": "single-sided impact", "double_sided": "double-sided impact"}
DIRECTION_STYLE = {"up": ("tab:blue", "-", "^"), "down": ("tab:red", "--", "v")}
#: Hatching of the frequencies with hysteresis (the up and down sweeps on different attractors).
HYSTERESIS_STYLE = {"facecolor": "none", "edgecolor": "0.3", "hatch": "////", "lw": 0.0}


def frequency_response_figure(ds: xr.Dataset, title: str) -> Figure:
    """RMS DTE (top) and dynamic factor K_v (bottom) against w, up (solid) and down (dashed): jumps marked,
    hysteresis hatched, impact classes shaded (lower half up, upper half down), natural frequencies and their
    halves and thirds as grey lines (docs/response.md, "Frequency response")."""
    fig = Figure(figsize=(9.0, 6.5), constrained_layout=True)
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    w = ds.w.values
    edges = np.concatenate([[w[0]], 0.5 * (w[1:] + w[:-1]), [w[-1]]])  # each frequency's span, to the mid-points
    hysteresis = ds["hysteresis"].values.astype(bool) if "hysteresis" in ds else np.zeros(w.size, bool)
    on = np.concatenate([[False], hysteresis, [False]])  # its runs of neighbours, each hatched as one span
    runs = list(zip(np.flatnonzero(on[1:] & ~on[:-1]), np.flatnonzero(~on[1:] & on[:-1]), strict=True))
    shaded = [(name, code) for name, code in IMPACT_CLASSES.items() if name != "no_impact"]
    for ax, var in ((ax1, "dte_rms"), (ax2, "dynamic_factor")):
        for d, direction in enumerate(ds.direction.values):
            band = (0.0, 0.5) if direction == "up" else (0.5, 1.0)
            for name, code in shaded:
                for j in np.flatnonzero(ds.impact_class.values[d] == code):
                    ax.axvspan(edges[j], edges[j + 1], *band, color=IMPACT_COLOURS[name], lw=0)
        for a, b in runs:
            ax.axvspan(edges[a], edges[b], **HYSTERESIS_STYLE)
        for d, direction in enumerate(ds.direction.values):
            colour, ls, marker = DIRECTION_STYLE[str(direction)]
            y = ds[var].values[d]
            ax.plot(w, y, color=colour, ls=ls, lw=1.1, label=f"sweep {direction}")
            jumps = ds.jump.values[d].astype(bool)
            ax.plot(w[jumps], y[jumps], ls="", marker=marker, color=colour, ms=6, mfc="none")
        for f in ds.natural_frequency.values:
            for h, style in ((1, "-"), (2, "--"), (3, ":")):
                if w[0] <= f / h <= w[-1]:
                    ax.axvline(f / h, color="0.45", lw=0.7, ls=style)
        ax.grid(alpha=0.3)
    for name in ("single_sided", "double_sided"):
        ax1.fill_between([], [], color=IMPACT_COLOURS[name], label=IMPACT_LABELS[name])
    ax1.plot([], [], color="0.45", lw=0.7, label="natural frequency w_i / h (h = 1, 2, 3)")
    ax1.fill_between([], [], label="hysteresis: up and down on different attractors", **HYSTERESIS_STYLE)
    ax1.plot([], [], ls="", marker="^", color="k", mfc="none", label="jump (triangle: direction of travel)")
    ax1.set_ylabel("RMS DTE  X_VH / b_c  (b_c = 1 um)")
    ax1.legend(fontsize=7, loc="upper left")
    ax2.axhline(1.0, color="k", lw=0.6)
    ax2.set(ylabel="dynamic factor K_v = F_max / F_s (-)", xlabel=ds.w.attrs.get("long_name", "w"))
    ax1.set_title(
        f"{title}\nshading: impact class (lower half: up sweep, upper half: down sweep); hatched: hysteresis",
        fontsize=9,
        loc="left",
    )
    return fig


def draw_map_layers(ax_kv: Axes, ax_impact: Axes, ds: xr.Dataset) -> None:
    """The dynamic factor K_v (log colour scale) and the impact class of a regime map on two axes."""
    x, y = ds["x"].values, ds["y"].values
    kv = ds["dynamic_factor"].values
    ok = np.isfinite(kv) & (kv > 0)
    lo, hi = (float(np.min(kv[ok])), float(np.max(kv[ok]))) if ok.any() else (1.0, 10.0)
    im = ax_kv.pcolormesh(
        x, y, np.where(ok, kv, np.nan), cmap="viridis", norm=LogNorm(max(lo, 1e-3), max(hi, lo * 1.01)),
        shading="nearest", rasterized=True,
    )  # fmt: skip
    ax_kv.figure.colorbar(im, ax=ax_kv, label="K_v (-)")
    names = list(IMPACT_CLASSES)
    cmap = ListedColormap(["#9e9e9e"] + [IMPACT_COLOURS[n] if n != "no_impact" else "#d9ecf7" for n in names])
    norm = BoundaryNorm(np.arange(-1, len(names) + 1) - 0.5, len(names) + 1)
    imc = ax_impact.pcolormesh(x, y, ds["impact_class"].values, cmap=cmap, norm=norm, shading="nearest")
    cb = ax_impact.figure.colorbar(imc, ax=ax_impact, ticks=np.arange(-1, len(names)))
    cb.ax.set_yticklabels(["not computed"] + [IMPACT_LABELS[n] for n in names], fontsize=7)
    ax_kv.set_title("dynamic factor K_v", fontsize=9, loc="left")
    ax_impact.set_title("impact class", fontsize=9, loc="left")
