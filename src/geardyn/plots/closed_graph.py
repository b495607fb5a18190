"""Paper 1, Fig. 3: the closed graph drawn from :func:`geardyn.khv.closed_graph.closed_graph`, and its caption."""

from __future__ import annotations

from types import ModuleType

import numpy as np
import xarray as xr
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from geardyn.khv.closed_graph import CUTTER_DEPENDENT, LINES, line4_crossings
from geardyn.plots import paper_says, single_axes

_LINE_COLOURS = {0: "0.5", 1: "tab:blue", 2: "tab:orange", 3: "tab:green", 4: "black"}


def plot_closed_graph(ds: xr.Dataset) -> Figure:
    """Closed graph: feasible region shaded, each constraint's zero contour labelled (drawn where G_s >= 0),
    line 4 (G_s = 0) bold, the paper's M and N and our points marked (a Figure built without pyplot)."""
    title = f"Closed graph, z1 = {ds.attrs['z1']}, z2 = {ds.attrs['z2']}, m = {ds.attrs['module_mm']} mm"
    xlabel, ylabel = "planet shift x1", "annulus shift x2 (Chinese convention)"
    fig, ax = single_axes((7.0, 5.6), title, xlabel, ylabel, "constrained")
    x1, x2 = ds["x1"].values, ds["x2"].values
    ax.contourf(x1, x2, ds["feasible_cutter_free"].values, levels=[0.5, 1.5], colors=["#dbe9f6"])
    ax.contourf(x1, x2, ds["feasible"].values, levels=[0.5, 1.5], colors=["#9ecae1"])
    handles: list[Line2D | Patch] = [
        Patch(color="#9ecae1", label="feasible (all constraints)"),
        Patch(color="#dbe9f6", label="feasible without cutter-dependent (*)"),
    ]
    for name, (_, short) in LINES.items():
        if name not in ds or name == "overlap_interference":
            continue
        # Only where the teeth do not overlap (G_s >= 0): below line 4 the other margins describe
        # an impossible mesh and their contours would only clutter the graph.
        values = np.where(ds["overlap_interference"].values >= 0.0, ds[name].values, np.nan)
        if not (np.nanmin(values) < 0.0 < np.nanmax(values)):
            continue
        line = int(ds[name].attrs.get("closed_graph_line", 0))
        style = "--" if name in CUTTER_DEPENDENT else "-"
        cs = ax.contour(x1, x2, values, levels=[0.0], colors=[_LINE_COLOURS[line]], linewidths=1.1, linestyles=style)
        ax.clabel(cs, fmt={0.0: f"{line}: {short}"}, fontsize=7, inline=True)
    ax.plot(x1, ds["x2_line4"].values, color="black", lw=2.0)
    l4 = ds["feasible_line4"].values.astype(bool)
    ax.plot(np.where(l4, x1, np.nan), np.where(l4, ds["x2_line4"].values, np.nan), color="red", lw=3.0)
    handles += [
        Line2D([], [], color="black", lw=2.0, label="line 4: G_s = 0"),
        Line2D([], [], color="red", lw=3.0, label="admissible part of line 4 (computed)"),
    ]
    handles += [Line2D([], [], color=_LINE_COLOURS[line], label=f"line {line}") for line in (1, 2, 3)]
    if "point" in ds.dims:
        ax.plot(ds["paper_x1"].values, ds["paper_x2"].values, "o", mfc="none", mec="crimson", ms=9)
        ax.plot(ds["paper_x1"].values, ds["computed_x2"].values, "x", color="k", ms=7)
        for p in ds["point"].values:
            at = (float(ds["paper_x1"].sel(point=p)), float(ds["paper_x2"].sel(point=p)))
            ax.annotate(str(p), at, xytext=(6, -12), textcoords="offset points", color="crimson")
        printed = "printed " + ", ".join(str(p) for p in ds["point"].values)
        handles += [
            Line2D([], [], ls="", marker="o", mfc="none", mec="crimson", label=printed),
            Line2D([], [], ls="", marker="x", color="k", label="computed (G_s = 0)"),
        ]
    ax.set(xlim=(x1.min(), x1.max()), ylim=(x2.min(), x2.max()))
    ax.legend(handles=handles, fontsize=7, loc="upper left")
    return fig


def caption_closed_graph(
    ds: xr.Dataset, paper: ModuleType | None = None, segment: tuple[float, float] | None = None
) -> str:
    """Caption: what the figure shows and, for a design that names a paper, how it compares, with numbers;
    ``segment``: the design's configured admissible segment (x1_min, x1_max)."""
    a = ds.attrs
    lo, hi = a["line4_feasible_x1_min"], a["line4_feasible_x1_max"]
    found = (
        f"the admissible part of line 4 on the grid is x1 in [{lo:.3f}, {hi:.3f}]"
        if np.isfinite(lo)
        else "no grid point of line 4 is admissible"
    )
    if segment is not None:
        found += f" (design segment [{segment[0]:.3f}, {segment[1]:.3f}])"
    trim = line4_crossings(ds, "trimming_interference_annulus")
    root = line4_crossings(ds, "root_interference_annulus")
    eps1 = line4_crossings(ds, "contact_ratio_margin")
    text = (
        f"Closed graph of the internal pair z1 = {a['z1']}, z2 = {a['z2']}, m = {a['module_mm']} mm, ha* = "
        f"{a['addendum_coefficient']}, alpha = {a['pressure_angle_deg']} deg, computed from the geometry (every "
        "constraint a signed margin, zero contours drawn; dashed = depends on the shaper cutter). Line 1: eps = 1; "
        "line 2: involute and root transition-curve interference; line 3: tip thickness >= "
        f"{a['min_tip_thickness_modules']} m and shaper-cutter trimming; line 4: tooth-profile overlap interference "
        f"G_s = 0. With the {a['cutter_source']} cutter z0 = {a['cutter_teeth']}, x0 = {a['cutter_shift']:.4f}, ha0* = "
        f"{a['cutter_addendum']} {found}; on line 4 the trimming limit is at x1 = "
        f"{', '.join(f'{v:.3f}' for v in trim) or 'none'}, the annulus root interference limit at x1 = "
        f"{', '.join(f'{v:.3f}' for v in root) or 'none'} and eps = 1 at x1 = "
        f"{', '.join(f'{v:.3f}' for v in eps1) or 'none (outside the grid)'}."
    )
    if paper is None or "point" not in ds.dims:
        return text
    pts = []
    for p in ds["point"].values:
        s = ds.sel(point=p)
        pts.append(
            f"{p}: paper ({float(s.paper_x1):.3f}, {float(s.paper_x2):.3f}), computed x2 = "
            f"{float(s.computed_x2):.5f} (residual {float(s.residual_x2):+.5f}), eps = "
            f"{float(s.contact_ratio_point):.4f}, a' = {float(s.working_pressure_angle_point):.3f} deg"
        )
    worst = float(np.max(np.abs(ds["residual_x2"].values)))
    verdict = "within" if worst <= paper.POINT_TOLERANCE else "NOT within"
    return (
        paper_says(paper, "closed_graph", text=text)
        + " "
        + "; ".join(pts)
        + ". "
        + f"The printed points are reproduced {verdict} {paper.POINT_TOLERANCE:g} in x2 (largest |residual| "
        f"{worst:.5f}), the precision the paper prints. The paper gives no cutter."
    )
