"""Robustness and sensitivity of a search's best candidate: one-at-a-time moves (tornado), a 2-D score map
over the two unknowns that matter most, and a Markdown summary."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

import numpy as np
import xarray as xr

from geardyn.io import cf
from geardyn.khv import point
from geardyn.khv.calibrate.evaluate import Evaluator, Problem
from geardyn.khv.calibrate.records import Record
from geardyn.khv.calibrate.space import SearchSpace, Unknown, perturbed


def sensitivity(
    problem: Problem,
    evaluator: Evaluator,
    best_values: Mapping[str, float],
    steps: Sequence[float],
    map_points: int = 7,
) -> tuple[xr.Dataset, xr.Dataset, str]:
    """Robustness and sensitivity of the best candidate.

    One-at-a-time moves of each unknown by +-step (:func:`perturbed`) give the score, the number of
    agreeing claims and the transitions along x1 (tornado); the smallest move that changes any claim
    verdict, or any label along x1, is the distance to the nearest label change.  Then a 2-D map of
    the score over the two unknowns whose moves change the score most (+-50 %, ``map_points`` per
    axis).  Returns (one-at-a-time dataset, map dataset, Markdown summary).
    """
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
    units = []
    for u in space.unknowns:
        for st in signed:
            v = dict(best_values)
            v[u.name] = perturbed(best_values[u.name], u, st)
            units.append(list(space.unit(v)))
    recs = evaluator.records(units)
    main = evaluator.problem.grids.main
    shape = (len(space.unknowns), len(signed))
    dims = ("unknown", "step")

    def grid(fn: Callable[[Record], float]) -> np.ndarray:
        return np.array([fn(r) for r in recs], float).reshape(shape)

    return xr.Dataset(
        {
            "score": cf(dims, grid(lambda r: r.score), "1", "score"),
            "agree": cf(dims, grid(lambda r: r.agree), "1", "claims that agree"),
            "leave_p1": cf(dims, grid(lambda r: r.transitions["leave_p1"]), "1", "first x1 not P1"),
            "first_chaos": cf(dims, grid(lambda r: r.transitions["first_chaos"]), "1", "first chaotic x1"),
            "verdicts_changed": cf(
                dims,
                grid(lambda r: float(r.verdicts != base.verdicts)),
                "1",
                "1 when any claim verdict differs from the best's",
            ),
            "labels_changed": cf(
                dims,
                grid(lambda r: float(r.labels[main] != base.labels[main])),
                "1",
                "1 when any label along x1 differs from the best's",
            ),
        },
        coords={
            "unknown": cf("unknown", space.names, "1", "searched unknown"),
            "step": cf("step", np.array(signed), "1", "relative move of the unknown"),
        },
        attrs={
            "base_score": base.score,
            "base_agree": base.agree,
            "base_leave_p1": base.transitions["leave_p1"],
            "base_first_chaos": base.transitions["first_chaos"],
        },
    )


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
    va = [perturbed(best_values[a.name], a, r) for r in rel]
    vb = [perturbed(best_values[b.name], b, r) for r in rel]
    units = []
    for y in vb:
        for x in va:
            v = dict(best_values)
            v[a.name], v[b.name] = x, y
            units.append(list(space.unit(v)))
    recs = evaluator.records(units)
    shape = (map_points, map_points)
    dims = (b.name, a.name)
    return xr.Dataset(
        {
            "score": cf(dims, np.array([r.score for r in recs]).reshape(shape), "1", "score"),
            "agree": cf(dims, np.array([r.agree for r in recs]).reshape(shape), "1", "claims that agree"),
            "leave_p1": cf(
                dims, np.array([r.transitions["leave_p1"] for r in recs]).reshape(shape), "1", "first x1 not P1"
            ),
        },
        coords={
            a.name: cf(a.name, np.array(va), point.units_of(a.name), f"{a.name} (searched unknown)"),
            b.name: cf(b.name, np.array(vb), point.units_of(b.name), f"{b.name} (searched unknown)"),
        },
        attrs={"x": a.name, "y": b.name, "best_x": best_values[a.name], "best_y": best_values[b.name]},
    )


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
    lines = [
        "# Calibration: robustness and sensitivity of the best candidate",
        "",
        f"Best: score {base.score:.3f}, {base.agree} claims agree, leaves P1 at x1 = "
        f"{base.transitions['leave_p1']:.4g}, first chaos at {base.transitions['first_chaos']:.4g}.",
        "",
        "| unknown | value | bounds | position in bounds | smallest move changing a verdict | smallest move "
        "changing a label along x1 | max score change |",
        "|---|---|---|---|---|---|---|",
    ]
    for k, u in enumerate(space.unknowns):
        vc = oat["verdicts_changed"].values[k]
        lc = oat["labels_changed"].values[k]
        dv = min((abs(s) for s, c in zip(signed, vc, strict=True) if c), default=None)
        dl = min((abs(s) for s, c in zip(signed, lc, strict=True) if c), default=None)
        pos = u.to_unit(best_values[u.name])
        lines.append(
            f"| {u.name} | {best_values[u.name]:.4g} | [{u.low:g}, {u.high:g}]{' log' if u.log else ''} | "
            f"{pos:.2f}{' (edge)' if min(pos, 1 - pos) < 0.05 else ''} | "
            f"{'> ' + format(max(steps), 'g') if dv is None else '+-' + format(dv, 'g')} | "
            f"{'> ' + format(max(steps), 'g') if dl is None else '+-' + format(dl, 'g')} | {impact[k]:.3f} |"
        )
    lines += [
        "",
        f"2-D map over {mp.attrs['x']} and {mp.attrs['y']} (the two with the largest score change): best score on "
        f"the map {float(mp['score'].max()):.3f}, at the centre {base.score:.3f}.",
    ]
    return "\n".join(lines) + "\n"
