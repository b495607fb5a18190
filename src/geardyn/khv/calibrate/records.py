"""The evaluated candidates of a search: one typed record each, one JSON line each in the cache file."""

from __future__ import annotations

import copy
import dataclasses
import json
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

from geardyn.jsontypes import Json


@dataclass(frozen=True)
class Record:
    """One evaluated candidate: its unit-cube vector (``key`` = :func:`cache_key`), its values, score
    (:func:`geardyn.khv.calibrate.objective.score_labels`), the claims verdicts and its labels along each of
    the paper's lines (``labels``, by role: a list, or {``f"{case:g}"``: list} for a family of lines)."""

    key: str
    unit: list[float]
    values: dict[str, float]
    score: float
    agree: int = 0
    partial: float = 0.0
    transitions: dict[str, float] = field(default_factory=dict)
    order: str = ""
    verdicts: dict[str, str] = field(default_factory=dict)
    labels: dict[str, Json] = field(default_factory=dict)

    def to_json(self) -> dict[str, Json]:
        """The record as the JSON object of a cache line: the fields in order, the labels of each line
        under its role."""
        out = {f.name: getattr(self, f.name) for f in dataclasses.fields(self) if f.name != "labels"}
        return copy.deepcopy({**out, **self.labels})

    @classmethod
    def from_json(cls, data: dict[str, Json]) -> Record:
        """A record from its JSON object: every key that is not a field holds the labels of one line."""
        names = {f.name for f in dataclasses.fields(cls)} - {"labels"}
        return cls(
            **{k: v for k, v in data.items() if k in names}, labels={k: v for k, v in data.items() if k not in names}
        )


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
