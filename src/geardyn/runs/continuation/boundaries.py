"""What a map's (or a ``curves:`` study's) regime boundaries are drawn in and from: the plane (:class:`Region`), its
lines (:class:`Line`), the ``curves:`` settings (:class:`BoundarySpec`), and the result (:class:`Boundaries`: the
curves, the branches along the lines and the fate of each of the map's records; docs/orbits.md, section 5)."""

from __future__ import annotations

import logging
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, NamedTuple

from geardyn.config import settings_from
from geardyn.jsontypes import Json
from geardyn.khv.design import resolve_fractions
from geardyn.runs.continuation.branch import Branch
from geardyn.runs.continuation.corrector import CURVES, ContinuationSettings
from geardyn.runs.continuation.curves import BoundaryCurve, Curve, lies_on

#: The branches along a line: up to 2000 points each (five times a curve's 400), and a period doubling within 2e-3
#: of a point of a known period-2n branch (sx and the range scaled to 1) starts none.
LINE_BRANCHES = ContinuationSettings(max_points=2000, touch_tol=2e-3)

if TYPE_CHECKING:  # for the annotations only
    from geardyn.runs.maps import MapSpec

log = logging.getLogger("geardyn.curves")


@dataclass(frozen=True)
class BoundarySpec:
    """The ``curves:`` settings of a map or a curves study: every key with its meaning, default and range in
    ``$defs/curve_settings`` of the config schema; ``probes`` (seed points per line without a map) is a curves
    study's own key."""

    enabled: bool = True
    ds_max: float = 0.03
    branch_ds_max: float = 0.02
    max_period: int = 12
    max_seeds: int = 3
    map_seeds: bool = True
    max_map_seeds: int = 30
    record_tol: float = 2.5
    back_grazing: bool = True
    nodes: int = 41
    lines_x: tuple[float, ...] = ()
    lines_y: tuple[float, ...] = ()
    probes: int = 7
    check_every: int = 5
    max_points: int = 400

    @classmethod
    def from_config(cls, spec: Mapping[str, Json] | None) -> BoundarySpec:
        values = {k: v for k, v in (spec or {}).items() if k not in _ENTRY_KEYS}
        for key in ("lines_x", "lines_y"):
            if key in values:
                values[key] = tuple(float(v) for v in values[key])
        return settings_from(cls, values, "curves settings")

    def curve_settings(self) -> ContinuationSettings:
        return replace(CURVES, ds=min(CURVES.ds_max, self.ds_max), ds_max=self.ds_max, max_points=self.max_points)

    def branch_settings(self) -> ContinuationSettings:
        return replace(LINE_BRANCHES, ds=self.branch_ds_max, ds_max=self.branch_ds_max)

    def record_settings(self) -> ContinuationSettings:
        """A record's branch: searched for the record's kind only (no grazing margins)."""
        return replace(self.branch_settings(), ds=0.05, ds_max=0.05, grazing=False)


#: Keys of a curves study entry that are not curve settings.
_ENTRY_KEYS = ("designs", "title", "x", "y", "fixed", "integration")


@dataclass(frozen=True)
class Region:
    """The plane: names (x, y parameters), box (x_lo, x_hi, y_lo, y_hi), the fixed overrides."""

    names: tuple[str, str]
    box: tuple[float, float, float, float]
    fixed: tuple[tuple[str, float], ...] = ()

    @classmethod
    def of_map(cls, spec: MapSpec) -> Region:
        """The plane of a :class:`geardyn.runs.maps.MapSpec`."""
        return cls(
            (spec.x.parameter, spec.y.parameter), (spec.x.start, spec.x.stop, spec.y.start, spec.y.stop), spec.fixed
        )

    @classmethod
    def from_config(cls, spec: Mapping[str, Json], segment: tuple[float, float]) -> Region:
        """The plane of a curves study entry (x1 percentages resolved on the design's segment)."""
        s = resolve_fractions(spec, segment)
        x, y = s["x"], s["y"]
        box = (float(x["start"]), float(x["stop"]), float(y["start"]), float(y["stop"]))
        return cls((x["parameter"], y["parameter"]), box, tuple(sorted((s.get("fixed") or {}).items())))


@dataclass(frozen=True)
class Line:
    """A line of the plane: axis "x" is the line x = value (the branch runs along y, the plane's q), "y" the
    line y = value (along x, p)."""

    axis: str
    value: float

    @property
    def along(self) -> str:
        return "q" if self.axis == "x" else "p"

    def __str__(self) -> str:
        return f"{self.axis} = {self.value:g}"


class RecordFate(NamedTuple):
    """A map's record (:func:`map_records`) as a seed: its kind, the period before it (0: not periodic), where
    the loss lies (x, y) and its fate (:data:`RECORD_FATES`)."""

    kind: str
    n: int
    x: float
    y: float
    fate: str


class Unseeded(NamedTuple):
    """An event of a branch that seeded no curve (the corrector did not reach the seed, or its orbit is of a
    shorter period): its kind in the curves file, period, (x, y) and whether it was located."""

    kind: str
    n: int
    x: float
    y: float
    located: bool


@dataclass
class Boundaries:
    """The curves of a plane, the branches along the lines, the fate of each of the map's records, the events that
    seeded no curve and the seconds per stage (``timing``)."""

    region: Region
    lines: list[Line] = field(default_factory=list)
    curves: list[BoundaryCurve] = field(default_factory=list)
    branches: list[tuple[Line, Branch]] = field(default_factory=list)
    records: list[RecordFate] = field(default_factory=list)
    unseeded: list[Unseeded] = field(default_factory=list)
    timing: dict[str, float] = field(default_factory=dict)

    def add(self, c: Curve | None, origin: str, flank: str = "working") -> None:
        if c is not None and len(c) >= 2:
            self.curves.append(BoundaryCurve(c, flank, origin))
            msg = "%s: %s curve (period %d), %d points, ends %s, %d codim-2"
            log.info(msg, origin, c.kind, c.n, len(c), c.end_status, len(c.codim2))

    def known(self, kind: str, n: int, pq: tuple[float, float], tol: float, flank: str = "working") -> bool:
        """True when (p, q) lies on a curve of that kind, period and flank (:func:`lies_on`, within ``tol`` of the
        box with its sides scaled to 1)."""
        x0, x1, y0, y1 = self.region.box
        units = (x1 - x0, y1 - y0)
        return any(b.flank == flank and lies_on(b.curve, kind, n, *pq, tol, units) for b in self.curves)
