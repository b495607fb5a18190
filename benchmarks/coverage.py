"""Coverage of the RMS error bars: how often the RMS values of two independent records of one point differ by
at most 1.96 sqrt(SE1^2 + SE2^2), per design and label (method and results: ``docs/response.md``)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
from scipy.stats import binomtest

from benchmarks.common import PAPER1_SWEEPS, load_design, workflow_config
from geardyn.khv import point
from geardyn.label import vocabulary
from geardyn.runs import response, sweep
from geardyn.solve.base import Lane, Sums
from geardyn.solve.response import measures_of_sums, rms_errors_many
from geardyn.solve.run import simulate_batch

NAMES = {vocabulary.LABELS["quasi_periodic"]: "quasi-periodic", vocabulary.LABELS["chaotic"]: "chaotic"}
#: windows of mesh periods run on after a record to say whether it is stationary (:func:`_drifts`)
WINDOWS, WINDOW = 5, 1000


def _record(systems, starts, settings, before):
    """A record of ``settings.recorded_periods`` after ``before`` periods from ``starts``: each point's (RMS DTE,
    its error, RMS force, its error) or None where it diverged, and the final states."""
    rec = settings.recorded_periods
    runs = simulate_batch(
        [Lane(s, x, before, rec, sums=Sums(rec)) for s, x in zip(systems, starts, strict=True)], settings
    )
    measures = [measures_of_sums(None if r.diverged else r.sums, s, rec) for r, s in zip(runs, systems, strict=True)]
    errors = rms_errors_many(systems, [r.poincare for r in runs], measures, settings)
    out = [
        None if m.diverged else (m.dte_rms, e.dte_rms_error, m.force_rms, e.force_rms_error)
        for m, e in zip(measures, errors, strict=True)
    ]
    return out, [r.final_state for r in runs]


def _drifts(systems, starts, settings) -> list[bool]:
    """Whether each record ending at ``starts`` is a transient: its run on diverges, or the RMS DTE over the first
    of :data:`WINDOWS` windows of :data:`WINDOW` periods after it differs from that over the last by more than 2 %."""
    s = dataclasses.replace(settings, recorded_periods=WINDOW)
    first = last = None
    for _ in range(WINDOWS):
        rms, starts = _record(systems, starts, s, 0)
        first, last = first or rms, rms
    return [a is None or b is None or abs(a[0] - b[0]) > 0.02 * b[0] for a, b in zip(first, last, strict=True)]


def _pairs(systems, first, finals, settings, gap):
    """The rows of one set: record 1 (``first``, ending at ``finals``), record 2 after ``gap`` more periods."""
    second, _ = _record(systems, finals, settings, gap)
    drift = _drifts(systems, finals, settings)
    return [(a, b, d) for a, b, d in zip(first, second, drift, strict=True) if a is not None and b is not None]


def _covered(rows, k: int) -> str:
    hits = sum(abs(a[k] - b[k]) <= 1.96 * np.hypot(a[k + 1], b[k + 1]) for a, b, _ in rows)
    ci = binomtest(int(hits), len(rows)).proportion_ci(0.95, "exact")
    return f"{hits}/{len(rows)} = {100 * hits / len(rows):.1f} % ({100 * ci.low:.0f}-{100 * ci.high:.0f})"


def coverage_check(config_path: Path, results: Path, gap: int = 1000, n_qp: int = 300, seed: int = 0, log=print) -> str:
    """The coverage of the error bars: (1) at the non-periodic points of every built frequency response, the
    file's RMS and error (the labeller's record) against a record ``gap`` periods after its final state; (2) at
    the sweeps' quasi-periodic (``n_qp`` drawn at random) and chaotic points, two records at the frequency
    response's settings from the newest stored Poincare point (400 periods to settle), ``gap`` periods apart.
    Each set also without the records that drift (:func:`_drifts`)."""
    import xarray as xr  # noqa: PLC0415

    config = workflow_config(config_path)
    root = config_path.resolve().parent.parent
    raw = config["responses"]["frequency_response"]
    sets: dict[tuple[str, str, str], list] = {}
    pools: dict[int, list] = {}
    for dname in config["designs"]:
        path = results / dname / "response" / "frequency_response.nc"
        if not path.exists():
            continue
        d = load_design(dname, config, root)
        spec = response.ResponseSpec.from_config("frequency_response", raw, dname, d.segment)
        base, settings = point.point_coefficients(d, dict(spec.fixed)), spec.policy(d).integration
        settings = dataclasses.replace(settings, transient_periods=0, early_stop=False)
        ds = xr.open_dataset(path).load()
        for code, name in NAMES.items():
            idx = list(zip(*np.nonzero(ds.label.values == code), strict=True))
            if idx:
                systems = [base.replace(omega=float(ds.w.values[j])) for _, j in idx]
                first = [
                    tuple(float(ds[v].values[i]) for v in ("dte_rms", "dte_rms_error", "force_rms", "force_rms_error"))
                    for i in idx
                ]
                finals = [ds.final_state.values[i] for i in idx]
                sets["frequency response", dname, name] = _pairs(systems, first, finals, settings, gap)
                log(f"{dname} {name}: {len(idx)} points")
        for sname in PAPER1_SWEEPS:
            path = results / dname / "sweeps" / f"{sname}.nc"
            if path.exists():
                sw = sweep.SweepSpec.from_config(sname, dict(config["sweeps"][sname]), dname, d.segment)
                cube = xr.open_dataset(path).load()
                for code in NAMES:
                    for c, r, j in zip(*np.nonzero(cube.label.values == code), strict=True):
                        state = np.array(
                            [cube[v].values[c, r, j, -1] for v in ("x_dh", "x_vh", "x_vl", "v_dh", "v_vh", "v_vl")]
                        )
                        system = point.point_coefficients(d, sweep.point_overrides(sw, int(c), float(sw.values[j])))
                        pools.setdefault(code, []).append((dname, system, state, settings))
    rng = np.random.default_rng(seed)
    for code, pool in pools.items():
        if code == vocabulary.LABELS["quasi_periodic"] and len(pool) > n_qp:
            pool = [pool[k] for k in sorted(rng.choice(len(pool), n_qp, replace=False))]
        for dname in sorted({p[0] for p in pool}):
            part = [p for p in pool if p[0] == dname]
            systems, settings = [p[1] for p in part], part[0][3]
            first, finals = _record(systems, [p[2] for p in part], settings, 400)
            keep = [k for k, f in enumerate(first) if f is not None]
            sets["sweeps", dname, NAMES[code]] = _pairs(
                [systems[k] for k in keep], [first[k] for k in keep], [finals[k] for k in keep], settings, gap
            )
            log(f"sweeps {dname} {NAMES[code]}: {len(part)} points")
    lines = [
        f"Records of the frequency response's settings, the second {gap} periods after the first; covered: "
        "|RMS1 - RMS2| <= 1.96 sqrt(SE1^2 + SE2^2) (exact 95 % binomial intervals); stationary: without the "
        f"records whose RMS over {WINDOW} periods after them drifts by more than 2 % in {WINDOWS * WINDOW} periods.",
        "",
        "| points | design | label | RMS DTE | RMS force | stationary: RMS DTE | RMS force |",
        "|---|---|---|---|---|---|---|",
    ]
    for (where, dname, name), rows in sets.items():
        still = [r for r in rows if not r[2]]
        cells = [_covered(rows, 0), _covered(rows, 2)] + (
            [_covered(still, 0), _covered(still, 2)] if still else ["-", "-"]
        )
        lines.append(f"| {where} | {dname} | {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"
