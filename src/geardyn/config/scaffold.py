"""``geardyn new-design``: a commented design file of your own (each key with its schema description), naming no
paper: for a KHV drive the pair you name, x2 on line 4, the nominal cutter (reported, not enforced), the segment of
:func:`admissible_segment` and example dynamics; for a plus set the schema's defaults."""

from __future__ import annotations

import numpy as np
import yaml

from geardyn.config import ConfigError, schema, validated
from geardyn.gears import constraints
from geardyn.gears import geometry as geo
from geardyn.jsontypes import Json
from geardyn.khv.closed_graph import CUTTER_DEPENDENT
from geardyn.runs.bands import bands

KINDS = {"khv": "khv.schema.json", "plus": "plus_planetary.schema.json"}


def admissible_segment(
    z1: int,
    z2: int,
    module: float,
    pressure_angle_deg: float = 20.0,
    addendum: float = 1.0,
    clearance: float = 0.25,
    min_tip_thickness: float = 0.25,
) -> tuple[float, float]:
    """The longest x1 interval on line 4 (G_s = 0) where every cutter-independent constraint holds,
    trimmed by 2 % of its length at each end (x1 on a 0.002 grid from -1 to 2)."""
    base = geo.GearPair(z1, z2, module, 0.0, 0.0, pressure_angle_deg, addendum, clearance)
    x1 = np.round(np.arange(-1.0, 2.0005, 0.002), 6)

    def on_line4(v: float) -> float:
        try:
            return constraints.x2_on_overlap_boundary(float(v), base)
        except (ValueError, RuntimeError):
            return float("nan")

    with np.errstate(all="ignore"):
        x2 = np.array([on_line4(v) for v in x1])
        pair = geo.with_shifts(base, x1, np.where(np.isfinite(x2), x2, 0.0))
        margins = constraints.constraint_grid(pair, min_tip_thickness=min_tip_thickness)
    kept = [np.asarray(v) >= 0.0 for k, v in margins.items() if k not in (*CUTTER_DEPENDENT, "overlap_interference")]
    ok = np.isfinite(x2) & np.all(kept, axis=0)
    # the longest run of admissible grid points (the last of equals), by index
    runs = [(int(a), int(b)) for a, b, good in bands(np.arange(ok.size), ok) if good]
    best = max(reversed(runs), key=lambda r: r[1] - r[0], default=(0, 0))
    if best[1] <= best[0]:
        raise ConfigError(
            f"z1 = {z1}, z2 = {z2}, m = {module}: no part of line 4 satisfies every constraint; choose another pair"
        )
    lo, hi = float(x1[best[0]]), float(x1[best[1]])
    trim = 0.02 * (hi - lo)
    return round(lo + trim, 4), round(hi - trim, 4)


def khv_design(name: str, z1: int = 40, z2: int = 43, module: float = 2.0) -> dict[str, Json]:
    """The validated dict of a new KHV design (see the module docstring)."""
    lo, hi = admissible_segment(z1, z2, module)
    raw = {
        "kind": "khv",
        "name": name,
        "title": f"KHV drive z1 = {z1}, z2 = {z2}, m = {module} mm",
        "paper": None,
        "pair": {"z1": z1, "z2": z2, "module": module, "x1": round(0.5 * (lo + hi), 4), "x2": "line4"},
        "admissible": {"x1_min": lo, "x1_max": hi, "enforce_cutter_constraints": False},
        # the standard probabilities studies read them (docs/probabilities.md, "Tolerance classes"): class 6 of
        # ISO 1328-1:2013 (profile tolerances, both gears root-sum-square); b from example tooth thickness
        # allowances [upper, lower] um of planet and annulus and a centre distance allowance +- um (take yours
        # from DIN 3967 and DIN 3964 for the drive)
        "tolerances": {
            "grade": 6,
            "te_tolerance": "profile",
            "combine": "rss",
            "tooth_thickness_allowances": [[-5.0, -15.0], [-5.0, -15.0]],
            "centre_distance_allowance": 2.0,
        },
    }
    return validated(raw, KINDS["khv"], name)


def plus_design(name: str) -> dict[str, Json]:
    """The validated dict of a new plus-set design: the schema's defaults under a name of your own."""
    raw = {"kind": "plus_planetary", "name": name, "title": f"Plus planetary set {name}", "paper": None}
    return validated(raw, KINDS["plus"], name)


def _scalar(value: Json) -> str:
    return yaml.safe_dump(value, default_flow_style=True, width=1000).strip().removesuffix("\n...").strip()


def _emit(data: dict[str, Json], node: dict[str, Json], indent: int, lines: list[str], defs: dict[str, Json]) -> None:
    props = node.get("properties", {})
    for key, value in data.items():
        sub = props.get(key, {})
        if str(sub.get("$ref", "")).startswith("#/$defs/"):  # a local definition, its keys' comments too
            sub = {**defs[sub["$ref"].rpartition("/")[2]], **sub}
        desc = " ".join(str(sub.get("description", "")).split())
        pad = "  " * indent
        if isinstance(value, dict) and value:
            lines.append(f"{pad}{key}:" + (f"  # {desc}" if desc else ""))
            _emit(value, sub, indent + 1, lines, defs)
        else:
            lines.append(f"{pad}{key}: {_scalar(value)}" + (f"  # {desc}" if desc else ""))


def render(raw: dict[str, Json], kind: str) -> str:
    """YAML text of a design dict, every key followed by its schema description as a comment."""
    header = [
        f"# Design {raw['name']}: written by `geardyn new-design --kind {kind}`.",
        "# Every value below is an example or a default: replace it with your drive's. It names no paper,",
        "# so its results are compared with none. Check it with `geardyn check-design <this file>`.",
    ]
    if kind == "khv":
        header += [
            "# admissible: computed from the geometry (line 4, every cutter-independent constraint, "
            "2 % inside its ends).",
            "# Its default regime map (config.yaml, map_own_w_e) spans the mesh frequency w against the TE amplitude",
            "# e at mid-segment: the plane of a gear engineer's operating chart, where a drive's regimes change (over",
            "# (x1, b) at e = 5 a drive such as z1 = 40, z2 = 43, m = 2 is P1 throughout).",
        ]
    lines: list[str] = []
    node = schema(KINDS[kind])
    _emit(raw, node, 0, lines, node.get("$defs", {}))
    return "\n".join(header + lines) + "\n"
