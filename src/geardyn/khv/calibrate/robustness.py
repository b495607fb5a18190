"""Robustness and sensitivity of a search's best candidate: one-at-a-time moves (tornado), a 2-D score map
over the two unknowns that matter most, and a Markdown summary."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

import numpy as np
import xarray as xr
from numpy.typing import DTypeLike

from geardyn import io
from geardyn.io import Var, markdown_table
from geardyn.jsontypes import Json
from geardyn.khv import point
from geardyn.khv.calibrate.evaluate import Evaluator, Problem
from geardyn.khv.calibrate.records import Record
from geardyn.khv.calibrate.space import SearchSpace, Unknown, perturbed

#: What the robustness datasets store of a record: name -> (its value, long name).
MEASURES: dict[str, tuple[Callable[[Record], float], str]] = {
    "score": (lambda r: r.score, "score"),
    "agree": (lambda r: r.agree, "claims that agree"),
    "leave_p1": (lambda r: r.transitions["leave_p1"], "first x1 not P1"),
    "first_chaos": (lambda r: r.transitions["first_chaos"], "first chaotic x1"),
}


def _grid(
    recs: Sequence[Record], coords: Sequence[tuple[Var, Json]], measures: Mapping, dtype: DTypeLike | None, attrs: dict
) -> xr.Dataset:
    """Each measure (name -> (value of a record, long name)) of ``recs`` on the grid of ``coords`` (each a variable
    and its values), with the global ``attrs``."""
    shape, dims = tuple(len(v) for _, v in coords), tuple(var.name for var, _ in coords)
    data = {name: np.array([f(r) for r in recs], dtype).reshape(shape) for name, (f, _) in measures.items()}
    table = [*(Var(name, dims, "1", long_name) for name, (_, long_name) in measures.items()), *(c for c, _ in coords)]
    return io.dataset(table, data | {var.name: values for var, values in coords}, **attrs)


def sensitivity(
    problem: Problem,
    evaluator: Evaluator,
    best_values: Mapping[str, float],
    steps: Sequence[float],
    map_points: int = 7,
) -> tuple[xr.Dataset, xr.Dataset, str]:
    """Robustness and sensitivity of the best candidate: one-at-a-time moves of each unknown by +-step
    (tornado), then a 2-D score map over the two unknowns that move the score most (docs/calibration.md,
    "Robustness and sensitivity").  Returns (one-at-a-time dataset, map dataset, Markdown summary)."""
    space = problem.space
    base = evaluator.records([list(space.unit(best_values))])[0]
    steps = sorted(float(s) for s in steps)
    signed = [-s for s in reversed(steps)] + steps
    oat = one_at_a_time(space, evaluator, best_values, base, signed)
    impact = np.nanmax(np.abs(oat["score"].values - base.score), axis=1)
    order = np.argsort(-impact, kind="stable")
    a, b = space.unknowns[order[0]], space.unknowns[order[1]]
    mp = score_map(space, evaluator, best_values, a, b, map_points)
    return oat, mp, summary(space, oat, mp, base, best_values, steps, impact)


def one_at_a_time(
    space: SearchSpace,
    evaluator: Evaluator,
    best_values: Mapping[str, float],
    base: Record,
    signed: Sequence[float],
) -> xr.Dataset:
    """Each unknown moved by each relative step of ``signed`` (the others at ``best_values``): score,
    agreeing claims, transitions along x1, and whether any verdict or label along x1 changed."""
    recs = evaluator.records(space.one_at_a_time(best_values, signed))
    main = evaluator.problem.grids.main
    measures = {
        **MEASURES,
        "verdicts_changed": (lambda r: r.verdicts != base.verdicts, "1 when any claim verdict differs from the best's"),
        "labels_changed": (
            lambda r: r.labels[main] != base.labels[main],
            "1 when any label along x1 differs from the best's",
        ),
    }
    coords = [
        (Var("unknown", "unknown", "1", "searched unknown"), space.names),
        (Var("step", "step", "1", "relative move of the unknown"), np.array(signed)),
    ]
    return _grid(recs, coords, measures, float, {f"base_{name}": value(base) for name, (value, _) in MEASURES.items()})


def score_map(
    space: SearchSpace,
    evaluator: Evaluator,
    best_values: Mapping[str, float],
    a: Unknown,
    b: Unknown,
    map_points: int,
) -> xr.Dataset:
    """Score, agreeing claims and where P1 is left along x1 over ``a`` (across) and ``b`` (up), each
    moved by -50 % .. +50 % in ``map_points`` steps."""
    rel = np.linspace(-0.5, 0.5, map_points)
    va, vb = ([perturbed(best_values[u.name], u, r) for r in rel] for u in (a, b))
    recs = evaluator.records(space.moved(best_values, [{a.name: x, b.name: y} for y in vb for x in va]))
    measures = {k: MEASURES[k] for k in ("score", "agree", "leave_p1")}
    coords = [
        (Var(u.name, u.name, point.units_of(u.name), f"{u.name} (searched unknown)"), np.array(v))
        for u, v in ((b, vb), (a, va))
    ]
    attrs = {"x": a.name, "y": b.name, "best_x": best_values[a.name], "best_y": best_values[b.name]}
    return _grid(recs, coords, measures, None, attrs)


def summary(
    space: SearchSpace,
    oat: xr.Dataset,
    mp: xr.Dataset,
    base: Record,
    best_values: Mapping[str, float],
    steps: Sequence[float],
    impact: np.ndarray,
) -> str:
    """Markdown: per unknown its value, bounds, position in them, the smallest moves that change a verdict
    or a label along x1, the largest score change; then the map's best score."""
    signed = oat["step"].values.tolist()

    def smallest(changed: np.ndarray) -> str:
        """The smallest move (of ``signed``) that changed something, or '> largest step'."""
        d = min((abs(s) for s, c in zip(signed, changed, strict=True) if c), default=None)
        return "> " + format(max(steps), "g") if d is None else "+-" + format(d, "g")

    lines = [
        "# Calibration: robustness and sensitivity of the best candidate",
        "",
        f"Best: score {base.score:.3f}, {base.agree} claims agree, leaves P1 at x1 = "
        f"{base.transitions['leave_p1']:.4g}, first chaos at {base.transitions['first_chaos']:.4g}.",
        "",
    ]
    cells = []
    for k, u in enumerate(space.unknowns):
        pos = u.to_unit(best_values[u.name])
        edge = " (edge)" if min(pos, 1 - pos) < 0.05 else ""
        changed = [smallest(oat[f"{what}_changed"].values[k]) for what in ("verdicts", "labels")]
        bounds = f"[{u.low:g}, {u.high:g}]{' log' if u.log else ''}"
        cells.append((u.name, f"{best_values[u.name]:.4g}", bounds, f"{pos:.2f}{edge}", *changed, f"{impact[k]:.3f}"))
    head = ("unknown", "value", "bounds", "position in bounds", "smallest move changing a verdict")
    lines.append(markdown_table((*head, "smallest move changing a label along x1", "max score change"), cells))
    lines += [
        "",
        f"2-D map over {mp.attrs['x']} and {mp.attrs['y']} (the two with the largest score change): best score on "
        f"the map {float(mp['score'].max()):.3f}, at the centre {base.score:.3f}.",
    ]
    return "\n".join(lines) + "\n"
