"""The statistics of a probabilities study's merged cube (``docs/probabilities.md``): per operating point the
probability of each motion family and impact class with 95 % Wilson intervals and its quasi-Monte Carlo standard
error across the independent scramblings, its convergence over nested prefixes, the 5 / 50 / 95 % quantiles of K_v
and of the RMS DTE with distribution-free intervals, the inputs' sensitivity indices (SALib) each beside its
permutation null, and, for a design that names a paper, the probability that each claim decided along the study's
line holds."""

from __future__ import annotations

import math
from collections.abc import Callable
from functools import partial
from types import ModuleType

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike

from geardyn import claims
from geardyn.io import Var, variables
from geardyn.jsontypes import Json
from geardyn.label.vocabulary import LABELS
from geardyn.runs.probabilities import ProbabilitySpec, Samples
from geardyn.solve.response import IMPACT_CLASSES

#: The motion families: name -> which label codes belong to it (``not_periodic``: decided QP or chaos, not which;
#: ``undetermined``: the labeller did not decide).
FAMILIES: dict[str, Callable[[np.ndarray], np.ndarray]] = {
    "P1": lambda lab: lab == 1,
    "Pn": lambda lab: lab >= 2,
    "long_period": lambda lab: lab == LABELS["long_period"],
    "quasi_periodic": lambda lab: lab == LABELS["quasi_periodic"],
    "chaotic": lambda lab: lab == LABELS["chaotic"],
    "not_periodic": lambda lab: lab == LABELS["not_periodic"],
    "undetermined": lambda lab: np.isin(lab, [LABELS["undetermined"], LABELS["transient"]]),
    "diverged": lambda lab: lab == LABELS["diverged"],
}
#: The impact classes and ``diverged`` (no response measured: ``impact_class`` -1), so that they sum to 1.
IMPACTS: dict[str, Callable[[np.ndarray], np.ndarray]] = {
    **{name: partial(np.equal, code) for name, code in IMPACT_CLASSES.items()},
    "diverged": lambda c: c < 0,
}
#: The response measures whose quantiles a study gives, and the quantiles.
MEASURES = {"dynamic_factor": "dynamic factor K_v", "dte_rms": "RMS of the DTE X_VH / b_c"}
QUANTILES = (0.05, 0.5, 0.95)
CONFIDENCE = 0.95
#: The indicators whose sensitivity a study computes by default.
INDICATORS = ("dynamic_factor", "dte_rms", "P1", "double_sided")
#: The fewest finite samples a given-data index is computed from (RBD-FAST's 10 harmonics need 2 x 10 + 2).
MIN_SAMPLES = 22
#: RBD-FAST's harmonics (SALib's default M) and PAWN's slices (SALib's default S).
HARMONICS, SLICES = 10, 10
#: The smallest prefix of the convergence of the probabilities.
FIRST_PREFIX = 32


def wilson(k: ArrayLike, n: ArrayLike, confidence: float = CONFIDENCE) -> tuple[np.ndarray, np.ndarray]:
    """Wilson score interval of the probability of k successes in n trials (arrays; NaN where n = 0):
    ``scipy.stats.binomtest(k, n).proportion_ci(method="wilson")``."""
    from scipy.stats import binomtest  # noqa: PLC0415 - scipy.stats: only the jobs that summarise

    def one(k: float, n: float) -> tuple[float, float]:
        if n <= 0:
            return math.nan, math.nan
        ci = binomtest(int(k), int(n)).proportion_ci(confidence, method="wilson")
        return float(ci.low), float(ci.high)

    pairs, at = np.unique(np.stack(np.broadcast_arrays(k, n)).reshape(2, -1), axis=1, return_inverse=True)
    lo, hi = np.vectorize(one, otypes=[float, float])(*pairs)  # one call per distinct (k, n)
    shape = np.broadcast_shapes(np.shape(k), np.shape(n))
    return lo[at.ravel()].reshape(shape), hi[at.ravel()].reshape(shape)


def quantile_interval(x: np.ndarray, q: float, confidence: float = CONFIDENCE) -> tuple[float, float, float]:
    """The q-quantile of the values of ``x`` (NaN left out, +inf kept: a diverged sample's K_v) and its
    distribution-free interval of order statistics (``scipy.stats.quantile_test(...).confidence_interval()``;
    NaN where the sample is too small for it); +inf where they fall among the infinite values."""
    from scipy.stats import quantile_test  # noqa: PLC0415

    x = x[~np.isnan(x)]
    if not x.size:
        return math.nan, math.nan, math.nan
    top = float(np.max(x[np.isfinite(x)], initial=0.0))
    big = np.where(np.isinf(x), 2.0 * abs(top) + 1.0, x)  # above every finite value: the order is the same
    ci = quantile_test(big, p=q).confidence_interval(confidence)
    value, low, high = (math.inf if v > top else float(v) for v in (np.quantile(big, q), ci.low, ci.high))
    return value, low, high


def indicator(ds: xr.Dataset, name: str) -> np.ndarray:
    """The indicator ``name`` of every point (sample, axis): a motion family or an impact class (1 or 0) or a
    response measure (+inf where the point diverged)."""
    if name in FAMILIES:
        return FAMILIES[name](ds["label"].values).astype(float)
    if name in IMPACTS:
        return IMPACTS[name](ds["impact_class"].values).astype(float)
    return np.where(ds["label"].values == LABELS["diverged"], np.inf, ds[name].values.astype(float))


def _problem(d: int) -> dict[str, Json]:
    return {"num_vars": d, "names": [f"u{k}" for k in range(d)], "bounds": [[0.0, 1.0]] * d}


def rbd_fast_index(x: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """SALib's RBD-FAST first-order index (its ``permute_outputs``, ``unskew_S1`` and the periodogram of its
    ``compute_first_order``, M = 10 harmonics) of each input (columns of ``x``, n x D) for each row of outputs
    ``ys`` (P x n) at once: (P, D)."""
    from SALib.analyze.rbd_fast import permute_outputs, unskew_S1  # noqa: PLC0415
    from scipy.signal import periodogram  # noqa: PLC0415

    out = np.empty((ys.shape[0], x.shape[1]))
    for i in range(x.shape[1]):
        _, pxx = periodogram(permute_outputs(x[:, i], ys.T).T, axis=-1)
        out[:, i] = unskew_S1(pxx[:, 1 : HARMONICS + 1].sum(-1) / pxx[:, 1:].sum(-1), HARMONICS, ys.shape[1])
    return out


def pawn_index(x: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """SALib's PAWN index (``SALib.analyze.pawn``: the median over S = 10 slices of x_i, between its quantiles,
    of the two-sample KS statistic between the slice's outputs and all; an empty slice left out) of each input
    for each row of outputs ``ys`` (P x n) at once: (P, D).  The same numbers as SALib's (a test), for P rows
    in one product instead of P x D x S calls of ``scipy.stats.ks_2samp``."""
    n, d = ys.shape[1], x.shape[1]
    edges = np.nanquantile(x, np.arange(0, 1 + 1 / SLICES, 1 / SLICES), axis=0)  # (S + 1, D)
    member = (x.T[None] >= edges[:-1, :, None]) & (x.T[None] < edges[1:, :, None])  # (S, D, n)
    counts = member.sum(axis=-1)[None, ..., None]  # (1, S, D, 1)
    at = np.sort(ys[0])
    out = np.empty((ys.shape[0], d))
    with np.errstate(invalid="ignore", divide="ignore"):
        for p in range(0, ys.shape[0], 32):
            below = (ys[p : p + 32, :, None] <= at).astype(float)  # (P, n, n): y_j <= t_k
            part = (member.reshape(-1, n).astype(float) @ below).reshape(-1, SLICES, d, n) / counts
            ks = np.abs(part - below.sum(axis=1)[:, None, None] / n).max(axis=-1)  # (P, S, D)
            out[p : p + 32] = np.nanmedian(np.where(counts[..., 0] > 0, ks, np.nan), axis=1)
    return out


GIVEN_DATA = {"rbd_fast": rbd_fast_index, "pawn": pawn_index}


def indices(
    method: str, unit: np.ndarray, y: np.ndarray, resamples: int, seed: int, permutations: int = 200
) -> np.ndarray:
    """(first, its confidence half-width, total, its half-width, null) (5, D) of the D inputs for outputs ``y``
    at the unit-cube coordinates ``unit``.  Given data (finite values only): RBD-FAST's or PAWN's index, its
    half-width from ``resamples`` bootstrap resamples (RBD-FAST: SALib's, half-size; PAWN: full size), and its
    null: the 95th percentile of the same estimator on the output permuted ``permutations`` times.  ``sobol``:
    SALib's first-order and total indices on Saltelli's design (every value finite; no null).  NaN where the
    output does not vary or too few samples are finite."""
    from scipy.stats import norm  # noqa: PLC0415

    d, ok = unit.shape[1], np.isfinite(y)
    out = np.full((5, d), np.nan)
    if ok.sum() < MIN_SAMPLES or np.ptp(y[ok]) == 0.0 or (method == "sobol" and not ok.all()):
        return out
    rng = np.random.default_rng(seed)
    with np.errstate(invalid="ignore", divide="ignore"):  # a bootstrap resample of a rare indicator may not vary
        if method == "sobol":
            from SALib.analyze import sobol  # noqa: PLC0415 - SALib: only the summary job

            r = sobol.analyze(_problem(d), y, calc_second_order=False, num_resamples=resamples, seed=seed)
            out[:4] = r["S1"], r["S1_conf"], r["ST"], r["ST_conf"]
            return out
        x, y = unit[ok], y[ok]
        if method == "rbd_fast":
            from SALib.analyze import rbd_fast  # noqa: PLC0415

            r = rbd_fast.analyze(_problem(d), x, y, num_resamples=resamples, seed=seed)
            out[:2] = r["S1"], r["S1_conf"]
        else:
            out[0] = pawn_index(x, y[None])[0]
            boot = np.array([pawn_index(x[i], y[i][None])[0] for i in rng.integers(0, y.size, (resamples, y.size))])
            out[1] = norm.ppf(0.5 + 0.5 * CONFIDENCE) * np.nanstd(boot, axis=0, ddof=1)
        shuffled = np.array([rng.permutation(y) for _ in range(permutations)])
        out[4] = np.nanquantile(GIVEN_DATA[method](x, shuffled), CONFIDENCE, axis=0)
    return out


def sensitivity_points(n: int, points: int) -> np.ndarray:
    """The indices of at most ``points`` operating points, evenly spread along an axis of n."""
    return np.unique(np.round(np.linspace(0, n - 1, min(points, n))).astype(int))


def sensitivities(ds: xr.Dataset, spec: ProbabilitySpec, table: Samples) -> dict[str, Json]:
    """The sensitivity variables (indicator, input, sensitivity_at): the index, its confidence half-width and
    (given data) its permutation null, on the indices' own design (the Latin hypercube's lines; Saltelli's
    design under ``sobol``, with the total index), at :func:`sensitivity_points` of the axis."""
    opts = dict(spec.sensitivity)
    names = tuple(opts.get("indicators", INDICATORS))
    at = sensitivity_points(ds.sizes[spec.dim], int(opts.get("points", 10)))
    rows = np.ones(table.block.size, bool) if spec.method == "sobol" else table.block < 0
    res = np.full((5, len(names), len(table.names), at.size), np.nan)
    resamples, permutations = int(opts.get("resamples", 30)), int(opts.get("permutations", 200))
    for a, name in enumerate(names):
        y = indicator(ds, name)[rows]
        for b, j in enumerate(at):
            res[:, a, :, b] = indices(spec.method, table.unit[rows], y[:, j], resamples, spec.seed, permutations)
    what = {"rbd_fast": "RBD-FAST first-order", "pawn": "PAWN (median KS)", "sobol": "Sobol' first-order"}
    dims, index = ("indicator", "input", "sensitivity_at"), what[spec.method] + " index (SALib)"
    null = f"95th percentile of the {index} on the output permuted {permutations} times (its null)"
    variables_ = [
        Var("sensitivity_index", dims, "1", f"{index} of each input for each indicator"),
        Var("sensitivity_index_conf", dims, "1", f"half-width of the 95 % bootstrap interval of the {index}"),
        Var("total_index", dims, "1", "Sobol' total index (SALib)"),
        Var("total_index_conf", dims, "1", "half-width of the 95 % interval of the Sobol' total index"),
        Var("sensitivity_null", dims, "1", null),
    ]
    kept = [0, 1, 2, 3] if spec.method == "sobol" else [0, 1, 4]
    return {"names": names, "at": at, "variables": variables([variables_[k] for k in kept], res[kept])}


def leading(ds: xr.Dataset) -> dict[str, str]:
    """Per indicator, the input with the largest mean index over the operating points among those whose mean
    index, less the mean half-width of its interval, exceeds the mean of its null (under ``sobol``: zero);
    "none" where no input does.  The points without an index or interval (an output that does not vary) do not
    count."""
    s, c = ds["sensitivity_index"].values, ds["sensitivity_index_conf"].values
    null = ds["sensitivity_null"].values if "sensitivity_null" in ds else np.zeros_like(s)
    out = {}
    for a, name in enumerate(ds["indicator"].values):
        ok = np.isfinite(s[a]) & np.isfinite(c[a]) & np.isfinite(null[a])
        n = ok.sum(axis=1)
        mean, conf, nul = (np.where(ok, v[a], 0.0).sum(axis=1) / np.maximum(n, 1) for v in (s, c, null))
        clears = (n > 0) & (mean - conf > nul)
        k = int(np.argmax(np.where(clears, mean, -np.inf)))
        out[str(name)] = str(ds["input"].values[k]) if clears[k] else "none"
    return out


def _probabilities(flags: dict[str, np.ndarray], block: np.ndarray, dim: str, what: str) -> dict[str, Json]:
    """Probability, Wilson interval and QMC standard error (class, axis) of each of ``flags`` (sample, axis)
    over the probabilities' samples (block >= 0): the standard deviation of the R scramblings' probabilities
    over sqrt(R) (NaN for one scrambling)."""
    rows, r = block >= 0, int(block.max()) + 1
    n = int(rows.sum())
    k = np.array([f[rows].sum(axis=0) for f in flags.values()])
    lo, hi = wilson(k, n)
    each = np.array([[f[block == b].mean(axis=0) for f in flags.values()] for b in range(r)])
    se = each.std(axis=0, ddof=1) / math.sqrt(r) if r > 1 else np.full(k.shape, np.nan)
    table = [
        Var(f"{what}_probability", (what, dim), "1", f"probability of each {what} (share of the {n} samples)"),
        Var(f"{what}_probability_low", (what, dim), "1", "lower end of the 95 % Wilson interval of the probability"),
        Var(f"{what}_probability_high", (what, dim), "1", "upper end of the 95 % Wilson interval of the probability"),
        Var(
            f"{what}_probability_qmc_se",
            (what, dim),
            "1",
            f"quasi-Monte Carlo standard error of the probability: spread of its {r} independent scramblings",
        ),
    ]
    return variables(table, (k / n, lo, hi, se))


def headline(spec: ProbabilitySpec) -> tuple[str, ...]:
    """The study's headline probabilities: the families and impact classes among its sensitivity indicators
    (P1 and double-sided impact where there are none)."""
    names = dict(spec.sensitivity).get("indicators", INDICATORS)
    return tuple(i for i in names if i in FAMILIES or i in IMPACTS) or ("P1", "double_sided")


def convergence(ds: xr.Dataset, spec: ProbabilitySpec, block: np.ndarray) -> dict[str, Json]:
    """The headline probabilities, averaged along the axis, on nested prefixes of the scramblings: n = 32, 64,
    ... and the whole sample, each the first n / R points of every scrambling, with their QMC standard errors."""
    r = int(block.max()) + 1
    rows = [np.flatnonzero(block == b) for b in range(r)]
    total = sum(len(b) for b in rows)
    sizes = [m for m in FIRST_PREFIX * 2 ** np.arange(20) if m < total] + [total]
    names = headline(spec)
    p, se = np.full((2, len(names), len(sizes)), np.nan)
    for a, name in enumerate(names):
        y = indicator(ds, name).mean(axis=1)
        for m, size in enumerate(sizes):
            each = np.array([y[b[: max(1, round(size * len(b) / total))]].mean() for b in rows])
            p[a, m] = np.average(each, weights=[len(b) for b in rows])
            se[a, m] = each.std(ddof=1) / math.sqrt(r) if r > 1 else np.nan
    table = [
        Var("convergence_probability", ("headline", "prefix"), "1", "headline probability along the axis (mean)"),
        Var("convergence_probability_qmc_se", ("headline", "prefix"), "1", "its QMC standard error (scramblings)"),
    ]
    coords = {
        "headline": ("headline", list(names), {"long_name": "headline indicator of the convergence"}),
        "prefix": Var("prefix", "prefix", "1", "samples of the nested prefix (n / R of each scrambling)")(
            np.array(sizes, dtype=np.int32)
        ),
    }
    return {"variables": variables(table, (p, se)), "coords": coords}


def summarize(ds: xr.Dataset, spec: ProbabilitySpec, table: Samples) -> xr.Dataset:
    """The merged cube with the inputs' samples, the probabilities, the measures' quantiles, their convergence
    and the sensitivities; attributes ``leading_input_<indicator>``."""
    lab, imp, dim, block = ds["label"].values, ds["impact_class"].values, spec.dim, table.block
    inputs = [
        Var("input_value", ("sample", "input"), "1", "value of each input (units of its override)"),
        Var("input_unit", ("sample", "input"), "1", "the sample's coordinate in the unit cube"),
        Var("sample_block", "sample", "1", "the sample's scrambling; -1: the index design's only", dtype=np.int32),
    ]
    data = {
        **variables(inputs, (table.values, table.unit, block)),
        **_probabilities({f: FAMILIES[f](lab) for f in FAMILIES}, block, dim, "family"),
        **_probabilities({c: IMPACTS[c](imp) for c in IMPACTS}, block, dim, "impact"),
    }
    for name, long_name in MEASURES.items():
        v = indicator(ds, name)[block >= 0]
        q = np.array([[quantile_interval(v[:, j], p) for j in range(ds.sizes[dim])] for p in QUANTILES])
        for k, (end, what) in enumerate((("", "quantile"), ("_low", "lower end"), ("_high", "upper end"))):
            text = f"{long_name} (diverged: +inf): {what}" + (" of the 95 % interval of the quantile" if end else "")
            data |= variables([Var(f"{name}_quantile{end}", ("quantile", dim), "1", text)], [q[..., k]])
    sens, conv = sensitivities(ds, spec, table), convergence(ds, spec, block)
    coords = {
        "family": ("family", list(FAMILIES), {"long_name": "motion family (label codes: geardyn.label.vocabulary)"}),
        "impact": ("impact", list(IMPACTS), {"long_name": "impact class (diverged: no response measured)"}),
        "quantile": Var("quantile", "quantile", "1", "probability of the quantile")(np.array(QUANTILES)),
        "input": ("input", list(table.names), {"long_name": "uncertain input (an override of the design's point)"}),
        "indicator": ("indicator", list(sens["names"]), {"long_name": "indicator whose sensitivity is given"}),
        "sensitivity_at": Var(
            "sensitivity_at", "sensitivity_at", ds[dim].attrs["units"], f"{dim} of the sensitivities"
        )(ds[dim].values[sens["at"]]),
        **conv["coords"],
    }
    out = ds.assign(**data, **sens["variables"], **conv["variables"]).assign_coords(coords)
    out.attrs.update({"sensitivity_method": spec.method, "confidence": CONFIDENCE})
    out.attrs.update({f"leading_input_{k}": v for k, v in leading(out).items()})
    return out


def claim_probabilities(paper: ModuleType, ds: xr.Dataset, role: str) -> list[dict[str, Json]]:
    """For each claim of ``paper`` decided along its line ``role`` (``CLAIM_LINES``; one line, no case), the
    share of the probabilities' samples on which :func:`geardyn.claims.sweep_claim` gives each verdict, with the
    Wilson interval of "agree" (the claim holds)."""
    specs = [c for c in paper.CLAIMS if c.get("line") == role and "case" not in c]
    x, lab = ds[ds.attrs["axis_parameter"]].values, ds["label"].values
    lam, sig = ds["lyapunov"].values, ds["lyapunov_sigma"].values
    kept = np.flatnonzero(ds["sample_block"].values >= 0)  # the probabilities' samples
    tracks = [claims.Track(x, lab[s], lam[s], sig[s]) for s in kept]
    rows = []
    for c in specs:
        got = [claims.sweep_claim(c, {role: t}, paper.CLAIM_LINES).verdict for t in tracks]
        share = {v: got.count(v) / len(got) for v in ("agree", "borderline", "disagree", "not comparable")}
        lo, hi = wilson(got.count("agree"), len(got))
        rows.append({"id": c["id"], "figure": c["figure"], "statement": c["statement"], **share, "low": lo, "high": hi})
    return rows
