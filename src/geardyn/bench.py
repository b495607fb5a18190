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

import argparse  # noqa: E402
import json  # noqa: E402
import platform  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from geardyn.solve import SimulationSettings, largest_lyapunov, simulate, warm_up  # noqa: E402
from geardyn.khv.model import Coefficients, KHVParameters, dimensionless, static_deflection  # noqa: E402
from geardyn.papers import li2013  # noqa: E402
from geardyn.solve.reference import simulate_reference  # noqa: E402

STEPS = (32, 64, 128, 256, 512, 1024)
RTOLS = (1e-6, 1e-8, 1e-10)
TARGET_ERROR = 1e-6


def cases() -> dict[str, Coefficients]:
    """The benchmark cases: paper 1's drive (Table 2 and the li2013 design's assumptions) at a periodic
    and a chaotic operating point."""
    base = {**li2013.TABLE2, **li2013.ASSUMED}
    return {
        "periodic": dimensionless(KHVParameters(eps=1.30, k_c=3.1e8, **{**base, "omega_bar": 0.9})),
        "chaotic": dimensionless(KHVParameters(eps=1.24, k_c=3.1e8, **{**base, "omega_bar": 0.55, "T_D": 2.0,
                                                                        "T_L": 2.0})),
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
            ref2 = simulate(c, SimulationSettings(integrator="rk4_event", steps_per_period=4096,
                                                  transient_periods=ntr, recorded_periods=nrec), y1)
            res["floor"] = _w1(ref2.poincare, ref.poincare)
            lam_ref, _ = largest_lyapunov(c, SimulationSettings(steps_per_period=2048, transient_periods=100),
                                          n_periods=100 if quick else 500)
            res["lyap_ref"] = lam_ref
            log(f"[{name}] distribution floor {res['floor']:.3g}, Lyapunov (2048 steps) {lam_ref:.4f}")
        for integ in ("rk4", "rk4_event"):
            times, errs, lyap, nsps = [], [], [], []
            for n in steps:
                s = SimulationSettings(integrator=integ, steps_per_period=n, transient_periods=ntr,
                                       recorded_periods=nrec)
                t, r = _timed(lambda: simulate(c, s, y0), 3)
                nsps.append(t / ((ntr + nrec) * n) * 1e9)
                times.append(t)
                if name == "periodic":
                    errs.append(float(np.abs(r.poincare - ref.poincare).max()))
                    lyap.append(np.nan)
                else:
                    errs.append(_w1(r.poincare, ref.poincare))
                    lam, _ = largest_lyapunov(c, SimulationSettings(integrator=integ, steps_per_period=n,
                                                                    transient_periods=100),
                                              n_periods=100 if quick else 500)
                    lyap.append(lam)
                log(f"[{name}] {integ:9s} N={n:5d}: {t * 1e3:8.2f} ms  error {errs[-1]:.3e}  "
                    f"{nsps[-1]:.1f} ns/step  events {r.n_events}")
            res[integ] = {"time": np.array(times), "error": np.array(errs), "lyapunov": np.array(lyap),
                          "ns_per_step": np.array(nsps)}
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
            "wall_time": (("case", "integrator", "steps_per_period"), stack("time"),
                          {"units": "s", "long_name": "wall time per sweep point (single thread)"}),
            "error": (("case", "integrator", "steps_per_period"), stack("error"),
                      {"units": "1", "long_name": "periodic: max abs Poincare error vs DOP853 rtol 1e-12 "
                       "(units of b_c); chaotic: normalised Wasserstein-1 distance of Poincare x2/v2"}),
            "lyapunov": (("case", "integrator", "steps_per_period"), stack("lyapunov"),
                         {"units": "1", "long_name": "largest Lyapunov exponent per unit dimensionless time "
                          "(chaotic case only)"}),
            "ns_per_step": (("case", "integrator", "steps_per_period"), stack("ns_per_step"),
                            {"units": "ns", "long_name": "wall time per RK4 step, events included"}),
            "dop853_wall_time": (("case", "rtol"), np.array([out["cases"][c]["dop853"]["time"] for c in names]),
                                 {"units": "s", "long_name": "DOP853 wall time per sweep point"}),
            "dop853_error": (("case", "rtol"), np.array([out["cases"][c]["dop853"]["error"] for c in names]),
                             {"units": "1", "long_name": "DOP853 error (same measure as error)"}),
            "reference_wall_time": (("case",), np.array([out["cases"][c]["ref_time"] for c in names]),
                                    {"units": "s", "long_name": "DOP853 rtol 1e-12 reference wall time"}),
        },
        coords={
            "case": ("case", names, {"long_name": "test case"}),
            "integrator": ("integrator", integ, {"long_name": "fixed-step integrator"}),
            "steps_per_period": ("steps_per_period", steps, {"units": "1", "long_name": "RK4 steps per mesh period"}),
            "rtol": ("rtol", rtols, {"units": "1", "long_name": "DOP853 relative tolerance"}),
        },
    )
    s = out["summary"]
    ds.attrs.update({
        "title": "Work-precision of the KHV integrators",
        "source": "geardyn.bench",
        "history": f"{time.strftime('%Y-%m-%dT%H:%M:%SZ', time.gmtime())} python -m geardyn.bench",
        "model_variant": "corrected Eq. (9), time-varying stiffness, backlash and TE on",
        "machine": f"{platform.node()} {platform.processor() or platform.machine()}, 1 thread",
        "summary": json.dumps({k: v for k, v in s.items()}),
    })
    for c in names:
        ds.attrs[f"coefficients_{c}"] = json.dumps(out["cases"][c]["coeffs"].as_dict())
        ds.attrs[f"periods_{c}"] = out["cases"][c]["n_periods"]
    if "floor" in out["cases"].get("chaotic", {}):
        ds.attrs["chaotic_distribution_floor"] = out["cases"]["chaotic"]["floor"]
        ds.attrs["chaotic_lyapunov_reference"] = out["cases"]["chaotic"]["lyap_ref"]
    return ds


def markdown(out: dict) -> str:
    lines = ["| case | integrator | steps/period | wall time per point (ms) | error | ns/step | Lyapunov |",
             "|---|---|---:|---:|---:|---:|---:|"]
    for c, res in out["cases"].items():
        for integ in ("rk4", "rk4_event"):
            r = res[integ]
            for i, n in enumerate(out["steps"]):
                lam = "" if np.isnan(r["lyapunov"][i]) else f"{r['lyapunov'][i]:.4f}"
                lines.append(f"| {c} | {integ} | {n} | {r['time'][i] * 1e3:.1f} | {r['error'][i]:.2e} | "
                             f"{r['ns_per_step'][i]:.1f} | {lam} |")
        for i, rt in enumerate(out["rtols"]):
            d = res["dop853"]
            lines.append(f"| {c} | dop853 rtol {rt:.0e} | - | {d['time'][i] * 1e3:.0f} | {d['error'][i]:.2e} | - | |")
        lines.append(f"| {c} | dop853 rtol 1e-12 (reference) | - | {res['ref_time'] * 1e3:.0f} | 0 | - | "
                     f"{res.get('lyap_ref', float('nan')):.4f} |")
    s = out["summary"]
    lines += ["", "Periodic-case errors: max |Poincare point - reference| (units of b_c = 1 um). Chaotic-case "
              "errors: normalised Wasserstein-1 distance of the Poincare distributions of x2 and v2; floor "
              f"(reference vs. itself from 1e-10 away) {out['cases'].get('chaotic', {}).get('floor', float('nan')):.3g}.",
              "", f"- observed order, event RK4 (64-512): {s['order_event']:.2f}; plain RK4: {s['order_plain']:.2f}",
              f"- ns per step (median, N >= 128): event {s['ns_per_step_event']:.1f}, plain {s['ns_per_step_plain']:.1f}",
              f"- default steps per period: {s['default_steps']} (error {s['default_error']:.2e} < {TARGET_ERROR:g}), "
              f"{s['default_time_per_point'] * 1e3:.1f} ms per 600-period sweep point",
              "- speed ratio vs DOP853 at equal error: " + ", ".join(f"{k}: {v:.0f}x" for k, v in s['speed_ratio'].items())]
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
    """``throughput`` and ``agreement`` modes (previous vs batch method)."""
    ap = argparse.ArgumentParser(prog=f"python -m geardyn.bench {argv[0]}")
    ap.add_argument("--out", type=Path, default=None, help="directory for throughput.* / agreement.*")
    ap.add_argument("--config", type=Path, default=Path("config/config.yaml"))
    ap.add_argument("--quick", action="store_true", help="short runs (smoke test)")
    ap.add_argument("--map-stride", type=int, default=1, help="agreement: every n-th x and y of the map")
    a = ap.parse_args(argv[1:])
    log = lambda m: print(m, flush=True)  # noqa: E731
    if argv[0] == "throughput":
        out = throughput(a.config, quick=a.quick, log=log)
        md = "# Throughput: batch method vs previous method\n\n" + throughput_markdown(out)
        md += "\n## Label agreement on the paper 1 sweeps\n\n" + agreement_markdown(out["figures"]["runs"])
        ds = throughput_dataset(out)
        stem = "throughput"
    else:
        runs = agreement(a.config, map_stride=a.map_stride * (8 if a.quick else 1), sweep_stride=20 if a.quick else 1,
                         log=log)
        md = "# Labels: previous method vs batch method\n\n" + agreement_markdown(runs)
        ds = None
        stem = "agreement"
    print(md)
    if a.out is not None:
        from geardyn import io

        a.out.mkdir(parents=True, exist_ok=True)
        io.write_text(md, a.out / f"{stem}.md")
        if ds is not None:
            io.write_netcdf(ds, a.out / f"{stem}.nc", io.provenance(title=ds.attrs["title"], paper="li2013",
                                                                   model_variant="benchmark"))
        print(f"wrote {a.out}/{stem}.*")
    return 0


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    if argv and argv[0] in ("throughput", "agreement"):
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

        io.write_netcdf(to_dataset(out), a.out / "work_precision.nc",
                        io.provenance(title="Work-precision study of the KHV integrators", paper="li2013",
                                      model_variant="benchmark"))
        io.write_text(md, a.out / "work_precision.md")
        figure(out, a.out / "work_precision.png")
        print(f"wrote {a.out}/work_precision.nc, .md, .png")
    return 0



# ----------------------------------------------------------------------------------------------
# throughput and agreement: the batch method (early stop, Floquet exponents, lockstep lanes on all
# cores) against the previous method (point by point, full transient, tangent vector), one run
# ----------------------------------------------------------------------------------------------

PAPER1_SWEEPS = ("fig07_bifurcation_x1", "fig09_bifurcation_b", "fig11_bifurcation_e")


def _config(path: Path) -> dict:
    from geardyn import config as cfg_mod

    return cfg_mod.read_yaml(path)


def _design(name: str, config: dict, root: Path):
    from geardyn.khv import design as design_mod

    return design_mod.load(root / config["designs"][name])


def _sweep_points(design, spec):
    from geardyn.khv import point
    from geardyn.runs.sweep import point_overrides

    out = []
    for case in range(len(spec.cases)):
        for j, v in enumerate(spec.values):
            out.append(((spec.case_label(case), float(v)), point.point_coefficients(design, point_overrides(spec, case, v))))
    return out


def _map_points(design, spec, stride: int = 1):
    from geardyn.khv import point
    from geardyn.runs import maps

    out = []
    xs, ys = spec.x.values, spec.y.values
    for i in range(0, len(xs), stride):
        base = point.point_coefficients(design, {**dict(spec.fixed), spec.x.parameter: float(xs[i])})
        for j in range(0, len(ys), stride):
            out.append(((float(xs[i]), float(ys[j])), maps.point_coefficients(design, spec, xs[i], ys[j], base)))
    return out


def _old_worker(args):
    systems, settings, classifier, cheap = args
    from geardyn.runs.points import analyse_points

    t0 = time.process_time()
    out = analyse_points(systems, settings, classifier, cheap=cheap)  # settings.batch is False: point by point
    return [(lab.label, lab.lyapunov, lab.reason, r.transient_used) for r, lab in out], time.process_time() - t0


def compare_methods(systems, settings, classifier, cheap: bool, workers: int = 2, log=print) -> dict:
    """Labels and costs of the previous method (``analyse_point`` point by point, full transient,
    tangent exponent; ``workers`` processes) and of the batch method (``analyse_points`` with the
    settings' early stop and exponent; numba threads) on the same points."""
    import dataclasses
    from concurrent.futures import ProcessPoolExecutor

    from geardyn.runs.points import analyse_points

    old_settings = dataclasses.replace(settings, batch=False)
    parts = np.array_split(np.arange(len(systems)), workers)
    t0 = time.perf_counter()
    with ProcessPoolExecutor(workers) as ex:
        res = list(ex.map(_old_worker, [([systems[i] for i in p], old_settings, classifier, cheap) for p in parts]))
    old_wall = time.perf_counter() - t0
    old = [x for r, _ in res for x in r]
    old_cpu = sum(c for _, c in res)
    analyse_points(systems[:16], settings, classifier, cheap=cheap)  # compile / load the kernels
    t0 = time.perf_counter()
    c0 = time.process_time()
    new_pairs = analyse_points(systems, settings, classifier, cheap=cheap)
    new_wall = time.perf_counter() - t0
    new_cpu = time.process_time() - c0
    new = [(lab.label, lab.lyapunov, lab.reason, r.transient_used) for r, lab in new_pairs]
    log(f"  {len(systems)} points: previous {old_cpu:.1f} CPU-s ({old_wall:.1f} s wall on {workers} processes), "
        f"batch {new_wall:.1f} s wall ({new_cpu:.1f} CPU-s)")
    return {"old": old, "new": new, "old_cpu": old_cpu, "old_wall": old_wall, "new_wall": new_wall,
            "new_cpu": new_cpu}


def confusion(old_labels, new_labels) -> tuple[list[int], np.ndarray]:
    """Confusion matrix (rows: previous label, columns: new label) over the codes present."""
    codes = sorted(set(old_labels) | set(new_labels))
    m = np.zeros((len(codes), len(codes)), np.int64)
    pos = {c: k for k, c in enumerate(codes)}
    for a, b in zip(old_labels, new_labels, strict=True):
        m[pos[a], pos[b]] += 1
    return codes, m


def confusion_markdown(codes, m) -> str:
    from geardyn.classify import short_name

    head = "| previous \\ new | " + " | ".join(short_name(c) for c in codes) + " |"
    lines = [head, "|---|" + "---:|" * len(codes)]
    for k, c in enumerate(codes):
        lines.append(f"| {short_name(c)} | " + " | ".join(str(int(v)) for v in m[k]) + " |")
    return "\n".join(lines)


def agreement(config_path: Path = Path("config/config.yaml"), designs=("li2013", "li2013_calibrated"),
              map_name: str = "map_x1_b", map_stride: int = 1, sweep_stride: int = 1, log=print) -> dict:
    """Previous vs batch method on paper 1's sweeps (Figs. 7, 9, 11) for ``designs`` and on one map:
    labels (confusion matrices, every disagreement listed) and costs."""
    from geardyn import classify
    from geardyn.khv import point
    from geardyn.runs.maps import MapSpec
    from geardyn.runs.sweep import SweepSpec

    root = config_path.resolve().parent.parent
    config = _config(config_path)
    runs = {}
    for dname in designs:
        design = _design(dname, config, root)
        for sname in PAPER1_SWEEPS:
            spec = SweepSpec.from_config(sname, config["sweeps"][sname], dname, design.segment)
            settings = point.integration_settings(design, **dict(spec.integration))
            classifier = classify.ClassifierSettings.from_mapping(dict(spec.classifier))
            pts = _sweep_points(design, spec)[::sweep_stride]
            log(f"[{dname} {sname}] {settings.steps_per_period} steps/period, "
                f"{settings.transient_periods}+{settings.recorded_periods} periods")
            r = compare_methods([c for _, c in pts], settings, classifier, cheap=False, log=log)
            r["where"] = [w for w, _ in pts]
            runs[f"{dname}/{sname}"] = r
    if map_name:
        mspec_raw = config["maps"][map_name]
        dname = mspec_raw["designs"][0]
        design = _design(dname, config, root)
        spec = MapSpec.from_config(map_name, mspec_raw, dname, design.segment)
        settings = point.integration_settings(design, **dict(spec.integration))
        classifier = classify.ClassifierSettings.from_mapping(dict(spec.classifier))
        pts = _map_points(design, spec, map_stride)
        log(f"[{dname} {map_name}] {len(pts)} points (every {map_stride}. x and y)")
        r = compare_methods([c for _, c in pts], settings, classifier, cheap=True, log=log)
        r["where"] = [w for w, _ in pts]
        runs[f"{dname}/{map_name}"] = r
    return runs


def agreement_markdown(runs: dict) -> str:
    from geardyn.classify import short_name

    lines = ["| run | points | agree | share | previous CPU-s | batch wall s | batch CPU-s | mean transient used |",
             "|---|---:|---:|---:|---:|---:|---:|---:|"]
    allo, alln = [], []
    for name, r in runs.items():
        lo = [o[0] for o in r["old"]]
        ln = [n[0] for n in r["new"]]
        agree = sum(a == b for a, b in zip(lo, ln, strict=True))
        used = np.mean([n[3] for n in r["new"]])
        lines.append(f"| {name} | {len(lo)} | {agree} | {agree / len(lo):.4f} | {r['old_cpu']:.1f} | "
                     f"{r['new_wall']:.1f} | {r['new_cpu']:.1f} | {used:.0f} |")
        if "map" not in name:
            allo += lo
            alln += ln
    if allo:
        agree = sum(a == b for a, b in zip(allo, alln, strict=True))
        lines.append(f"| all sweeps | {len(allo)} | {agree} | {agree / len(allo):.4f} | | | | |")
    for name, r in runs.items():
        lo = [o[0] for o in r["old"]]
        ln = [n[0] for n in r["new"]]
        codes, m = confusion(lo, ln)
        lines += ["", f"### {name}", "", confusion_markdown(codes, m), ""]
        bad = [k for k in range(len(lo)) if lo[k] != ln[k]]
        if bad:
            lines += ["| point | previous | new | previous reason | new reason | transient used |", "|---|---|---|---|---|---:|"]
            for k in bad:
                o, n = r["old"][k], r["new"][k]
                lines.append(f"| {r['where'][k]} | {short_name(o[0])} (lambda {o[1]:.2e}) | {short_name(n[0])} "
                             f"(lambda {n[1]:.2e}) | {o[2]} | {n[2]} | {n[3]} |")
        used = np.array([n[3] for n in r["new"]])
        lines.append(f"\ntransient periods used: min {used.min()}, median {np.median(used):.0f}, max {used.max()}; "
                     f"stopped early: {int(np.sum(used < max(used.max(), 1)))} of {used.size}")
    return "\n".join(lines) + "\n"


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
    """Cost per point-step: scalar C RK4 (gcc, this run), the scalar numba kernel (previous method) and
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
        s = SimulationSettings(integrator=integ, steps_per_period=steps, transient_periods=periods - 1,
                               recorded_periods=1)
        simulate(systems[0], s)
        simulate_batch(systems[:9], s)
        t_s, rs = _timed(lambda: [simulate(c, s) for c in systems], 3)
        nthreads = numba.get_num_threads()
        numba.set_num_threads(1)
        t_b1, _ = _timed(lambda: simulate_batch(systems, s), 3)
        numba.set_num_threads(nthreads)
        t_b, rb = _timed(lambda: simulate_batch(systems, s), 3)
        same = all(np.array_equal(a.final_state, b.final_state) for a, b in zip(rs, rb, strict=True))
        out[integ] = {"scalar_ns": t_s / n_steps * 1e9, "batch1_ns": t_b1 / n_steps * 1e9,
                      "batch_ns": t_b / n_steps * 1e9, "bit_identical": same}
        if integ == "rk4":
            out["c_equals_numba"] = all(np.array_equal(a, r.final_state) for a, r in zip(yc, rs, strict=True))
        log(f"[kernel] {integ}: C {out['c_ns']:.1f} ns/step, numba scalar {out[integ]['scalar_ns']:.1f}, "
            f"batch 1 thread {out[integ]['batch1_ns']:.1f}, batch {nthreads} threads {out[integ]['batch_ns']:.1f} "
            f"ns per point-step (bit-identical: {same})")
    return out


def dop853_ratios(quick: bool = False, log=print) -> dict:
    """Speed against DOP853 at equal Poincare error (periodic case, 500 + 100 periods): wall time of the
    fixed-step RK4 (previous: one point; batch: per point of a 64-point batch) interpolated to the
    errors 1e-6 and 1e-8, against DOP853 (no step limit) at rtol 1e-6, 1e-8, 1e-10."""
    from geardyn.solve.simulate import simulate_batch

    c = cases()["periodic"]
    ntr, nrec = (50, 10) if quick else (500, 100)
    y0 = static_deflection(c)
    ref = simulate(c, SimulationSettings(integrator="dop853", transient_periods=ntr, recorded_periods=nrec,
                                         rtol=1e-12), y0)
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
        log(f"[dop853] N={n}: error {err[-1]:.2e}, previous {to * 1e3:.1f} ms/point, batch {tn / lanes * 1e3:.2f} ms/point")
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


def map_throughput(config_path: Path, map_name: str = "map_x1_b", subset_stride: int = 10, quick: bool = False,
                   log=print) -> dict:
    """A whole regime map by the batch method (maps.run_chunk, one chunk, wall time) and the previous
    method on every ``subset_stride``-th x value of it (one process), scaled to the whole map."""
    import dataclasses

    from geardyn import classify
    from geardyn.khv import point
    from geardyn.runs import maps
    from geardyn.runs.points import analyse_points

    root = config_path.resolve().parent.parent
    config = _config(config_path)
    raw = dict(config["maps"][map_name])
    if quick:
        raw["x"] = {**raw["x"], "num": 20}
        raw["y"] = {**raw["y"], "num": 20}
    raw["chunks"] = 1
    dname = raw["designs"][0]
    design = _design(dname, config, root)
    spec = maps.MapSpec.from_config(map_name, raw, dname, design.segment)
    settings = point.integration_settings(design, **dict(spec.integration))
    classifier = classify.ClassifierSettings.from_mapping(dict(spec.classifier))
    pts = _map_points(design, spec, 1)
    sub = [c for k, (_, c) in enumerate(pts) if (k // spec.y.num) % subset_stride == 0]
    analyse_points(sub[:16], settings, classifier, cheap=True)
    old_s = dataclasses.replace(settings, batch=False)
    t0, c0 = time.perf_counter(), time.process_time()
    old = analyse_points(sub, old_s, classifier, cheap=True)  # point by point
    t_old_sub, c_old_sub = time.perf_counter() - t0, time.process_time() - c0
    t0, c0 = time.perf_counter(), time.process_time()
    new_sub = analyse_points(sub, settings, classifier, cheap=True)
    t_new_sub, c_new_sub = time.perf_counter() - t0, time.process_time() - c0
    t0, c0 = time.perf_counter(), time.process_time()
    ds = maps.run_chunk(design, spec, 0)
    t_map, c_map = time.perf_counter() - t0, time.process_time() - c0
    agree = sum(a[1].label == b[1].label for a, b in zip(old, new_sub, strict=True))
    out = {"map": map_name, "design": dname, "points": spec.n_points, "subset_points": len(sub),
           "old_ms_per_point": 1e3 * t_old_sub / len(sub), "new_ms_per_point_subset": 1e3 * t_new_sub / len(sub),
           "map_wall_s": t_map, "old_map_s_estimate": t_old_sub / len(sub) * spec.n_points,
           "map_cpu_s": c_map, "old_map_cpu_estimate": c_old_sub / len(sub) * spec.n_points,
           "subset_cpu_ratio": c_old_sub / c_new_sub, "load_average": os.getloadavg()[0],
           "subset_agree": agree, "transient_used_mean": float(ds["transient_used"].mean()),
           "transient_used_min": int(ds["transient_used"].min())}
    log(f"[map] {map_name} {spec.n_points} points: batch {t_map:.1f} s wall "
        f"({1e3 * t_map / spec.n_points:.2f} ms/point); previous {out['old_ms_per_point']:.2f} ms/point "
        f"(subset of {len(sub)}), i.e. {out['old_map_s_estimate']:.0f} s for the map; subset labels agree "
        f"{agree}/{len(sub)}; CPU: batch {c_map:.1f} CPU-s for the map, previous {out['old_map_cpu_estimate']:.0f} "
        f"CPU-s (estimate); load average {out['load_average']:.1f}")
    return out


def figures_throughput(config_path: Path, design: str = "li2013", quick: bool = False, log=print) -> dict:
    """Paper 1's sweeps (Figs. 7, 9, 11) for ``design``: previous method (CPU-s, 2 processes) and the
    batch method (wall), with label agreement."""
    runs = agreement(config_path, designs=(design,), map_name="", sweep_stride=20 if quick else 1, log=log)
    old_cpu = sum(r["old_cpu"] for r in runs.values())
    new_wall = sum(r["new_wall"] for r in runs.values())
    n = sum(len(r["old"]) for r in runs.values())
    agree = sum(sum(a[0] == b[0] for a, b in zip(r["old"], r["new"], strict=True)) for r in runs.values())
    new_cpu = sum(r["new_cpu"] for r in runs.values())
    return {"design": design, "points": n, "old_cpu_s": old_cpu, "new_wall_s": new_wall, "agree": agree,
            "new_cpu_s": new_cpu,
            "runs": runs}


def throughput(config_path: Path = Path("config/config.yaml"), quick: bool = False, log=print) -> dict:
    out = {"kernel": kernel_costs(periods=20 if quick else 100, log=log)}
    out["dop853"] = dop853_ratios(quick=quick, log=log)
    out["map"] = map_throughput(config_path, quick=quick, log=log)
    out["figures"] = figures_throughput(config_path, quick=quick, log=log)
    return out


def throughput_markdown(out: dict) -> str:
    import numba

    k, d, m, f = out["kernel"], out["dop853"], out["map"], out["figures"]
    lines = [f"Machine: {platform.node()} {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
             f"{numba.get_num_threads()} numba threads; previous and batch method measured in the same run; "
             f"load average {os.getloadavg()[0]:.1f} at the end (shared machine: wall times are upper bounds, "
             f"CPU times are the steadier comparison).", "",
             "| what | previous method | batch method | ratio (previous / batch) |", "|---|---:|---:|---:|"]
    lines.append(f"| map {m['map']} ({m['points']} points, 128 steps/period, 400+50 periods, cheap classifier), wall | "
                 f"{m['old_map_s_estimate']:.0f} s (1 core, {m['old_ms_per_point']:.2f} ms/point on a subset of "
                 f"{m['subset_points']}) | {m['map_wall_s']:.1f} s | {m['old_map_s_estimate'] / m['map_wall_s']:.1f}x |")
    lines.append(f"| same map, CPU time (both threads counted) | {m['old_map_cpu_estimate']:.0f} CPU-s | "
                 f"{m['map_cpu_s']:.1f} CPU-s | {m['old_map_cpu_estimate'] / m['map_cpu_s']:.1f}x |")
    lines.append(f"| paper 1 sweeps for {f['design']} ({f['points']} points, 512 steps/period, 500+100 periods, "
                 f"full classifier) | {f['old_cpu_s']:.0f} CPU-s | {f['new_wall_s']:.1f} s wall | "
                 f"{f['old_cpu_s'] / f['new_wall_s']:.1f}x |")
    lines.append(f"| same sweeps, CPU time | {f['old_cpu_s']:.0f} CPU-s | {f['new_cpu_s']:.1f} CPU-s | "
                 f"{f['old_cpu_s'] / f['new_cpu_s']:.1f}x |")
    for integ in ("rk4", "rk4_event"):
        r = k[integ]
        lines.append(f"| cost per point-step, {integ}, vs scalar C RK4 ({k['c_ns']:.1f} ns) | "
                     f"{r['scalar_ns'] / k['c_ns']:.2f}x | {r['batch_ns'] / k['c_ns']:.2f}x ({k['threads']} threads), "
                     f"{r['batch1_ns'] / k['c_ns']:.2f}x (1 thread) | {r['scalar_ns'] / r['batch_ns']:.1f}x |")
    for target in ("1e-06", "1e-08"):
        lines.append(f"| speed vs scipy DOP853 at equal Poincare error {target} | {d[f'ratio_old_{target}']:.0f}x | "
                     f"{d[f'ratio_new_{target}']:.0f}x | |")
    lines += ["", f"- kernel: {k['lanes']} points x {k['periods']} periods x {k['steps']} steps; C: gcc "
              f"{' '.join(C_FLAGS)}, same expressions (final states equal to the numba kernel's: "
              f"{k['c_equals_numba']}); batch results bit-identical to the scalar kernel: "
              f"{k['rk4']['bit_identical'] and k['rk4_event']['bit_identical']}.",
              f"- map: transient periods used, mean {m['transient_used_mean']:.0f} (min {m['transient_used_min']}) of "
              f"400; labels of the subset agree {m['subset_agree']}/{m['subset_points']}.",
              f"- paper 1 sweeps: labels agree {f['agree']}/{f['points']}.",
              "- DOP853 (no step limit) at rtol 1e-6, 1e-8, 1e-10: " + ", ".join(
                  f"{t:.2f} s (error {e:.1e})" for t, e in zip(d["dop_time"], d["dop_error"], strict=True)),
              "- RK4 event, steps " + ", ".join(str(s) for s in d["steps"]) + ": errors " + ", ".join(
                  f"{e:.1e}" for e in d["error"]) + "; ms per point previous " + ", ".join(
                  f"{t * 1e3:.1f}" for t in d["t_old"]) + "; batch " + ", ".join(f"{t * 1e3:.2f}" for t in d["t_new"])]
    return "\n".join(lines) + "\n"


def throughput_dataset(out: dict):
    import xarray as xr

    k, d, m, f = out["kernel"], out["dop853"], out["map"], out["figures"]
    method = ["previous", "batch"]
    ds = xr.Dataset(
        {
            "ns_per_point_step": (("integrator", "method"), [[k[i]["scalar_ns"], k[i]["batch_ns"]] for i in ("rk4", "rk4_event")],
                                  {"units": "ns", "long_name": "wall time per point and RK4 step (batch: all threads)"}),
            "ns_per_point_step_one_thread": (("integrator",), [k[i]["batch1_ns"] for i in ("rk4", "rk4_event")],
                                             {"units": "ns", "long_name": "batch kernel, one thread"}),
            "c_ns_per_step": ((), k["c_ns"], {"units": "ns", "long_name": "scalar C RK4 (gcc) per step"}),
            "wall_time_per_point": (("steps_per_period", "method"), np.array([d["t_old"], d["t_new"]]).T,
                                    {"units": "s", "long_name": "periodic case, 500+100 periods, per point"}),
            "poincare_error": (("steps_per_period",), d["error"], {"units": "1", "long_name": "max |Poincare - DOP853 rtol 1e-12|"}),
            "dop853_wall_time": (("rtol",), d["dop_time"], {"units": "s", "long_name": "DOP853 wall time (no step limit)"}),
            "dop853_error": (("rtol",), d["dop_error"], {"units": "1", "long_name": "DOP853 Poincare error"}),
            "speed_vs_dop853": (("target_error", "method"), [[d[f"ratio_{mm}_{t}"] for mm in ("old", "new")] for t in ("1e-06", "1e-08")],
                                {"units": "1", "long_name": "DOP853 time / RK4 time at equal Poincare error"}),
            "map_points_per_second": (("method",), [1e3 / m["old_ms_per_point"], m["points"] / m["map_wall_s"]],
                                      {"units": "s-1", "long_name": f"regime map {m['map']}: points per second (wall)"}),
            "figures_time": (("method",), [f["old_cpu_s"], f["new_wall_s"]],
                             {"units": "s", "long_name": f"paper 1 sweeps for {f['design']}: previous CPU-s, batch wall s"}),
        },
        coords={"integrator": ("integrator", ["rk4", "rk4_event"], {"long_name": "fixed-step integrator"}),
                "method": ("method", method, {"long_name": "previous (point by point) or batch method"}),
                "steps_per_period": ("steps_per_period", list(d["steps"]),
                                     {"units": "1", "long_name": "RK4 steps per mesh period"}),
                "rtol": ("rtol", [1e-6, 1e-8, 1e-10], {"units": "1", "long_name": "DOP853 relative tolerance"}),
                "target_error": ("target_error", [1e-6, 1e-8], {"units": "1", "long_name": "Poincare error"})},
    )
    ds.attrs.update({"title": "Throughput of the batch method against the previous method", "source": "geardyn.bench",
                     "machine": f"{platform.node()} {os.cpu_count()} cores", "map_transient_used_mean": m["transient_used_mean"],
                     "figures_labels_agree": f"{f['agree']}/{f['points']}", "map_subset_labels_agree":
                     f"{m['subset_agree']}/{m['subset_points']}"})
    return ds


if __name__ == "__main__":
    sys.exit(main())
