"""The cost of a probabilities study against a regime map, both in one run (``python -m benchmarks.bench
probabilities``): ``samples`` x ``points`` of a study's axis (default 256 x 100 of ``fig07_unknowns``, paper 1's
unknowns along x1: 25 600 points) against the map ``map_x1_b`` (40 000 points), each labelled in one call on
every core, and the study's summary (probabilities, quantiles, SALib indices)."""

from __future__ import annotations

import os
import time
from pathlib import Path

from benchmarks.common import load_design, map_lines, map_study, timed_labels, workflow_config
from geardyn.khv import point
from geardyn.runs import cube, probabilities, probability_stats, tolerance_classes
from geardyn.solve import warm_up


def _timed_map(config_path: Path, map_name: str, every: int | None, log, tag: str) -> tuple[int, float, float]:
    """The map's points (every ``every``-th row; None: all) labelled in one call: (points, wall s, CPU s)."""
    _, design, spec, policy = map_study(config_path, map_name)
    warm_up(point.point_coefficients(design))
    lines = map_lines(design, spec, None if every is None else range(0, spec.y.num, every))
    _, t_map, c_map = timed_labels(lines, policy)
    n_map = sum(map(len, lines))
    log(f"[{tag}] {map_name}: {n_map} points in {t_map:.1f} s wall, {c_map:.0f} CPU-s")
    return n_map, t_map, c_map


def _timed_study(config_path: Path, study: str, samples: int, points: int):
    """The study at ``samples`` x ``points`` in one chunk: (its spec, design, chunk, wall s, CPU s)."""
    config = workflow_config(config_path)
    raw = {**config["probabilities"][study], "samples": samples, "chunks": 1}
    raw["axis"] = {**raw["axis"], "num": points}
    dname = raw["designs"][0]
    drive = load_design(dname, config, config_path.resolve().parent.parent)
    pspec = probabilities.ProbabilitySpec.from_config(study, raw, dname, drive.segment)
    t0, c0 = time.perf_counter(), time.process_time()
    ds = probabilities.run_chunk(drive, pspec, 0)
    return pspec, drive, ds, time.perf_counter() - t0, time.process_time() - c0


def probabilities_benchmark(
    config_path: Path,
    study: str = "fig07_unknowns",
    map_name: str = "map_x1_b",
    samples: int = 256,
    points: int = 100,
    quick: bool = False,
    log=print,
) -> str:
    """The wall and CPU times of the map and of the study (labels, then summary) and their ratios (Markdown)."""
    n_map, t_map, c_map = _timed_map(config_path, map_name, 20 if quick else None, log, "probabilities")
    pspec, drive, ds, t_run, c_run = _timed_study(config_path, study, 16 if quick else samples, 20 if quick else points)
    t0 = time.perf_counter()
    probability_stats.summarize(cube.merge_chunks([ds]), pspec, probabilities.samples(drive, pspec))
    t_sum = time.perf_counter() - t0
    n = int(ds["computed"].sum())
    log(f"[probabilities] {study}: {n} points in {t_run:.1f} s wall, {c_run:.0f} CPU-s; summary {t_sum:.1f} s")
    return (
        f"Load average {os.getloadavg()[0]:.1f} at the end; both labelled in one call on every core.\n\n"
        "| what | points | wall (s) | CPU (s) | wall / map's |\n|---|---:|---:|---:|---:|\n"
        f"| map {map_name} | {n_map} | {t_map:.1f} | {c_map:.0f} | 1 |\n"
        f"| {study}: ({pspec.samples} samples + {pspec.index_samples} index lines) x {ds.sizes[pspec.dim]} points "
        f"| {n} | {t_run:.1f} | {c_run:.0f} | "
        f"{t_run / t_map:.2f} |\n"
        f"| its summary (probabilities, quantiles, {pspec.method} indices) | | {t_sum:.1f} | | {t_sum / t_map:.2f} |\n"
    )


def class_benchmark(
    config_path: Path,
    study: str = "classes_w_calibrated",
    map_name: str = "map_x1_b",
    samples: int = 128,
    points: int = 100,
    every: int = 10,
    log=print,
) -> str:
    """The class study's target (7 classes x ``samples`` x ``points`` against ``map_name``, at most twice its
    cost), both thinned alike in one run: every ``every``-th row of the map and ``points`` / ``every`` points of
    the study's axis, so the ratio is that of the full sizes (Markdown)."""
    n_map, t_map, c_map = _timed_map(config_path, map_name, every, log, "classes")
    pspec, drive, ds, t_run, c_run = _timed_study(config_path, study, samples, max(1, points // every))
    t0 = time.perf_counter()
    tolerance_classes.summarize(cube.merge_chunks([ds]), pspec, drive)
    t_sum = time.perf_counter() - t0
    n = int(ds["computed"].sum())
    log(f"[classes] {study}: {n} points in {t_run:.1f} s wall, {c_run:.0f} CPU-s; summary {t_sum:.1f} s")
    size = f"{len(pspec.classes)} classes x {samples} samples x {ds.sizes[pspec.dim]} points"
    return (
        f"Load average {os.getloadavg()[0]:.1f} at the end; both labelled in one call on every core, both thinned "
        f"by {every} (the map's rows, the study's points).\n\n"
        "| what | points | wall (s) | CPU (s) | wall / map's | CPU / map's |\n|---|---:|---:|---:|---:|---:|\n"
        f"| map {map_name}, every {every}th row | {n_map} | {t_map:.1f} | {c_map:.0f} | 1 | 1 |\n"
        f"| {study}: {size} | {n} | {t_run:.1f} | {c_run:.0f} | {t_run / t_map:.2f} | {c_run / c_map:.2f} |\n"
        f"| its summary | | {t_sum:.1f} | | {t_sum / t_map:.2f} | |\n"
    )
