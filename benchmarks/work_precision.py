"""Speed against error of the KHV integrators.  Run: ``python -m benchmarks.bench [--out DIR]``.

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

import functools
import json
import math
import platform
import time
from pathlib import Path

import numba
import numpy as np
from matplotlib.figure import Figure
from scipy.stats import wasserstein_distance

from benchmarks.common import timed
from geardyn import io
from geardyn.io import Var
from geardyn.khv.model import Coefficients, KHVParameters, dimensionless, static_deflection
from geardyn.papers import li2013
from geardyn.solve import SimulationSettings, System, simulate, warm_up
from geardyn.solve.reference import simulate_reference

STEPS = (32, 64, 128, 256, 512, 1024)
RTOLS = (1e-6, 1e-8, 1e-10)
TARGET_ERROR = 1e-6


def largest_lyapunov(
    coeffs: System,
    settings: SimulationSettings,
    x0: np.ndarray | None = None,
    n_periods: int = 500,
    d0: float = 1e-7,
) -> tuple[float, np.ndarray]:
    """Largest Lyapunov exponent (per unit dimensionless time) by two nearby trajectories.

    Benettin's method: a companion started d0 away (all 6 states, Euclidean norm) is
    renormalised back to distance d0 at the end of every mesh period.  Starts after
    ``settings.transient_periods``.  Returns (lambda, running estimate per period).
    Positive: chaos (or parametric instability); ~0: quasi-periodic; negative: periodic.
    """
    one = SimulationSettings(
        integrator=settings.integrator,
        steps_per_period=settings.steps_per_period,
        transient_periods=0,
        recorded_periods=1,
        divergence_threshold=settings.divergence_threshold,
        aligned=settings.aligned,
    )
    y = coeffs.static_state() if x0 is None else np.asarray(x0, dtype=float)
    if settings.transient_periods > 0:
        tr = SimulationSettings(
            integrator=settings.integrator,
            steps_per_period=settings.steps_per_period,
            transient_periods=settings.transient_periods - 1,
            recorded_periods=1,
            divergence_threshold=settings.divergence_threshold,
            aligned=settings.aligned,
        )
        r = simulate(coeffs, tr, y)
        if r.diverged:
            return float("inf"), np.array([np.inf])
        y = r.final_state
    rng = np.random.default_rng(0)
    d = rng.standard_normal(6)
    z = y + d0 * d / np.linalg.norm(d)
    acc = 0.0
    est = np.empty(n_periods)
    for k in range(n_periods):
        ry = simulate(coeffs, one, y)
        rz = simulate(coeffs, one, z)
        if ry.diverged or rz.diverged:
            return float("inf"), est[:k]
        y, z = ry.final_state, rz.final_state
        dist = np.linalg.norm(z - y)
        acc += math.log(dist / d0)
        z = y + (z - y) * (d0 / dist)
        est[k] = acc / ((k + 1) * coeffs.period)
    return float(est[-1]), est


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


def _w1(a: np.ndarray, b: np.ndarray) -> float:

    d = 0.0
    for k in (1, 4):  # x2, v2
        d = max(d, wasserstein_distance(a[:, k], b[:, k]) / np.std(b[:, k]))
    return float(d)


def run(quick: bool = False, log=print) -> dict:
    """Compute the study; returns a dict of arrays and scalars (see :func:`to_dataset`)."""

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
        t_ref, ref = timed(functools.partial(simulate, c, ref_s, y0), 1)
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
                t, r = timed(functools.partial(simulate, c, s, y0), 3)
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
            t, r = timed(functools.partial(simulate_reference, c, s, y0, max_step_fraction=np.inf), 1)
            e = float(np.abs(r.poincare - ref.poincare).max()) if name == "periodic" else _w1(r.poincare, ref.poincare)
            dt.append(t)
            de.append(e)
            log(f"[{name}] dop853 rtol={rt:.0e}: {t:8.2f} s  error {e:.3e}")
        res["dop853"] = {"time": np.array(dt), "error": np.array(de)}
        out["cases"][name] = res
    out["summary"] = summarize(out)
    return out


def interp_time(err: np.ndarray, time_: np.ndarray, target: float) -> float:
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
        t_rk = interp_time(ev["error"], ev["time"], target)
        t_dp = interp_time(dp["error"], dp["time"], target)
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

    steps, rtols = out["steps"], out["rtols"]
    names = list(out["cases"])
    integ = ["rk4", "rk4_event"]

    def stack(key):
        return np.array([[out["cases"][c][i][key] for i in integ] for c in names])

    runs, dop = ("case", "integrator", "steps_per_period"), ("case", "rtol")
    table = (
        Var("wall_time", runs, "s", "wall time per sweep point (single thread)"),
        Var(
            "error",
            runs,
            "1",
            "periodic: max abs Poincare error vs DOP853 rtol 1e-12 (units of b_c); chaotic: normalised Wasserstein-1 "
            "distance of Poincare x2/v2",
        ),
        Var("lyapunov", runs, "1", "largest Lyapunov exponent per unit dimensionless time (chaotic case only)"),
        Var("ns_per_step", runs, "ns", "wall time per RK4 step, events included"),
        Var("dop853_wall_time", dop, "s", "DOP853 wall time per sweep point"),
        Var("dop853_error", dop, "1", "DOP853 error (same measure as error)"),
        Var("reference_wall_time", "case", "s", "DOP853 rtol 1e-12 reference wall time"),
        Var("case", "case", None, "test case"),
        Var("integrator", "integrator", None, "fixed-step integrator"),
        Var("steps_per_period", "steps_per_period", "1", "RK4 steps per mesh period"),
        Var("rtol", "rtol", "1", "DOP853 relative tolerance"),
    )
    values = {"wall_time": stack("time"), **{k: stack(k) for k in ("error", "lyapunov", "ns_per_step")}}
    dop853 = {k: np.array([out["cases"][c]["dop853"][k] for c in names]) for k in ("time", "error")}
    values |= {"dop853_wall_time": dop853["time"], "dop853_error": dop853["error"]}
    values["reference_wall_time"] = np.array([out["cases"][c]["ref_time"] for c in names])
    ds = io.dataset(table, values | {"case": names, "integrator": integ, "steps_per_period": steps, "rtol": rtols})
    s = out["summary"]
    ds.attrs.update(
        {
            "title": "Work-precision of the KHV integrators",
            "source": "benchmarks.bench",
            "history": f"{time.strftime('%Y-%m-%dT%H:%M:%SZ', time.gmtime())} python -m benchmarks.bench",
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
    cells = []
    for c, res in out["cases"].items():
        for integ in ("rk4", "rk4_event"):
            r = res[integ]
            for i, n in enumerate(out["steps"]):
                lam = "" if np.isnan(r["lyapunov"][i]) else f"{r['lyapunov'][i]:.4f}"
                cells.append(
                    (
                        c,
                        integ,
                        n,
                        f"{r['time'][i] * 1e3:.1f}",
                        f"{r['error'][i]:.2e}",
                        f"{r['ns_per_step'][i]:.1f}",
                        lam,
                    )
                )
        for i, rt in enumerate(out["rtols"]):
            d = res["dop853"]
            cells.append(
                (c, f"dop853 rtol {rt:.0e}", "-", f"{d['time'][i] * 1e3:.0f}", f"{d['error'][i]:.2e}", "-", "")
            )
        lam = f"{res.get('lyap_ref', float('nan')):.4f}"
        cells.append((c, "dop853 rtol 1e-12 (reference)", "-", f"{res['ref_time'] * 1e3:.0f}", "0", "-", lam))
    head = ("case", "integrator", "steps/period", "wall time per point (ms)", "error", "ns/step", "Lyapunov")
    lines = [io.markdown_table(head, cells, "--rrrrr")]
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
    """Error against wall time of each integrator, one panel per case (no pyplot: any backend)."""
    fig = Figure(figsize=(10, 4))
    axes = fig.subplots(1, 2)
    for ax, (c, res) in zip(axes, out["cases"].items(), strict=True):
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
