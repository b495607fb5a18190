"""Run the benchmarks: ``python -m benchmarks.bench [--out DIR] [--quick]`` (work precision),
``python -m benchmarks.bench throughput|labels|check ...`` (see ``--help`` of each), ``python -m benchmarks.bench
growth --old OLD --new NEW [--points 300] [--csv FILE]`` (the points whose label moved between two builds, run
20 000 periods from their follow start),
``python -m benchmarks.bench curves [--map map_x1_b] [--rows 10]`` (a map's regime boundaries against the map),
``python -m benchmarks.bench coverage [--new results]`` (the coverage of the frequency response's RMS error bars),
``python -m benchmarks.bench probabilities`` (256 samples x 100 points of a probabilities study against map_x1_b),
``python -m benchmarks.bench classes [--rows 10]`` (the class study, 7 classes x 128 samples x 100 points, against
map_x1_b, both thinned by --rows),
``python -m benchmarks.bench fingerprint [--write]`` (a hash per stage of a small fixed study, to compare
machines; ``--write`` replaces the committed reference), ``python -m benchmarks.bench ledger [--write]`` (the
cost of fixed small workloads in kernel point-steps against the committed reference; ``ledger --log LOG
[--reference-log LOG]``: a build's job-seconds per stage from its Snakemake log), ``python -m benchmarks.bench
stages [map | design/sweep]`` (the labeller's periods by stage and label).

Single-threaded by construction when run as a program (thread pools pinned to 1 before numpy/numba
load); importing the module sets nothing.
"""

from __future__ import annotations

import os

if __name__ == "__main__":  # run as a program only: importing this module changes nothing
    for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(_v, "1")
# numba threads: one for the work-precision study (set in run()), all cores for ``throughput``

import argparse
import sys
from pathlib import Path

from benchmarks import (
    circles,
    coverage,
    curves,
    fingerprint,
    labels,
    ledger,
    long_run,
    probabilities,
    stages,
    throughput,
    work_precision,
)
from geardyn import io, libm
from geardyn.io import provenance


def main_speed(argv: list[str]) -> int:
    """``throughput`` (follow against fixed starts, kernel, DOP853), ``labels`` (the labels of two builds'
    cubes compared), ``check`` (random map points run long from their follow start), ``growth`` (the points whose
    label moved between two builds run long from their follow start), ``circles`` (the
    invariant circles of the non-periodic labels of random map rows) and ``curves`` (a map's regime
    boundaries against the map itself) modes."""
    ap = argparse.ArgumentParser(prog=f"python -m benchmarks.bench {argv[0]}")
    ap.add_argument("--out", type=Path, default=None, help="directory for the .md (and .nc) written")
    ap.add_argument("--config", type=Path, default=Path("config/config.yaml"))
    ap.add_argument("--quick", action="store_true", help="short runs (smoke test)")
    ap.add_argument("--old", type=Path, help="labels: the results/ directory of the earlier build")
    ap.add_argument("--new", type=Path, default=Path("results"), help="labels: the results/ directory to compare")
    ap.add_argument(
        "--explain",
        nargs="*",
        help="labels: cubes (design/sweeps|maps/name) whose differing points are labelled again from the fixed start",
    )
    ap.add_argument("--points", type=int, default=200, help="check: random map points; growth: per map")
    ap.add_argument("--csv", type=Path, default=None, help="growth: the per-point list written here")
    ap.add_argument("--gap", type=int, default=1000, help="coverage: mesh periods between the two records")
    ap.add_argument("--periods", type=int, default=20000, help="check: mesh periods of each long run")
    ap.add_argument("--map", default=None, help="check, circles: the regime map (map_x1_b, map_x1_e)")
    ap.add_argument(
        "--rows", type=int, default=10, help="circles: random rows of the map labelled; curves: every n-th row labelled"
    )
    ap.add_argument(
        "--sweeps",
        nargs="*",
        help="check: the built sweeps' points with these labels (quasi_periodic, chaotic, long_period, "
        "periodic, all) instead of a map's, read from --new",
    )
    ap.add_argument("--designs", nargs="*", help="check --sweeps: only these designs' cubes")
    a = ap.parse_args(argv[1:])
    log = lambda m: print(m, flush=True)  # noqa: E731
    ds = None
    if argv[0] == "throughput":
        out = throughput.throughput(a.config, quick=a.quick, log=log)
        md = "# Throughput: the follow start against the fixed start (the same labeller, one run)\n\n"
        md += throughput.throughput_markdown(out)
        ds = throughput.throughput_dataset(out)
    elif argv[0] == "labels":
        md = "# Labels of two builds compared, cube by cube\n\n" + labels.compare_builds(a.old, a.new)
        for item in a.explain or ():
            design, kind, name = item.split("/")
            md += "\n" + labels.explain_differences(a.config, a.old, a.new, design, kind, name, log=log)
    elif argv[0] == "probabilities":
        md = "# A probabilities study against a regime map (one run)\n\n" + probabilities.probabilities_benchmark(
            a.config, quick=a.quick, log=log
        )
    elif argv[0] == "classes":
        md = "# The class study against a regime map (one run)\n\n" + probabilities.class_benchmark(
            a.config, every=a.rows or 10, log=log
        )
    elif argv[0] == "curves":
        md = "# Regime boundaries against the map\n\n" + curves.curves_benchmark(
            a.config, a.new, a.map or "map_x1_b", every=a.rows, log=log
        )
    elif argv[0] == "circles":
        md = "# Invariant circles of the non-periodic labels\n\n" + circles.circle_check(
            a.config, map_name=a.map or "map_x1_e", n_rows=2 if a.quick else a.rows, per_class=5 if a.quick else 40
        )
    elif argv[0] == "coverage":
        md = "# Coverage of the RMS error bars\n\n" + coverage.coverage_check(a.config, a.new, gap=a.gap, log=log)
    elif argv[0] == "growth":
        md = "# Independent check: the points whose label moved, run long from their follow start\n\n"
        md += long_run.growth_check(a.config, a.old, a.new, map_points=a.points, periods=a.periods, log=log, csv=a.csv)
    elif a.sweeps is not None:
        md = "# Independent check: long runs from the sweeps' stored points\n\n" + long_run.sweep_check(
            a.config,
            a.new,
            tuple(a.sweeps) or ("quasi_periodic",),
            n_points=a.points,
            periods=a.periods,
            log=log,
            designs=tuple(a.designs or ()),
        )
    else:
        md = "# Independent check: long runs from the follow start\n\n" + long_run.long_run_check(
            a.config, map_name=a.map or "map_x1_b", n_points=a.points, periods=a.periods, log=log
        )
    print(md)
    if a.out is not None:
        a.out.mkdir(parents=True, exist_ok=True)
        io.write_text(md, a.out / f"{argv[0]}.md")
        if ds is not None:
            io.write_netcdf(
                ds,
                a.out / f"{argv[0]}.nc",
                provenance.attributes(title=ds.attrs["title"], paper="li2013", model_variant="benchmark"),
            )
        print(f"wrote {a.out}/{argv[0]}.*")
    return 0


def main_fingerprint(argv: list[str]) -> int:
    """Print the fingerprint (:mod:`benchmarks.fingerprint`) and the machine; with ``--write``, replace the
    committed reference (only when a change of the code means to change those bits)."""
    ap = argparse.ArgumentParser(prog="python -m benchmarks.bench fingerprint")
    ap.add_argument("--write", action="store_true", help="write benchmarks/fingerprint.txt")
    a = ap.parse_args(argv)
    stages = fingerprint.study()
    text = fingerprint.format_lines(stages)
    where = "".join(f"# {k}: {v}\n" for k, v in fingerprint.machine().items())
    print(where + text, end="")
    differs = fingerprint.first_difference(stages, fingerprint.read_reference())
    print(f"reference: {'the same' if differs is None else 'differs from ' + differs + ' on'}")
    if a.write:
        fingerprint.REFERENCE.write_text(
            "# python -m benchmarks.bench fingerprint --write, on the machine below\n" + where + text
        )
        print(f"wrote {fingerprint.REFERENCE}")
    return 0


def main_stages(argv: list[str]) -> int:
    """Where the labeller's periods go (:mod:`benchmarks.stages`), on map rows or a sweep's chunk 0."""
    ap = argparse.ArgumentParser(prog="python -m benchmarks.bench stages")
    ap.add_argument("--config", type=Path, default=Path("config/config.yaml"))
    ap.add_argument("what", nargs="?", default="map_x1_e", help="a map, or design/sweep")
    ap.add_argument("--rows", default="0:200:10", help="the map's rows, start:stop:step")
    a = ap.parse_args(argv)
    stages.stages_benchmark(a.config, a.what, a.rows)
    return 0


def main_ledger(argv: list[str]) -> int:
    """The cost ledger (:mod:`benchmarks.ledger`) against the committed reference; ``--write`` replaces it."""
    ap = argparse.ArgumentParser(prog="python -m benchmarks.bench ledger")
    ap.add_argument("--config", type=Path, default=Path("config/config.yaml"))
    ap.add_argument("--write", action="store_true", help="write benchmarks/ledger.json")
    ap.add_argument("--only", default="", help="only the workloads whose name contains this")
    ap.add_argument("--log", type=Path, help="a build's Snakemake log: print its job-seconds per stage, run nothing")
    ap.add_argument("--reference-log", type=Path, help="with --log: the reference build's log, side by side")
    a = ap.parse_args(argv)
    if a.write and a.only:
        ap.error("--write replaces the whole reference: not with --only")
    if a.log is not None:
        ref = ledger.build_stages(a.reference_log) if a.reference_log is not None else None
        print(ledger.stage_markdown(ledger.build_stages(a.log), ref), end="")
        return 0
    now = ledger.ledger(a.config, log=lambda m: print(m, flush=True), only=a.only)
    print(ledger.markdown(now, ledger.read_reference()), end="")
    if a.write:
        ledger.write_reference(now, fingerprint.machine())
        print(f"wrote {ledger.REFERENCE}")
    return 0


def main(argv: list[str] | None = None) -> int:
    if argv is None:  # as a program: the C library's plain math, as in the pipeline's jobs
        libm.restart_canonical()
    argv = sys.argv[1:] if argv is None else list(argv)
    if argv and argv[0] == "fingerprint":
        return main_fingerprint(argv[1:])
    if argv and argv[0] == "ledger":
        return main_ledger(argv[1:])
    if argv and argv[0] == "stages":
        return main_stages(argv[1:])
    speed = ("throughput", "labels", "check", "growth", "circles", "curves", "coverage", "probabilities", "classes")
    if argv and argv[0] in speed:
        return main_speed(argv)
    ap = argparse.ArgumentParser(prog="python -m benchmarks.bench", description=work_precision.__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=None, help="directory for work_precision.nc/.md/.png")
    ap.add_argument("--quick", action="store_true", help="short runs (smoke test)")
    a = ap.parse_args(argv)
    out = work_precision.run(quick=a.quick, log=lambda m: print(m, flush=True))
    md = work_precision.markdown(out)
    print(md)
    if a.out is not None:
        a.out.mkdir(parents=True, exist_ok=True)

        io.write_netcdf(
            work_precision.to_dataset(out),
            a.out / "work_precision.nc",
            provenance.attributes(
                title="Work-precision study of the KHV integrators", paper="li2013", model_variant="benchmark"
            ),
        )
        io.write_text(md, a.out / "work_precision.md")
        work_precision.figure(out, a.out / "work_precision.png")
        print(f"wrote {a.out}/work_precision.nc, .md, .png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
