"""The class a drive needs (``docs/probabilities.md``, "The class study"): a probabilities study whose samples are
drawn again at each of several ISO 1328-1:2013 tolerance classes (:func:`geardyn.runs.probabilities.class_samples`,
the same runner and chunks), summarised per class and operating point as P(double-sided impact), P(contact loss),
P(chaos, QP or diverged) and the 95 % quantile of K_v with their intervals, and the coarsest class that keeps each
under its limit."""

from __future__ import annotations

import numpy as np
import xarray as xr

from geardyn.io import Var, variables
from geardyn.khv.design import KHVDesign
from geardyn.runs import probabilities, probability_stats
from geardyn.runs.probabilities import ProbabilitySpec

CONFIDENCE = probability_stats.CONFIDENCE
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
    """The limited shares' indicators, from the study's own families and impact classes
    (:mod:`geardyn.runs.probability_stats`): a diverged sample fails each."""
    fam, imp = probability_stats.FAMILIES, probability_stats.IMPACTS
    diverged = fam["diverged"](label) | imp["diverged"](impact)
    wandering = fam["chaotic"](label) | fam["quasi_periodic"](label) | fam["not_periodic"](label)
    return {
        "double_sided": imp["double_sided"](impact) | diverged,
        "contact_loss": imp["single_sided"](impact) | imp["double_sided"](impact) | diverged,
        "not_periodic": wandering | diverged,
    }


def coarsest(ok: np.ndarray, classes: np.ndarray) -> np.ndarray:
    """Per column of ``ok`` (class, point): the coarsest class whose limits all hold, 0 where no class's do."""
    return np.where(ok.any(axis=0), np.max(np.where(ok, classes[:, None], 0), axis=0), 0)


def summarize(ds: xr.Dataset, spec: ProbabilitySpec, design: KHVDesign) -> xr.Dataset:
    """The class study of a merged cube (sample c N + i, ``docs/probabilities.md``): per class and point the
    quantities of :data:`QUANTITIES` with 95 % intervals, whether the class meets the study's :func:`limits` (on
    the estimates) and per point the coarsest class that does; each class's inputs (their text) and e_max."""
    classes, dim, lim = np.asarray(spec.classes), spec.dim, limits(spec)
    block = probabilities.study_samples(design, spec).block.reshape(len(classes), -1)[0]
    kept = np.flatnonzero(block >= 0)  # the probabilities' samples of each class (the same at every class)
    n, r, shape = kept.size, int(block.max()) + 1, (len(classes), block.size, ds.sizes[dim])
    label, impact = (ds[v].values.reshape(shape)[:, kept] for v in ("label", "impact_class"))
    kv = probability_stats.indicator(ds, "dynamic_factor").reshape(shape)[:, kept]  # diverged: +inf
    table: dict[str, np.ndarray] = {}
    se: dict[str, np.ndarray] = {}
    for key, flag in _flags(label, impact).items():
        k = flag.sum(axis=1)
        table[key] = np.stack([k / n, *probability_stats.wilson(k, n)])
        each = np.array([flag[:, block[kept] == b].mean(axis=1) for b in range(r)])  # per scrambling
        se[key] = each.std(axis=0, ddof=1) / np.sqrt(r) if r > 1 else np.full(k.shape, np.nan)
    quantile = probability_stats.quantile_interval
    table["dynamic_factor_95"] = np.moveaxis(
        np.array([[quantile(kv[c, :, j], 0.95) for j in range(shape[2])] for c in range(shape[0])]), -1, 0
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
        if key in se:
            text = f"{what}: quasi-Monte Carlo standard error (spread of the class's {r} scramblings)"
            rows.append((Var(f"{key}_qmc_se", dims, "1", text), se[key]))
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
