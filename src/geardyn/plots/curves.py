"""Regime boundaries as curves (docs/orbits.md, "Regime boundaries as curves"): the curves of a curves file
drawn over a map's panels or on their own with the codimension-2 points, the figure's caption and the table
of codimension-2 points.  Reads the file only (no solver)."""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterator

import numpy as np
import xarray as xr
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.typing import LegendLocType

from geardyn.io import markdown_table
from geardyn.jsontypes import Json
from geardyn.solve import bifurcations

#: Colour of each curve kind (the file's ``curve_kind`` flag meanings; the legend text of the one vocabulary).
KIND_COLOUR = {
    "fold": "#000000",
    "period_doubling": "#1f3fbf",
    "neimark_sacker": "#d0006f",
    "grazing": "#1b9e3b",
    "back_grazing": "#e66100",
}
#: Marker of each codimension-2 type.
CODIM2_MARKERS = {
    "cusp": "^",
    "resonance_1_1": "s",
    "resonance_1_2": "D",
    "fold_flip": "P",
    "fold_neimark_sacker": "X",
    "flip_neimark_sacker": "*",
    "double_neimark_sacker": "h",
    "grazing_fold": "v",
    "grazing_flip": "<",
    "grazing_neimark_sacker": ">",
}


def _meanings(ds: xr.Dataset, name: str) -> dict[int, str]:
    """code -> meaning of the flag variable ``name``."""
    return bifurcations.decode(ds[name].attrs)


def names_of(ds: xr.Dataset) -> tuple[str, str]:
    """The two parameters of a curves file (x, y)."""
    x, y = str(ds.attrs["curve_parameters"]).split()
    return x, y


def curves_of(ds: xr.Dataset) -> Iterator[dict[str, Json]]:
    """Each curve of the file: kind, period, x, y, bounds (the curve bounds a stable orbit at that point)."""
    xn, yn = names_of(ds)
    kinds = _meanings(ds, "curve_kind")
    for k in range(ds.sizes.get("curve", 0)):
        a, n = int(ds["curve_start"][k]), int(ds["curve_length"][k])
        sl = slice(a, a + n)
        bounds = ds["bounds_stable"].values[sl] == 1 if "bounds_stable" in ds else np.ones(n, bool)
        yield {
            "kind": kinds[int(ds["curve_kind"][k])],
            "n": int(ds["curve_period"][k]),
            "x": ds[xn].values[sl],
            "y": ds[yn].values[sl],
            "bounds": bounds,
        }


def codim2_of(ds: xr.Dataset) -> list[dict[str, Json]]:
    """The codimension-2 points: type, curve kind and period, x, y, located."""
    if not ds.sizes.get("codim2", 0):
        return []
    xn, yn = names_of(ds)
    types, kinds = _meanings(ds, "codim2_type"), _meanings(ds, "curve_kind")
    mu = ds["codim2_multiplier_real"].values + 1j * ds["codim2_multiplier_imag"].values
    return [
        {
            "type": types[int(ds["codim2_type"][i])],
            "curve": k,
            "kind": kinds[int(ds["curve_kind"][k])],
            "n": int(ds["curve_period"][k]),
            "x": float(ds[f"codim2_{xn}"][i]),
            "y": float(ds[f"codim2_{yn}"][i]),
            "located": bool(ds["codim2_located"][i]),
            "multipliers": mu[i],
        }
        for i, k in enumerate(int(c) for c in ds["codim2_curve"].values)
    ]


def _unique_codim2(points: list[dict[str, Json]]) -> list[dict[str, Json]]:
    """One entry per codimension-2 point found on several curves (same type, within 1e-6)."""
    out: list[dict[str, Json]] = []
    for p in points:
        if not any(q["type"] == p["type"] and abs(q["x"] - p["x"]) + abs(q["y"] - p["y"]) < 1e-6 for q in out):
            out.append(p)
    return out


def say_on_face(ax: Axes, text: str) -> None:
    """``text`` in the middle of ``ax``, boxed, above what is drawn (a figure that holds one regime says so)."""
    ax.text(
        0.5,
        0.5,
        text,
        transform=ax.transAxes,
        ha="center",
        va="center",
        fontsize=12,
        zorder=10,
        bbox={"facecolor": "white", "alpha": 0.85, "edgecolor": "0.3"},
    )


def draw_curves(
    ax: Axes, ds: xr.Dataset, legend: bool = True, lw: float = 1.4, loc: LegendLocType = "upper right"
) -> None:
    """The curves on ``ax``: solid where they bound a stable orbit, dotted elsewhere, coloured by kind, with
    a legend of the kinds present (and their periods) at ``loc`` (an earlier legend of ``ax`` is kept)."""
    periods: dict[str, set[int]] = {}
    for c in curves_of(ds):
        colour = KIND_COLOUR.get(c["kind"], "0.3")
        ax.plot(c["x"], c["y"], ":", color=colour, lw=0.7 * lw)
        ax.plot(c["x"], np.where(c["bounds"], c["y"], np.nan), "-", color=colour, lw=lw)
        periods.setdefault(c["kind"], set()).add(c["n"])
    if legend and periods:
        earlier = ax.get_legend()
        if earlier is not None:
            ax.add_artist(earlier)
        label = {k: f"{bifurcations.legend(k)}: " + ", ".join(f"P{n}" for n in sorted(v)) for k, v in periods.items()}
        handles = [Line2D([], [], color=KIND_COLOUR.get(k, "0.3"), lw=lw, label=label[k]) for k in periods]
        handles.append(Line2D([], [], color="0.3", lw=0.7 * lw, ls=":", label="dotted: orbit already unstable"))
        ax.legend(handles=handles, loc=loc, fontsize=6, framealpha=0.8)


def plot_curves(ds: xr.Dataset, title: str, background: tuple[np.ndarray, tuple] | None = None) -> Figure:
    """The curves in their plane with the codimension-2 points marked; ``background``: an RGB image and its
    extent (a map's labels, :func:`geardyn.plots.dynamics.label_image`) drawn faintly behind them, with the
    pixel check's samples (circles pass, crosses fail, grey dots excluded)."""
    fig = Figure(figsize=(8.5, 6.5))
    ax = fig.subplots()
    xn, yn = names_of(ds)
    box = [float(v) for v in str(ds.attrs.get("box", "")).split(",")] if ds.attrs.get("box") else None
    if background is not None:
        rgb, extent = background
        ax.imshow(0.35 * rgb + 0.65, origin="lower", aspect="auto", extent=extent, interpolation="nearest")
    draw_curves(ax, ds, legend=True)
    if not any(True for _ in curves_of(ds)):  # an empty square: say why on its face
        say_on_face(ax, "no regime boundary in this plane")
    kinds_legend = ax.get_legend()
    if "check_reason" in ds and ds.sizes.get("check", 0):
        code = _meanings(ds, "check_reason")
        reasons = np.array([code[int(c)] for c in ds["check_reason"].values])
        ok, failed = reasons == "ok", np.isin(reasons, str(ds["check_reason"].attrs.get("failures", "")).split())
        cx, cy = ds[f"check_{xn}"].values, ds[f"check_{yn}"].values
        ax.plot(cx[~ok & ~failed], cy[~ok & ~failed], ".", ms=1.5, color="0.6")
        ax.plot(cx[ok], cy[ok], "o", ms=2.5, mfc="none", mec="#2ca02c", mew=0.6)
        ax.plot(cx[failed], cy[failed], "x", ms=3, color="k", mew=0.6)
    handles = []
    for p in _unique_codim2(codim2_of(ds)):
        ax.plot(p["x"], p["y"], CODIM2_MARKERS.get(p["type"], "o"), ms=9, mfc="#ffd700", mec="k", mew=0.8)
    for t in sorted({p["type"] for p in codim2_of(ds)}):
        marker = CODIM2_MARKERS.get(t, "o")
        handles.append(Line2D([], [], ls="", marker=marker, mfc="#ffd700", mec="k", label=bifurcations.legend(t)))
    if handles:
        if kinds_legend is not None:
            ax.add_artist(kinds_legend)
        ax.legend(handles=handles, loc="lower right", fontsize=6, title="codimension 2", title_fontsize=6)
    if box:
        ax.set_xlim(box[0], box[1])
        ax.set_ylim(box[2], box[3])
    ax.set_xlabel(ds[xn].attrs.get("long_name", xn))
    ax.set_ylabel(ds[yn].attrs.get("long_name", yn))
    ax.set_title(title, fontsize=10)
    fig.tight_layout()
    return fig


def summary(ds: xr.Dataset) -> dict[str, Json]:
    """Counts by kind (with periods), the codimension-2 points, the records' fates, the pixel check."""
    kinds = Counter(f"{c['kind']} P{c['n']}" for c in curves_of(ds))
    return {
        "curves": dict(sorted(kinds.items())),
        "codim2": _unique_codim2(codim2_of(ds)),
        "records": {k.removeprefix("records_"): int(v) for k, v in ds.attrs.items() if k.startswith("records_")},
        "check": {k.removeprefix("pixel_check_"): v for k, v in ds.attrs.items() if k.startswith("pixel_check_")},
    }


def caption(name: str, ds: xr.Dataset, over_map: bool) -> str:
    """The caption of a curves figure: what is drawn, how it was computed, what was found and measured."""
    s = summary(ds)
    xn, yn = names_of(ds)
    lines = [
        f"{name}: regime boundaries in the plane ({xn}, {yn}) over [{ds.attrs.get('box', '')}] "
        f"(fixed {ds.attrs.get('fixed_overrides', 'none')}), continued in two parameters (geardyn.runs.continuation, "
        "docs/orbits.md 'Regime boundaries as curves'): solid where the curve bounds a stable orbit, dotted where the "
        "orbit is already unstable.",
        f"Seeds: the orbits along the lines {ds.attrs.get('lines', '')} continued in one parameter"
        + (", and the map's records of lost stability" if over_map else "")
        + ".",
        "Curves: " + ("; ".join(f"{v} {k}" for k, v in s["curves"].items()) or "none") + ".",
        "Codimension-2 points: "
        + ("; ".join(f"{p['type']} at ({p['x']:.5g}, {p['y']:.5g})" for p in s["codim2"]) or "none")
        + ".",
    ]
    if over_map and s["records"]:
        lines.append("Map records as seeds: " + ", ".join(f"{k} {v}" for k, v in s["records"].items()) + ".")
    if s["check"] and int(s["check"].get("samples", 0)) > 0:
        c = s["check"]
        lines.append(
            "Pixel check (the two pixels on either side of a curve where it crosses a row or column of the map, "
            f"every {c.get('every', '?')} rows and columns; tables/<map>_codim2.md lists every sample not passed): "
            f"{c['fraction']:.1%} of {c['samples']} checked crossings as predicted; failures: {c['failures']}; "
            f"excluded: {c['excluded']} (circles pass, crosses fail, grey dots excluded)."
        )
    return "\n".join(lines)


def codim2_table(name: str, ds: xr.Dataset) -> str:
    """The codimension-2 points as a Markdown table (one row per point and curve it lies on)."""
    xn, yn = names_of(ds)
    rows = [
        f"# Codimension-2 points: {name}",
        "",
        f"Plane ({xn}, {yn}), fixed {ds.attrs.get('fixed_overrides', 'none')}; located: refined by Brent on the "
        "curve (else bracketed between two curve points). Multipliers of the n-period map.",
        "",
    ]
    cells = []
    for p in codim2_of(ds):
        mu = ", ".join(
            f"{z.real:.5f}{z.imag:+.5f}i" if abs(z.imag) > 1e-9 else f"{z.real:.5f}" for z in p["multipliers"]
        )
        located = "yes" if p["located"] else "no"
        cells.append((p["type"], p["kind"], p["n"], f"{p['x']:.6f}", f"{p['y']:.6f}", located, mu))
    rows.append(markdown_table(("type", "on curve", "period", xn, yn, "located", "multipliers"), cells))
    return "\n".join(rows) + ("\n" if cells else "\n| none | | | | | | |\n")


def check_table(name: str, ds: xr.Dataset) -> str:
    """The pixel check of a curves file as Markdown: the figures, then every sample that failed or was
    excluded, with its reason (geardyn.runs.continuation.curve_check), pixels, labels and the orbit's modulus."""
    if "check_reason" not in ds or not ds.sizes.get("check", 0):
        return f"\n## Pixel check: {name}\n\nno samples\n"
    a = ds.attrs
    xn, yn = names_of(ds)
    kinds = _meanings(ds, "check_kind")
    rows = [
        f"\n## Pixel check: {name}\n",
        f"{a['pixel_check_passed']} of {a['pixel_check_samples']} checked crossings as predicted "
        f"({a['pixel_check_fraction']:.1%}; every {a['pixel_check_every']} rows and columns). By kind: "
        f"{a['pixel_check_by_kind']}. Failures: {a['pixel_check_failures']}. Excluded: "
        f"{a['pixel_check_excluded']}. Crossings where the curve bounds no stable orbit: "
        f"{a['pixel_check_interior']}. Slow: the orbit's modulus above 1 - {a['pixel_check_slow_margin']:.3g}.",
        "",
    ]
    cells = []
    reasons = _meanings(ds, "check_reason")
    crit = _meanings(ds, "check_criticality")
    for k in range(ds.sizes["check"]):
        r = reasons[int(ds["check_reason"][k])]
        if r == "ok":
            continue
        j0, i0, j1, i1 = (int(v) for v in ds["check_pixels"][k].values)
        l0, l1 = (int(v) for v in ds["check_labels"][k].values)
        pix = (f"({j0}, {i0})", f"({j1}, {i1})", f"{l0}, {l1}") if j0 >= 0 else ("", "", "")
        fwd = "forward" if int(ds["check_forward"][k]) else "return"
        at = [f"{float(ds[f'check_{v}'][k]):.5f}" for v in (xn, yn)]
        last = (f"{float(ds['check_modulus'][k]):.6f}", crit[int(ds["check_criticality"][k])], fwd)
        cells.append((r, kinds[int(ds["check_kind"][k])], int(ds["check_curve"][k]), *at, *pix, *last))
    head = ("reason", "kind", "curve", xn, yn, "stable pixel", "other pixel", "labels", "modulus", "criticality", "row")
    return "\n".join([*rows, markdown_table(head, cells)]) + "\n"
