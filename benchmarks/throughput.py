"""Throughput of the labeller: the follow start against the fixed start on a whole map and on paper 1's
sweeps, with the kernels' costs (``python -m benchmarks.bench throughput``)."""

from __future__ import annotations

import os
import platform
from pathlib import Path

import numba

from benchmarks.common import PAPER1_SWEEPS, load_design, map_lines, timed_labels, workflow_config
from benchmarks.kernels import C_FLAGS, dop853_ratios, kernel_costs
from geardyn import io
from geardyn.io import Var, markdown_table
from geardyn.khv import point
from geardyn.runs import maps, sweep
from geardyn.solve import warm_up


def map_throughput(
    config_path: Path, map_name: str = "map_x1_b", fixed_stride: int = 10, quick: bool = False, log=print
) -> dict:
    """A whole regime map with the follow start (every row a line, all rows in one call, wall time) against
    the fixed start on every ``fixed_stride``-th row, scaled to the whole map; labels of those rows compared."""

    root = config_path.resolve().parent.parent
    config = workflow_config(config_path)
    raw = dict(config["maps"][map_name])
    if quick:
        raw["x"] = {**raw["x"], "num": 20}
        raw["y"] = {**raw["y"], "num": 20}
    dname = raw["designs"][0]
    design = load_design(dname, config, root)
    spec = maps.MapSpec.from_config(map_name, raw, dname, design.segment)
    policy = spec.policy(design)
    lines = map_lines(design, spec)
    sub = list(range(0, spec.y.num, fixed_stride))

    warm_up(point.point_coefficients(design))
    fol, t_fol, c_fol = timed_labels(lines, policy.with_start("follow"))
    fix, t_fix, c_fix = timed_labels([lines[j] for j in sub], policy.with_start("fixed"))
    scale = spec.y.num / len(sub)
    lf = [v.label for j in sub for v in fol[j]]
    lx = [v.label for row in fix for v in row]
    und = sum(v.label == -1 for row in fol for v in row)
    out = {
        "map": map_name,
        "design": dname,
        "points": spec.n_points,
        "follow_wall_s": t_fol,
        "follow_cpu_s": c_fol,
        "fixed_wall_s_estimate": t_fix * scale,
        "fixed_cpu_s_estimate": c_fix * scale,
        "fixed_rows": len(sub),
        "rows_agree": int(sum(a == b for a, b in zip(lf, lx, strict=True))),
        "rows_points": len(lf),
        "undetermined": und,
        "load_average": os.getloadavg()[0],
    }
    log(
        f"[map] {map_name} {spec.n_points} points: follow {t_fol:.1f} s wall ({c_fol:.0f} CPU-s); fixed "
        f"{out['fixed_wall_s_estimate']:.0f} s wall (from {len(sub)} rows); "
        f"ratio {out['fixed_wall_s_estimate'] / t_fol:.1f}x;"
        f" labels of those rows agree {out['rows_agree']}/{len(lf)}; undetermined {und}"
    )
    return out


def figures_throughput(config_path: Path, design: str = "li2013", quick: bool = False, log=print) -> dict:
    """Paper 1's sweeps (Figs. 7, 9, 11) for ``design``, follow against fixed start: wall, CPU, labels."""

    root = config_path.resolve().parent.parent
    config = workflow_config(config_path)
    d = load_design(design, config, root)
    out = {
        "design": design,
        "points": 0,
        "follow_wall_s": 0.0,
        "fixed_wall_s": 0.0,
        "follow_cpu_s": 0.0,
        "fixed_cpu_s": 0.0,
        "agree": 0,
    }
    for name in PAPER1_SWEEPS:
        raw = dict(config["sweeps"][name])
        if quick:
            raw["num"] = 20
        spec = sweep.SweepSpec.from_config(name, raw, design, d.segment)
        policy = spec.policy(d)
        lines = [
            [point.point_coefficients(d, sweep.point_overrides(spec, c, v)) for v in spec.values]
            for c in range(len(spec.cases))
        ]
        fol, tf, cf = timed_labels(lines, policy.with_start("follow"))
        fix, tx, cx = timed_labels(lines, policy.with_start("fixed"))
        n = sum(len(line) for line in lines)
        agree = sum(a.label == b.label for la, lb in zip(fol, fix, strict=True) for a, b in zip(la, lb, strict=True))
        log(f"[{design} {name}] {n} points: follow {tf:.1f} s, fixed {tx:.1f} s wall; labels agree {agree}/{n}")
        out["points"] += n
        out["agree"] += agree
        out["follow_wall_s"] += tf
        out["fixed_wall_s"] += tx
        out["follow_cpu_s"] += cf
        out["fixed_cpu_s"] += cx
    return out


def throughput(config_path: Path = Path("config/config.yaml"), quick: bool = False, log=print) -> dict:
    out = {"kernel": kernel_costs(periods=20 if quick else 100, log=log)}
    out["dop853"] = dop853_ratios(quick=quick, log=log)
    out["map"] = map_throughput(config_path, quick=quick, log=log)
    out["figures"] = figures_throughput(config_path, quick=quick, log=log)
    return out


def throughput_markdown(out: dict) -> str:

    k, d, m, f = out["kernel"], out["dop853"], out["map"], out["figures"]
    cells = [
        (
            f"map {m['map']} of {m['design']} ({m['points']} points), wall",
            f"{m['fixed_wall_s_estimate']:.0f} s (from {m['fixed_rows']} rows)",
            f"{m['follow_wall_s']:.1f} s",
            f"{m['fixed_wall_s_estimate'] / m['follow_wall_s']:.1f}x",
        ),
        (
            "same map, CPU time",
            f"{m['fixed_cpu_s_estimate']:.0f} CPU-s",
            f"{m['follow_cpu_s']:.0f} CPU-s",
            f"{m['fixed_cpu_s_estimate'] / m['follow_cpu_s']:.1f}x",
        ),
        (
            f"paper 1 sweeps for {f['design']} ({f['points']} points), wall",
            f"{f['fixed_wall_s']:.1f} s",
            f"{f['follow_wall_s']:.1f} s",
            f"{f['fixed_wall_s'] / f['follow_wall_s']:.1f}x",
        ),
    ]
    for integ in ("rk4", "rk4_event"):
        r, c = k[integ], k["c_ns"]
        batch = f"{r['batch_ns'] / c:.2f}x ({k['threads']} threads), {r['batch1_ns'] / c:.2f}x (1 thread)"
        what = f"cost per point-step, {integ}, vs scalar C RK4 ({c:.1f} ns): scalar loop / batch"
        cells.append((what, f"{r['scalar_ns'] / c:.2f}x", batch, ""))
    for target in ("1e-06", "1e-08"):
        what = f"speed vs scipy DOP853 at equal Poincare error {target} (batch)"
        cells.append((what, "", f"{d[f'ratio_new_{target}']:.0f}x", ""))
    lines = [
        f"Machine: {platform.node()} {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
        f"{numba.get_num_threads()} numba threads; both starts measured in the same run; load average "
        f"{os.getloadavg()[0]:.1f} at the end (shared machine: wall times are upper bounds).",
        "",
        markdown_table(("what", "fixed start", "follow start", "ratio (fixed / follow)"), cells, "-rrr"),
    ]
    lines += [
        "",
        f"- map: labels of the {m['fixed_rows']} rows compared agree {m['rows_agree']}/{m['rows_points']}; "
        f"undetermined with the follow start: {m['undetermined']} of {m['points']}.",
        f"- paper 1 sweeps: labels agree {f['agree']}/{f['points']} between the two starts.",
        f"- kernel: {k['lanes']} points x {k['periods']} periods x {k['steps']} steps; C: gcc "
        f"{' '.join(C_FLAGS)}, same expressions (final states equal to the numba kernel's: "
        f"{k['c_equals_numba']}); batch results bit-identical to the scalar kernel: "
        f"{k['rk4']['bit_identical'] and k['rk4_event']['bit_identical']}.",
    ]
    return "\n".join(lines) + "\n"


def throughput_dataset(out: dict):

    k, m, f = out["kernel"], out["map"], out["figures"]
    integ = ("rk4", "rk4_event")
    table = (
        Var("ns_per_point_step", "integrator", "ns", "batch kernel per point and RK4 step (all threads)"),
        Var("ns_per_point_step_scalar", "integrator", "ns", "scalar loop per RK4 step"),
        Var("c_ns_per_step", (), "ns", "scalar C RK4 (gcc) per step"),
        Var(
            "map_wall_time",
            "start",
            "s",
            f"regime map {m['map']}: wall time (fixed: estimate from {m['fixed_rows']} rows)",
        ),
        Var("figures_wall_time", "start", "s", f"paper 1 sweeps for {f['design']}: wall time"),
        Var("integrator", "integrator", None, "fixed-step integrator"),
        Var("start", "start", None, "start of each point: fixed state or the previous attractor"),
    )
    values = {
        "ns_per_point_step": [k[i]["batch_ns"] for i in integ],
        "ns_per_point_step_scalar": [k[i]["scalar_ns"] for i in integ],
        "c_ns_per_step": k["c_ns"],
        "map_wall_time": [m["fixed_wall_s_estimate"], m["follow_wall_s"]],
        "figures_wall_time": [f["fixed_wall_s"], f["follow_wall_s"]],
    }
    ds = io.dataset(table, values | {"integrator": list(integ), "start": ["fixed", "follow"]})
    ds.attrs.update(
        {
            "title": "Throughput of the labeller: follow against fixed starts",
            "source": "benchmarks.bench",
            "machine": f"{platform.node()} {os.cpu_count()} cores",
            "map_rows_labels_agree": f"{m['rows_agree']}/{m['rows_points']}",
            "figures_labels_agree": f"{f['agree']}/{f['points']}",
        }
    )
    return ds
