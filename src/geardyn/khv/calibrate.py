"""Search the paper's unknowns for the best agreement with its regime sequence along x1.

The target is a paper's regime sequence along x1 (for paper 1: :data:`geardyn.papers.li2013.SEQUENCE`,
Sec. 4.1, b = 2, e = 5).  Shaft stiffnesses, mesh frequency and planet mass are not given.  A candidate is a set of values of such unknowns;
its score is the fraction of x1 points of a coarse sweep whose label matches the paper's.
Quasi-periodic and chaotic are both "not periodic" here (the Poincaré period test cannot
separate them; the classifier of :mod:`geardyn.classify` does that for the final figures).

Nothing is tuned silently: every candidate's score is written to netCDF, and the best set is
written to a design file with its score in the header.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence

import numpy as np
import xarray as xr

from geardyn import classify
from geardyn.khv import point
from geardyn.khv.design import KHVDesign
from geardyn.solve import SimulationSettings, simulate

RegimeSequence = Sequence[tuple[float, float, "int | str"]]


def paper_label(x1: np.ndarray, sequence: RegimeSequence) -> np.ndarray:
    """The paper's label at each x1 from its regime ``sequence`` ((from, to, label) with label n >= 1
    for period-n, "QP" or "chaos"): period n, or 0 for quasi-periodic or chaotic, -1 outside."""
    x1 = np.asarray(x1, dtype=float)
    out = np.full(x1.shape, -1, dtype=np.int16)
    for lo, hi, lab in sequence:
        out[(x1 >= lo) & (x1 <= hi)] = lab if isinstance(lab, int) else 0
    return out


def score(x1: np.ndarray, labels: np.ndarray, sequence: RegimeSequence) -> float:
    """Balanced agreement with the paper: for each regime type the paper names along ``x1`` (P1, P5, P6,
    not periodic), the fraction of its points we label the same; then the mean over the types.

    Balanced so that a candidate cannot score by getting only the commonest regime right (plain
    accuracy gives 0.56 to 'not periodic everywhere').  Diverged and undetermined never match.
    """
    want = paper_label(x1, sequence)
    got = np.asarray(labels)
    types = [t for t in np.unique(want) if t >= 0]
    return float(np.mean([np.mean(got[want == t] == t) for t in types])) if types else 0.0


def candidate_grid(grid: Mapping[str, Sequence[float]]) -> list[dict[str, float]]:
    """Every combination of the grid values, in a fixed order (last key fastest)."""
    keys = list(grid)
    return [dict(zip(keys, map(float, combo), strict=True)) for combo in itertools.product(*(grid[k] for k in keys))]


def labels_along_x1(design: KHVDesign, overrides: Mapping[str, float], x1: np.ndarray,
                    settings: SimulationSettings) -> np.ndarray:
    """Poincaré period at each x1 (:func:`geardyn.classify.strict_period`; independent points from the
    static deflection)."""
    cs = classify.ClassifierSettings()
    out = np.empty(x1.size, dtype=np.int16)
    for i, value in enumerate(x1):
        coeffs = point.point_coefficients(design, {**overrides, "x1": float(value)})
        res = simulate(coeffs, settings)
        out[i] = classify.LABELS["diverged"] if res.diverged else classify.strict_period(res.poincare, cs)
    return out


def run_candidates(design: KHVDesign, candidates: Sequence[Mapping[str, float]], fixed: Mapping[str, float],
                   x1: np.ndarray, settings: SimulationSettings, sequence: RegimeSequence,
                   first_index: int = 0) -> xr.Dataset:
    """Labels and score of each candidate; ``first_index`` numbers the candidates globally."""
    keys = sorted({k for c in candidates for k in c})
    labels = np.stack([labels_along_x1(design, {**fixed, **c}, x1, settings) for c in candidates]) \
        if candidates else np.zeros((0, x1.size), np.int16)
    scores = np.array([score(x1, row, sequence) for row in labels])
    data = {
        "label": (("candidate", "x1"), labels, {"units": "1", "long_name": "Poincare period (0 not periodic, -2 diverged)"}),
        "score": ("candidate", scores, {"units": "1", "long_name": "balanced agreement with the paper's regimes along x1"}),
        "paper_label": ("x1", paper_label(x1, sequence), {"units": "1", "long_name": "the paper's label at x1"}),
    }
    for k in keys:
        data[k] = ("candidate", np.array([c.get(k, np.nan) for c in candidates], float),
                   {"units": point.units_of(k),
                    "long_name": f"candidate value of {k}"})
    coords = {
        "candidate": ("candidate", np.arange(first_index, first_index + len(candidates)),
                      {"units": "1", "long_name": "candidate index"}),
        "x1": ("x1", x1, {"units": "1", "long_name": "planet profile-shift coefficient x1"}),
    }
    return xr.Dataset(data, coords=coords)


def best(scores: xr.Dataset) -> tuple[int, dict[str, float], float]:
    """Index, values and score of the best candidate (the first one on ties: deterministic)."""
    i = int(np.argmax(scores["score"].values))
    names = [v for v in scores.data_vars if v not in ("label", "score", "paper_label")]
    values = {k: float(scores[k].values[i]) for k in names}
    return int(scores["candidate"].values[i]), values, float(scores["score"].values[i])


def chunk_slice(n_candidates: int, chunks: int, chunk: int) -> slice:
    """Contiguous candidates of chunk ``chunk`` (deterministic; every candidate in exactly one chunk)."""
    edges = np.linspace(0, n_candidates, min(chunks, max(n_candidates, 1)) + 1).round().astype(int)
    if not 0 <= chunk < len(edges) - 1:
        raise ValueError(f"chunk {chunk} outside 0..{len(edges) - 2}")
    return slice(int(edges[chunk]), int(edges[chunk + 1]))


def n_chunks(n_candidates: int, chunks: int) -> int:
    return min(chunks, max(n_candidates, 1))


def calibrated_design_text(source: str, name: str, values: Mapping[str, float], value_score: float,
                           n_candidates: int) -> str:
    """A design file: the source design with the best candidate's values written into it.

    ``values`` are overrides (x1, b, e, w, speed, or SI model parameters); w and speed become
    ``dynamics.parameters.omega_bar`` / ``input_speed_rpm``; b and e stay sweep-level (not design) values.
    """
    import yaml

    data = yaml.safe_load(source)
    source_name = data.get("name")
    data["name"] = name
    data["title"] = f"{data.get('title', '')} (calibrated)"
    params = data.setdefault("dynamics", {}).setdefault("parameters", {})
    renames = {"w": "omega_bar", "speed": "input_speed_rpm"}
    for key, value in values.items():
        if key in ("b", "e", "x1"):
            continue
        params[renames.get(key, key)] = float(value)
    header = (
        f"# GENERATED by the calibration target from design '{source_name}'; do not edit by hand.\n"
        f"# Best of {n_candidates} candidates: score {value_score:.3f} (balanced agreement of the Poincare\n"
        f"# period along a coarse x1 sweep with paper 1's stated sequence). Values chosen: "
        + ", ".join(f"{k} = {v:g}" for k, v in values.items()) + "\n"
        "# These values are fitted to the paper's regime sequence, not taken from it.\n"
    )
    return header + yaml.safe_dump(data, sort_keys=False)


def score_table(scores: xr.Dataset, top: int = 10) -> str:
    """Markdown: the best candidates, then the best one's regime bands beside the paper's."""
    names = [v for v in scores.data_vars if v not in ("label", "score", "paper_label")]
    order = np.argsort(-scores["score"].values, kind="stable")[:top]
    lines = [f"# Calibration: {scores.sizes['candidate']} candidates scored against paper 1's sequence", "",
             "| rank | candidate | " + " | ".join(names) + " | score |",
             "|---|---|" + "---|" * len(names) + "---|"]
    for rank, i in enumerate(order, 1):
        vals = " | ".join(f"{float(scores[n].values[i]):.4g}" for n in names)
        lines.append(f"| {rank} | {int(scores['candidate'].values[i])} | {vals} | {float(scores['score'].values[i]):.3f} |")
    x1 = scores["x1"].values
    best_i = int(order[0])
    lines += ["", "Best candidate, regime bands along x1 (label: period n, 0 = not periodic, -2 diverged):", "",
              "| source | bands |", "|---|---|"]
    for source, labels in (("paper", scores["paper_label"].values), ("best candidate", scores["label"].values[best_i])):
        text = "; ".join(f"{classify.label_name(lab)} [{a:.3f}, {b:.3f}]" for a, b, lab in classify.bands(x1, labels))
        lines.append(f"| {source} | {text} |")
    lines += ["", "Scores are measured, not tuned by hand: every candidate's labels are in the netCDF file."]
    return "\n".join(lines) + "\n"
