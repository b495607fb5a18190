"""Independent check of the non-periodic labels: the invariant circle of each point, computed by Newton.

For random rows of a regime map, every point is labelled (follow start), and up to ``per_class`` points of
each non-periodic label are run on for ``periods`` mesh periods from their verdict's final state.  Newton's
method on the invariance equation (:mod:`benchmarks.invariant_circle`) then looks for the invariant circle near the
record.  A point *lies on an attracting circle* when Newton converges, the invariance error between the nodes
is at most ``tol``, the normal radius is below 1 and every point of the newest half of the record is within
``tol`` of the circle (relative to max(1, |K|)).  A quasi-periodic verdict is confirmed by such a circle; a
chaotic one must have none.  The table also says how long the labeller and the circles took per point.
"""

from __future__ import annotations

import time
from collections import Counter
from pathlib import Path

import numpy as np

from benchmarks.common import map_lines, map_study
from benchmarks.invariant_circle import distance_to_circle, find_circles
from geardyn.io import markdown_table
from geardyn.label import label_lines, vocabulary
from geardyn.solve import SimulationSettings
from geardyn.solve.base import Lane
from geardyn.solve.run import simulate_batch

#: the labels whose points are checked
CLASSES = ("quasi_periodic", "long_period", "chaotic", "undetermined")


def _outcome(c, record: np.ndarray, tol: float) -> tuple[str, float, float]:
    """('on circle' | 'circle, run off it' | 'unstable circle' | 'unresolved' | 'no circle', invariance, distance)."""
    if c is None or not c.converged:
        return "no circle", float("nan"), float("nan")
    dist = float(np.max(distance_to_circle(c.nodes, record))) / max(1.0, float(np.max(np.abs(c.nodes))))
    if not c.invariance <= tol:
        return "unresolved", c.invariance, dist
    if not c.normal_radius < 1.0:
        return "unstable circle", c.invariance, dist
    return ("on circle" if dist <= tol else "circle, run off it"), c.invariance, dist


def circle_check(
    config_path: Path,
    map_name: str = "map_x1_e",
    n_rows: int = 10,
    per_class: int = 40,
    periods: int = 400,
    nodes: int = 41,
    tol: float = 1e-3,
    seed: int = 0,
    log=print,
) -> str:
    """The markdown report of the check (see the module's docstring)."""
    dname, design, spec, policy = map_study(config_path, map_name)
    rng = np.random.default_rng(seed)
    rows = sorted(int(j) for j in rng.choice(spec.y.num, size=min(n_rows, spec.y.num), replace=False))
    lines = map_lines(design, spec, rows)
    t0 = time.perf_counter()
    verdicts = label_lines(lines, policy)
    t_label = (time.perf_counter() - t0) / sum(len(line) for line in lines)
    s = SimulationSettings(
        steps_per_period=policy.integration.steps_per_period, transient_periods=0, recorded_periods=periods
    )
    md = [
        f"{map_name} of {dname}: rows {rows}; up to {per_class} points per label, run on {periods} periods "
        f"from the verdict's final state; circles on {nodes} nodes, tolerance {tol:g}. The labeller took "
        f"{1e3 * t_label:.1f} ms per point of these rows.\n",
    ]
    cells = []
    for name in CLASSES:
        code = vocabulary.LABELS[name]
        where = [(r, i) for r, row in enumerate(verdicts) for i, v in enumerate(row) if v.label == code]
        if not where:
            continue
        pick = [where[k] for k in sorted(rng.choice(len(where), size=min(per_class, len(where)), replace=False))]
        systems = [lines[r][i] for r, i in pick]
        t1 = time.perf_counter()
        runs = simulate_batch([Lane(c, verdicts[r][i].final_state) for c, (r, i) in zip(systems, pick, strict=True)], s)
        circles = find_circles(systems, [run.poincare for run in runs], s, m=nodes)
        t_circle = (time.perf_counter() - t1) / len(pick)
        outcomes = [_outcome(c, run.poincare[periods // 2 :], tol) for c, run in zip(circles, runs, strict=True)]
        counts = Counter(o[0] for o in outcomes)
        inv = [o[1] for o in outcomes if np.isfinite(o[1])]
        found = (counts[k] for k in ("on circle", "circle, run off it", "unstable circle", "unresolved", "no circle"))
        cells.append(
            (name, len(pick), *found, f"{np.median(inv) if inv else float('nan'):.1e}", f"{1e3 * t_circle:.0f}")
        )
        log(cells[-1])
    head = ("label", "points", "on an attracting circle", "circle, run off it", "unstable circle", "unresolved")
    head += ("no circle", "median invariance", "ms per point")
    return "\n".join([*md, markdown_table(head, cells, "-" + "r" * 8)]) + "\n"
