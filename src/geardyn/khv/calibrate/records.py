"""The evaluated candidates of a search: one typed record each, one JSON line each in the cache file."""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any


@dataclass(frozen=True)
class Record:
    """One evaluated candidate: its unit-cube vector (``key`` = :func:`cache_key`), its values, score
    (:func:`geardyn.khv.calibrate.objective.score_labels`), the claims verdicts and its labels along x1
    (``fig07``) and along b and e at each case x1 (``fig09``, ``fig11``, keyed ``f"{x1:g}"``)."""

    key: str
    unit: list[float]
    values: dict[str, float]
    score: float
    agree: int = 0
    partial: float = 0.0
    transitions: dict[str, float] = field(default_factory=dict)
    order: str = ""
    verdicts: dict[str, str] = field(default_factory=dict)
    fig07: list[int] = field(default_factory=list)
    fig09: dict[str, list[int]] = field(default_factory=dict)
    fig11: dict[str, list[int]] = field(default_factory=dict)

    def to_json(self) -> dict[str, Any]:
        """The record as the JSON object of a cache line (keys in field order)."""
        return dataclasses.asdict(self)

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> Record:
        return cls(**data)


def cache_key(unit: Sequence[float]) -> str:
    return ",".join(f"{float(x):.12g}" for x in unit)


def read_cache(path: str | Path) -> dict[str, Record]:
    """Evaluations stored so far ({key: record}); a torn last line (interrupted write) is ignored."""
    out: dict[str, Record] = {}
    p = Path(path)
    if not p.exists():
        return out
    for line in p.read_text().splitlines():
        try:
            rec = json.loads(line)
        except json.JSONDecodeError:
            continue
        out[rec["key"]] = Record.from_json(rec)
    return out
