"""The rules of claims about a KHV drive's regimes, read on its labelled sweeps (:data:`SWEEP_RULES`; each
rule's keys and thresholds: docs/claims.md, "Sweep rules")."""

from __future__ import annotations

import itertools
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np
import xarray as xr

from geardyn.claims.verdicts import RANGE_AGREE, Claim, band, fraction_verdict
from geardyn.jsontypes import Json
from geardyn.khv import point
from geardyn.label import vocabulary
from geardyn.runs.cube import labels_of_cube
from geardyn.runs.spectrum import spectral_peaks

P1, QP, CHAOS = 1, vocabulary.LABELS["quasi_periodic"], vocabulary.LABELS["chaotic"]
#: The words for labels that are not period-n (:func:`geardyn.label.vocabulary.short_name`: "QP", "chaos", ...).
_WORDS = {vocabulary.short_name(c): c for c in vocabulary.LABELS.values()}
_name = vocabulary.short_name


def code(label: int | str) -> int | tuple[int, ...]:
    """A paper's label (n >= 1, "QP", "chaos" or alternatives "QP|chaos") as label code(s)."""
    if isinstance(label, int):
        return label
    parts = tuple(_WORDS[p] for p in label.split("|"))
    return parts if len(parts) > 1 else parts[0]


@dataclass(frozen=True)
class Track:
    """One labelled 1-D sweep, what a claim reads of it: parameter values, motion labels and (optionally) the
    exponent per point, from a stored cube (:func:`track_of_cube`) or a calibration candidate's labels."""

    values: np.ndarray
    labels: np.ndarray
    lyapunov: np.ndarray | None = None
    sigma: np.ndarray | None = None


def track_of_cube(cube: xr.Dataset, case: int = 0) -> Track:
    """The labelled sweep of case ``case`` of a sweep cube."""
    par = cube.attrs["control_parameter"]
    lam, sig = (cube[v].values[case, 0] if v in cube else None for v in ("lyapunov", "lyapunov_sigma"))
    return Track(cube[par].values, labels_of_cube(cube)[case, 0], lam, sig)


def first_non(values: np.ndarray, labels: np.ndarray, want: int) -> float:
    """First parameter value (from the start) whose label is not ``want`` (inf if none)."""
    bad = np.nonzero(labels != want)[0]
    return float(values[bad[0]]) if bad.size else float("inf")


def _first(values: np.ndarray, labels: np.ndarray, want: int) -> float:
    """The smallest parameter value whose label is ``want`` (inf if none)."""
    return float(values[labels == want].min()) if (labels == want).any() else float("inf")


def missing(spec: Mapping[str, Json], reason: str, ours: str = "not evaluated") -> Claim:
    """A claim whose input is not there: "not comparable", for ``reason``."""
    return _claim(spec, ours, "not comparable", reason)


def _paper_text(spec: Mapping[str, Json]) -> str:
    """The paper's value as the claims table shows it: stated, or derived from the claim's label and interval."""
    if "paper" in spec:
        return spec["paper"]
    if spec["rule"] == "peaks":
        return ", ".join(f"{v:g}" for v in spec["peaks"])
    want = code(spec["label"])
    if spec["rule"] == "range":
        return f"{_name(want)} on [{spec['interval'][0]}, {spec['interval'][1]}]"
    return " or ".join(_name(w) for w in (want if isinstance(want, tuple) else (want,)))


def _claim(spec: Mapping[str, Json], ours: str, verdict: str, reason: str) -> Claim:
    return Claim(spec["id"], spec["figure"], spec["statement"], _paper_text(spec), ours, verdict, reason)


def _on_line(spec: Mapping[str, Json], closed_graph: xr.Dataset) -> Claim:
    """A limit point (x1, x2) of the paper lies on the closed graph's line: our x2 at its x1 within tolerance."""
    names = [str(p) for p in closed_graph["point"].values]
    if spec["point"] not in names:
        return missing(spec, f"the closed graph has no point {spec['point']}")
    (x1, x2), tol = spec["at"], spec["tolerance"]
    cx2 = float(closed_graph["computed_x2"].values[names.index(spec["point"])])
    res = cx2 - x2
    return _claim(
        spec,
        f"x2 = {cx2:.5f} on G_s = 0 at x1 = {x1}",
        "agree" if abs(res) <= tol else "disagree",
        f"residual {res:+.5f} ({spec['precision']}: agree within {tol:g})",
    )


def _stiffness_falls(spec: Mapping[str, Json], stiffness: xr.Dataset) -> Claim:
    """The mean mesh stiffness falls at every step of the stiffness table (along the segment)."""
    km, kc, x1s = stiffness["k_mean"].values, stiffness["k_c"].values, stiffness["x1"].values
    frac_down = float(np.mean(np.diff(km) < 0))
    return _claim(
        spec,
        f"k_mean {km[0]:.4g} -> {km[-1]:.4g} N/m ({100 * (km[-1] / km[0] - 1):+.1f} %), "
        f"k_C {100 * (kc[-1] / kc[0] - 1):+.1f} %, x1 {x1s[0]:.3f} -> {x1s[-1]:.3f}",
        "agree" if frac_down == 1.0 else "disagree",
        f"k_mean falls at {100 * frac_down:.0f} % of the {len(km) - 1} steps along {spec['along']}",
    )


def _amplitude_falls(spec: Mapping[str, Json], amplitude: Mapping[str, np.ndarray]) -> Claim:
    """The peak-to-peak amplitude of dense runs falls as x1 grows (verdict on the fraction of falling steps)."""
    if len(amplitude["x1"]) <= 2:
        return missing(spec, "input not given")
    xa, ptp = np.asarray(amplitude["x1"]), np.asarray(amplitude["ptp"])
    falls, steps = int(np.sum(np.diff(ptp) < 0)), len(ptp) - 1
    return _claim(
        spec,
        f"peak-to-peak X_VH {ptp[0]:.3g} -> {ptp[-1]:.3g} over x1 {xa[0]:.3f}-{xa[-1]:.3f}",
        fraction_verdict(falls, steps),
        f"falls at {100 * falls / steps:.0f} % of {steps} steps (dense runs, recorded periods; {band(falls, steps)})",
    )


def _peaks(spec: Mapping[str, Json], points: xr.Dataset | None) -> Claim:
    """Each of the paper's spectral peaks has one of our ``highest`` peaks within ``tolerance`` (dense run ``case``)."""
    case = point.override_text(spec["case"], "")
    if points is None or case not in [str(c) for c in points["case"].values]:
        return missing(spec, "point missing", "no dense run")
    d = points.sel(case=case)
    if int(d["label"]) == vocabulary.LABELS["diverged"]:
        return missing(spec, "our run diverged", "diverged")
    peaks, tol = spec["peaks"], spec["tolerance"]
    ours = sorted(spectral_peaks(d["frequency"].values, d["amplitude"].values, n=spec["highest"]))
    matched = [any(abs(p - o) <= tol for o in ours) for p in peaks]
    reason = (
        f"{sum(matched)}/{len(peaks)} of the paper's peaks have one of our {spec['highest']} highest peaks "
        f"within {tol} {spec.get('note', '')}".rstrip()
    )
    return _claim(spec, ", ".join(f"{v:.3g}" for v in ours) or "none", "agree" if all(matched) else "disagree", reason)


def _range(spec: Mapping[str, Json], t: Track, line: Mapping[str, Json]) -> Claim:
    """At least RANGE_AGREE of the line's points on ``interval`` carry ``label`` (lower end open: ``open_below``)."""
    (lo, hi), want = spec["interval"], code(spec["label"])
    m = (t.values > lo if spec.get("open_below") else t.values >= lo) & (t.values <= hi)
    if not m.any():
        return missing(spec, "the sweep grid has no point inside the interval", "no sweep point in range")
    lab = t.labels[m]
    hits, n = int(np.sum(lab == want)), int(m.sum())
    found = {int(k): int(v) for k, v in zip(*np.unique(lab, return_counts=True), strict=True)}
    ours = ", ".join(f"{_name(k)} {v}/{n}" for k, v in sorted(found.items(), key=lambda kv: -kv[1]))
    reason = (
        f"{100 * hits / n:.0f} % ({hits}/{n}) of the sweep points in the interval are {_name(want)}"
        f" (agree needs >= {100 * RANGE_AGREE:.0f} %; {band(hits, n)})"
    )
    return _claim(spec, ours, fraction_verdict(hits, n), reason)


def _label_at(spec: Mapping[str, Json], t: Track, line: Mapping[str, Json]) -> Claim:
    """The label at the line's point nearest ``at`` is ``label`` (or one of its alternatives, "QP|chaos")."""
    j = int(np.argmin(np.abs(t.values - spec["at"])))
    got, want = int(t.labels[j]), code(spec["label"])
    extra = ""
    if t.lyapunov is not None and t.sigma is not None:
        extra = f", lambda = {float(t.lyapunov[j]):.2e} +- {float(t.sigma[j]):.1e}"
    ours = f"{_name(got)} at {t.values[j]:.4g}{extra}"
    if got in (vocabulary.LABELS["undetermined"], vocabulary.LABELS["diverged"], vocabulary.LABELS["transient"]):
        return _claim(spec, ours, "not comparable", f"our point is {_name(got)}")
    verdict = "agree" if got in (want if isinstance(want, tuple) else (want,)) else "disagree"
    return _claim(spec, ours, verdict, f"label at the nearest sweep point ({t.values[j]:.4g})")


def _route(spec: Mapping[str, Json], family: Mapping[float, Track], line: Mapping[str, Json]) -> Claim:
    """Along every line of a family the label starts as ``start`` and reaches ``end``; with ``via``, that label
    comes no later than the first ``end``."""
    par, cpar = line["parameter"], line["case_parameter"]
    start, end = code(spec["start"]), code(spec["end"])
    via = code(spec["via"]) if "via" in spec else None
    ok, parts = [], []
    for x in line["cases"]:
        t = family[float(x)]
        first_end = _first(t.values, t.labels, end)
        if via is None:
            last = t.values[t.labels == start].max() if (t.labels == start).any() else -np.inf
            ok.append(bool(t.labels[0] == start and np.isfinite(first_end)))
            parts.append(
                f"{cpar}={x}: starts {_name(t.labels[0])}, first {_name(end)} at {par} = {first_end:.3g}, "
                f"last {_name(start)} at {last:.3g}"
            )
        else:
            leave, first_via = first_non(t.values, t.labels, start), _first(t.values, t.labels, via)
            ok.append(bool(t.labels[0] == start and np.isfinite(first_end) and first_via <= first_end))
            parts.append(
                f"{cpar}={x}: leaves {_name(start)} at {par} = {leave:.3g}, first {_name(via)} {first_via:.3g}, "
                f"first {_name(end)} {first_end:.3g}"
            )
    if via is None:
        v0 = family[float(line["cases"][0])].values[0]
        reason = f"cases start {_name(start)} ({par} = {v0:g}) and reach {_name(end)} somewhere in the sweep"
    else:
        reason = f"cases show {_name(start)} first, then {_name(via)} no later than the first {_name(end)}"
    return _claim(spec, "; ".join(parts), "agree" if all(ok) else "disagree", f"{sum(ok)}/{len(ok)} {reason}")


_COUNT = {2: "two", 3: "three", 4: "four", 5: "five"}


def _narrows(spec: Mapping[str, Json], family: Mapping[float, Track], line: Mapping[str, Json]) -> Claim:
    """The first value where the label leaves ``label`` falls strictly from each line of a family to the next."""
    par, cpar, cases, want = line["parameter"], line["case_parameter"], line["cases"], code(spec["label"])
    ends = [first_non(family[float(x)].values, family[float(x)].labels, want) for x in cases]
    v0 = family[float(cases[0])].values[0]
    return _claim(
        spec,
        f"leaves {_name(want)} (from {par} = {v0:g}) at {par} = "
        + ", ".join(f"{s:.3g} ({cpar}={x})" for s, x in zip(ends, cases, strict=True)),
        "agree" if all(a > b for a, b in itertools.pairwise(ends)) else "disagree",
        f"first {par} where the label leaves {_name(want)}, compared across the paper's "
        f"{_COUNT.get(len(cases), len(cases))} {cpar} (inf: {_name(want)} throughout)",
    )


#: The rules of claims about a KHV drive's regimes: name -> (function, whether the claim reads a ``line``
#: (a labelled sweep) rather than an ``input`` product).  Each rule's keys: docs/claims.md, "Sweep rules".
SWEEP_RULES: dict[str, tuple[Callable[..., Claim], bool]] = {
    "on_line": (_on_line, False),
    "stiffness_falls": (_stiffness_falls, False),
    "amplitude_falls": (_amplitude_falls, False),
    "peaks": (_peaks, False),
    "range": (_range, True),
    "label_at": (_label_at, True),
    "route": (_route, True),
    "narrows": (_narrows, True),
}
