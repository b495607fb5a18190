"""A checked claim (:class:`Claim`), the one rule for a verdict on a fraction (:func:`fraction_verdict`), what a
verdict is worth to the calibration (:func:`credit`) and a design's claims table in CSV and Markdown."""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from geardyn.io import markdown_table
from geardyn.jsontypes import Json

RANGE_AGREE = 0.8
#: A fraction within this many binomial standard errors of its threshold is "borderline".
BORDERLINE_Z = 2.0
VERDICTS = ("agree", "borderline", "disagree", "not comparable")


def fraction_verdict(k: int, n: int, threshold: float = RANGE_AGREE, z: float = BORDERLINE_Z) -> str:
    """``agree`` (k/n clearly >= threshold), ``disagree`` (clearly below) or ``borderline`` (the threshold within ``z``
    binomial standard errors of k/n): the one rule for every verdict on a fraction (``docs/claims.md``)."""
    if n <= 0 or not 0 <= k <= n:
        raise ValueError(f"fraction_verdict needs 0 <= k <= n and n > 0, got k={k}, n={n}")
    p = k / n
    se = math.sqrt(p * (1.0 - p) / n)
    return "borderline" if abs(p - threshold) <= z * se else "agree" if p >= threshold else "disagree"


def credit(verdict: str) -> float:
    """What a verdict is worth in the calibration score: agree 1, borderline 1/2, otherwise 0."""
    return {"agree": 1.0, "borderline": 0.5}.get(verdict, 0.0)


CSV_COLUMNS = ("id", "figure", "statement", "paper", "ours", "verdict", "reason")


@dataclass(frozen=True)
class Claim:
    id: str
    figure: str
    statement: str
    paper: str
    ours: str
    verdict: str
    reason: str
    #: The tolerance the verdict applied, when the claim states one apart from its reason.
    tolerance: str = ""


def band(k: int, n: int) -> str:
    p = k / n
    half = BORDERLINE_Z * math.sqrt(p * (1.0 - p) / n)
    return (
        f"borderline if {100 * RANGE_AGREE:.0f} % lies in {100 * max(p - half, 0):.1f}-{100 * min(p + half, 1):.1f} %"
    )


def counts(rows: list[Claim]) -> dict[str, int]:
    c = dict.fromkeys(VERDICTS, 0)
    for r in rows:
        c[r.verdict] += 1
    return c


def headline(rows: list[Claim]) -> str:
    """``11 agree, 1 borderline, 14 disagree, 0 not comparable``."""
    c = counts(rows)
    return ", ".join(f"{c[v]} {v}" for v in VERDICTS)


def columns(rows: list[Claim]) -> tuple[str, ...]:
    """The table's columns: :data:`CSV_COLUMNS`, with ``tolerance`` after ``ours`` when a row states one."""
    if not any(r.tolerance for r in rows):
        return CSV_COLUMNS
    i = CSV_COLUMNS.index("ours") + 1
    return (*CSV_COLUMNS[:i], "tolerance", *CSV_COLUMNS[i:])


def to_csv(rows: list[Claim]) -> str:
    buf, cols = io.StringIO(), columns(rows)
    csv.writer(buf).writerows([cols, *([getattr(r, c) for c in cols] for r in rows)])
    return buf.getvalue()


def to_markdown(rows: list[Claim], design: str, note: str = "", paper: str = "the paper") -> str:
    """The claims table in Markdown: title (``paper``: the paper's short name), headline, ``note``, one row each."""
    cols = columns(rows)
    lines = [
        f"# Claims of {paper} checked: design `{design}`",
        "",
        f"**{headline(rows)}** (of {len(rows)} claims; borderline: a fraction within "
        f"{BORDERLINE_Z:g} binomial standard errors of its threshold).",
        "",
    ]
    if note:
        lines += [note, ""]
    cells = [[f"**{r.verdict}**" if c == "verdict" else getattr(r, c) for c in cols] for r in rows]
    return "\n".join([*lines, markdown_table(cols, cells)]) + "\n"


def unique_ids(specs: Sequence[Mapping[str, Json]]) -> None:
    """Raise if two claims share an ``id``."""
    ids = [s.get("id") for s in specs]
    if len(set(ids)) != len(ids):
        raise ValueError(f"claim ids repeat: {sorted({i for i in ids if ids.count(i) > 1})}")  # type: ignore[type-var]
