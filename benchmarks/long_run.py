"""Independent check of the labeller: random map points run long from their follow start."""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path

import numpy as np

from benchmarks.common import map_lines, map_study
from geardyn import classify
from geardyn.label import label_lines
from geardyn.label.compare import directed_distance, hausdorff
from geardyn.solve import SimulationSettings
from geardyn.solve.simulate import simulate_batch


def long_run_check(
    config_path: Path, map_name: str = "map_x1_b", n_points: int = 200, periods: int = 20000, seed: int = 0, log=print
) -> str:
    """Independent check of the labeller: ``n_points`` random points of a regime map, each run ``periods``
    mesh periods (plain RK4, no labeller) from the state its follow start used (the previous point's
    final state on its row, the static deflection for a row's first point).  A periodic verdict must be
    met by the long run's end: the same least period (rule 3 on its last periods, at least three cycles;
    up to ``long_max_n`` for a long cycle) and the same orbit within 1e-6 (every point the verdict stores, at
    most ``recorded_periods`` of a longer cycle, within 1e-6 of the long run's cycle).  A non-periodic verdict must
    not end on a cycle (rule 3 up to ``long_max_n`` on three of its longest periods)."""

    dname, design, spec, policy = map_study(config_path, map_name)
    rng = np.random.default_rng(seed)
    picks = sorted({(int(rng.integers(spec.y.num)), int(rng.integers(spec.x.num))) for _ in range(n_points)})
    rows = sorted({j for j, _ in picks})
    t0 = time.perf_counter()
    lines = map_lines(design, spec, rows)

    verdicts = dict(zip(rows, label_lines(lines, policy), strict=True))
    systems, starts, want = [], [], []
    for j, i in picks:
        row, line = verdicts[j], lines[rows.index(j)]
        systems.append(line[i])
        starts.append(row[i - 1].final_state if i > 0 and not row[i - 1].diverged else None)
        want.append(row[i])
    s = SimulationSettings(
        steps_per_period=policy.integration.steps_per_period,
        transient_periods=periods - 64,
        recorded_periods=64,
        early_stop=False,
    )
    # rule 3 up to the longest cycle the labeller looks for, on three of its periods (a periodic verdict: its
    # own period), so that a non-periodic verdict whose run ends on a long cycle is seen too
    cs = policy.classifier
    long_cs = dataclasses.replace(cs, max_n=cs.long_max_n)
    records = [max(64, 3 * (v.period if v.period > 0 else cs.long_max_n)) for v in want]
    runs = simulate_batch(systems, s, starts, recorded_periods=records)
    rows_md = [
        "| x | y | verdict | stage | long run: rule-3 period | orbit distance | agrees |",
        "|---:|---:|---|---|---:|---:|---|",
    ]
    counts = {"periodic": [0, 0], "other": [0, 0]}
    for (j, i), v, r in zip(picks, want, runs, strict=True):
        n = 0 if r.diverged else classify.strict_period(r.poincare, cs if 0 < v.period <= cs.max_n else long_cs)
        if v.period > 0:
            # the verdict keeps the newest ``recorded_periods`` points: a cycle longer than that is stored in
            # part, so every stored point must lie on the long run's cycle (with the same least period, the
            # same cycle); a shorter cycle is compared whole
            ours = v.poincare[: v.period]
            theirs = r.poincare[-v.period :]
            dist = float("inf")
            if not r.diverged:
                dist = hausdorff(theirs, ours) if ours.shape[0] == v.period else directed_distance(ours, theirs)
            ok = n == v.period and dist < 1e-6
            counts["periodic"][0] += ok
            counts["periodic"][1] += 1
        else:
            dist = float("nan")
            ok = n == 0 if v.label != classify.LABELS["diverged"] else r.diverged
            counts["other"][0] += ok
            counts["other"][1] += 1
        if not ok or v.period == 0:
            rows_md.append(
                f"| {spec.x.values[i]:.4g} | {spec.y.values[j]:.4g} | {classify.short_name(v.label)} | "
                f"{v.stage} | {n} | {dist:.2g} | {ok} |"
            )
    head = (
        f"{map_name} of {dname}: {len(picks)} random points, {periods} periods each "
        f"({time.perf_counter() - t0:.0f} s). Periodic verdicts met by the long run (same least period, orbit "
        f"within 1e-6): {counts['periodic'][0]} of {counts['periodic'][1]}. Non-periodic verdicts whose long "
        f"run is still not periodic: {counts['other'][0]} of {counts['other'][1]}.\n\n"
    )
    log(head)
    return head + "\n".join(rows_md) + "\n"
