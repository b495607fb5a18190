"""Speed against error of the KHV integrators.  Run: ``python -m geardyn.bench [--out DIR]``.

Single-threaded by construction when run as a program (thread pools pinned to 1 before numpy/numba
load); importing the module (e.g. for :func:`cases`) sets nothing.

* periodic case: x1 = 0.416 numbers (eps 1.30, k_C 3.1e8 N/m), Table 2, b = 2, e = 5, w = 0.9
  (period-1 with contact loss four times a period).  Error = max |Poincare point - reference|
  over the 100 recorded points and 6 states (500 + 100 mesh periods), reference DOP853
  rtol 1e-12 with events.
* chaotic case: eps 1.24, light load T_D = T_L = 2 N m, w = 0.55, otherwise the same
  (largest Lyapunov exponent ~ +0.036 per unit time).  Trajectories diverge, so the measures
  are statistical: Wasserstein-1 distance between the Poincare distributions of x2 and v2
  (500 points after 100 transient periods, normalised by the reference's standard deviation)
  and the largest Lyapunov exponent; the floor is the distance between two reference runs
  started 1e-10 apart.
"""

from __future__ import annotations

import os

if __name__ == "__main__":  # run as a program only: importing this module changes nothing
    for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(_v, "1")
# numba threads: one for the work-precision study (set in run()), all cores for ``throughput``

import argparse
import json
import platform
import sys
import time
from pathlib import Path

import numpy as np

from geardyn.khv.model import Coefficients, KHVParameters, dimensionless, static_deflection
from geardyn.papers import li2013
from geardyn.solve import SimulationSettings, largest_lyapunov, simulate, warm_up
from geardyn.solve.reference import simulate_reference

STEPS = (32, 64, 128, 256, 512, 1024)
RTOLS = (1e-6, 1e-8, 1e-10)
TARGET_ERROR = 1e-6


def cases() -> dict[str, Coefficients]:
    """The benchmark cases: paper 1's drive (Table 2 and the li2013 design's assumptions) at a periodic
    and a chaotic operating point."""
    base = {**li2013.TABLE2, **li2013.ASSUMED}
    return {
        "periodic": dimensionless(KHVParameters(eps=1.30, k_c=3.1e8, **{**base, "omega_bar": 0.9})),
        "chaotic": dimensionless(
            KHVParameters(eps=1.24, k_c=3.1e8, **{**base, "omega_bar": 0.55, "T_D": 2.0, "T_L": 2.0})
        ),
    }


def _split(case: str) -> tuple[int, int]:
    return (500, 100) if case == "periodic" else (100, 500)


def _timed(fn, repeats: int):
    best, out = np.inf, None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def _w1(a: np.ndarray, b: np.ndarray) -> float:
    from scipy.stats import wasserstein_distance

    d = 0.0
    for k in (1, 4):  # x2, v2
        d = max(d, wasserstein_distance(a[:, k], b[:, k]) / np.std(b[:, k]))
    return float(d)


def run(quick: bool = False, log=print) -> dict:
    """Compute the study; returns a dict of arrays and scalars (see :func:`to_dataset`)."""
    import numba

    numba.set_num_threads(1)
    for c in cases().values():
        warm_up(c)
    steps = STEPS[:4] if quick else STEPS
    rtols = RTOLS[:1] if quick else RTOLS
    out: dict = {"steps": np.array(steps), "rtols": np.array(rtols), "cases": {}}
    for name, c in cases().items():
        ntr, nrec = _split(name)
        if quick:
            ntr, nrec = ntr // 10, nrec // 10
        y0 = static_deflection(c)
        ref_s = SimulationSettings(integrator="dop853", transient_periods=ntr, recorded_periods=nrec, rtol=1e-12)
        t_ref, ref = _timed(lambda: simulate(c, ref_s, y0), 1)
        log(f"[{name}] reference DOP853 rtol 1e-12: {t_ref:.1f} s, {ref.n_events} events")
        res = {"ref_time": t_ref, "coeffs": c, "n_periods": ntr + nrec}
        if name == "chaotic":
            y1 = y0.copy()
            y1[0] += 1e-10
            ref2 = simulate(
                c,
                SimulationSettings(
                    integrator="rk4_event", steps_per_period=4096, transient_periods=ntr, recorded_periods=nrec
                ),
                y1,
            )
            res["floor"] = _w1(ref2.poincare, ref.poincare)
            lam_ref, _ = largest_lyapunov(
                c, SimulationSettings(steps_per_period=2048, transient_periods=100), n_periods=100 if quick else 500
            )
            res["lyap_ref"] = lam_ref
            log(f"[{name}] distribution floor {res['floor']:.3g}, Lyapunov (2048 steps) {lam_ref:.4f}")
        for integ in ("rk4", "rk4_event"):
            times, errs, lyap, nsps = [], [], [], []
            for n in steps:
                s = SimulationSettings(
                    integrator=integ, steps_per_period=n, transient_periods=ntr, recorded_periods=nrec
                )
                t, r = _timed(lambda: simulate(c, s, y0), 3)
                nsps.append(t / ((ntr + nrec) * n) * 1e9)
                times.append(t)
                if name == "periodic":
                    errs.append(float(np.abs(r.poincare - ref.poincare).max()))
                    lyap.append(np.nan)
                else:
                    errs.append(_w1(r.poincare, ref.poincare))
                    lam, _ = largest_lyapunov(
                        c,
                        SimulationSettings(integrator=integ, steps_per_period=n, transient_periods=100),
                        n_periods=100 if quick else 500,
                    )
                    lyap.append(lam)
                log(
                    f"[{name}] {integ:9s} N={n:5d}: {t * 1e3:8.2f} ms  error {errs[-1]:.3e}  "
                    f"{nsps[-1]:.1f} ns/step  events {r.n_events}"
                )
            res[integ] = {
                "time": np.array(times),
                "error": np.array(errs),
                "lyapunov": np.array(lyap),
                "ns_per_step": np.array(nsps),
            }
        dt, de = [], []
        for rt in rtols:
            s = SimulationSettings(integrator="dop853", transient_periods=ntr, recorded_periods=nrec, rtol=rt)
            t, r = _timed(lambda: simulate_reference(c, s, y0, max_step_fraction=np.inf), 1)
            e = float(np.abs(r.poincare - ref.poincare).max()) if name == "periodic" else _w1(r.poincare, ref.poincare)
            dt.append(t)
            de.append(e)
            log(f"[{name}] dop853 rtol={rt:.0e}: {t:8.2f} s  error {e:.3e}")
        res["dop853"] = {"time": np.array(dt), "error": np.array(de)}
        out["cases"][name] = res
    out["summary"] = summarize(out)
    return out


def _interp_time(err: np.ndarray, time_: np.ndarray, target: float) -> float:
    """Wall time needed for error = target, log-log interpolation (monotone part of the curve)."""
    order = np.argsort(err)
    le, lt = np.log(err[order]), np.log(time_[order])
    if not (le[0] <= np.log(target) <= le[-1]):
        return float("nan")
    return float(np.exp(np.interp(np.log(target), le, lt)))


def summarize(out: dict) -> dict:
    per = out["cases"]["periodic"]
    ev, rk, dp = per["rk4_event"], per["rk4"], per["dop853"]
    steps = out["steps"]
    ok = np.nonzero(ev["error"] < TARGET_ERROR)[0]
    n_def = int(steps[ok[0]]) if len(ok) else int(steps[-1])
    i_def = int(np.nonzero(steps == n_def)[0][0])
    sel = (steps >= 64) & (steps <= 512)
    order = float(-np.polyfit(np.log(steps[sel]), np.log(ev["error"][sel]), 1)[0])
    order_plain = float(-np.polyfit(np.log(steps[sel]), np.log(rk["error"][sel]), 1)[0])
    ratios = {}
    for target in (1e-6, 1e-8):
        t_rk = _interp_time(ev["error"], ev["time"], target)
        t_dp = _interp_time(dp["error"], dp["time"], target)
        ratios[f"{target:.0e}"] = t_dp / t_rk if np.isfinite(t_rk * t_dp) else float("nan")
    # equal-error fallback: reference cost (rtol 1e-12) against the default setting
    ratios["reference_vs_default"] = per["ref_time"] / ev["time"][i_def]
    return {
        "default_steps": n_def,
        "default_error": float(ev["error"][i_def]),
        "default_time_per_point": float(ev["time"][i_def]),
        "order_event": order,
        "order_plain": order_plain,
        "ns_per_step_event": float(np.median(ev["ns_per_step"][steps >= 128])),
        "ns_per_step_plain": float(np.median(rk["ns_per_step"][steps >= 128])),
        "speed_ratio": ratios,
    }


def to_dataset(out: dict):
    import xarray as xr

    steps, rtols = out["steps"], out["rtols"]
    names = list(out["cases"])
    integ = ["rk4", "rk4_event"]

    def stack(key):
        return np.array([[out["cases"][c][i][key] for i in integ] for c in names])

    ds = xr.Dataset(
        {
            "wall_time": (
                ("case", "integrator", "steps_per_period"),
                stack("time"),
                {"units": "s", "long_name": "wall time per sweep point (single thread)"},
            ),
            "error": (
                ("case", "integrator", "steps_per_period"),
                stack("error"),
                {
                    "units": "1",
                    "long_name": "periodic: max abs Poincare error vs DOP853 rtol 1e-12 "
                    "(units of b_c); chaotic: normalised Wasserstein-1 distance of Poincare x2/v2",
                },
            ),
            "lyapunov": (
                ("case", "integrator", "steps_per_period"),
                stack("lyapunov"),
                {
                    "units": "1",
                    "long_name": "largest Lyapunov exponent per unit dimensionless time (chaotic case only)",
                },
            ),
            "ns_per_step": (
                ("case", "integrator", "steps_per_period"),
                stack("ns_per_step"),
                {"units": "ns", "long_name": "wall time per RK4 step, events included"},
            ),
            "dop853_wall_time": (
                ("case", "rtol"),
                np.array([out["cases"][c]["dop853"]["time"] for c in names]),
                {"units": "s", "long_name": "DOP853 wall time per sweep point"},
            ),
            "dop853_error": (
                ("case", "rtol"),
                np.array([out["cases"][c]["dop853"]["error"] for c in names]),
                {"units": "1", "long_name": "DOP853 error (same measure as error)"},
            ),
            "reference_wall_time": (
                ("case",),
                np.array([out["cases"][c]["ref_time"] for c in names]),
                {"units": "s", "long_name": "DOP853 rtol 1e-12 reference wall time"},
            ),
        },
        coords={
            "case": ("case", names, {"long_name": "test case"}),
            "integrator": ("integrator", integ, {"long_name": "fixed-step integrator"}),
            "steps_per_period": ("steps_per_period", steps, {"units": "1", "long_name": "RK4 steps per mesh period"}),
            "rtol": ("rtol", rtols, {"units": "1", "long_name": "DOP853 relative tolerance"}),
        },
    )
    s = out["summary"]
    ds.attrs.update(
        {
            "title": "Work-precision of the KHV integrators",
            "source": "geardyn.bench",
            "history": f"{time.strftime('%Y-%m-%dT%H:%M:%SZ', time.gmtime())} python -m geardyn.bench",
            "model_variant": "corrected Eq. (9), time-varying stiffness, backlash and TE on",
            "machine": f"{platform.node()} {platform.processor() or platform.machine()}, 1 thread",
            "summary": json.dumps({k: v for k, v in s.items()}),
        }
    )
    for c in names:
        ds.attrs[f"coefficients_{c}"] = json.dumps(out["cases"][c]["coeffs"].as_dict())
        ds.attrs[f"periods_{c}"] = out["cases"][c]["n_periods"]
    if "floor" in out["cases"].get("chaotic", {}):
        ds.attrs["chaotic_distribution_floor"] = out["cases"]["chaotic"]["floor"]
        ds.attrs["chaotic_lyapunov_reference"] = out["cases"]["chaotic"]["lyap_ref"]
    return ds


def markdown(out: dict) -> str:
    lines = [
        "| case | integrator | steps/period | wall time per point (ms) | error | ns/step | Lyapunov |",
        "|---|---|---:|---:|---:|---:|---:|",
    ]
    for c, res in out["cases"].items():
        for integ in ("rk4", "rk4_event"):
            r = res[integ]
            for i, n in enumerate(out["steps"]):
                lam = "" if np.isnan(r["lyapunov"][i]) else f"{r['lyapunov'][i]:.4f}"
                lines.append(
                    f"| {c} | {integ} | {n} | {r['time'][i] * 1e3:.1f} | {r['error'][i]:.2e} | "
                    f"{r['ns_per_step'][i]:.1f} | {lam} |"
                )
        for i, rt in enumerate(out["rtols"]):
            d = res["dop853"]
            lines.append(f"| {c} | dop853 rtol {rt:.0e} | - | {d['time'][i] * 1e3:.0f} | {d['error'][i]:.2e} | - | |")
        lines.append(
            f"| {c} | dop853 rtol 1e-12 (reference) | - | {res['ref_time'] * 1e3:.0f} | 0 | - | "
            f"{res.get('lyap_ref', float('nan')):.4f} |"
        )
    s = out["summary"]
    lines += [
        "",
        "Periodic-case errors: max |Poincare point - reference| (units of b_c = 1 um). Chaotic-case "
        "errors: normalised Wasserstein-1 distance of the Poincare distributions of x2 and v2; floor "
        f"(reference vs. itself from 1e-10 away) {out['cases'].get('chaotic', {}).get('floor', float('nan')):.3g}.",
        "",
        f"- observed order, event RK4 (64-512): {s['order_event']:.2f}; plain RK4: {s['order_plain']:.2f}",
        f"- ns per step (median, N >= 128): event {s['ns_per_step_event']:.1f}, plain {s['ns_per_step_plain']:.1f}",
        f"- default steps per period: {s['default_steps']} (error {s['default_error']:.2e} < {TARGET_ERROR:g}), "
        f"{s['default_time_per_point'] * 1e3:.1f} ms per 600-period sweep point",
        "- speed ratio vs DOP853 at equal error: " + ", ".join(f"{k}: {v:.0f}x" for k, v in s["speed_ratio"].items()),
    ]
    return "\n".join(lines) + "\n"


def figure(out: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for ax, (c, res) in zip(axes, out["cases"].items()):
        for integ, mk in (("rk4", "s-"), ("rk4_event", "o-")):
            ax.loglog(res[integ]["time"], res[integ]["error"], mk, label=integ)
        ax.loglog(res["dop853"]["time"], res["dop853"]["error"], "^-", label="dop853 (scipy)")
        if c == "periodic":
            ax.axhline(TARGET_ERROR, color="grey", lw=0.8, ls=":")
        else:
            ax.axhline(res["floor"], color="grey", lw=0.8, ls=":", label="statistical floor")
        ax.set_xlabel("wall time per sweep point (s), 1 thread")
        ax.set_ylabel("Poincare error (b_c)" if c == "periodic" else "W1 distance / std")
        ax.set_title(f"{c} case, {res['n_periods']} mesh periods")
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main_speed(argv: list[str]) -> int:
    """``throughput`` (follow against fixed starts, kernel, DOP853), ``labels`` (the labels of two builds'
    cubes compared) and ``check`` (random map points run long from their follow start) modes."""
    ap = argparse.ArgumentParser(prog=f"python -m geardyn.bench {argv[0]}")
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
    ap.add_argument("--points", type=int, default=200, help="check: random map points")
    ap.add_argument("--periods", type=int, default=20000, help="check: mesh periods of each long run")
    a = ap.parse_args(argv[1:])
    log = lambda m: print(m, flush=True)  # noqa: E731
    ds = None
    if argv[0] == "throughput":
        out = throughput(a.config, quick=a.quick, log=log)
        md = "# Throughput: the follow start against the fixed start (the same labeller, one run)\n\n"
        md += throughput_markdown(out)
        ds = throughput_dataset(out)
    elif argv[0] == "labels":
        md = "# Labels of two builds compared, cube by cube\n\n" + compare_builds(a.old, a.new)
        for item in a.explain or ():
            design, kind, name = item.split("/")
            md += "\n" + explain_differences(a.config, a.old, a.new, design, kind, name, log=log)
    else:
        md = "# Independent check: long runs from the follow start\n\n" + long_run_check(
            a.config, n_points=a.points, periods=a.periods, log=log
        )
    print(md)
    if a.out is not None:
        from geardyn import io

        a.out.mkdir(parents=True, exist_ok=True)
        io.write_text(md, a.out / f"{argv[0]}.md")
        if ds is not None:
            io.write_netcdf(
                ds,
                a.out / f"{argv[0]}.nc",
                io.provenance(title=ds.attrs["title"], paper="li2013", model_variant="benchmark"),
            )
        print(f"wrote {a.out}/{argv[0]}.*")
    return 0


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    if argv and argv[0] in ("throughput", "labels", "check"):
        return main_speed(argv)
    ap = argparse.ArgumentParser(prog="python -m geardyn.bench", description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=None, help="directory for work_precision.nc/.md/.png")
    ap.add_argument("--quick", action="store_true", help="short runs (smoke test)")
    a = ap.parse_args(argv)
    out = run(quick=a.quick, log=lambda m: print(m, flush=True))
    md = markdown(out)
    print(md)
    if a.out is not None:
        a.out.mkdir(parents=True, exist_ok=True)
        from geardyn import io

        io.write_netcdf(
            to_dataset(out),
            a.out / "work_precision.nc",
            io.provenance(
                title="Work-precision study of the KHV integrators", paper="li2013", model_variant="benchmark"
            ),
        )
        io.write_text(md, a.out / "work_precision.md")
        figure(out, a.out / "work_precision.png")
        print(f"wrote {a.out}/work_precision.nc, .md, .png")
    return 0


# ----------------------------------------------------------------------------------------------
# the labeller's starts compared (one run), two builds' labels compared, long-run check
# ----------------------------------------------------------------------------------------------

PAPER1_SWEEPS = ("fig07_bifurcation_x1", "fig09_bifurcation_b", "fig11_bifurcation_e")


def _config(path: Path) -> dict:
    from geardyn import validate

    filled, _ = validate.validate_workflow(validate.read_config_file(path), path.resolve().parent.parent)
    return filled


def _design(name: str, config: dict, root: Path):
    from geardyn.khv import design as design_mod

    return design_mod.load(root / config["designs"][name])


def _map_lines(design, spec, rows=None):
    """The rows of a map (or ``rows`` of them) as lines of systems, as maps.run_chunk builds them."""
    from geardyn.khv import point
    from geardyn.runs import maps

    xs, ys = spec.x.values, spec.y.values
    bases = [point.point_coefficients(design, {**dict(spec.fixed), spec.x.parameter: float(x)}) for x in xs]
    rows = range(len(ys)) if rows is None else rows
    return [[maps.point_coefficients(design, spec, xs[i], ys[j], bases[i]) for i in range(len(xs))] for j in rows]


def _timed_labels(lines, policy):
    from geardyn.label import label_lines

    t0, c0 = time.perf_counter(), time.process_time()
    out = label_lines(lines, policy)
    return out, time.perf_counter() - t0, time.process_time() - c0


def confusion(old_labels, new_labels) -> tuple[list[int], np.ndarray]:
    """Confusion matrix (rows: the first labels, columns: the second) over the codes present."""
    codes = sorted(set(old_labels) | set(new_labels))
    m = np.zeros((len(codes), len(codes)), np.int64)
    pos = {c: k for k, c in enumerate(codes)}
    for a, b in zip(old_labels, new_labels, strict=True):
        m[pos[a], pos[b]] += 1
    return codes, m


def confusion_markdown(codes, m, first: str = "previous", second: str = "new") -> str:
    from geardyn.classify import short_name

    head = f"| {first} \\ {second} | " + " | ".join(short_name(c) for c in codes) + " |"
    lines = [head, "|---|" + "---:|" * len(codes)]
    for k, c in enumerate(codes):
        lines.append(f"| {short_name(c)} | " + " | ".join(str(int(v)) for v in m[k]) + " |")
    return "\n".join(lines)


def compare_builds(old: Path, new: Path) -> str:
    """The labels of every sweep cube and map that two builds' ``results/`` share, compared point by point
    (by data content): a confusion matrix per cube, the share of the earlier build's decided labels the
    new one repeats (points flagged ``coexisting`` left out), the new build's undetermined share and the
    stages that decided it."""
    import xarray as xr

    from geardyn.classify import LABELS
    from geardyn.label import STAGE_NAMES

    lines = [
        "| cube | points | same label | decided before, same now (no coexistence) | undetermined before | "
        "undetermined now |",
        "|---|---:|---:|---:|---:|---:|",
    ]
    parts = []
    for path in sorted(list(new.glob("*/sweeps/*.nc")) + list(new.glob("*/maps/*.nc"))):
        rel = path.relative_to(new)
        if path.name.startswith("chunk_") or not (old / rel).exists():
            continue
        with xr.open_dataset(old / rel) as a, xr.open_dataset(path) as b:
            lo, ln = a["label"].values.ravel(), b["label"].values.ravel()
            coex = b["coexisting"].values.ravel() == 1 if "coexisting" in b else np.zeros(ln.size, bool)
            stage = b["stage"].values.ravel() if "stage" in b else None
        und = LABELS["undetermined"]
        decided = (lo != und) & ~coex
        same_dec = int(np.sum((lo == ln) & decided))
        lines.append(
            f"| {rel} | {lo.size} | {int(np.sum(lo == ln))} ({np.mean(lo == ln):.1%}) | {same_dec} of "
            f"{int(decided.sum())} ({same_dec / max(1, int(decided.sum())):.2%}) | "
            f"{np.mean(lo == und):.1%} | {np.mean(ln == und):.1%} |"
        )
        codes, m = confusion(lo.tolist(), ln.tolist())
        parts += ["", f"### {rel}", "", confusion_markdown(codes, m)]
        if stage is not None:
            u, c = np.unique(stage, return_counts=True)
            parts.append(
                "\nstages now: "
                + ", ".join(f"{STAGE_NAMES.get(int(k), 'not computed')} {int(n)}" for k, n in zip(u, c, strict=True))
            )
    return "\n".join(lines + parts) + "\n"


def explain_differences(config_path: Path, old: Path, new: Path, design: str, kind: str, name: str, log=print) -> str:
    """Every point of one cube (``kind`` sweeps or maps) whose earlier label was decided and differs from the
    new one, labelled again from the fixed start (the static deflection) by the new labeller: where that
    gives the earlier label, the follow start found another attractor at the same point (coexistence, as
    a run with ``coexistence: true`` would flag it); else the class of the change (the earlier label was a
    slow transient or undetermined, a boundary point, ...)."""
    import xarray as xr

    from geardyn.classify import LABELS, short_name
    from geardyn.khv import point
    from geardyn.label import label_points
    from geardyn.runs import maps, sweep

    root = config_path.resolve().parent.parent
    config = _config(config_path)
    d = _design(design, config, root)
    rel = Path(design) / kind / f"{name}.nc"
    with xr.open_dataset(old / rel) as a, xr.open_dataset(new / rel) as b:
        lo, ln = a["label"].values, b["label"].values
    where = np.argwhere((lo != ln) & (lo != LABELS["undetermined"]))
    if kind == "maps":
        spec = maps.MapSpec.from_config(name, config["maps"][name], design, d.segment)
        policy = maps.map_policy(d, spec)
        systems = [maps.point_coefficients(d, spec, spec.x.values[i], spec.y.values[j]) for j, i in where]
    else:
        spec = sweep.SweepSpec.from_config(name, config["sweeps"][name], design, d.segment)
        policy = sweep.sweep_policy(d, spec)
        systems = [point.point_coefficients(d, sweep.point_overrides(spec, c, spec.values[j])) for c, _, j in where]
    t0 = time.perf_counter()
    fixed = label_points(systems, policy.with_start("fixed"))
    classes: dict[str, int] = {}
    examples: dict[str, str] = {}
    for idx, v in zip(where, fixed, strict=True):
        before, now = int(lo[tuple(idx)]), int(ln[tuple(idx)])
        if v.label == before:
            key = "coexistence: the fixed start ends on the earlier label, the follow start on another attractor"
        elif now == LABELS["undetermined"]:
            key = "now undetermined: the indicators disagree on the follow start"
        elif v.label == now:
            key = "both starts now agree on the new label (the earlier path decided otherwise)"
        else:
            key = "three different labels (a boundary point or a third attractor)"
        classes[key] = classes.get(key, 0) + 1
        examples.setdefault(
            key,
            f"{tuple(int(k) for k in idx)}: before {short_name(before)}, follow {short_name(now)}, "
            f"fixed {short_name(v.label)} ({v.stage})",
        )
    log(f"[{rel}] {len(where)} differing points relabelled from the fixed start in {time.perf_counter() - t0:.0f} s")
    lines = [
        f"### {rel}: {len(where)} points decided before and labelled otherwise now",
        "",
        "| class | points | example (index: labels) |",
        "|---|---:|---|",
    ]
    lines += [f"| {k} | {n} | {examples[k]} |" for k, n in sorted(classes.items(), key=lambda kv: -kv[1])]
    return "\n".join(lines) + "\n"


def map_throughput(
    config_path: Path, map_name: str = "map_x1_b", fixed_stride: int = 10, quick: bool = False, log=print
) -> dict:
    """A whole regime map with the follow start (every row a line, all rows in one call, wall time) against
    the fixed start on every ``fixed_stride``-th row, scaled to the whole map; labels of those rows compared."""
    from geardyn.khv import point
    from geardyn.runs import maps

    root = config_path.resolve().parent.parent
    config = _config(config_path)
    raw = dict(config["maps"][map_name])
    if quick:
        raw["x"] = {**raw["x"], "num": 20}
        raw["y"] = {**raw["y"], "num": 20}
    dname = raw["designs"][0]
    design = _design(dname, config, root)
    spec = maps.MapSpec.from_config(map_name, raw, dname, design.segment)
    policy = maps.map_policy(design, spec)
    lines = _map_lines(design, spec)
    sub = list(range(0, spec.y.num, fixed_stride))
    from geardyn.solve import warm_up

    warm_up(point.point_coefficients(design))
    fol, t_fol, c_fol = _timed_labels(lines, policy.with_start("follow"))
    fix, t_fix, c_fix = _timed_labels([lines[j] for j in sub], policy.with_start("fixed"))
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
        f"{out['fixed_wall_s_estimate']:.0f} s wall (from {len(sub)} rows); ratio {out['fixed_wall_s_estimate'] / t_fol:.1f}x;"
        f" labels of those rows agree {out['rows_agree']}/{len(lf)}; undetermined {und}"
    )
    return out


def figures_throughput(config_path: Path, design: str = "li2013", quick: bool = False, log=print) -> dict:
    """Paper 1's sweeps (Figs. 7, 9, 11) for ``design``, follow against fixed start: wall, CPU, labels."""
    from geardyn.khv import point
    from geardyn.runs import sweep

    root = config_path.resolve().parent.parent
    config = _config(config_path)
    d = _design(design, config, root)
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
        policy = sweep.sweep_policy(d, spec)
        lines = [
            [point.point_coefficients(d, sweep.point_overrides(spec, c, v)) for v in spec.values]
            for c in range(len(spec.cases))
        ]
        fol, tf, cf = _timed_labels(lines, policy.with_start("follow"))
        fix, tx, cx = _timed_labels(lines, policy.with_start("fixed"))
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


def long_run_check(
    config_path: Path, map_name: str = "map_x1_b", n_points: int = 200, periods: int = 20000, seed: int = 0, log=print
) -> str:
    """Independent check of the labeller: ``n_points`` random points of a regime map, each run ``periods``
    mesh periods (plain RK4, no labeller) from the state its follow start used (the previous point's
    final state on its row, the static deflection for a row's first point).  A periodic verdict must be
    met by the long run's end: the same least period (rule 3 on its last periods) and the same orbit within
    1e-6; other verdicts are reported with the long run's rule-3 period and its exponent."""
    from geardyn import classify
    from geardyn.label.compare import hausdorff
    from geardyn.runs import maps
    from geardyn.solve.simulate import simulate_batch

    root = config_path.resolve().parent.parent
    config = _config(config_path)
    raw = dict(config["maps"][map_name])
    dname = raw["designs"][0]
    design = _design(dname, config, root)
    spec = maps.MapSpec.from_config(map_name, raw, dname, design.segment)
    policy = maps.map_policy(design, spec)
    rng = np.random.default_rng(seed)
    picks = sorted({(int(rng.integers(spec.y.num)), int(rng.integers(spec.x.num))) for _ in range(n_points)})
    rows = sorted({j for j, _ in picks})
    t0 = time.perf_counter()
    lines = _map_lines(design, spec, rows)
    from geardyn.label import label_lines

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
    runs = simulate_batch(systems, s, starts)
    cs = policy.classifier
    rows_md = [
        "| x | y | verdict | stage | long run: rule-3 period | orbit distance | agrees |",
        "|---:|---:|---|---|---:|---:|---|",
    ]
    counts = {"periodic": [0, 0], "other": [0, 0]}
    for (j, i), v, r in zip(picks, want, runs, strict=True):
        n = 0 if r.diverged else classify.strict_period(r.poincare, cs)
        if v.period > 0:
            dist = hausdorff(r.poincare[-v.period :], v.poincare[: v.period]) if not r.diverged else float("inf")
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


# ----------------------------------------------------------------------------------------------
# throughput: ``python -m geardyn.bench throughput --out DIR``
# ----------------------------------------------------------------------------------------------

C_RK4 = r"""
#include <math.h>
/* Plain RK4 of the 3-DOF backlash model on the aligned step grid, the expressions of
   geardyn.solve._model.rk4 (kappa and TE tabulated per step at the 3 stage times); a test runs this
   text as Python against that function, bit for bit (tests/test_model_equations.py). */
static inline double fdead(double x, double b, double on) {
    if (on == 0.0) return x;
    if (x > b) return x - b;
    if (x < -b) return x + b;
    return 0.0;
}
#define RHS(X1, X2, X3, V1, V2, V3, KAP, PE, A1, A2, A3) { \
    double fm_ = (KAP) * fdead((X2), B, ON) + CM * (V2); \
    A1 = P1 - K11 * (X1) - C11 * (V1) - G1 * fm_; \
    A2 = (PE) - K21 * (X1) - C21 * (V1) - K23 * (X3) - C23 * (V3) - fm_; \
    A3 = P3 - K33 * (X3) - C33 * (V3) - G3 * fm_; }
void run(const double *c, const double *th, const double *tk, const double *tp, int n, int periods, double *y) {
    const double K11 = c[0], C11 = c[1], G1 = c[2], P1 = c[3], K21 = c[4], C21 = c[5], K23 = c[6], C23 = c[7];
    const double K33 = c[8], C33 = c[9], G3 = c[10], P3 = c[11], CM = c[12], B = c[13], ON = c[17];
    double x1 = y[0], x2 = y[1], x3 = y[2], v1 = y[3], v2 = y[4], v3 = y[5];
    for (int per = 0; per < periods; per++) {
        for (int j = 0; j < n; j++) {
            double h = th[j], hh = 0.5 * h;
            double k0 = tk[3 * j], k1 = tk[3 * j + 1], k2 = tk[3 * j + 2];
            double p0 = tp[3 * j], p1 = tp[3 * j + 1], p2 = tp[3 * j + 2];
            double a1, a2, a3, b1, b2, b3, c1, c2, c3, d1, d2, d3;
            RHS(x1, x2, x3, v1, v2, v3, k0, p0, a1, a2, a3);
            double X1 = x1 + hh * v1, X2 = x2 + hh * v2, X3 = x3 + hh * v3;
            double V1 = v1 + hh * a1, V2 = v2 + hh * a2, V3 = v3 + hh * a3;
            RHS(X1, X2, X3, V1, V2, V3, k1, p1, b1, b2, b3);
            double sx1 = v1 + 2.0 * V1, sx2 = v2 + 2.0 * V2, sx3 = v3 + 2.0 * V3;
            double sv1 = a1 + 2.0 * b1, sv2 = a2 + 2.0 * b2, sv3 = a3 + 2.0 * b3;
            double W1 = v1 + hh * b1, W2 = v2 + hh * b2, W3 = v3 + hh * b3;
            RHS(x1 + hh * V1, x2 + hh * V2, x3 + hh * V3, W1, W2, W3, k1, p1, c1, c2, c3);
            sx1 += 2.0 * W1; sx2 += 2.0 * W2; sx3 += 2.0 * W3;
            sv1 += 2.0 * c1; sv2 += 2.0 * c2; sv3 += 2.0 * c3;
            double U1 = v1 + h * c1, U2 = v2 + h * c2, U3 = v3 + h * c3;
            RHS(x1 + h * W1, x2 + h * W2, x3 + h * W3, U1, U2, U3, k2, p2, d1, d2, d3);
            double h6 = h / 6.0;
            double n1 = x1 + h6 * (sx1 + U1), n2 = x2 + h6 * (sx2 + U2), n3 = x3 + h6 * (sx3 + U3);
            double m1 = v1 + h6 * (sv1 + d1), m2 = v2 + h6 * (sv2 + d2), m3 = v3 + h6 * (sv3 + d3);
            x1 = n1; x2 = n2; x3 = n3; v1 = m1; v2 = m2; v3 = m3;
        }
    }
    y[0] = x1; y[1] = x2; y[2] = x3; y[3] = v1; y[4] = v2; y[5] = v3;
}
"""

C_FLAGS = ("-O3", "-march=native", "-ffp-contract=off", "-fno-fast-math")


def compile_c_rk4(tmp: Path):
    """Compile :data:`C_RK4` with gcc into ``tmp`` (a temporary directory) and load it (ctypes)."""
    import ctypes
    import subprocess

    src = tmp / "rk4.c"
    lib = tmp / "rk4.so"
    src.write_text(C_RK4)
    subprocess.run(["gcc", *C_FLAGS, "-shared", "-fPIC", str(src), "-o", str(lib), "-lm"], check=True)
    so = ctypes.CDLL(str(lib))
    dp = ctypes.POINTER(ctypes.c_double)
    so.run.argtypes = [dp, dp, dp, dp, ctypes.c_int, ctypes.c_int, dp]
    so.run.restype = None

    def run_c(c, th, tk, tp, periods, y0):
        y = np.array(y0, dtype=float)
        arrs = [np.ascontiguousarray(a, dtype=float) for a in (c, th, tk, tp)]
        so.run(*(a.ctypes.data_as(dp) for a in arrs), len(th), int(periods), y.ctypes.data_as(dp))
        return y

    return run_c


def kernel_costs(lanes: int = 64, periods: int = 100, steps: int = 512, log=print) -> dict:
    """Cost per point-step: scalar C RK4 (gcc, this run), the scalar numba kernel (one point) and
    the batch kernel (lockstep lanes; one thread and all threads), plain RK4 and event RK4."""
    import tempfile

    import numba

    from geardyn.solve.simulate import simulate_batch, step_tables

    base = cases()["periodic"]
    systems = [base.replace(b=float(b)) for b in np.linspace(0.5, 2.5, lanes)]
    out: dict = {"lanes": lanes, "periods": periods, "steps": steps, "threads": numba.get_num_threads()}
    n_steps = lanes * periods * steps
    with tempfile.TemporaryDirectory() as tmp:
        run_c = compile_c_rk4(Path(tmp))
        tabs = [step_tables(c, steps, True) for c in systems]
        y0s = [c.static_state() for c in systems]

        def c_all():
            return [run_c(t[0], t[1], t[4], t[5], periods, y) for t, y in zip(tabs, y0s, strict=True)]

        t_c, yc = _timed(c_all, 3)
    out["c_ns"] = t_c / n_steps * 1e9
    for integ in ("rk4", "rk4_event"):
        s = SimulationSettings(
            integrator=integ, steps_per_period=steps, transient_periods=periods - 1, recorded_periods=1
        )
        simulate(systems[0], s)
        simulate_batch(systems[:9], s)
        t_s, rs = _timed(lambda: [simulate(c, s) for c in systems], 3)
        nthreads = numba.get_num_threads()
        numba.set_num_threads(1)
        t_b1, _ = _timed(lambda: simulate_batch(systems, s), 3)
        numba.set_num_threads(nthreads)
        t_b, rb = _timed(lambda: simulate_batch(systems, s), 3)
        same = all(np.array_equal(a.final_state, b.final_state) for a, b in zip(rs, rb, strict=True))
        out[integ] = {
            "scalar_ns": t_s / n_steps * 1e9,
            "batch1_ns": t_b1 / n_steps * 1e9,
            "batch_ns": t_b / n_steps * 1e9,
            "bit_identical": same,
        }
        if integ == "rk4":
            out["c_equals_numba"] = all(np.array_equal(a, r.final_state) for a, r in zip(yc, rs, strict=True))
        log(
            f"[kernel] {integ}: C {out['c_ns']:.1f} ns/step, numba scalar {out[integ]['scalar_ns']:.1f}, "
            f"batch 1 thread {out[integ]['batch1_ns']:.1f}, batch {nthreads} threads {out[integ]['batch_ns']:.1f} "
            f"ns per point-step (bit-identical: {same})"
        )
    return out


def dop853_ratios(quick: bool = False, log=print) -> dict:
    """Speed against DOP853 at equal Poincare error (periodic case, 500 + 100 periods): wall time of the
    fixed-step RK4 (previous: one point; batch: per point of a 64-point batch) interpolated to the
    errors 1e-6 and 1e-8, against DOP853 (no step limit) at rtol 1e-6, 1e-8, 1e-10."""
    from geardyn.solve.simulate import simulate_batch

    c = cases()["periodic"]
    ntr, nrec = (50, 10) if quick else (500, 100)
    y0 = static_deflection(c)
    ref = simulate(
        c, SimulationSettings(integrator="dop853", transient_periods=ntr, recorded_periods=nrec, rtol=1e-12), y0
    )
    steps = (128, 256, 512, 1024)
    lanes = 64
    err, t_old, t_new = [], [], []
    for n in steps:
        s = SimulationSettings(steps_per_period=n, transient_periods=ntr, recorded_periods=nrec)
        simulate_batch([c] * 9, s)
        to, r = _timed(lambda: simulate(c, s, y0), 3)
        tn, rb = _timed(lambda: simulate_batch([c] * lanes, s, [y0] * lanes), 2)
        assert np.array_equal(rb[0].poincare, r.poincare)
        err.append(float(np.abs(r.poincare - ref.poincare).max()))
        t_old.append(to)
        t_new.append(tn / lanes)
        log(
            f"[dop853] N={n}: error {err[-1]:.2e}, previous {to * 1e3:.1f} ms/point, batch {tn / lanes * 1e3:.2f} ms/point"
        )
    dt, de = [], []
    for rt in (1e-6, 1e-8, 1e-10):
        s = SimulationSettings(integrator="dop853", transient_periods=ntr, recorded_periods=nrec, rtol=rt)
        t, r = _timed(lambda: simulate_reference(c, s, y0, max_step_fraction=np.inf), 1)
        dt.append(t)
        de.append(float(np.abs(r.poincare - ref.poincare).max()))
        log(f"[dop853] rtol {rt:.0e}: {t:.2f} s, error {de[-1]:.2e}")
    out = {"steps": steps, "error": err, "t_old": t_old, "t_new": t_new, "dop_time": dt, "dop_error": de}
    for target in (1e-6, 1e-8):
        t_dp = _interp_time(np.array(de), np.array(dt), target)
        for key, tt in (("old", t_old), ("new", t_new)):
            t_rk = _interp_time(np.array(err), np.array(tt), target)
            out[f"ratio_{key}_{target:.0e}"] = t_dp / t_rk if np.isfinite(t_rk * t_dp) else float("nan")
    return out


def throughput(config_path: Path = Path("config/config.yaml"), quick: bool = False, log=print) -> dict:
    out = {"kernel": kernel_costs(periods=20 if quick else 100, log=log)}
    out["dop853"] = dop853_ratios(quick=quick, log=log)
    out["map"] = map_throughput(config_path, quick=quick, log=log)
    out["figures"] = figures_throughput(config_path, quick=quick, log=log)
    return out


def throughput_markdown(out: dict) -> str:
    import numba

    k, d, m, f = out["kernel"], out["dop853"], out["map"], out["figures"]
    lines = [
        f"Machine: {platform.node()} {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
        f"{numba.get_num_threads()} numba threads; both starts measured in the same run; load average "
        f"{os.getloadavg()[0]:.1f} at the end (shared machine: wall times are upper bounds).",
        "",
        "| what | fixed start | follow start | ratio (fixed / follow) |",
        "|---|---:|---:|---:|",
    ]
    lines.append(
        f"| map {m['map']} of {m['design']} ({m['points']} points), wall | {m['fixed_wall_s_estimate']:.0f} s "
        f"(from {m['fixed_rows']} rows) | {m['follow_wall_s']:.1f} s | "
        f"{m['fixed_wall_s_estimate'] / m['follow_wall_s']:.1f}x |"
    )
    lines.append(
        f"| same map, CPU time | {m['fixed_cpu_s_estimate']:.0f} CPU-s | {m['follow_cpu_s']:.0f} CPU-s | "
        f"{m['fixed_cpu_s_estimate'] / m['follow_cpu_s']:.1f}x |"
    )
    lines.append(
        f"| paper 1 sweeps for {f['design']} ({f['points']} points), wall | {f['fixed_wall_s']:.1f} s | "
        f"{f['follow_wall_s']:.1f} s | {f['fixed_wall_s'] / f['follow_wall_s']:.1f}x |"
    )
    for integ in ("rk4", "rk4_event"):
        r = k[integ]
        lines.append(
            f"| cost per point-step, {integ}, vs scalar C RK4 ({k['c_ns']:.1f} ns): scalar loop / batch "
            f"| {r['scalar_ns'] / k['c_ns']:.2f}x | {r['batch_ns'] / k['c_ns']:.2f}x ({k['threads']} threads), "
            f"{r['batch1_ns'] / k['c_ns']:.2f}x (1 thread) | |"
        )
    for target in ("1e-06", "1e-08"):
        lines.append(
            f"| speed vs scipy DOP853 at equal Poincare error {target} (batch) | | {d[f'ratio_new_{target}']:.0f}x | |"
        )
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
    import xarray as xr

    k, m, f = out["kernel"], out["map"], out["figures"]
    start = ["fixed", "follow"]
    ds = xr.Dataset(
        {
            "ns_per_point_step": (
                ("integrator",),
                [k[i]["batch_ns"] for i in ("rk4", "rk4_event")],
                {"units": "ns", "long_name": "batch kernel per point and RK4 step (all threads)"},
            ),
            "ns_per_point_step_scalar": (
                ("integrator",),
                [k[i]["scalar_ns"] for i in ("rk4", "rk4_event")],
                {"units": "ns", "long_name": "scalar loop per RK4 step"},
            ),
            "c_ns_per_step": ((), k["c_ns"], {"units": "ns", "long_name": "scalar C RK4 (gcc) per step"}),
            "map_wall_time": (
                ("start",),
                [m["fixed_wall_s_estimate"], m["follow_wall_s"]],
                {
                    "units": "s",
                    "long_name": f"regime map {m['map']}: wall time (fixed: estimate from {m['fixed_rows']} rows)",
                },
            ),
            "figures_wall_time": (
                ("start",),
                [f["fixed_wall_s"], f["follow_wall_s"]],
                {"units": "s", "long_name": f"paper 1 sweeps for {f['design']}: wall time"},
            ),
        },
        coords={
            "integrator": ("integrator", ["rk4", "rk4_event"], {"long_name": "fixed-step integrator"}),
            "start": ("start", start, {"long_name": "start of each point: fixed state or the previous attractor"}),
        },
    )
    ds.attrs.update(
        {
            "title": "Throughput of the labeller: follow against fixed starts",
            "source": "geardyn.bench",
            "machine": f"{platform.node()} {os.cpu_count()} cores",
            "map_rows_labels_agree": f"{m['rows_agree']}/{m['rows_points']}",
            "figures_labels_agree": f"{f['agree']}/{f['points']}",
        }
    )
    return ds


if __name__ == "__main__":
    sys.exit(main())
