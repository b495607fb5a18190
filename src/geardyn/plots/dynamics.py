"""Figures 7-12 of paper 1: bifurcation diagrams and phase / Poincaré / spectrum panels."""

from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib.colors import BoundaryNorm, ListedColormap, Normalize, TwoSlopeNorm, to_rgb
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from geardyn.label import vocabulary
from geardyn.label.vocabulary import LABELS
from geardyn.plots.curves import draw_curves, say_on_face
from geardyn.plots.response import draw_map_layers
from geardyn.runs.cube import labels_of_cube

_LABELS = {"x_vh": "X_VH / b_c", "v_vh": "dX_VH/dtau / b_c", "x_dh": "X_DH / b_c", "x_vl": "X_VL / b_c"}


def label_colour(code: int) -> str:
    """Colour of a motion label: periods in blues/greens/purples, QP orange, chaos red, others grey/black."""
    fixed = {
        LABELS["chaotic"]: "#d62728",
        LABELS["quasi_periodic"]: "#ff7f0e",
        LABELS["diverged"]: "#000000",
        LABELS["undetermined"]: "#9e9e9e",
        LABELS["not_periodic"]: "#8c564b",
        LABELS["long_period"]: "#bcbd22",
        LABELS["transient"]: "#5c5c5c",
    }
    periods = "#1f77b4 #2ca02c #17becf #9467bd #bcbd22 #e377c2 #00441b #393b79 #637939 #8c6d31 #843c39 #7b4173".split()
    code = int(code)
    return fixed.get(code, periods[(code - 1) % len(periods)] if code >= 1 else "#9e9e9e")


def plot_bifurcation(cube: xr.Dataset, title: str, state: str = "x_vh") -> Figure:
    """Poincaré points of ``state`` against the control parameter, coloured by the motion label, with
    the largest Lyapunov exponent (and its uncertainty) in a panel below; one pair per case and direction."""
    par = cube.attrs["control_parameter"]
    cases, directions = list(cube["case"].values), list(cube["direction"].values)
    n = len(cases) * len(directions)
    labels = labels_of_cube(cube)
    has_lyap = "lyapunov" in cube
    rows = 2 * n if has_lyap else n
    ratios = [3, 1.3] * n if has_lyap else [1] * n
    fig = Figure(figsize=(7.5, (3.4 if has_lyap else 2.6) * n + 0.9))
    axes = fig.subplots(rows, 1, squeeze=False, sharex=True, gridspec_kw={"height_ratios": ratios})
    for i, case in enumerate(cases):
        for j, direction in enumerate(directions):
            k = i * len(directions) + j
            ax = axes[2 * k if has_lyap else k, 0]
            sel = cube[state].sel(case=case, direction=direction)
            xv = sel[par].values
            lab = labels[i, j]
            for code in np.unique(lab):
                m = lab == code
                x = np.broadcast_to(xv[m][:, None], sel.values[m].shape)
                ax.plot(x.ravel(), sel.values[m].ravel(), ",", color=label_colour(code), alpha=0.7, rasterized=True)
            handles = [
                Line2D([], [], ls="", marker="s", color=label_colour(c), label=vocabulary.short_name(c))
                for c in np.unique(lab)
            ]
            ax.legend(handles=handles, loc="upper right", fontsize=6, ncol=min(6, len(handles)), framealpha=0.7)
            div = lab == LABELS["diverged"]
            if div.any():
                ax.plot(xv[div], np.zeros(div.sum()), "|", color="k")
            label = f"({chr(97 + i)}) {case}" if len(cases) > 1 else case
            if direction != "none":
                label += f", sweep {direction}"
            ax.set_title(label, fontsize=9, loc="left")
            ax.set_ylabel(_LABELS.get(state, state))
            if has_lyap:
                axl = axes[2 * k + 1, 0]
                lam = cube["lyapunov"].sel(case=case, direction=direction).values
                sig = cube["lyapunov_sigma"].sel(case=case, direction=direction).values
                axl.fill_between(xv, lam - 2 * sig, lam + 2 * sig, color="0.8", lw=0)
                axl.scatter(xv, lam, s=2, c=[label_colour(c) for c in lab], rasterized=True)
                axl.axhline(0.0, color="k", lw=0.5)
                axl.set_ylabel("lambda_max", fontsize=8)
    axes[-1, 0].set_xlabel(cube[par].attrs.get("long_name", par))
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_points(ds: xr.Dataset, title: str, fmax: float = 3.0) -> Figure:
    """Per case: phase trajectory (X_VH, V_VH), Poincaré map, amplitude spectrum (f / f_mesh)."""
    cases = list(ds["case"].values)
    fig = Figure(figsize=(10.0, 2.6 * len(cases) + 0.6))
    axes = fig.subplots(len(cases), 3, squeeze=False)
    for i, case in enumerate(cases):
        d = ds.sel(case=case)
        ax_t, ax_p, ax_s = axes[i]
        if int(d["label"]) == LABELS["diverged"]:
            ax_t.text(0.5, 0.5, "diverged", ha="center", transform=ax_t.transAxes, color="r")
        ax_t.plot(d["x_vh"], d["v_vh"], lw=0.4, color="k")
        ax_t.set(xlabel=_LABELS["x_vh"], ylabel=_LABELS["v_vh"])
        ax_t.set_title(f"({chr(97 + i)}) {case}: trajectory", fontsize=9, loc="left")
        # the map on the trajectory's axes: a period-1 point is one dot, not a cloud of round-off
        ax_p.plot(d["x_vh"], d["v_vh"], lw=0.3, color="0.85")
        ax_p.plot(d["poincare_x_vh"], d["poincare_v_vh"], ".", ms=3, color="k")
        ax_p.set(xlim=ax_t.get_xlim(), ylim=ax_t.get_ylim(), xlabel=_LABELS["x_vh"])
        ax_p.set_title("Poincare map", fontsize=9, loc="left")
        f = d["frequency"].values
        keep = (f > 0) & (f <= fmax)
        ax_s.plot(f[keep], d["amplitude"].values[keep], lw=0.6, color="k")
        ax_s.set(xlabel="f / f_mesh", ylabel="amplitude")
        ax_s.set_title("spectrum", fontsize=9, loc="left")
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def label_image(ds: xr.Dataset) -> tuple[np.ndarray, tuple[float, float, float, float]]:
    """The label image of a map as RGB (the colours of :func:`label_colour`) and its extent, for ``imshow``."""
    lab = ds["label"].values
    codes = sorted(int(c) for c in np.unique(lab))
    rgb = np.array([to_rgb(label_colour(c)) for c in codes])[np.searchsorted(codes, lab)]
    x, y = ds["x"].values, ds["y"].values
    return rgb, (float(x[0]), float(x[-1]), float(y[0]), float(y[-1]))


def plot_map(ds: xr.Dataset, title: str, cuts_x=(), cuts_y=(), curves: xr.Dataset | None = None) -> Figure:
    """Regime map: labels (hatched where the fixed start ends elsewhere, ``coexisting``) and largest exponent, the
    1-D cuts dashed; with response measures the K_v and impact-class layers below (:func:`draw_map_layers`);
    ``curves``: a curves file drawn over the label and impact-class panels."""
    lab = ds["label"].values
    codes = sorted(int(c) for c in np.unique(lab))
    cmap = ListedColormap([label_colour(c) for c in codes])
    index = np.searchsorted(codes, lab)
    norm: Normalize = BoundaryNorm(np.arange(len(codes) + 1) - 0.5, len(codes))
    x, y = ds["x"].values, ds["y"].values
    layers = "dynamic_factor" in ds and "impact_class" in ds
    if layers:
        fig = Figure(figsize=(12.0, 9.5))
        (ax, axl), (ax_kv, ax_impact) = fig.subplots(2, 2)
        draw_map_layers(ax_kv, ax_impact, ds)
    else:
        fig = Figure(figsize=(12.0, 5.0))
        ax, axl = fig.subplots(1, 2)
    im = ax.pcolormesh(x, y, index, cmap=cmap, norm=norm, shading="nearest", rasterized=True)
    cb = fig.colorbar(im, ax=ax, ticks=np.arange(len(codes)))
    cb.ax.set_yticklabels([vocabulary.short_name(c) for c in codes], fontsize=7)
    if "coexisting" in ds:
        both = (ds["coexisting"].values == 1).astype(float)
        if both.any():
            ax.contourf(x, y, both, levels=[0.5, 1.5], colors="none", hatches=["////"])
            ax.plot([], [], ls="", marker="s", mfc="none", mec="k", label="coexisting attractors (hatched)")
            ax.legend(loc="upper right", fontsize=7)
    lam = ds["lyapunov"].values
    finite = np.isfinite(lam)
    vmax = max(float(np.nanmax(np.abs(lam))) if finite.any() else 1.0, 1e-6)
    norm = TwoSlopeNorm(0.0, -vmax, vmax)
    iml = axl.pcolormesh(
        x, y, np.where(finite, lam, np.nan), cmap="coolwarm", norm=norm, shading="nearest", rasterized=True
    )
    fig.colorbar(iml, ax=axl, label="lambda_max (per unit tau)")
    for a in (ax, axl, ax_kv, ax_impact) if layers else (ax, axl):
        for cx in cuts_x:
            a.axvline(cx, color="k", ls="--", lw=0.8)
        for cy in cuts_y:
            a.axhline(cy, color="k", ls="--", lw=0.8)
        a.set(xlabel=ds["x"].attrs.get("long_name", "x"), ylabel=ds["y"].attrs.get("long_name", "y"))
    if curves is not None:
        for a in (ax, ax_impact) if layers else (ax,):
            draw_curves(a, curves, legend=a is ax, lw=1.1, loc="lower right")
            a.set(xlim=(x[0], x[-1]), ylim=(y[0], y[-1]))
    if len(codes) == 1:  # one flat colour: say so on the figure's face
        say_on_face(ax, f"{vocabulary.short_name(codes[0])} everywhere in this plane")
    ax.set_title("motion label" + (" and regime boundaries" if curves is not None else ""), fontsize=9, loc="left")
    axl.set_title("largest exponent (Floquet or tangent)", fontsize=9, loc="left")
    fig.suptitle(title)
    fig.tight_layout()
    return fig
