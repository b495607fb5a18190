"""The Markdown and CSV tables of a probabilities study (``docs/probabilities.md``): per operating point the
families' and impact classes' probabilities with the K_v and DTE quantiles and the leading inputs, and the
probability that each claim of a paper holds."""

from __future__ import annotations

import math
from collections.abc import Sequence

import xarray as xr

from geardyn.io import markdown_table
from geardyn.jsontypes import Json


def _p(p: float, lo: float, hi: float, se: float = math.nan) -> str:
    return f"{p:.2f} [{lo:.2f}, {hi:.2f}]" + ("" if math.isnan(se) else f" +-{se:.3f}")


_OTHER = ("borderline", "disagree", "not comparable")


def claims_markdown(rows: Sequence[dict[str, Json]], title: str, note: str) -> str:
    """The claims' probabilities as a Markdown table."""
    head = ("claim", "figure", "statement", "P(holds) [95 % Wilson]", *(f"P({k})" for k in _OTHER))
    cells = [
        [r["id"], r["figure"], r["statement"], _p(r["agree"], float(r["low"]), float(r["high"]))]
        + [f"{r[k]:.2f}" for k in _OTHER]
        for r in rows
    ]
    return "\n".join([f"# {title}", "", note, "", markdown_table(head, cells, "---rrrr")]) + "\n"


def claims_csv(rows: Sequence[dict[str, Json]]) -> str:
    """The claims' probabilities as CSV (the report's table)."""
    import pandas as pd  # noqa: PLC0415

    return str(pd.DataFrame(list(rows)).to_csv(index=False, float_format="%.4f"))


def lead_text(ds: xr.Dataset) -> str:
    """The leading input of each indicator, with its index, interval and null (mean along the axis); a study
    without an index design (a class study, or one given values of an operating condition) says so."""
    if ds.attrs.get("sensitivity_method") != "sobol" and not (ds["sample_block"].values < 0).any():
        return "none computed (no index lines: a study given values of an operating condition draws none)"
    out = []
    for name in ds["indicator"].values:
        lead = ds.attrs[f"leading_input_{name}"]
        if lead == "none":
            out.append(f"{name}: none")
            continue
        at = {"indicator": name, "input": lead}
        s, c = (float(ds[v].sel(at).mean()) for v in ("sensitivity_index", "sensitivity_index_conf"))
        null = f" (null {float(ds['sensitivity_null'].sel(at).mean()):.2f})" if "sensitivity_null" in ds else ""
        out.append(f"{name}: {lead} {s:.2f} +- {c:.2f}{null}")
    return "; ".join(out)


def table_markdown(ds: xr.Dataset, title: str) -> str:
    """Per operating point: each family's and impact class's probability with its Wilson interval and QMC
    standard error, the K_v quantiles and the median RMS DTE; the leading inputs beside their nulls."""
    dim, fam, imp = ds.attrs["axis_parameter"], ds["family"].values, ds["impact"].values
    head = [dim, *map(str, fam), *(f"impact {c}" for c in imp), "K_v 5/50/95 %", "DTE RMS 50 %"]
    lines = [
        f"# {title}",
        "",
        f"Inputs: {ds.attrs['inputs']}. Sampling: {ds.attrs['sampling']}. Each probability: p [95 % Wilson "
        "interval] +- its QMC standard error (the spread of the independent scramblings).",
        "",
        f"Leading input per indicator ({ds.attrs['sensitivity_method']}; index +- half-width, its permutation "
        f"null; none: no input clears its null by its interval): {lead_text(ds)}.",
        "",
    ]
    rows = []
    for j, x in enumerate(ds[dim].values):
        cells = [f"{float(x):.4g}"]
        for what in ("family", "impact"):
            p, lo, hi, se = (ds[f"{what}_probability{e}"].values[:, j] for e in ("", "_low", "_high", "_qmc_se"))
            cells += [_p(*v) for v in zip(p, lo, hi, se, strict=True)]
        kv = ds["dynamic_factor_quantile"].values[:, j]
        rows.append([*cells, "/".join(f"{v:.3g}" for v in kv), f"{ds['dte_rms_quantile'].values[1, j]:.3g}"])
    return "\n".join([*lines, markdown_table(head, rows, "r" * len(head))]) + "\n"


def class_table_markdown(ds: xr.Dataset, title: str) -> str:
    """The class study's table (:func:`geardyn.runs.tolerance_classes.summarize`), per point of the axis: the
    coarsest class meeting the limits and, at it, each limited quantity with its interval; "none" where no class
    does."""
    dim, keys = ds.attrs["axis_parameter"], ds.attrs["limited"].split()
    rows = []
    for j, x in enumerate(ds[dim].values):
        c = int(ds["coarsest_class"].values[j])
        if c == 0:
            rows.append([f"{x:.4g}", "none", *("" for _ in keys)])
            continue
        at = ds.sel(tolerance_class=c).isel({dim: j})
        rows.append(
            [
                f"{x:.4g}",
                str(c),
                *(f"{float(at[k]):.3g} [{float(at[f'{k}_low']):.3g}, {float(at[f'{k}_high']):.3g}]" for k in keys),
            ]
        )
    none = [f"{x:.4g}" for x, c in zip(ds[dim].values, ds["coarsest_class"].values, strict=True) if c == 0]
    head = (
        f"## {title}\n\nThe coarsest ISO 1328-1:2013 class meeting {ds.attrs['limits']} "
        f"(decided {ds.attrs['decision']}; "
        f"{ds.attrs['samples_per_class']} samples per class, 95 % intervals). Where no class meets them: "
        + (", ".join(f"{dim} = {x}" for x in none) or "nowhere")
        + ".\n\n"
    )
    return head + markdown_table([dim, "coarsest class", *(ds[k].attrs["long_name"] for k in keys)], rows, "rr") + "\n"
