"""The pixel check's numbers (:class:`CheckSettings`), its outcomes (:data:`REASONS`) and its results: one
:class:`Sample` per crossing of a curve with a row or column of the map, gathered in a :class:`PixelCheck` with
the variables and attributes it adds to the curves file (docs/orbits.md, section 5, "The pixel check")."""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from geardyn.io import Var
from geardyn.jsontypes import Json
from geardyn.runs.continuation.corrector import ContinuationSettings
from geardyn.runs.continuation.output import index, quantity
from geardyn.solve import bifurcations
from geardyn.solve.base import ShootingSettings
from geardyn.solve.bifurcations import CODES

#: Failures of a checked sample.
FAILURES = ("not_straddled", "stable_side", "other_side", "impact_class")
#: Samples left out of the fraction, each with its reason (module doc).
EXCLUDED = ("codim2", "crowded", "edge", "slow", "hysteresis", "coexistence")
#: Outcomes of a sample (``check_reason`` flags); the first is a pass.
REASONS = ("ok", *FAILURES, *EXCLUDED)
FORWARD = "the stable pixel's row reaches it without crossing the curve"
#: Criticality of a period doubling (``check_criticality`` flags; "untyped" for the other kinds).
CRITICALITY = ("untyped", "supercritical", "subcritical")


@dataclass(frozen=True)
class CheckSettings:
    """The numbers of the pixel check (docs/orbits.md, section 5): the samples (``every``, ``max_samples``), left
    out (``margin``, ``crowd`` pixels), the orbit at a pixel (Newton: ``shooting``, ``pushes`` along the
    fold eigenvector, within ``near``; else ``follow``, the probes' branches: about 8 steps over the way, none below
    1/512 of it, from ``follow_share`` of it; a period doubling's switched branch halves its steps down to
    ``switch_ds_min``), a pixel on the orbit (``mean_rtol``, ``mean_spread``, ``spread_rtol``)."""

    every: int = 5
    margin: float = 3.0
    crowd: float = 1.5
    max_samples: int = 80
    shooting: ShootingSettings = ShootingSettings(max_iter=12)
    pushes: tuple[float, ...] = (0.02, -0.02, 0.1, -0.1)
    near: float = 0.1
    follow: ContinuationSettings = ContinuationSettings(
        ds=0.125, ds_min=2e-3, ds_max=0.125, max_points=40, grazing=False, locate=False
    )
    switch_ds_min: float = 1e-7
    follow_share: float = 0.125
    mean_rtol: float = 1e-3
    mean_spread: float = 0.1
    spread_rtol: float = 1e-2


class Crossing(NamedTuple):
    """A row (``line`` "row", index ``idx`` of y) or a column (``line`` "column", index of x) that crosses a
    curve at the fraction ``w`` of its segment ``seg``."""

    line: str
    idx: int
    seg: int
    w: float


@dataclass(frozen=True)
class Sample:
    """One crossing (x, y) of a curve: the two pixels ((row, column), the stable side first), their labels, the
    outcome (:data:`REASONS`), :data:`FORWARD`, the stable side's largest multiplier modulus, the criticality."""

    curve: int
    kind: str
    n: int
    x: float
    y: float
    pixels: tuple = ()
    labels: tuple[int, int] = (0, 0)
    reason: str = "ok"
    forward: bool = True
    modulus: float = float("nan")
    criticality: str = "untyped"

    @property
    def ok(self) -> bool:
        return self.reason == "ok"

    @property
    def checked(self) -> bool:
        return self.reason not in EXCLUDED


@dataclass
class PixelCheck:
    """The samples, and how many crossings lay where the curve bounds no stable orbit (``interior``)."""

    samples: list[Sample] = field(default_factory=list)
    every: int = 1
    seconds: float = 0.0
    interior: int = 0
    slow_margin: float = 0.0

    @property
    def checked(self) -> list[Sample]:
        return [s for s in self.samples if s.checked]

    @property
    def fraction(self) -> float:
        """The share of the checked samples that pass."""
        c = self.checked
        return sum(s.ok for s in c) / len(c) if c else float("nan")

    def by_kind(self) -> dict[str, tuple[int, int]]:
        out: dict[str, tuple[int, int]] = {}
        for s in self.checked:
            ok, n = out.get(s.kind, (0, 0))
            out[s.kind] = (ok + s.ok, n + 1)
        return out

    def tally(self, reasons: Sequence[str]) -> Counter:
        return Counter(f"{s.kind}: {s.reason}" for s in self.samples if s.reason in reasons)

    def attrs(self) -> dict[str, Json]:
        """Global attributes of the curves file."""

        def text(c: Counter) -> str:
            return "; ".join(f"{k} {v}" for k, v in sorted(c.items())) or "none"

        kinds = "; ".join(f"{k} {ok}/{n}" for k, (ok, n) in sorted(self.by_kind().items()))
        return {
            "pixel_check_fraction": round(self.fraction, 4) if self.checked else -1.0,
            "pixel_check_samples": len(self.checked),
            "pixel_check_passed": sum(s.ok for s in self.samples),
            "pixel_check_every": self.every,
            "pixel_check_by_kind": kinds or "none",
            "pixel_check_failures": text(self.tally(FAILURES)),
            "pixel_check_excluded": text(self.tally(EXCLUDED)),
            "pixel_check_interior": self.interior,
            "pixel_check_slow_margin": self.slow_margin,
        }

    def variables(self, names: tuple[str, str], kinds: Sequence[str]) -> list[tuple[Var, Json]]:
        """The samples as (row, values) of dimension ``check``."""
        s, C = self.samples, "check"
        pix = np.array([list(v.pixels[0]) + list(v.pixels[1]) if v.pixels else [-1] * 4 for v in s], np.int32)
        pixels = "row, column of the stable-side pixel, then the other (-1: none)"
        labels, modulus = (
            "map label at the stable-side pixel and the other",
            "largest multiplier modulus, stable-side orbit",
        )
        reason = Var(
            "check_reason", C, None, "outcome of the check", index(REASONS), attrs={"failures": " ".join(FAILURES)}
        )
        return [
            *[
                (Var(f"check_{n}", C, quantity(n)[0], f"{n} at the crossing"), [getattr(v, a) for v in s])
                for n, a in zip(names, "xy", strict=True)
            ],
            (Var("check_curve", C, "1", "index of the curve", dtype=np.int32), [v.curve for v in s]),
            (Var("check_kind", C, None, "curve kind", bifurcations.flags(kinds)), [CODES[v.kind] for v in s]),
            (Var("check_forward", C, None, FORWARD, index(("return", "forward"))), [v.forward for v in s]),
            (reason, [REASONS.index(v.reason) for v in s]),
            (Var("check_pixels", (C, "pixel_index"), "1", pixels), pix.reshape(len(s), 4)),
            (
                Var("check_labels", (C, "side"), "1", labels, dtype=np.int16),
                np.reshape([v.labels for v in s], (len(s), 2)),
            ),
            (Var("check_modulus", C, "1", modulus), np.array([v.modulus for v in s], float)),
            (
                Var("check_criticality", C, None, "criticality", index(CRITICALITY)),
                [CRITICALITY.index(v.criticality) for v in s],
            ),
        ]
