"""The cost of a map's regime boundaries against the cost of the map: ``python -m benchmarks.bench curves
[--map map_x1_b] [--rows 10] [--new results]``; ``--rows 0``: no labelling, the curves of the built map and
their pixel check with its table (every sample not passed).

In one process, one core (numba's threads set to 1, as a map chunk job runs): every ``rows``-th row of the
map labelled as a chunk job labels it (:func:`geardyn.runs.maps.run_chunk`: the labeller, the response
measures, the cube), scaled to the whole map; then all its curves (:func:`geardyn.runs.continuation.
curve_maps.boundary_curves`: the branches along the cut lines, their curves, the map's records) from the
built map cube under ``--new``, and the pixel check.  Prints the ratio (target: at most 10 %) and the chunk
jobs' own wall times from the built cube for comparison.
"""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path

import numba

from benchmarks.common import map_study, workflow_config
from geardyn import io
from geardyn.khv import point
from geardyn.plots.curves import check_table
from geardyn.runs import maps
from geardyn.runs.continuation import curve_maps
from geardyn.solve import warm_up


def curves_benchmark(config: Path, results: Path, map_name: str = "map_x1_b", every: int = 10, log=print) -> str:
    """The Markdown report of the benchmark (module doc)."""
    numba.set_num_threads(1)
    dname, design, spec, _ = map_study(config, map_name)
    entry = workflow_config(config)["maps"][map_name]
    cube_path = results / dname / "maps" / f"{map_name}.nc"
    if not cube_path.exists():
        raise SystemExit(f"{cube_path} is missing: build the map first (snakemake --cores 2 {cube_path})")
    cube = io.read_dataset(cube_path)
    warm_up(point.point_coefficients(design))
    if every == 0:
        return _check_only(cube, design, spec, entry, map_name, dname, log)

    part = dataclasses.replace(spec, chunks=every)
    t0 = time.perf_counter()
    maps.run_chunk(design, part, 0)
    t_rows = time.perf_counter() - t0
    n_rows = len(maps.chunk_rows(part, 0))
    t_map = t_rows * spec.y.num / n_rows
    log(f"{n_rows} of {spec.y.num} rows labelled in {t_rows:.2f} s: the map {t_map:.1f} s")

    bd, check, settings = curve_maps.map_boundaries(design, spec, entry, cube)
    t_curves = bd.timing["total"]
    log(f"{len(bd.curves)} curves in {t_curves:.2f} s, pixel check {check.seconds:.2f} s")

    built = [float(v) for v in str(cube.attrs.get("chunk_wall_time_s", "")).split(",") if v]
    rows = [
        "| stage | seconds | of the map |",
        "|---|---|---|",
        f"| labelling the map ({n_rows} of {spec.y.num} rows, scaled) | {t_map:.2f} | 100 % |",
        f"| all curves ({len(bd.curves)}; lines {bd.timing['lines']:.2f} s, records "
        f"{bd.timing.get('records', 0):.2f} s) | {t_curves:.2f} | {100 * t_curves / t_map:.1f} % |",
        f"| pixel check ({len(check.samples)} crossings) | {check.seconds:.2f} | {100 * check.seconds / t_map:.1f} % |",
        f"| curves and check | {t_curves + check.seconds:.2f} | {100 * (t_curves + check.seconds) / t_map:.1f} % |",
    ]
    if built:
        rows.append(
            f"| the build's chunk jobs ({len(built)}, wall) | {sum(built):.2f} | {100 * sum(built) / t_map:.1f} % |"
        )
    head = f"{map_name} ({dname}, {spec.x.num} x {spec.y.num}, {settings.steps_per_period} steps per period)"
    return (
        head
        + ", one core:\n\n"
        + "\n".join(rows)
        + f"\n\nratio curves / map: {t_curves / t_map:.3f} (target <= 0.10); with the pixel check "
        f"{(t_curves + check.seconds) / t_map:.3f}\n"
    )


def _check_only(cube, design, spec, entry, map_name: str, dname: str, log) -> str:
    """The curves of the built map and their pixel check: its attributes and table."""
    bd, check, _ = curve_maps.map_boundaries(design, spec, entry, cube)
    log(f"{len(bd.curves)} curves in {bd.timing['total']:.2f} s, pixel check {check.seconds:.2f} s")
    ds = curve_maps.boundary_dataset(bd, check)
    head = f"{map_name} ({dname}): {len(bd.curves)} curves, pixel check in {check.seconds:.2f} s\n\n"
    return head + "\n".join(f"- {k}: {v}" for k, v in check.attrs().items()) + "\n" + check_table(map_name, ds)
