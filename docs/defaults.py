"""Write docs/defaults.md, the default of every numerical setting, from the settings dataclasses themselves:
``python docs/defaults.py > docs/defaults.md``.  tests/test_docs_defaults.py fails when the page is stale."""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator

from geardyn.label import indicators, policy
from geardyn.runs.continuation import boundaries, corrector, pixel_samples
from geardyn.solve import base

#: (title, the settings, the instances side by side: (column, instance)), in the order of the page.
SECTIONS = (
    ("Integration (`geardyn.solve.base.SimulationSettings`)", [("default", base.SimulationSettings())]),
    ("Early stop of the transient (`geardyn.solve.base.EarlyStop`)", [("default", base.EarlyStop())]),
    ("Newton shooting (`geardyn.solve.base.ShootingSettings`)", [("default", base.SHOOTING)]),
    (
        "Continuation (`geardyn.runs.continuation.corrector.ContinuationSettings`)",
        [("branch (default)", corrector.ContinuationSettings()), ("curve (`CURVES`)", corrector.CURVES)],
    ),
    (
        "Regime boundaries (`geardyn.runs.continuation.boundaries.BoundarySpec`)",
        [("default", boundaries.BoundarySpec())],
    ),
    (
        "Pixel check (`geardyn.runs.continuation.pixel_samples.CheckSettings`)",
        [("default", pixel_samples.CheckSettings())],
    ),
    (
        "Labeller thresholds (`geardyn.label.indicators.ClassifierSettings`)",
        [("default", indicators.ClassifierSettings())],
    ),
    ("Labeller's shooting (`geardyn.label.policy.Newton`)", [("default", policy.Newton())]),
    ("Deflated shooting (`geardyn.label.policy.Deflation`)", [("default", policy.Deflation())]),
    ("Chord iteration (`geardyn.label.policy.Chord`)", [("default", policy.Chord())]),
    ("Slow transients (`geardyn.label.policy.Settle`)", [("default", policy.Settle())]),
    ("Locked cycles (`geardyn.label.policy.Locked`)", [("default", policy.Locked())]),
)


def fields(obj: object, prefix: str = "") -> Iterator[tuple[str, object]]:
    """(name, value) of every field of a settings dataclass, a nested one's as ``outer.inner``."""
    for f in dataclasses.fields(obj):  # type: ignore[arg-type]
        value = getattr(obj, f.name)
        if dataclasses.is_dataclass(value) and not isinstance(value, type):
            yield from fields(value, f"{prefix}{f.name}.")
        else:
            yield f"{prefix}{f.name}", value


def render() -> str:
    """The page."""
    out = [
        "# Defaults of the numerical settings",
        "",
        "Generated from the settings dataclasses by `python docs/defaults.py > docs/defaults.md` (the test",
        "`tests/test_docs_defaults.py` fails when this page is stale). What each setting means: the dataclass's",
        "docstring and the page of its subject (`docs/numerics.md`, `docs/orbits.md`, `docs/classify.md`).",
    ]
    for title, columns in SECTIONS:
        table = [dict(fields(obj)) for _, obj in columns]
        out += ["", f"## {title}", "", "| setting | " + " | ".join(c for c, _ in columns) + " |"]
        out.append("|---|" + "---:|" * len(columns))
        out += [f"| `{k}` | " + " | ".join(repr(t[k]) for t in table) + " |" for k in table[0]]
    return "\n".join(out) + "\n"


if __name__ == "__main__":
    print(render(), end="")
