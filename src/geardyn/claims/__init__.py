"""Every checkable statement of a paper (data: a paper module's ``CLAIMS``) against our results, for designs that
name the paper: the verdict rules on a KHV drive's labelled sweeps (:data:`SWEEP_RULES`) and on a model family's
products (:data:`DATA_RULES`); the rules, the keys of a claim and the thresholds: docs/claims.md."""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from numbers import Real
from types import ModuleType

import numpy as np
import xarray as xr

from geardyn.claims.verdicts import BORDERLINE_Z, RANGE_AGREE, Claim, band, fraction_verdict
from geardyn.jsontypes import Json
from geardyn.khv import point
from geardyn.label import classify
from geardyn.runs.cube import labels_of_cube

P1, QP, CHAOS = 1, classify.LABELS["quasi_periodic"], classify.LABELS["chaotic"]
#: The words for labels that are not period-n (:func:`geardyn.label.classify.short_name`: "QP", "chaos", ...).
_WORDS = {classify.short_name(c): c for c in classify.LABELS.values()}
_name = classify.short_name


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


def lines_of_runs(lines: Mapping[str, Mapping[str, Json]], runs: Mapping[str, Json]) -> dict[str, Json]:
    """The labelled lines (``lines``: a paper's ``CLAIM_LINES``) of the sweep cubes ``runs`` (by role): a
    :class:`Track`, or {case value: Track} for a family of lines; the roles ``runs`` lacks are left out."""
    out: dict[str, Json] = {}
    for role, spec in lines.items():
        cube = runs.get(role)
        if cube is None:
            continue
        if spec.get("cases") is None:
            out[role] = track_of_cube(cube)
        else:  # a family: {value: Track} of the cases ``<case_parameter>=<value>``
            names = [str(c) for c in cube["case"].values]
            index = {float(v): names.index(point.override_text({spec["case_parameter"]: v}, "")) for v in spec["cases"]}
            out[role] = {v: track_of_cube(cube, i) for v, i in index.items()}
    return out


def first_non(values: np.ndarray, labels: np.ndarray, want: int) -> float:
    """First parameter value (from the start) whose label is not ``want`` (inf if none)."""
    bad = np.nonzero(labels != want)[0]
    return float(values[bad[0]]) if bad.size else float("inf")


def _first(values: np.ndarray, labels: np.ndarray, want: int) -> float:
    """The smallest parameter value whose label is ``want`` (inf if none)."""
    return float(values[labels == want].min()) if (labels == want).any() else float("inf")


def claims(paper: ModuleType, products: Mapping[str, Json]) -> list[Claim]:
    """:func:`evaluate` on the pipeline's products (``closed_graph``, ``stiffness``, ``amplitude`` = {"x1", "ptp"} of
    dense runs, the sweep cubes and point runs of the paper's ``CLAIM_RUNS`` roles) and the cubes' labelled lines."""
    return evaluate(paper, {**products, **lines_of_runs(paper.CLAIM_LINES, products)})


def evaluate(paper: ModuleType, inputs: Mapping[str, Json]) -> list[Claim]:
    """The claims of ``paper`` (its ``CLAIMS``, in order) from ``inputs`` (a ``line``: a :class:`Track`, or
    {case value: Track} for a family; an ``input``: a product), behind ``claims.md`` and the calibration objective;
    a claim whose input is not given is "not comparable"."""
    _unique_ids(paper.CLAIMS)
    return [sweep_claim(spec, inputs, paper.CLAIM_LINES) for spec in paper.CLAIMS]


def _unique_ids(specs: Sequence[Mapping[str, Json]]) -> None:
    ids = [s.get("id") for s in specs]
    if len(set(ids)) != len(ids):
        raise ValueError(f"claim ids repeat: {sorted({i for i in ids if ids.count(i) > 1})}")  # type: ignore[type-var]


def sweep_claim(spec: Mapping[str, Json], inputs: Mapping[str, Json], lines: Mapping[str, Mapping[str, Json]]) -> Claim:
    """One claim about a KHV drive's regimes (:data:`SWEEP_RULES`) from ``inputs``."""
    if spec.get("rule") not in SWEEP_RULES:
        raise ValueError(f"claim {spec.get('id')!r}: rule {spec.get('rule')!r} (allowed: {sorted(SWEEP_RULES)})")
    rule, needs_line = SWEEP_RULES[spec["rule"]]
    role = spec["line"] if needs_line else spec["input"]
    got = inputs.get(role)
    if got is not None and needs_line and "case" in spec:
        got = got.get(float(spec["case"]))
    if got is None and spec["rule"] != "peaks":  # a dense run missing is the peaks rule's own answer
        return _missing(spec, "input not given")
    return rule(spec, got, lines.get(role, {})) if needs_line else rule(spec, got)


def _missing(spec: Mapping[str, Json], reason: str, ours: str = "not evaluated") -> Claim:
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
        return _missing(spec, f"the closed graph has no point {spec['point']}")
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
        return _missing(spec, "input not given")
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
        return _missing(spec, "point missing", "no dense run")
    d = points.sel(case=case)
    if int(d["diverged"]) == 1:
        return _missing(spec, "our run diverged", "diverged")
    peaks, tol = spec["peaks"], spec["tolerance"]
    ours = sorted(classify.spectral_peaks(d["frequency"].values, d["amplitude"].values, n=spec["highest"]))
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
        return _missing(spec, "the sweep grid has no point inside the interval", "no sweep point in range")
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
    if got in (classify.LABELS["undetermined"], classify.LABELS["diverged"], classify.LABELS["transient"]):
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


# --- Claims stated as data ---------------------------------------------------------------------------------
#: The comparison rules of claims stated as data (a paper module's ``CLAIMS``; the keys of a claim and what
#: each rule checks: docs/claims.md, "Claims stated as data").
DATA_RULES = ("within", "at_most", "equal", "matches", "all", "unchecked")
#: Keys a claim stated as data may have.
DATA_KEYS = frozenset(
    "id figure statement quantity args rule paper paper_of tolerance relative bound unit paper_text why note".split()
)


@dataclass(frozen=True)
class Measured:
    """One of our numbers: ``value`` (a number, a sequence, a mapping of sequences, or ``None`` when our
    products cannot give it) and ``text``, what it is and where it comes from, shown beside it."""

    value: Json
    text: str = ""


@dataclass(frozen=True)
class Quantity:
    """How a quantity is read: ``measure(products, **args)`` from our products; ``derive(table, **args)``
    the same quantity from a table in the paper's form (for claims that give ``paper_of``)."""

    measure: Callable[..., Measured]
    derive: Callable[..., Json] | None = None


def format_value(v: Json, unit: str = "") -> str:
    """A value for the claims table: numbers to 4 significant digits, sequences joined, mappings by key."""
    u = f" {unit}" if unit else ""
    if v is None:
        return "none"
    if isinstance(v, Mapping):
        return "; ".join(f"{k}: {format_value(x)}" for k, x in v.items()) + u
    if isinstance(v, str):
        return v + u
    if isinstance(v, bool | np.bool_):
        return "yes" if v else "no"
    if isinstance(v, Sequence | np.ndarray):
        if len(v) and all(isinstance(x, bool | np.bool_) for x in v):
            return f"{sum(bool(x) for x in v)}/{len(v)}"
        return ", ".join(format_value(x) for x in v) + u
    if isinstance(v, Real):
        return f"{float(v):.4g}{u}"
    return str(v) + u


def _cells(v: Json, keys: Sequence | None = None) -> list[tuple[str, Json]]:
    """(label, cell) pairs of a value: a mapping of sequences in ``keys`` order (``I #2``), a sequence
    (``#2``) or one cell."""
    if isinstance(v, Mapping):
        return [(f"{k} {label}".strip(), x) for k in (keys if keys is not None else v) for label, x in _cells(v[k])]
    if isinstance(v, Sequence | np.ndarray) and not isinstance(v, str):
        return [(f"#{i}", x) for i, x in enumerate(v, start=1)]
    return [("", v)]


def _missing_value(v: Json) -> bool:
    """None, NaN or infinity, or a mapping or sequence holding one."""
    if isinstance(v, Mapping | Sequence | np.ndarray) and not isinstance(v, str):
        return any(_missing_value(x) for x in (v.values() if isinstance(v, Mapping) else v))
    return v is None or (isinstance(v, Real) and not isinstance(v, bool | np.bool_) and not math.isfinite(float(v)))


def _names(cell: Json) -> set[str]:
    """A cell of a "matches" rule as a set of names: "a, b" and ("a", "b") are {"a", "b"}."""
    parts = cell.split(",") if isinstance(cell, str) else list(cell)
    return {str(p).strip() for p in parts if str(p).strip()}


def _normal(v: Json) -> Json:
    """Sequences as tuples, numbers as Python numbers, mappings recursively: for the "equal" rule."""
    if isinstance(v, Mapping):
        return {k: _normal(x) for k, x in v.items()}
    if isinstance(v, Sequence | np.ndarray) and not isinstance(v, str):
        return tuple(_normal(x) for x in v)
    if isinstance(v, np.generic):
        return v.item()
    return v


def tolerance_text(spec: Mapping[str, Json]) -> str:
    """The tolerance of a claim stated as data, as the claims table shows it."""
    rule, unit = spec["rule"], spec.get("unit", "")
    if rule == "within":
        tol = spec["tolerance"]
        return f"+-{100 * tol:.3g} %" if spec.get("relative") else f"+-{tol:.3g} {unit}".rstrip()
    if rule == "at_most":
        return f"<= {spec['bound']:g} {unit}".rstrip()
    if rule == "matches":
        return f">= {100 * RANGE_AGREE:.0f} % of the cells (borderline: {BORDERLINE_Z:g} binomial standard errors)"
    return {"equal": "exact", "all": "every case", "unchecked": "none"}[rule]


def within_verdict(
    ours: Json, paper: Json, tolerance: float, relative: bool = False, unit: str = ""
) -> tuple[str, str]:
    """Rule "within": (verdict, reason).  Every cell of ``ours`` within ``tolerance`` of the paper's cell
    (relative: ``|ours - paper| <= tolerance |paper|``); the reason names the worst cell and, for relative
    tolerances on several cells, the range of ours/paper."""
    keys = list(paper) if isinstance(paper, Mapping) else None
    o, p = _cells(ours, keys), _cells(paper, keys)
    if len(o) != len(p):
        return "not comparable", f"we have {len(o)} values, the paper {len(p)}"
    # an absolute difference is divided by 1.0, which is exact
    err = [(float(a) - float(b)) / (abs(float(b)) if relative else 1.0) for (_, a), (_, b) in zip(o, p, strict=True)]
    worst = int(np.argmax(np.abs(err)))
    label = f" at {o[worst][0]}" if len(o) > 1 else ""
    shown = f"{100 * err[worst]:+.1f} %" if relative else f"{err[worst]:+.3g} {unit}".rstrip()
    reason = f"{'worst ' if len(o) > 1 else ''}difference {shown}{label}"
    if relative and len(o) > 1:
        ratio = [float(a) / float(b) for (_, a), (_, b) in zip(o, p, strict=True)]
        reason += f"; ours/paper {min(ratio):.3g}-{max(ratio):.3g}"
    ok = all(abs(e) <= tolerance for e in err)
    return ("agree" if ok else "disagree"), reason


def matches_verdict(ours: Json, paper: Json) -> tuple[str, str]:
    """Rule "matches": cell by cell, a cell agrees when our names and the paper's share one; the verdict on
    the fraction of agreeing cells is :func:`fraction_verdict`."""
    keys = list(paper) if isinstance(paper, Mapping) else None
    o, p = _cells(ours, keys), _cells(paper, keys)
    if len(o) != len(p) or not p:
        return "not comparable", f"we have {len(o)} cells, the paper {len(p)}"
    hits = [bool(_names(a) & _names(b)) for (_, a), (_, b) in zip(o, p, strict=True)]
    k, n = sum(hits), len(hits)
    miss = ", ".join(label for (label, _), h in zip(o, hits, strict=True) if not h)
    reason = f"{k}/{n} cells agree ({100 * k / n:.0f} %; agree needs >= {100 * RANGE_AGREE:.0f} %; {band(k, n)})" + (
        f"; differ at {miss}" if miss else ""
    )
    return fraction_verdict(k, n), reason


def data_claim(spec: Mapping[str, Json], products: Json, quantities: Mapping[str, Quantity]) -> Claim:
    """One claim stated as data (see DATA_RULES and the keys above) evaluated on our ``products``."""
    unknown = set(spec) - DATA_KEYS
    if unknown or spec.get("rule") not in DATA_RULES or spec.get("quantity") not in quantities:
        raise ValueError(
            f"claim {spec.get('id')!r}: unknown keys {sorted(unknown)}, rule {spec.get('rule')!r} "
            f"(allowed: {DATA_RULES}) or quantity {spec.get('quantity')!r} (known: {sorted(quantities)})"
        )
    rule, unit, args = spec["rule"], spec.get("unit", ""), dict(spec.get("args", {}))
    q = quantities[spec["quantity"]]
    if "paper_of" in spec:
        if q.derive is None:
            raise ValueError(f"claim {spec['id']!r}: quantity {spec['quantity']!r} cannot be derived from a table")
        paper = q.derive(spec["paper_of"], **args)
    else:
        paper = spec.get("paper", spec.get("bound"))
    measured = q.measure(products, **args)
    ours = format_value(measured.value, unit) + (f" ({measured.text})" if measured.text else "")
    paper_shown = spec.get("paper_text") or format_value(paper, unit)
    if rule == "unchecked":
        verdict, reason = "not comparable", "the statement is not a result of our model"
    elif _missing_value(measured.value):
        verdict, reason = "not comparable", "our products do not give this number"
    elif rule == "within":
        verdict, reason = within_verdict(measured.value, paper, spec["tolerance"], spec.get("relative", False), unit)
    elif rule == "at_most":
        ok = float(measured.value) <= float(spec["bound"])
        verdict = "agree" if ok else "disagree"
        reason = f"ours {format_value(measured.value, unit)} {'<=' if ok else '>'} {spec['bound']:g} {unit}".rstrip()
    elif rule == "equal":
        same = _normal(measured.value) == _normal(paper)
        verdict, reason = ("agree", "the same") if same else ("disagree", "they differ")
    elif rule == "matches":
        verdict, reason = matches_verdict(measured.value, paper)
    else:  # all
        flags = [bool(x) for _, x in _cells(measured.value)]
        k, n = sum(flags), len(flags)
        verdict = "agree" if n and k == n else "disagree"
        reason = f"{k}/{n} of our cases"
    if verdict != "agree" and spec.get("why"):
        reason += f". {spec['why']}"
    if spec.get("note"):
        reason += f". {spec['note']}"
    return Claim(
        spec["id"], spec["figure"], spec["statement"], paper_shown, ours, verdict, reason, tolerance_text(spec)
    )


def data_claims(specs: Sequence[Mapping[str, Json]], products: Json, quantities: Mapping[str, Quantity]) -> list[Claim]:
    """Every claim of a paper stated as data (its ``CLAIMS``), in the paper module's order."""
    _unique_ids(specs)
    return [data_claim(s, products, quantities) for s in specs]


def note(design: str, title: str, paper: ModuleType) -> str:
    """The paragraph under the claims table's title: which design, how the labels were obtained, and the
    paper's labels compared (its ``CLAIM_LABELS``)."""
    return (
        f"Design `{design}` ({title}). Labels: the labeller's verdicts stored in the sweep cubes (geardyn.label: "
        "each point follows the attractor of the previous one; period-n certified by shooting and its Floquet "
        f"multipliers, QP by the torus test, chaos by a positive exponent the torus test confirms). Paper labels "
        f"compared: {paper.CLAIM_LABELS}."
    )
