"""The class a drive needs (``docs/probabilities.md``, "The class study"): a probabilities study whose samples are
drawn again at each of several ISO 1328-1:2013 tolerance classes (:func:`geardyn.runs.probabilities.class_samples`,
the same runner and chunks), summarised per class and operating point as P(double-sided impact), P(contact loss),
P(chaos, QP or diverged) and the 95 % quantile of K_v with their intervals, and the coarsest class that keeps each
under its limit."""

from __future__ import annotations

import numpy as np
import xarray as xr

from geardyn.io import Var, markdown_table, variables
from geardyn.khv.design import KHVDesign
from geardyn.label.classify import LABELS
from geardyn.runs.probabilities import ProbabilitySpec
from geardyn.solve.response import IMPACT_CLASSES

CONFIDENCE = 0.95
#: The quantities a class study limits: name -> what it is. A diverged sample counts as a failure in each
#: (impact, not periodic, K_v = +inf).
QUANTITIES = {
    "double_sided": "P(double-sided impact)",
    "contact_loss": "P(contact loss: single- or double-sided impact)",
    "not_periodic": "P(chaos, QP or diverged)",
    "dynamic_factor_95": "95 % quantile of the dynamic factor K_v",
}
#: The limits of a class study that states none: P(double-sided) and P(chaos, QP or diverged) at most 0.05.
DEFAULT_LIMITS = {"double_sided": 0.05, "not_periodic": 0.05}


def limits(spec: ProbabilitySpec) -> dict[str, float]:
    """The study's limits (``limits:``), else :data:`DEFAULT_LIMITS`."""
    return dict(spec.limits) or dict(DEFAULT_LIMITS)


def _flags(label: np.ndarray, impact: np.ndarray) -> dict[str, np.ndarray]:
    diverged = label == LABELS["diverged"]
    wandering = np.isin(label, [LABELS[k] for k in ("chaotic", "quasi_periodic", "not_periodic")])
    return {
        "double_sided": (impact == IMPACT_CLASSES["double_sided"]) | diverged,
        "contact_loss": (impact == IMPACT_CLASSES["single_sided"])
        | (impact == IMPACT_CLASSES["double_sided"])
        | diverged,
        "not_periodic": wandering | diverged,
    }


def _share(k: np.ndarray, n: int) -> np.ndarray:
    """(estimate, low, high) of k successes in n trials: the 95 % Wilson interval of scipy."""
    from scipy.stats import binomtest  # noqa: PLC0415 - scipy.stats: only the jobs that summarise

    ends = [binomtest(int(kk), n).proportion_ci(CONFIDENCE, method="wilson") for kk in k.ravel()]
    return np.stack([k / n, *(np.reshape([getattr(e, a) for e in ends], k.shape) for a in ("low", "high"))])


def _quantile95(x: np.ndarray) -> tuple[float, float, float]:
    """The 95 % quantile of ``x`` (+inf allowed: a diverged sample) and its distribution-free 95 % interval
    (scipy's quantile_test)."""
    from scipy.stats import quantile_test  # noqa: PLC0415

    q = float(np.quantile(x, 0.95, method="inverted_cdf"))
    ci = quantile_test(x, q=q, p=0.95).confidence_interval(CONFIDENCE)
    return q, float(ci.low), float(ci.high)


def coarsest(ok: np.ndarray, classes: np.ndarray) -> np.ndarray:
    """Per column of ``ok`` (class, point): the coarsest class whose limits all hold, 0 where no class's do."""
    return np.where(ok.any(axis=0), np.max(np.where(ok, classes[:, None], 0), axis=0), 0)


def summarize(ds: xr.Dataset, spec: ProbabilitySpec, design: KHVDesign) -> xr.Dataset:
    """The class study of a merged cube (sample c N + i, ``docs/probabilities.md``): per class and point the
    quantities of :data:`QUANTITIES` with 95 % intervals, whether the class meets the study's :func:`limits` (on
    the estimates) and per point the coarsest class that does; each class's inputs (their text) and e_max."""
    classes, dim, lim = np.asarray(spec.classes), spec.dim, limits(spec)
    n = ds.sizes["sample"] // len(classes)
    shape = (len(classes), n, ds.sizes[dim])
    label, impact = (ds[v].values.reshape(shape) for v in ("label", "impact_class"))
    kv = np.where(label == LABELS["diverged"], np.inf, ds["dynamic_factor"].values.reshape(shape))
    table: dict[str, np.ndarray] = {k: _share(f.sum(axis=1), n) for k, f in _flags(label, impact).items()}
    table["dynamic_factor_95"] = np.moveaxis(
        np.array([[_quantile95(kv[c, :, j]) for j in range(shape[2])] for c in range(shape[0])]), -1, 0
    )
    ok = np.ones(shape[::2], dtype=bool)
    for key, value in lim.items():
        ok &= table[key][0] <= value
    rows = []
    for key, what in QUANTITIES.items():
        dims = ("tolerance_class", dim)
        rows += [
            (Var(key, dims, "1", what), table[key][0]),
            (Var(f"{key}_low", dims, "1", f"{what}: lower end of its 95 % interval"), table[key][1]),
            (
                Var(
                    f"{key}_high",
                    dims,
                    "1",
                    f"{what}: upper end of its 95 % interval (NaN: too few samples to bound it)",
                ),
                table[key][2],
            ),
        ]
    rows += [
        (Var("meets_limits", ("tolerance_class", dim), "1", "1 where the class meets every limit", dtype=np.int8), ok),
        (
            Var("coarsest_class", dim, "1", "coarsest tolerance class meeting every limit (0: none)", dtype=np.int32),
            coarsest(ok, classes),
        ),
    ]
    coords = {
        "tolerance_class": Var(
            "tolerance_class", "tolerance_class", "1", "flank tolerance class of ISO 1328-1:2013", dtype=np.int32
        )(classes),
        dim: (dim, ds[dim].values, ds[dim].attrs),
    }
    inputs = [{i.name: i for i in spec.uncertain(design, int(c))} for c in classes]
    e_max = [ins["e"].high if "e" in ins else np.nan for ins in inputs]
    rows.append((Var("e_max", "tolerance_class", "um", "largest TE amplitude of the class (NaN: e not drawn)"), e_max))
    data = variables([r[0] for r in rows], [r[1] for r in rows])
    text = ", ".join(f"{QUANTITIES[k]} <= {v:g}" for k, v in lim.items())
    per_class = zip(classes, inputs, strict=True)
    attrs = {
        **ds.attrs,
        "class_inputs": " | ".join(f"class {c}: " + "; ".join(i.text for i in ins.values()) for c, ins in per_class),
        "limits": text,
        "limited": " ".join(lim),
        "samples_per_class": n,
        "confidence": CONFIDENCE,
        "decision": "on the estimates; the intervals say how sure each is",
    }
    return xr.Dataset(data, coords=coords, attrs=attrs)


def table_markdown(ds: xr.Dataset, title: str) -> str:
    """Per point of the axis: the coarsest class meeting the limits and, at it, each limited quantity with its
    interval; "none" where no class does."""
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
    return head + markdown_table([dim, "coarsest class", *(QUANTITIES[k] for k in keys)], rows, "rr") + "\n"
