"""Figures of paper 2 (plus planetary set): modal energy bars and mode shapes (Figs. 6-7 style), TE, relief and
the forced response, each a :class:`matplotlib.figure.Figure` (object API, no pyplot); saving is the caller's."""

from __future__ import annotations

from collections.abc import Iterator
from typing import TYPE_CHECKING

import numpy as np
import xarray as xr
from matplotlib.figure import Figure

from geardyn.plots import single_axes
from geardyn.plus.modal import MESH_TYPES, distinct_groups

if TYPE_CHECKING:
    import pandas as pd

    from geardyn.plus.design import PlusDesign

_COMPONENTS = [*(f"revolution{k}" for k in (1, 2, 3)), "p1", "p2", "p3", "d1", "d2", "d3", "sun", "ring", "carrier"]
#: The energy-bar figures (Figs. 6-7 style): variable of modal.nc, its dimension, the bars in the order of the
#: paper's Table 3 or 4, their tick labels and the title.
ENERGY_BARS = {
    "strain": (
        "strain_energy_share",
        "element",
        ["sp1", "sp2", "sp3", "pd1", "pd2", "pd3", "dr1", "dr2", "dr3"],
        ["1\ns-p1", "2\ns-p2", "3\ns-p3", "4\np1-d1", "5\np2-d2", "6\np3-d3", "7\nd1-r", "8\nd2-r", "9\nd3-r"],
        "Modal strain energy per mesh (Table 3 numbering; doubled modes averaged over the pair)",
    ),
    "kinetic": (
        "kinetic_energy_share",
        "component",
        _COMPONENTS,
        [f"{k}\n{name}" for k, name in enumerate(["rev 1", "rev 2", "rev 3", *_COMPONENTS[3:]], start=1)],
        "Modal kinetic energy per component (Table 4 numbering; doubled modes averaged over the pair)",
    ),
}


def orders(ds: xr.Dataset, n_orders: int = 6) -> Iterator[tuple[str, xr.Dataset, np.ndarray, list[list[int]]]]:
    """Per condition of modal.nc: its name, its modes, their frequencies and the mode groups of its first
    ``n_orders`` distinct elastic frequencies."""
    for cond in ds.condition.values:
        sub = ds.sel(condition=cond)
        freq = sub.natural_frequency.values
        yield cond, sub, freq, distinct_groups(freq)[:n_orders]


def modal_energy_figure(ds: xr.Dataset, kind: str, n_orders: int = 6) -> Figure:
    """Figs. 6-7 analogue: share of the modal strain energy in each mesh (``kind`` "strain") or of the kinetic
    energy in each component ("kinetic") for the first ``n_orders`` distinct modes (:data:`ENERGY_BARS`)."""
    var, dim, order, ticks, title = ENERGY_BARS[kind]
    conds = list(ds.condition.values)
    fig = Figure(figsize=(11, 2.9 * len(conds)), constrained_layout=True)
    axes = fig.subplots(len(conds), 1, squeeze=False)[:, 0]
    for ax, (cond, sub, freq, groups) in zip(axes, orders(ds, n_orders), strict=True):
        width = 0.8 / len(groups)
        x = np.arange(len(order))
        for g_i, grp in enumerate(groups):
            # mean over a doubled pair: basis-independent (trace over the eigenspace)
            vals = sub[var].isel(mode=grp).sel({dim: order}).mean("mode").values
            label = f"{g_i + 1}: {freq[grp[0]]:.0f} Hz {'x2' if len(grp) == 2 else ''}".strip()
            ax.bar(x + (g_i - (len(groups) - 1) / 2) * width, vals, width, label=label)
        ax.set_xticks(x, ticks, fontsize=7)
        ax.set_ylabel("share of energy (-)")
        ax.set_title(f"working condition {cond}", fontsize=9)
        ax.legend(fontsize=7, ncol=3, title="order: frequency", title_fontsize=7)
        ax.grid(axis="y", alpha=0.3)
    fig.suptitle(title, fontsize=10)
    return fig


def te_unmodified_figure(te: xr.Dataset) -> Figure:
    """Fig. 4 analogue: TE of the unmodified p-d pair over two mesh periods, with the load per pair."""
    fig = Figure(figsize=(8, 5.5), constrained_layout=True)
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    s2 = np.concatenate([te.mesh_phase.values, te.mesh_phase.values + 1])
    tr = te.transmission_error.sel(case="unmodified").values
    ax1.plot(s2, np.tile(tr, 2), color="k")
    ax1.set_ylabel("TE = E - delta (um)")
    ax1.set_title(
        f"p-d pair, W = {te.attrs['load_N']:.0f} N, eps = {te.attrs['contact_ratio']:.3f}; "
        f"peak-to-peak {np.ptp(tr):.2f} um",
        fontsize=9,
    )
    ax1.grid(alpha=0.3)
    loads = te.load_per_pair.values
    for k in range(loads.shape[0]):
        ax2.plot(s2, np.tile(loads[k], 2), label=f"pair slot {k}")
    ax2.set(xlabel="mesh phase (base pitches)", ylabel="load per pair (N)")
    ax2.legend(fontsize=8)
    ax2.grid(alpha=0.3)
    return fig


def te_relief_figure(te: xr.Dataset, paper=None) -> Figure:
    """TE before and after the optimal reliefs (two mesh periods, mean removed); the title gives the
    paper's before and after values for a design that names a paper."""
    title = "Static TE of the p-d pair before/after optimal tip relief"
    if paper is not None:
        title += f" (paper: {paper.TE_BEFORE_UM:g} -> {paper.TE_AFTER_UM:g} um)"
    fig, ax = single_axes((8, 4.5), title, "mesh phase (base pitches)", "TE - mean (um)", "constrained")
    s2 = np.concatenate([te.mesh_phase.values, te.mesh_phase.values + 1])
    for case in te.case.values:
        tr = te.transmission_error.sel(case=case).values
        tr = tr - tr.mean()
        ax.plot(s2, np.tile(tr, 2), label=f"{case}: ptp {np.ptp(tr):.2f} um", lw=2 if case == "unmodified" else 1.2)
    ax.title.set_fontsize(9)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    return fig


def relief_landscape_figure(land: xr.Dataset, optima: pd.DataFrame, design: PlusDesign) -> Figure:
    """Objective landscape: peak-to-peak TE over (relief amount, relief length), one panel per shape, with the
    design's stated and physical bounds as dashed boxes and the rows of the relief-optima table marked (the
    paper's row, if any, with our TE at its relief)."""
    r = design.relief
    boxes = {
        ("paper" if design.paper else "stated"): (r.paper_amount, r.paper_length),
        "physical": (r.physical_amount, r.physical_length),
    }
    shapes = list(land.shape_.values) if "shape_" in land.dims else list(land["shape"].values)
    fig = Figure(figsize=(5.2 * len(shapes), 4.4), constrained_layout=True)
    axes = fig.subplots(1, len(shapes), squeeze=False)[0]
    a, L = land.amount.values, land.length.values
    vmin, vmax = float(land.te_ptp.min()), float(land.te_ptp.max())
    for ax, sh in zip(axes, shapes, strict=True):
        z = land.te_ptp.sel(shape=sh).values
        cs = ax.contourf(L, a, z, levels=np.linspace(vmin, vmax, 25), cmap="viridis")
        ax.contour(L, a, z, levels=np.arange(np.floor(vmin), np.ceil(vmax) + 0.01, 1.0), colors="w", linewidths=0.5)
        for name, (amount, length) in boxes.items():
            a0, a1, l0, l1 = amount[0] * 1e6, amount[1] * 1e6, length[0] * 1e3, length[1] * 1e3  # um, mm
            colour = "r" if name in ("paper", "stated") else "orange"
            ax.plot([l0, l1, l1, l0, l0], [a0, a0, a1, a1, a0], ls="--", color=colour, lw=1.2, label=f"{name} bounds")
        for o in optima.to_dict("records"):
            at, physical = (o["length_mm"], o["amount_um"]), o["bounds"] == "physical"
            if o["shape"] == sh:
                label = f"{o['bounds']} optimum: {o['te_ptp_after_um']:.2f} um"
                style = {"marker": "*" if physical else "o", "ms": 11, "color": "orange" if physical else "r"}
                ax.plot(*at, mec="k", ls="none", label=label, **style)
            if o["shape"].startswith("linear (paper)") and sh == "linear":
                label = f"paper optimum (ours: {o.get('ours_at_this_relief_um', float('nan')):.2f} um)"
                ax.plot(*at, marker="X", ms=10, mec="k", color="w", ls="none", label=label)
        ax.set(xlabel="relief length along the path of contact (mm)", ylabel="relief amount (um)")
        ax.set_title(f"{sh} tip relief", fontsize=9)
        ax.legend(fontsize=7, loc="upper right")
        fig.colorbar(cs, ax=ax, label="peak-to-peak TE (um)")
    return fig


COORD_TICKS = ["s", "r", "c", "p1", "p2", "p3", "d1", "d2", "d3", "x_s", "y_s"]


def mode_shape_figure(ds: xr.Dataset, n_orders: int = 6) -> Figure:
    """Fig. 7-style mode shapes: displacement amplitude of each coordinate (rotations times their lever
    arm: base radius, carrier a_sp; planets relative to the carrier), normalised to a largest |value| of 1.
    For a doubled frequency the member of the pair with y_s = 0 is drawn."""
    conds = list(ds.condition.values)
    fig = Figure(figsize=(2.3 * n_orders, 2.2 * len(conds)), constrained_layout=True)
    axes = fig.subplots(len(conds), n_orders, squeeze=False, sharey=True)
    arm = ds.lever_arm.values
    x = np.arange(len(COORD_TICKS))
    colours = ["tab:blue"] * 3 + ["tab:orange"] * 3 + ["tab:green"] * 3 + ["tab:red"] * 2
    for r, (cond, sub, freq, groups) in enumerate(orders(ds, n_orders)):
        for c, grp in enumerate(groups):
            ax = axes[r, c]
            shape = sub.mode_shape.isel(mode=grp[0]).values * arm
            shape = shape / np.max(np.abs(shape))
            ax.bar(x, shape, color=colours)
            ax.axhline(0, color="k", lw=0.5)
            ax.set_xticks(x, COORD_TICKS, fontsize=6, rotation=90)
            kind = sub.mode_type.values[grp[0]]
            ax.set_title(f"{cond}-{c + 1}: {freq[grp[0]]:.0f} Hz\n{kind}{' x2' if len(grp) == 2 else ''}", fontsize=8)
            ax.set_ylim(-1.1, 1.1)
            ax.tick_params(axis="y", labelsize=7)
        axes[r, 0].set_ylabel("normalised\ndisplacement (-)", fontsize=8)
    fig.suptitle("Mode shapes (displacement along the lever arms; planets relative to the carrier)", fontsize=10)
    return fig


MESH_COLOURS = {"sp": "tab:blue", "pd": "tab:red", "dr": "tab:green"}


def forced_response_figure(ds: xr.Dataset, planet: int = 1, max_harmonic_marks: int = 3) -> Figure:
    """RMS fluctuating mesh force (top) and dynamic factor (bottom) of one planet's three meshes against input speed,
    unrelieved (solid) and best relief (dashed); grey: natural frequencies / harmonic h = 1, 2, 3."""
    fig = Figure(figsize=(9, 6.5), constrained_layout=True)
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    speed = ds.speed.values
    best = ds.attrs.get("best_relief_case") or None
    cases = [("unmodified", "-")] + ([(best, "--")] if best else [])
    for kind in MESH_TYPES:
        mesh = f"{kind}{planet}"
        for case, ls in cases:
            lab = f"{mesh}, {case} (TE ptp {float(ds.te_ptp.sel(case=case)):.2f} um)"
            ax1.plot(speed, ds.rms_force.sel(case=case, mesh=mesh), ls=ls, color=MESH_COLOURS[kind], lw=1.2, label=lab)
            ax2.plot(speed, ds.dynamic_factor.sel(case=case, mesh=mesh), ls=ls, color=MESH_COLOURS[kind], lw=1.2)
    styles = ["-", "--", ":", "-."]
    top = speed[-1]
    for hi, h in enumerate(ds.harmonic.values[:max_harmonic_marks]):
        for n in np.unique(np.round(ds.resonance_speed.sel(harmonic=h).values, 6)):
            if n <= top:
                for ax in (ax1, ax2):
                    ax.axvline(n, color="0.5", lw=0.7, ls=styles[hi % len(styles)], alpha=0.7)
    for f in np.unique(np.round(ds.natural_frequency.values, 3)):
        n = f / float(ds.mesh_frequency[0] / ds.speed[0])
        if n <= top:
            text = {"rotation": 90, "fontsize": 6, "va": "top", "ha": "right", "transform": ax1.get_xaxis_transform()}
            ax1.text(n, 1.0, f"{f:.0f} Hz", **text)
    ax1.set(yscale="log", ylabel="RMS fluctuating mesh force (N)")
    ax1.legend(fontsize=7, loc="lower right")
    ax1.grid(alpha=0.3, which="both")
    ax2.axhline(1.0, color="k", lw=0.6)
    ax2.set(ylabel="dynamic factor F_max / F_static (-)", xlabel="input (sun) speed (rpm)")
    ax2.grid(alpha=0.3)
    ax1.set_title(
        f"Forced response to the static TE, condition {ds.attrs['condition']}, modal damping "
        f"zeta = {ds.attrs['damping_ratio']:g}, static mesh force {ds.attrs['static_force_N']:.0f} N; "
        "grey: natural frequencies / h (h = 1 solid, 2 dashed, 3 dotted)",
        fontsize=8,
    )
    return fig
