"""The cost ledger (``python -m benchmarks.bench ledger [--write]``): a fixed set of small workloads, one of
each kind the pipeline runs, each costed in CPU seconds and expressed in kernel point-steps (its CPU time
divided by the kernel's own ns per point-step, measured in the same process), so that the figure holds from
machine to machine; compared with the committed reference ``benchmarks/ledger.json``
(``docs/performance.md``).  One thread; each workload runs twice and keeps the cheaper run."""

from __future__ import annotations

import json
import re
import time
from collections.abc import Callable
from datetime import datetime
from pathlib import Path

import numpy as np

from benchmarks.common import load_design, map_lines, workflow_config
from geardyn.khv import point
from geardyn.label import label_lines
from geardyn.runs import continuation, maps, response, sweep
from geardyn.runs.continuation import boundaries, curve_maps
from geardyn.solve import Lane, SimulationSettings, Tangent, simulate_batch, warm_up

REFERENCE = Path(__file__).with_name("ledger.json")
#: a workload this much dearer than the reference is reported
DEARER = 1.10
CAL = "li2013_calibrated"
FIG7, FIG9, FIG11 = "fig07_bifurcation_x1", "fig09_bifurcation_b", "fig11_bifurcation_e"


def kernel_ns(config: dict, root: Path, repeats: int = 5) -> float:
    """The kernel's ns per point-step: 64 points of a torus row of ``map_x1_e`` (row 100), 100 transient and 200
    recorded periods with the tangent vector, 128 steps per period, in the lockstep blocks; the cheapest of
    ``repeats`` runs."""
    raw = dict(config["maps"]["map_x1_e"])
    design = load_design(raw["designs"][0], config, root)
    spec = maps.MapSpec.from_config("map_x1_e", raw, raw["designs"][0], design.segment)
    systems = map_lines(design, spec, [100])[0][:64]
    s = SimulationSettings(steps_per_period=128, transient_periods=100, recorded_periods=200)
    best = np.inf
    for _ in range(repeats):
        c0 = time.process_time()
        simulate_batch([Lane(c, variational=Tangent(200)) for c in systems], s)
        best = min(best, time.process_time() - c0)
    return best * 1e9 / (len(systems) * 300 * 128)


def _sweep(config: dict, root: Path, design: str, name: str, first: int, points: int) -> Callable[[], object]:
    """Chunk 0 of a sweep cut to its points ``first`` .. ``first + points - 1`` (the study runner, cube and all)."""
    raw = dict(config["sweeps"][name])
    d = load_design(design, config, root)
    step = (raw["stop"] - raw["start"]) / (raw["num"] - 1)
    raw.update(start=raw["start"] + first * step, num=points, stop=raw["start"] + (first + points - 1) * step)
    spec = sweep.SweepSpec.from_config(name, raw, design, d.segment)
    return lambda: sweep.run_chunk(d, spec, 0)


def _map_rows(config: dict, root: Path, name: str, rows: list[int]) -> Callable[[], object]:
    """Rows of a regime map labelled (the labeller alone, as ``docs/performance.md``'s command)."""
    raw = dict(config["maps"][name])
    d = load_design(raw["designs"][0], config, root)
    spec = maps.MapSpec.from_config(name, raw, raw["designs"][0], d.segment)
    lines, policy = map_lines(d, spec, rows), spec.policy(d)
    return lambda: label_lines(lines, policy)


def _response(config: dict, root: Path, design: str, num: int) -> Callable[[], object]:
    """The frequency response of ``design`` on ``num`` frequencies, up and down."""
    raw = {**config["responses"]["frequency_response"], "num": num}
    d = load_design(design, config, root)
    spec = response.ResponseSpec.from_config("frequency_response", raw, design, d.segment)
    return lambda: response.run(d, spec)


def _curves(config: dict, root: Path, design: str, name: str) -> Callable[[], object]:
    """A curves study: the regime boundaries of a parameter plane continued from its lines."""
    entry = config["curves"][name]
    d = load_design(design, config, root)
    region = boundaries.Region.from_config(entry, d.segment)
    settings = boundaries.BoundarySpec.from_config(entry)
    integration = point.integration_settings(d, **dict(entry.get("integration", {})))
    return lambda: curve_maps.boundary_curves(d, region, settings, integration)


def _orbits(config: dict, root: Path, design: str, name: str) -> Callable[[], object]:
    """The periodic orbits of a sweep continued from its periodic points (the sweep's cube built first, not
    costed)."""
    d = load_design(design, config, root)
    spec = sweep.SweepSpec.from_config(name, config["sweeps"][name], design, d.segment)
    cube = sweep.run_chunk(d, spec, 0)
    orbits = continuation.OrbitSpec.from_config(config["orbits"][name])
    return lambda: continuation.sweep_orbits(d, spec, cube, orbits)


#: the ledger's workloads: name, builder and its arguments after (config, root)
WORKLOADS: tuple[tuple[str, Callable[..., Callable[[], object]], tuple], ...] = (
    ("sweep x1: li2013_calibrated Fig. 7, points 300-549, 1 line", _sweep, (CAL, FIG7, 300, 250)),
    ("sweep b: li2013_route Fig. 9, points 380-499, 2 lines", _sweep, ("li2013_route", FIG9, 380, 120)),
    ("sweep e: li2013_calibrated Fig. 11, points 380-479, 2 lines", _sweep, (CAL, FIG11, 380, 100)),
    ("map_x1_b: 4 rows", _map_rows, ("map_x1_b", [20, 70, 120, 170])),
    ("map_x1_e: 4 rows", _map_rows, ("map_x1_e", [30, 80, 130, 180])),
    ("map_x1_w: 4 rows", _map_rows, ("map_x1_w", [40, 90, 140, 190])),
    ("frequency response: li2013_calibrated, 2 x 80 frequencies", _response, (CAL, 80)),
    ("curves: li2013, boundaries over (b, e)", _curves, ("li2013", "boundaries_b_e")),
    ("orbits: li2013 Fig. 7, branches", _orbits, ("li2013", FIG7)),
)


def ledger(config_path: Path, repeats: int = 2, log=print, only: str = "") -> dict:
    """Every workload's CPU seconds (the cheaper of ``repeats`` runs) and cost in million kernel point-steps,
    with the kernel's ns per point-step (the cheaper of its runs before and after the workloads); ``only``:
    the workloads whose name contains it."""
    import numba  # noqa: PLC0415 - only the ledger's own runs

    # one thread: CPU time counts every thread of the process, and an idle OpenMP thread spins after each
    # parallel region (two threads read 1.2-2.4x the CPU of one for the same work on this machine)
    numba.set_num_threads(1)
    config = workflow_config(config_path)
    root = config_path.resolve().parent.parent
    warm_up(point.point_coefficients(load_design("li2013", config, root)))
    ns = kernel_ns(config, root)
    out: dict = {"workloads": {}}
    for name, build, args in WORKLOADS:
        if only not in name:
            continue
        run = build(config, root, *args)
        cpu = np.inf
        for _ in range(repeats):
            c0 = time.process_time()
            run()
            cpu = min(cpu, time.process_time() - c0)
        out["workloads"][name] = {"cpu_s": round(float(cpu), 3)}
        log(f"{name}: {cpu:.2f} CPU-s")
    out["kernel_ns_per_point_step"] = round(min(ns, kernel_ns(config, root)), 3)
    for w in out["workloads"].values():
        w["cost_M_point_steps"] = round(w["cpu_s"] * 1e3 / out["kernel_ns_per_point_step"], 1)
    return out


def read_reference(path: Path = REFERENCE) -> dict:
    return json.loads(path.read_text()) if path.exists() else {"workloads": {}}


def markdown(now: dict, reference: dict) -> str:
    """The ledger against the reference: each workload's cost, the reference's, their ratio, and a mark where
    it is more than :data:`DEARER` times the reference's."""
    ref = reference.get("workloads", {})
    rows = []
    for name, w in now["workloads"].items():
        r = ref.get(name, {}).get("cost_M_point_steps")
        ratio = w["cost_M_point_steps"] / r if r else float("nan")
        mark = " **dearer**" if ratio > DEARER else ""
        shown = f"{ratio:.2f}{mark}" if r else "-"
        rows.append(f"| {name} | {w['cpu_s']:.2f} | {w['cost_M_point_steps']:.0f} | {r if r else '-'} | {shown} |")
    dearer = [n for n, w in now["workloads"].items() if _ratio(w, ref.get(n)) > DEARER]
    return (
        f"kernel: {now['kernel_ns_per_point_step']:.2f} ns per point-step (reference machine: "
        f"{reference.get('kernel_ns_per_point_step', '-')})\n\n"
        "| workload | CPU-s | cost (M point-steps) | reference | ratio |\n|---|---:|---:|---:|---:|\n"
        + "\n".join(rows)
        + "\n\n"
        + (f"more than {DEARER:.2f}x dearer: {', '.join(dearer)}\n" if dearer else "no workload dearer than 1.10x\n")
    )


def _ratio(now: dict, ref: dict | None) -> float:
    r = (ref or {}).get("cost_M_point_steps")
    return now["cost_M_point_steps"] / r if r else 0.0


def write_reference(now: dict, machine: dict[str, str], path: Path = REFERENCE) -> None:
    """Replace the committed reference with ``now`` (a commit that makes a workload dearer says why)."""
    path.write_text(json.dumps({"machine": machine, **now}, indent=1) + "\n")


# --- the whole build: job-seconds per stage, read from a Snakemake log -------------------------------------

CONTINUATION = ("map_curves", "curves_study", "orbit_branches", "orbit_attractors")
#: the build's stages, each the rules whose jobs it sums (in the order printed); every other rule's jobs are
#: "the other jobs" (figures, merges, point runs, plus, claims, tables)
STAGES: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("map chunks", ("map_chunk",)),
    ("sweep chunks", ("sweep_chunk",)),
    ("kernels (compiling once)", ("kernels",)),
    ("continuation: map curves, curves studies, branches, attractors", CONTINUATION),
    ("probabilities chunks", ("probabilities_chunk",)),
    ("work precision", ("work_precision",)),
)
OTHER = "the other jobs: figures, merges, point runs, plus, claims, tables"

_STAMP = re.compile(r"^\[(\w{3} \w{3} +\d+ \d\d:\d\d:\d\d \d{4})\]$")
_RULE = re.compile(r"^(?:local)?(?:rule|checkpoint) (\w+):$")
_JOBID = re.compile(r"^\s+jobid: (\d+)$")
_FINISHED = re.compile(r"^Finished job(?:id:)? (\d+)")


def build_jobs(text: str) -> list[tuple[str, float, float]]:
    """The jobs of a build that wrote files, from its Snakemake log (``.snakemake/log/*.snakemake.log``):
    (rule, start, end) in seconds since the log's first time stamp, a job's start the stamp above its ``rule
    <name>:`` block and its end the stamp above its ``Finished jobid`` line (both to the second, as the log
    writes them).  Target rules (a block without ``output:``, such as ``all``) and jobs that never finished
    (a failed or cut build) are left out."""
    stamp = first = None
    rule, writes = "", False
    started: dict[str, tuple[str, datetime]] = {}
    jobs = []
    for line in text.splitlines():
        if m := _STAMP.match(line.strip()):
            stamp = datetime.strptime(" ".join(m.group(1).split()), "%a %b %d %H:%M:%S %Y")
            first = first or stamp
        elif m := _RULE.match(line):
            rule, writes = m.group(1), False
        elif line.startswith("    output: "):
            writes = True
        elif (m := _JOBID.match(line)) and rule and stamp is not None:
            if writes:
                started[m.group(1)] = (rule, stamp)
            rule = ""
        elif (m := _FINISHED.match(line)) and m.group(1) in started and stamp is not None:
            name, t0 = started.pop(m.group(1))
            jobs.append((name, (t0 - first).total_seconds(), (stamp - first).total_seconds()))
    return jobs


def stage_seconds(jobs: list[tuple[str, float, float]]) -> dict[str, tuple[float, int]]:
    """Job-seconds and jobs per stage (:data:`STAGES`, then :data:`OTHER`), then "all" and "wall" (the
    first start to the last end, 0 jobs)."""
    stage_of = {r: name for name, rules in STAGES for r in rules}
    out = {name: (0.0, 0) for name, _ in STAGES} | {OTHER: (0.0, 0)}
    for r, t0, t1 in jobs:
        s, n = out[stage_of.get(r, OTHER)]
        out[stage_of.get(r, OTHER)] = (s + t1 - t0, n + 1)
    out["all"] = (sum(s for s, _ in out.values()), len(jobs))
    out["wall"] = (max((t for *_, t in jobs), default=0.0) - min((t for _, t, _ in jobs), default=0.0), 0)
    return out


def stage_markdown(now: dict[str, tuple[float, int]], reference: dict[str, tuple[float, int]] | None = None) -> str:
    """The stage table: job-seconds (and jobs) per stage of a build, beside a reference build's and their
    ratio; the last rows all jobs and the wall time."""
    ref = reference or {}
    head = "| stage (job-s) | this build | reference | ratio |\n|---|---:|---:|---:|\n"
    rows = []
    for name, (s, n) in now.items():
        r, rn = ref.get(name, (0.0, 0))
        bold = "**" if name in ("all", "wall") else ""
        rows.append(
            f"| {bold}{name}{bold} | {_cell(s, n)} | {_cell(r, rn) if reference else '-'} | "
            f"{f'{s / r:.2f}' if r else '-'} |"
        )
    return head + "\n".join(rows) + "\n"


def _cell(seconds: float, jobs: int) -> str:
    return f"{seconds:.0f}" + (f" ({jobs} jobs)" if jobs else "")


def build_stages(log: Path) -> dict[str, tuple[float, int]]:
    """The stage table's column of one build: :func:`stage_seconds` of the jobs of its Snakemake log."""
    return stage_seconds(build_jobs(log.read_text(encoding="utf-8", errors="replace")))
