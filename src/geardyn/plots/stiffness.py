"""Figures 4-6 of paper 1: single-tooth stiffness, k(t) for three x1 values, backlash function."""

from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib.figure import Figure

from geardyn.gears.backlash import backlash
from geardyn.gears.stiffness import single_tooth_stiffness
from geardyn.plots import paper_says, single_axes

_STYLES = ("-.", ":", "--", "-")


def plot_single_tooth(props) -> Figure:  # props: geardyn.khv.design.MeshProperties
    """Fig. 4: stiffness of one tooth pair (the parabola at ``props``) from engaging-in point A through pitch C
    to exit B."""
    xlabel = "time since engagement (mesh periods)"
    fig, ax = single_axes((5.5, 3.5), "Fig. 4  single tooth-pair stiffness", xlabel, "single-pair stiffness (N/um)")
    eps, k_prime = float(props.contact_ratio), float(props.k_prime) / 1e6
    s = np.linspace(0.0, props.contact_ratio, 401)
    ax.plot(s, single_tooth_stiffness(s, props.contact_ratio, props.k_prime) / 1e6, color="k")
    for label, at, kk in (("A", 0.0, k_prime), ("C", eps / 2, 1.5 * k_prime), ("B", eps, k_prime)):
        ax.plot([at], [kk], "o", color="k")
        ax.annotate(label, (at, kk), textcoords="offset points", xytext=(4, 6))
    ax.set_ylim(0, 1.7 * k_prime)
    fig.tight_layout()
    return fig


def plot_mesh_stiffness(table: xr.Dataset) -> Figure:
    """Fig. 5: k(t) over two mesh periods at the x1 values of ``table`` (already selected)."""
    fig, ax = single_axes((6.5, 3.8), "Fig. 5  time-varying mesh stiffness", "t (mesh periods)", "k(t) (N/um)")
    t = np.concatenate([table["phase"].values, table["phase"].values + 1.0])
    for i, x1 in enumerate(table["x1"].values):
        k = np.tile(table["k_t"].sel(x1=x1).values, 2) / 1e6
        label = f"x1 = {x1:.3f}, eps = {float(table['contact_ratio'].sel(x1=x1)):.3f}"
        ax.step(t, k, where="post", linestyle=_STYLES[i % len(_STYLES)], label=label)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def plot_backlash(b: float = 1.0) -> Figure:
    """Fig. 6: the dead-zone backlash function f(X) of Eq. (11), in units of b."""
    x = np.linspace(-3 * b, 3 * b, 601)
    fig, ax = single_axes((4.5, 3.5), "Fig. 6  backlash function", "X", "f(X)")
    ax.plot(x / b, backlash(x, b) / b, color="k")
    ax.axhline(0, color="0.7", lw=0.5)
    ax.axvline(0, color="0.7", lw=0.5)
    ax.set_xticks([-2, -1, 0, 1, 2], ["-2b", "-b", "0", "b", "2b"])
    ax.set_yticks([-2, -1, 0, 1, 2], ["-2b", "-b", "0", "b", "2b"])
    fig.tight_layout()
    return fig


def caption_fig04(props, paper=None) -> str:  # props: geardyn.khv.design.MeshProperties
    """Caption of the single-pair stiffness; the paper's wording only for a design that names one."""
    text = (
        f"Stiffness of one tooth pair over its engagement, the parabola "
        f"k'(1 + 2u(1 - u)), u = s/eps, drawn at x1 = {props.x1:.3f} (eps = {props.contact_ratio:.4f}, "
        f"k' = {props.k_prime / 1e6:.1f} N/um, k_C = 1.5 k' = {props.k_c / 1e6:.1f} N/um, ISO 6336-1 method B); "
        "k_A = k_B = k' at the ends of the engagement and k_C = 1.5 k' at the pitch point."
    )
    return paper_says(paper, "single_tooth", text=text) or text


def caption_fig05(table: xr.Dataset, design, paper=None) -> str:
    """Caption of the k(t) figure; the comparison with the paper only for a design that names one."""
    rows = "; ".join(
        f"x1 = {x1:.3f}: x2 = {float(table['x2'].sel(x1=x1)):.4f}, eps = "
        f"{float(table['contact_ratio'].sel(x1=x1)):.4f}, k_C = {float(table['k_c'].sel(x1=x1)) / 1e6:.1f} N/um, mean "
        f"k = {float(table['k_mean'].sel(x1=x1)) / 1e6:.1f} N/um"
        for x1 in table["x1"].values
    )
    x2_text = "x2 on line 4 (G_s = 0)" if design.x2_on_line4 else f"x2 fixed at {design.base.x2:g}"
    text = (
        f"Time-varying mesh stiffness k(t) over two mesh periods at x1 = "
        f"{', '.join(f'{v:g}' for v in table['x1'].values)}, {x2_text}. Stiffness options: "
        f"{design.stiffness.label}. {rows}. The double-pair zone is on [0, eps - 1] (sum of the single-pair "
        "parabolas), so k(t) jumps by k' where a pair enters or leaves; the exact mean is (8/9) eps k_C."
    )
    return paper_says(paper, "mesh_stiffness", text=text) or text


def caption_fig06(paper=None) -> str:
    """Caption of the backlash function; the paper's misprint only for a design that names it."""
    text = (
        "The backlash (dead-zone) function f(X): X - b above b, 0 inside |X| <= b, X + b below -b, with b half "
        "the backlash."
    )
    return paper_says(paper, "backlash", text=text) or text
