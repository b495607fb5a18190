"""Claims stated as data: a paper module's ``CLAIMS`` compared with our products by the rules of
:data:`DATA_RULES` (the keys of a claim and what each rule checks: docs/claims.md, "Claims stated as data")."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from numbers import Real

import numpy as np

from geardyn.claims.verdicts import BORDERLINE_Z, RANGE_AGREE, Claim, band, fraction_verdict, unique_ids
from geardyn.jsontypes import Json

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
    unique_ids(specs)
    return [data_claim(s, products, quantities) for s in specs]
