"""The statistics of a probabilities study's merged cube (``docs/probabilities.md``): per operating point the
probability of each motion family and impact class with 95 % Wilson intervals, the 5 / 50 / 95 % quantiles of K_v and of
the RMS DTE with distribution-free intervals, the inputs' sensitivity indices (SALib), and, for a design that names a
paper, the probability that each claim decided along the study's line holds."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from types import ModuleType

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike

from geardyn import claims
from geardyn.io import Var, markdown_table, variables
from geardyn.jsontypes import Json
from geardyn.label.classify import LABELS
from geardyn.runs.probabilities import ProbabilitySpec, Samples
from geardyn.solve.response import IMPACT_CLASSES

#: The motion families: name -> which label codes belong to it (``undetermined``: the labeller did not decide).
FAMILIES: dict[str, Callable[[np.ndarray], np.ndarray]] = {
    "P1": lambda lab: lab == 1,
    "Pn": lambda lab: lab >= 2,
    "long_period": lambda lab: lab == LABELS["long_period"],
    "quasi_periodic": lambda lab: lab == LABELS["quasi_periodic"],
    "chaotic": lambda lab: lab == LABELS["chaotic"],
    "undetermined": lambda lab: (lab == LABELS["undetermined"]) | (lab == LABELS["not_periodic"]),
    "diverged": lambda lab: lab == LABELS["diverged"],
}
#: The response measures whose quantiles a study gives, and the quantiles.
MEASURES = {"dynamic_factor": "dynamic factor K_v", "dte_rms": "RMS of the DTE X_VH / b_c"}
QUANTILES = (0.05, 0.5, 0.95)
CONFIDENCE = 0.95
#: The indicators whose sensitivity a study computes by default.
INDICATORS = ("dynamic_factor", "dte_rms", "P1", "double_sided")
#: The fewest finite samples a given-data index is computed from (RBD-FAST's 10 harmonics need 2 x 10 + 2).
MIN_SAMPLES = 22


def wilson(k: ArrayLike, n: ArrayLike, confidence: float = CONFIDENCE) -> tuple[np.ndarray, np.ndarray]:
    """Wilson score interval of the probability of k successes in n trials (arrays; NaN where n = 0):
    (p + z^2/2n -+ z sqrt(p (1 - p)/n + z^2/4n^2)) / (1 + z^2/n), z the normal quantile at (1 + confidence)/2."""
    from scipy.stats import norm  # noqa: PLC0415 - scipy.stats: only the jobs that summarise

    k, n = np.asarray(k, dtype=float), np.asarray(n, dtype=float)
    z = float(norm.ppf(0.5 + 0.5 * confidence))
    with np.errstate(invalid="ignore", divide="ignore"):
        p = k / n
        centre, half = p + z * z / (2 * n), z * np.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
        return (centre - half) / (1 + z * z / n), (centre + half) / (1 + z * z / n)


def quantile_interval(x: np.ndarray, q: float, confidence: float = CONFIDENCE) -> tuple[float, float, float]:
    """The q-quantile of the finite values of ``x`` and its distribution-free interval [X_(r), X_(s)]: r and s the
    binomial (n, q) quantiles at (1 -+ confidence)/2, s + 1 (clipped to the sample's range)."""
    from scipy.stats import binom  # noqa: PLC0415

    x = np.sort(x[np.isfinite(x)])
    if not x.size:
        return math.nan, math.nan, math.nan
    r, s = binom.ppf([0.5 - 0.5 * confidence, 0.5 + 0.5 * confidence], x.size, q)
    return float(np.quantile(x, q)), float(x[max(int(r), 1) - 1]), float(x[min(int(s) + 1, x.size) - 1])


def indicator(ds: xr.Dataset, name: str) -> np.ndarray:
    """The indicator ``name`` of every point (sample, axis): a motion family or an impact class (1 or 0; NaN
    where the point diverged, for an impact class) or a response measure."""
    if name in FAMILIES:
        return FAMILIES[name](ds["label"].values).astype(float)
    if name in IMPACT_CLASSES:
        c = ds["impact_class"].values
        return np.where(c < 0, np.nan, (c == IMPACT_CLASSES[name]).astype(float))
    return ds[name].values.astype(float)


def indices(method: str, unit: np.ndarray, y: np.ndarray, resamples: int, seed: int) -> np.ndarray:
    """(first, its confidence half-width, total, its half-width) (4, D) of the D inputs for outputs ``y`` at the
    unit-cube coordinates ``unit``, by SALib: RBD-FAST's or PAWN's (the median KS statistic; no interval) index on
    the given data (finite values only), or Sobol' first-order and total indices on Saltelli's design (every value
    finite).  NaN where the output does not vary or too few samples are finite."""
    from SALib.analyze import pawn, rbd_fast, sobol  # noqa: PLC0415 - SALib: only the summary job

    d, ok = unit.shape[1], np.isfinite(y)
    out = np.full((4, d), np.nan)
    if ok.sum() < MIN_SAMPLES or np.ptp(y[ok]) == 0.0 or (method == "sobol" and not ok.all()):
        return out
    problem = {"num_vars": d, "names": [f"u{k}" for k in range(d)], "bounds": [[0.0, 1.0]] * d}
    with np.errstate(invalid="ignore", divide="ignore"):  # a bootstrap resample of a rare indicator may not vary
        if method == "sobol":
            r = sobol.analyze(problem, y, calc_second_order=True, num_resamples=resamples, seed=seed)
            out[:] = r["S1"], r["S1_conf"], r["ST"], r["ST_conf"]
        elif method == "pawn":
            out[0] = pawn.analyze(problem, unit[ok], y[ok], seed=seed)["median"]
        else:
            r = rbd_fast.analyze(problem, unit[ok], y[ok], num_resamples=resamples, seed=seed)
            out[:2] = r["S1"], r["S1_conf"]
    return out


def sensitivity_points(n: int, points: int) -> np.ndarray:
    """The indices of at most ``points`` operating points, evenly spread along an axis of n."""
    return np.unique(np.round(np.linspace(0, n - 1, min(points, n))).astype(int))


def sensitivities(ds: xr.Dataset, spec: ProbabilitySpec, table: Samples) -> dict[str, Json]:
    """The sensitivity variables (indicator, input, sensitivity_at): the index and its confidence half-width,
    for Sobol' the total index too, at :func:`sensitivity_points` of the axis."""
    opts = dict(spec.sensitivity)
    names = tuple(opts.get("indicators", INDICATORS))
    at = sensitivity_points(ds.sizes[spec.dim], int(opts.get("points", 10)))
    res = np.full((4, len(names), len(table.names), at.size), np.nan)
    for a, name in enumerate(names):
        y = indicator(ds, name)
        for b, j in enumerate(at):
            res[:, a, :, b] = indices(spec.method, table.unit, y[:, j], int(opts.get("resamples", 30)), spec.seed)
    what = {"rbd_fast": "RBD-FAST first-order", "pawn": "PAWN (median KS)", "sobol": "Sobol' first-order"}
    dims, index = ("indicator", "input", "sensitivity_at"), what[spec.method] + " index (SALib)"
    table = [  # type: ignore[assignment]  # the table of the output variables
        Var("sensitivity_index", dims, "1", f"{index} of each input for each indicator"),
        Var("sensitivity_index_conf", dims, "1", f"half-width of the 95 % interval of the {index}"),
        Var("total_index", dims, "1", "Sobol' total index (SALib)"),
        Var("total_index_conf", dims, "1", "half-width of the 95 % interval of the Sobol' total index"),
    ]
    kept = 4 if spec.method == "sobol" else 2
    return {"names": names, "at": at, "variables": variables(table[:kept], res[:kept])}  # type: ignore[arg-type]


def leading(ds: xr.Dataset) -> dict[str, str]:
    """Per indicator, the input with the largest mean index over the operating points, where that mean exceeds
    the mean half-width of its interval ("none" otherwise: no input tells from zero).  The points whose bootstrap
    gave no interval (a rare indicator's resamples that do not vary) do not count; PAWN's index has none."""
    s, c = ds["sensitivity_index"].values, ds["sensitivity_index_conf"].values
    if ds.attrs["sensitivity_method"] == "pawn":
        c = np.zeros_like(c)
    out = {}
    for a, name in enumerate(ds["indicator"].values):
        ok = np.isfinite(s[a]) & np.isfinite(c[a])
        n = np.maximum(ok.sum(axis=1), 1)
        mean, conf = np.where(ok, s[a], 0.0).sum(axis=1) / n, np.where(ok, c[a], 0.0).sum(axis=1) / n
        k = int(np.argmax(np.where(ok.any(axis=1), mean, -np.inf)))
        out[str(name)] = str(ds["input"].values[k]) if ok[k].any() and mean[k] > conf[k] else "none"
    return out


def _probabilities(flags: dict[str, np.ndarray], dim: str, what: str) -> dict[str, Json]:
    """Probability and Wilson interval (class, axis) of each of ``flags`` (sample, axis), of all samples."""
    n = next(iter(flags.values())).shape[0]
    k = np.array([f.sum(axis=0) for f in flags.values()])
    lo, hi = wilson(k, n)
    table = [
        Var(f"{what}_probability", (what, dim), "1", f"probability of each {what} (share of the samples)"),
        Var(f"{what}_probability_low", (what, dim), "1", "lower end of the 95 % Wilson interval of the probability"),
        Var(f"{what}_probability_high", (what, dim), "1", "upper end of the 95 % Wilson interval of the probability"),
    ]
    return variables(table, (k / n, lo, hi))


def summarize(ds: xr.Dataset, spec: ProbabilitySpec, table: Samples) -> xr.Dataset:
    """The merged cube with the inputs' samples, the probabilities, the measures' quantiles and the
    sensitivities; attributes ``leading_input_<indicator>``."""
    lab, imp, dim = ds["label"].values, ds["impact_class"].values, spec.dim
    inputs = [
        Var("input_value", ("sample", "input"), "1", "value of each input (units of its override)"),
        Var("input_unit", ("sample", "input"), "1", "the sample's coordinate in the unit cube"),
    ]
    data = {
        **variables(inputs, (table.values, table.unit)),
        **_probabilities({f: FAMILIES[f](lab) for f in FAMILIES}, dim, "family"),
        **_probabilities({c: imp == code for c, code in IMPACT_CLASSES.items()}, dim, "impact"),
    }
    for name, long_name in MEASURES.items():
        q = np.array([[quantile_interval(ds[name].values[:, j], p) for j in range(ds.sizes[dim])] for p in QUANTILES])
        for k, (end, what) in enumerate((("", "quantile"), ("_low", "lower end"), ("_high", "upper end"))):
            text = f"{long_name}: {what}" + (" of the 95 % interval of the quantile" if end else "")
            data |= variables([Var(f"{name}_quantile{end}", ("quantile", dim), "1", text)], [q[..., k]])
    sens = sensitivities(ds, spec, table)
    coords = {
        "family": ("family", list(FAMILIES), {"long_name": "motion family (label codes: geardyn.label.classify)"}),
        "impact": ("impact", list(IMPACT_CLASSES), {"long_name": "impact class"}),
        "quantile": Var("quantile", "quantile", "1", "probability of the quantile")(np.array(QUANTILES)),
        "input": ("input", list(table.names), {"long_name": "uncertain input (an override of the design's point)"}),
        "indicator": ("indicator", list(sens["names"]), {"long_name": "indicator whose sensitivity is given"}),
        "sensitivity_at": Var(
            "sensitivity_at", "sensitivity_at", ds[dim].attrs["units"], f"{dim} of the sensitivities"
        )(ds[dim].values[sens["at"]]),
    }
    out = ds.assign(**data, **sens["variables"]).assign_coords(coords)
    out.attrs.update({"sensitivity_method": spec.method, "confidence": CONFIDENCE})
    out.attrs.update({f"leading_input_{k}": v for k, v in leading(out).items()})
    return out


def claim_probabilities(paper: ModuleType, ds: xr.Dataset, role: str) -> list[dict[str, Json]]:
    """For each claim of ``paper`` decided along its line ``role`` (``CLAIM_LINES``; one line, no case), the
    share of the samples on which :func:`geardyn.claims.sweep_claim` gives each verdict, with the Wilson interval
    of "agree" (the claim holds)."""
    specs = [c for c in paper.CLAIMS if c.get("line") == role and "case" not in c]
    x, lab = ds[ds.attrs["axis_parameter"]].values, ds["label"].values
    lam, sig = ds["lyapunov"].values, ds["lyapunov_sigma"].values
    tracks = [claims.Track(x, lab[s], lam[s], sig[s]) for s in range(lab.shape[0])]
    rows = []
    for c in specs:
        got = [claims.sweep_claim(c, {role: t}, paper.CLAIM_LINES).verdict for t in tracks]
        share = {v: got.count(v) / len(got) for v in ("agree", "borderline", "disagree", "not comparable")}
        lo, hi = wilson(got.count("agree"), len(got))
        rows.append({"id": c["id"], "figure": c["figure"], "statement": c["statement"], **share, "low": lo, "high": hi})
    return rows


def _p(p: float, lo: float, hi: float) -> str:
    return f"{p:.2f} [{lo:.2f}, {hi:.2f}]"


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


def table_markdown(ds: xr.Dataset, title: str) -> str:
    """Per operating point: each family's and impact class's probability with its Wilson interval, the K_v
    quantiles and the median RMS DTE."""
    dim, fam, imp = ds.attrs["axis_parameter"], ds["family"].values, ds["impact"].values
    head = [dim, *map(str, fam), *(f"impact {c}" for c in imp), "K_v 5/50/95 %", "DTE RMS 50 %"]
    lines = [f"# {title}", "", f"Inputs: {ds.attrs['inputs']}. Sampling: {ds.attrs['sampling']}.", ""]
    rows = []
    for j, x in enumerate(ds[dim].values):
        cells = [f"{float(x):.4g}"]
        for what in ("family", "impact"):
            p, lo, hi = (ds[f"{what}_probability{e}"].values[:, j] for e in ("", "_low", "_high"))
            cells += [_p(*v) for v in zip(p, lo, hi, strict=True)]
        kv = ds["dynamic_factor_quantile"].values[:, j]
        rows.append([*cells, "/".join(f"{v:.3g}" for v in kv), f"{ds['dte_rms_quantile'].values[1, j]:.3g}"])
    return "\n".join([*lines, markdown_table(head, rows, "r" * len(head))]) + "\n"
