"""The figure of a probabilities study (``docs/probabilities.md``): stacked probability bands of the motion families and
of the impact classes against the operating axis, the K_v quantile band, the leading inputs named (or "none"), the
convergence of the headline probabilities over nested prefixes; and its caption."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import numpy as np
import xarray as xr
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from geardyn.io.tables import lead_text
from geardyn.plots.response import IMPACT_COLOURS, IMPACT_LABELS

FAMILY_COLOURS = {
    "P1": "#4c9bd6",
    "Pn": "#8fd18a",
    "long_period": "#2f7d32",
    "quasi_periodic": "#f2c14e",
    "chaotic": "#d1495b",
    "not_periodic": "#e07b39",
    "undetermined": "#9e9e9e",
    "diverged": "#333333",
}


def _lead(ds: xr.Dataset, among: np.ndarray) -> str:
    """The leading input of the first of the study's indicators that is among ``among`` (families, impacts):
    "none" where no input clears its null."""
    names = {str(a) for a in among}
    name = next((str(i) for i in ds["indicator"].values if str(i) in names), None)
    if name is None:
        return ""
    return f"; leading input of P({name}) ({ds.attrs['sensitivity_method']}): {ds.attrs[f'leading_input_{name}']}"


def probabilities_figure(ds: xr.Dataset, title: str) -> Figure:
    """Stacked probabilities of the motion families (top) and impact classes (second) and the 5-95 % band and
    median of K_v (third) against the axis (bars for a study of one point); the convergence of the headline
    probabilities (along the axis) over nested prefixes of the scramblings, +- 2 QMC standard errors (bottom)."""
    fig = Figure(figsize=(9.0, 10.5), constrained_layout=True)
    axes = fig.subplots(4, 1, height_ratios=(1, 1, 1, 0.8))
    for ax in axes[1:3]:
        ax.sharex(axes[0])
    dim = ds.attrs["axis_parameter"]
    x = ds[dim].values.astype(float)
    one = x.size == 1
    for ax, what, names, colours, labels in (
        (axes[0], "family", ds.family.values, FAMILY_COLOURS, {}),
        (
            axes[1],
            "impact",
            ds.impact.values,
            {**IMPACT_COLOURS, "no_impact": "#d9ecf7", "diverged": FAMILY_COLOURS["diverged"]},
            IMPACT_LABELS,
        ),
    ):
        p = ds[f"{what}_probability"].values
        kw = [{"color": colours[str(n)], "label": labels.get(str(n), str(n))} for n in names]
        if one:
            for k in range(len(names)):
                ax.bar(x, p[k], bottom=p[:k].sum(axis=0), width=1.0, **kw[k])
        else:
            ax.stackplot(x, p, colors=[k["color"] for k in kw], labels=[k["label"] for k in kw])
        ax.set(ylim=(0, 1), ylabel="probability")
        ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.0, 0.5))
    q = ds["dynamic_factor_quantile"].values
    top, inf = float(np.nanmax(np.where(np.isfinite(q), q, np.nan), initial=1.0)), bool(np.isinf(q).any())
    q = np.where(np.isinf(q), 1.15 * top, q)  # a quantile among the diverged samples (+inf): drawn at the top
    band = "5-95 %" + (" (at the top: +inf, diverged)" if inf else "")
    if one:
        axes[2].errorbar(x, q[1], [q[1] - q[0], q[2] - q[1]], fmt="o", capsize=8, label=f"median, {band}")
    else:
        axes[2].fill_between(x, q[0], q[2], color="tab:blue", alpha=0.3, label=band)
        axes[2].plot(x, q[1], color="tab:blue", label="median")
    axes[2].set(ylabel="K_v (-)", xlabel=ds[dim].attrs.get("long_name", dim))
    axes[2].legend(fontsize=7, loc="center left", bbox_to_anchor=(1.0, 0.5))
    _convergence(axes[3], ds)
    n = int((ds["sample_block"].values >= 0).sum())
    axes[0].set_title(f"{title}\nmotion families, {n} samples{_lead(ds, ds.family.values)}", fontsize=9, loc="left")
    axes[1].set_title(f"impact classes{_lead(ds, ds.impact.values)}", fontsize=9, loc="left")
    kv = ds.attrs.get("leading_input_dynamic_factor", "none")
    axes[2].set_title(
        f"dynamic factor K_v; leading input ({ds.attrs['sensitivity_method']}): {kv}", fontsize=9, loc="left"
    )
    return fig


def _convergence(ax: Axes, ds: xr.Dataset) -> None:
    """Each headline probability (its mean along the axis) against the prefix n, +- 2 QMC standard errors."""
    n = ds["prefix"].values
    for name in ds["headline"].values:
        p, se = (ds[v].sel(headline=name).values for v in ("convergence_probability", "convergence_probability_qmc_se"))
        line = ax.plot(n, p, marker="o", ms=3, label=f"P({name})")[0]
        ax.fill_between(n, p - 2 * se, p + 2 * se, color=line.get_color(), alpha=0.25, lw=0)
    ax.set(xlabel="samples n (nested prefixes of the scramblings)", ylabel="probability (axis mean)")
    ax.set_xscale("log", base=2)
    ax.set_xticks(n, [str(int(v)) for v in n])
    ax.tick_params(which="minor", labelbottom=False)
    ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.0, 0.5))
    r = int(ds["sample_block"].values.max()) + 1
    ax.set_title(f"convergence: +- 2 QMC standard errors over {r} independent scrambling(s)", fontsize=9, loc="left")


def caption(name: str, ds: xr.Dataset) -> str:
    """Caption of a probabilities study: its inputs, sampling, start, labelling, largest probabilities and
    leading inputs."""
    dim = ds.attrs["axis_parameter"]
    x = ds[dim].values
    p = ds["family_probability"]
    most = []
    for fam in ("chaotic", "quasi_periodic", "Pn"):
        j = int(np.argmax(p.sel(family=fam).values))
        most.append(f"P({fam}) at most {float(p.sel(family=fam).values[j]):.2f} (at {dim} = {float(x[j]):.4g})")
    n, r = int((ds["sample_block"].values >= 0).sum()), int(ds["sample_block"].values.max()) + 1
    return (
        f"{name}: probability of each motion family and impact class (95 % Wilson intervals and the quasi-Monte "
        f"Carlo standard error across {r} independent scramblings in the table and the file) and the 5/50/95 % "
        f"quantiles of the dynamic factor K_v (a diverged sample: +inf) against {dim}, over {n} samples of the "
        f"uncertain inputs: {ds.attrs['inputs']}. Sampling: {ds.attrs['sampling']}. Start: "
        f"{ds.attrs['initial_state']}; each sample is a line along {dim} on which every point starts from its "
        f"neighbour's attractor (geardyn.label), {ds.attrs['steps_per_period']} steps per period. Fixed overrides: "
        f"{ds.attrs['fixed_overrides']}. {'; '.join(most)}. Bottom: the headline probabilities (mean along {dim}) "
        f"on nested prefixes of the scramblings. Leading input per indicator ({ds.attrs['sensitivity_method']}, "
        "mean index along the axis, +- its half-width, beside its null, the 95th percentile of the index on the "
        f"output permuted; none: no input clears its null by its interval): {lead_text(ds)}. {conditioning(ds)}"
    )


def conditioning(ds: xr.Dataset) -> str:
    """What a study's probabilities condition on: its axis and fixed overrides; where it draws an operating
    condition on purpose (``operating: true``), that its numbers are shares of the box of that condition."""
    drawn = ds.attrs.get("operating_inputs", "")
    given = f"Each probability is conditional on {ds.attrs['axis_parameter']} and the fixed overrides"
    if not drawn:
        return f"{given}; only the inputs above are drawn."
    return (
        f"{given}, but {drawn} (an operating condition) is drawn over its range or pooled over its values: these "
        "probabilities are shares of the box, not probabilities of a drive."
    )


def class_figure(ds: xr.Dataset, title: str) -> Figure:
    """A class study at a glance: tolerance class (rows, fine at the bottom) against the operating axis, each cell
    green where the class meets every limit and red where not, the coarsest class that does marked with a black
    step line; the points where no class does shaded grey along the top."""
    from matplotlib.colors import ListedColormap  # noqa: PLC0415

    dim = ds.attrs["axis_parameter"]
    x, classes = ds[dim].values.astype(float), ds["tolerance_class"].values
    fig = Figure(figsize=(9.0, 4.5), constrained_layout=True)
    ax = fig.subplots()
    edges = (
        np.r_[x[0] - 0.5 * (x[1] - x[0]), 0.5 * (x[1:] + x[:-1]), x[-1] + 0.5 * (x[-1] - x[-2])]
        if x.size > 1
        else np.r_[x - 0.5, x + 0.5]
    )
    rows = np.r_[classes - 0.5, classes[-1] + 0.5]
    ax.pcolormesh(edges, rows, ds["meets_limits"].values, cmap=ListedColormap(["#d1495b", "#8fd18a"]), vmin=0, vmax=1)
    best = ds["coarsest_class"].values.astype(float)
    ax.step(
        x, np.where(best > 0, best, np.nan), where="mid", color="k", lw=2, label="coarsest class meeting the limits"
    )
    none = best == 0
    if none.any():
        ax.scatter(x[none], np.full(none.sum(), classes[-1] + 0.3), marker="x", color="k", s=12, label="no class does")
    ax.set(xlabel=ds[dim].attrs.get("long_name", dim), ylabel="ISO 1328-1:2013 tolerance class", yticks=classes)
    ax.set_title(f"{title}\n{ds.attrs['limits']} (green: met, red: not)", fontsize=9, loc="left")
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    return fig


def class_caption(name: str, ds: xr.Dataset) -> str:
    """Caption of a class study: what is limited, how the classes were sampled, the answer per point."""
    dim = ds.attrs["axis_parameter"]
    best = ds["coarsest_class"].values
    none = [f"{dim} = {v:.4g}" for v, c in zip(ds[dim].values, best, strict=True) if c == 0]
    classes = ", ".join(map(str, ds.tolerance_class.values))
    return (
        f"{name}: the coarsest ISO 1328-1:2013 tolerance class (classes {classes}) "
        f"that keeps {ds.attrs['limits']} at each {dim}, decided {ds.attrs['decision']} (95 % Wilson intervals of the "
        "probabilities and distribution-free intervals of the K_v quantile in the file and the table; the "
        "probabilities' QMC standard errors across each class's scramblings in the file). "
        f"{ds.attrs['samples_per_class']} samples per class, the same unit-cube points at every class "
        f"({ds.attrs['sampling']}); a diverged sample counts as an impact, as not periodic and as K_v = +inf. Inputs: "
        f"{ds.attrs['class_inputs']}. Fixed overrides: {ds.attrs['fixed_overrides']}. Where no class meets the limits: "
        f"{', '.join(none) or 'nowhere'}. {conditioning(ds)}"
    )
