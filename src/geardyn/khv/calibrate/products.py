"""The products of a search: the candidates as a dataset, the calibrated design file, the search table."""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from types import ModuleType
from typing import Any

import numpy as np
import xarray as xr
import yaml

from geardyn.io import cf
from geardyn.khv import point
from geardyn.khv.calibrate.objective import REQUIREMENTS, Grids, paper_regime_string, requirement_text
from geardyn.khv.calibrate.records import Record
from geardyn.khv.calibrate.space import SearchSpace, interior
from geardyn.khv.design import KHVDesign
from geardyn.papers import paper_of

#: the header line that carries the search result in a calibrated design file (machine-readable)
RESULT_PREFIX = "# search-result: "


def records_dataset(records: Sequence[Record], space: SearchSpace, grids: Grids) -> xr.Dataset:
    """All evaluated candidates as a dataset (candidate order: order of evaluation), with their labels along
    the main line (``grids.main``)."""
    n = len(records)
    main = grids.lines[grids.main]
    par = main.parameter
    columns = {  # name: (value of a record, dtype, units, long name)
        "score": (lambda r: r.score, None, "1", "claims that agree + 0.99 * partial credit"),
        "agree": (lambda r: r.agree, np.int16, "1", "claims that agree (of those the labels decide)"),
        "partial": (lambda r: r.partial, None, "1", "partial credit: transition positions and regime order"),
        "leave_p1": (lambda r: r.transitions["leave_p1"], None, point.units_of(par), f"first {par} not P1"),
        "first_chaos": (lambda r: r.transitions["first_chaos"], None, point.units_of(par), f"first chaotic {par}"),
    }
    data: dict = {
        name: cf("candidate", np.array([value(r) for r in records], dtype), units, long_name)
        for name, (value, dtype, units, long_name) in columns.items()
    }
    data["label"] = cf(
        ("candidate", par),
        np.array([r.labels[grids.main] for r in records], np.int16).reshape(n, main.values.size),
        "1",
        f"motion label along {par} after the slow-transient check (geardyn.classify codes)",
    )
    for u in space.unknowns:
        data[u.name] = cf(
            "candidate",
            np.array([r.values[u.name] for r in records]),
            point.units_of(u.name),
            f"candidate value of {u.name}",
            search_low=u.low,
            search_high=u.high,
            search_scale="log" if u.log else "linear",
        )
    coords = {
        "candidate": cf("candidate", np.arange(n), "1", "candidate (evaluation order)"),
        par: cf(par, main.values, point.units_of(par), point.CONTROLS[par][1]),
    }
    return xr.Dataset(data, coords=coords)


def _with_values(
    source: str, name: str, values: Mapping[str, float], note: str = "calibrated"
) -> tuple[dict[str, Any], str | None]:
    """The source design (YAML text) renamed, titled "(calibrated)", with ``values`` written into its
    ``dynamics.parameters`` (w and speed as omega_bar and input_speed_rpm; b, e and x1 stay run values).
    Returns the design dict and the source design's name."""

    data = yaml.safe_load(source)
    source_name = data.get("name")
    data["name"] = name
    data["title"] = f"{data.get('title', '')} ({note})"
    params = data.setdefault("dynamics", {}).setdefault("parameters", {})
    renames = {"w": "omega_bar", "speed": "input_speed_rpm"}
    for key, value in values.items():
        if key in ("b", "e", "x1"):
            continue
        params[renames.get(key, key)] = float(value)
    return data, source_name


def search_result(
    record: Record,
    spec_name: str,
    n_evaluations: int,
    verified: Record | None = None,
    require: str | None = None,
) -> dict:
    """The part of a best record a calibrated design file stores (enough to regenerate it); ``verified``:
    the same candidate re-scored at the design's own settings."""
    out = {
        "search": spec_name,
        "evaluations": int(n_evaluations),
        "score": round(float(record.score), 6),
        "agree": int(record.agree),
        "agreeing": sorted(k for k, v in record.verdicts.items() if v == "agree"),
        "values": {k: float(f"{v:.6g}") for k, v in record.values.items()},
    }
    if require is not None:
        out["require"] = require
        out["meets_requirement"] = bool(REQUIREMENTS[require][0](record))
    if verified is not None:
        out["verified_score"] = round(float(verified.score), 6)
        out["verified_agreeing"] = sorted(k for k, v in verified.verdicts.items() if v == "agree")
    return out


def search_design_text(source: str, name: str, result: Mapping[str, Any]) -> str:
    """A calibrated design file: the source design with the searched values written into it, and a
    header that says it is calibrated, what it was fitted to, and the search result (one JSON line
    from which this text is regenerated: :func:`design_text_from_file`)."""

    note = "calibrated" + (f", {result['require']} required" if result.get("require") else "")
    data, source_name = _with_values(source, name, result["values"], note)
    paper = paper_of(data.get("paper"))
    header = (
        f"# GENERATED by the calibration search '{result['search']}' from design '{source_name}'; do not edit.\n"
        "# CALIBRATED: the values in the search result below are fitted to the paper, not taken from it.\n"
        + "".join(f"# {line}\n" for line in paper.CALIBRATION["fitted_to"])
        + (
            f"# Required: {requirement_text(result['require'], paper)}; among the candidates that meet it the claims\n"
            "# decide, so it may agree on fewer claims than a search without the requirement.\n"
            if result.get("require")
            else ""
        )
        + f"# Best of {result['evaluations']} evaluated candidates: score {result['score']:.3f}, "
        f"{result['agree']} claims agree during the search: {', '.join(result['agreeing'])}.\n"
        + (
            f"# Verified at the design's own settings: score {result['verified_score']:.3f}, "
            f"{len(result['verified_agreeing'])} agree: {', '.join(result['verified_agreeing'])}.\n"
            if "verified_score" in result
            else ""
        )
        + RESULT_PREFIX
        + json.dumps(result, sort_keys=True)
        + "\n"
    )
    return header + yaml.safe_dump(data, sort_keys=False)


def design_text_from_file(text: str, source: str) -> str:
    """Regenerate a calibrated design file from its own search-result line and the source design."""

    line = next(ln for ln in text.splitlines() if ln.startswith(RESULT_PREFIX))
    result = json.loads(line[len(RESULT_PREFIX) :])
    name = yaml.safe_load(text)["name"]
    return search_design_text(source, name, result)


def design_values(design: KHVDesign, space: SearchSpace) -> dict[str, float]:
    """The values a design has for the searched unknowns (the start of a search, a reference)."""
    phys, _, _ = point.point_model(design, {})
    out = {}
    for u in space.unknowns:
        out[u.name] = float(phys.omega_bar) if u.name == "w" else float(getattr(phys, u.name))
    return out


def search_table(
    records: Sequence[Record],
    space: SearchSpace,
    paper: ModuleType,
    best_rec: Record,
    cost: Mapping[str, float],
    top: int = 10,
    verified: Record | None = None,
    pairs: Sequence[tuple[Record, Record]] = (),
) -> str:
    """Markdown: the best candidates, the best one's bands along x1 beside the paper's, its claims."""
    order = sorted(range(len(records)), key=lambda i: -records[i].score)[:top]
    names = space.names
    lines = [
        f"# Calibration search: {len(records)} candidates scored by {paper.CALIBRATION['claims']}",
        "",
        "Score = claims that agree + 0.99 x partial credit (transition positions, regime order); docs/calibration.md.",
        "",
        "Cost: " + ", ".join(f"{k} {v:.3g}" for k, v in cost.items()),
        "",
        "| rank | " + " | ".join(names) + " | agree | partial | leave P1 | first chaos | order | score |",
        "|---|" + "---|" * len(names) + "---|---|---|---|---|---|",
    ]
    for rank, i in enumerate(order, 1):
        r = records[i]
        vals = " | ".join(f"{r.values[n]:.4g}" for n in names)
        lines.append(
            f"| {rank} | {vals} | {r.agree} | {r.partial:.3f} | {r.transitions['leave_p1']:.4g} | "
            f"{r.transitions['first_chaos']:.4g} | {r.order} | {r.score:.3f} |"
        )
    if pairs:
        lines += [
            "",
            "Verification of the best at the design's own settings (512 steps, 500 + 100 periods, default "
            "classifier with the slow-transient check); the chosen one has the highest verified score "
            "(ties: search score, then distance from the bounds):",
            "",
            "| " + " | ".join(names) + " | search score | verified score | verified agree | distance from bounds |",
            "|" + "---|" * (len(names) + 4),
        ]
        for a, b in pairs:
            lines.append(
                "| "
                + " | ".join(f"{a.values[n]:.4g}" for n in names)
                + f" | {a.score:.3f} | {b.score:.3f} | {b.agree} | {interior(a.unit):.3f} |"
            )
    rec = verified if verified is not None else best_rec
    lines += [
        "",
        f"Paper's transitions along x1: {', '.join(f'{t:g}' for t in paper.TRANSITIONS)}; "
        f"paper's regime order {paper_regime_string(paper)} (1 = P1, Q = QP, n = period > 1, C = chaos).",
        "",
        f"Chosen candidate: leaves P1 at x1 = {rec.transitions['leave_p1']:.4g}, first chaos at "
        f"{rec.transitions['first_chaos']:.4g}, regime order {rec.order}.",
        "",
        "Chosen candidate's claims verdicts (search settings; verified settings; static claims and those that "
        "need dense runs are not evaluated here):",
        "",
        "| claim | search | verified |",
        "|---|---|---|",
    ]
    checked = verified.verdicts if verified is not None else {}
    lines += [f"| {k} | {v} | {checked.get(k, '-')} |" for k, v in best_rec.verdicts.items()]
    return "\n".join(lines) + "\n"
