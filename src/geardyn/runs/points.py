"""Dense runs at single operating points: phase trajectory, Poincaré map and amplitude spectrum.

Only the points drawn in Figs. 8, 10 and 12 of paper 1 need the dense trajectory, so it is
computed here, for those points only, and never inside a sweep.
"""

from __future__ import annotations

import dataclasses
import logging
from collections.abc import Mapping

import numpy as np
import xarray as xr

from geardyn.khv import point
from geardyn.khv.design import KHVDesign
from geardyn.solve import SimulationSettings, simulate
from geardyn import classify
from geardyn.runs.cube import SETTLED_ATTRS, STATE_NAMES, STATES

log = logging.getLogger("geardyn.points")

UNDETERMINED = classify.LABELS["undetermined"]


def amplitude_spectrum(x: np.ndarray, samples_per_period: int) -> tuple[np.ndarray, np.ndarray]:
    """One-sided amplitude spectrum of a uniformly sampled signal (mean removed, Hann window).

    Frequencies are in multiples of the mesh frequency (the sampling covers whole mesh periods);
    amplitudes are corrected for the window's coherent gain, so a pure sine of amplitude A shows A.
    """
    x = np.asarray(x, dtype=float)
    n = x.size
    window = np.hanning(n)
    spec = np.fft.rfft((x - x.mean()) * window)
    amp = 2.0 * np.abs(spec) / window.sum()
    freq = np.fft.rfftfreq(n, d=1.0 / samples_per_period)
    return freq, amp


def dense_point(design: KHVDesign, overrides: Mapping[str, float], settings: SimulationSettings,
                samples_per_period: int = 64) -> xr.Dataset:
    """Trajectory over the recorded periods (uniform, ``samples_per_period``), Poincaré points, spectrum."""
    coeffs = point.point_coefficients(design, overrides)
    res = simulate(coeffs, settings, dense=True)
    data: dict = {}
    if res.diverged:
        tau = np.zeros(0)
        states = np.zeros((0, 6))
    else:
        tau, states = res.uniform(samples_per_period)
    for k, name in enumerate(STATES):
        data[name] = ("time", states[:, k], {"units": "1", "long_name": STATE_NAMES[name]})
        data[f"poincare_{name}"] = ("section", res.poincare[:, k],
                                    {"units": "1", "long_name": f"Poincare section: {STATE_NAMES[name]}"})
    if states.shape[0] > 8:
        freq, amp = amplitude_spectrum(states[:, 1], samples_per_period)
    else:
        freq, amp = np.zeros(0), np.zeros(0)
    data["amplitude"] = ("frequency", amp, {"units": "1", "long_name": "amplitude spectrum of X_VH / b_c (Hann)"})
    coords = {
        "time": ("time", (tau - (tau[0] if tau.size else 0.0)) / coeffs.period, {
            "units": "1", "long_name": "time since the end of the transient, in mesh periods"}),
        "section": ("section", np.arange(res.poincare.shape[0], dtype=np.int32),
                    {"units": "1", "long_name": "index of the recorded mesh period"}),
        "frequency": ("frequency", freq, {"units": "1", "long_name": "frequency / mesh frequency"}),
    }
    attrs = {f"coef_{k}": (float(v) if not isinstance(v, str) else v) for k, v in coeffs.as_dict().items()}
    attrs.update({f"override_{k}": float(v) for k, v in overrides.items()})
    attrs["diverged"] = int(res.diverged)
    attrs["integrator"] = settings.integrator
    attrs["steps_per_period"] = settings.steps_per_period
    attrs["transient_periods"] = settings.transient_periods
    attrs["recorded_periods"] = settings.recorded_periods
    return xr.Dataset(data, coords=coords, attrs=attrs)


def dense_points(design: KHVDesign, fixed: Mapping[str, float], cases: list[Mapping[str, float]],
                 settings: SimulationSettings, samples_per_period: int = 64,
                 classifier: classify.ClassifierSettings = classify.ClassifierSettings()) -> xr.Dataset:
    """:func:`dense_point` for each case, concatenated along ``case`` (labels like ``x1=0.5``), with each
    case's motion label from the one classification path (:func:`analyse_points`, the sweeps' labels:
    variables ``label``, ``period``, ``lyapunov``, ``settled``)."""
    labels = analyse_points([point.point_coefficients(design, {**fixed, **case}) for case in cases], settings,
                            classifier)
    parts = []
    for case in cases:
        ds = dense_point(design, {**fixed, **case}, settings, samples_per_period)
        label = ",".join(f"{k}={v:g}" for k, v in case.items()) or "base"
        attrs = ds.attrs
        ds = ds.expand_dims(case=[label])
        for key, value in attrs.items():
            if key.startswith(("coef_", "override_", "diverged")):
                ds[key] = ("case", [value], {"units": "1", "long_name": f"point parameter {key}"})
        parts.append(ds)
    out = xr.concat(parts, dim="case", join="outer", data_vars="all", coords="different", compat="equals",
                    combine_attrs="override")
    out.attrs = {}
    out["case"].attrs["long_name"] = "operating point (overrides)"
    out["label"] = ("case", np.array([lab.label for _, lab in labels], np.int16), {
        "long_name": "motion label (the sweeps' classification, slow-transient check included)",
        **classify.flag_attrs(classifier.max_n)})
    out["period"] = ("case", np.array([lab.period for _, lab in labels], np.int16),
                     {"units": "1", "long_name": "period n in mesh periods (0: not periodic)"})
    out["lyapunov"] = ("case", np.array([lab.lyapunov for _, lab in labels]),
                       {"units": "1", "long_name": "largest Lyapunov exponent per unit dimensionless time tau"})
    out["settled"] = ("case", np.array([int(lab.settled) for _, lab in labels], np.int8), SETTLED_ATTRS)
    out.attrs.update({"integrator": settings.integrator, "steps_per_period": settings.steps_per_period,
                      "transient_periods": settings.transient_periods,
                      "recorded_periods": settings.recorded_periods,
                      "fixed_overrides": ",".join(f"{k}={v:g}" for k, v in fixed.items())})
    return out


def analyse_point(coeffs, settings, classifier: classify.ClassifierSettings = classify.ClassifierSettings(),
                  x0: np.ndarray | None = None, cheap: bool = False):
    """Integrate one point with its tangent vector and classify it: (TangentResult, Classification).

    ``cheap`` (regime maps): integrate without the tangent vector first; a point that passes the
    strict period test (rule 3) is labelled at once with no exponent (NaN); only the others are
    continued from their final state for ``tangent_periods`` more periods with the tangent vector
    (Poincaré points and the 0-1 samples then come from the continuation).  The labels of periodic
    points are the same as the full path's; non-periodic points get a longer transient.
    """
    if not cheap:
        res = simulate(coeffs, settings, x0=x0, tangent_periods=classifier.tangent_periods)
        return res, classify.classify_point(res.poincare, res.growth, res.period, res.diverged, classifier,
                                   samples=res.strobe)
    res = simulate(coeffs, settings, x0=x0, tangent_periods=0)
    if res.diverged:
        return res, classify.classify_point(res.poincare, res.growth, res.period, True, classifier)
    p = res.poincare[~np.isnan(res.poincare).any(axis=1)]
    n = classify.strict_period(p, classifier) if p.shape[0] >= 3 else 0
    if n > 0:
        nan = float("nan")
        return res, classify.Classification(n, n, nan, nan, nan, nan, -1, "periodic (cheap path: no exponent)")
    more = dataclasses.replace(settings, transient_periods=0,
                   recorded_periods=max(settings.recorded_periods, classifier.tangent_periods))
    res2 = simulate(coeffs, more, x0=res.final_state, tangent_periods=classifier.tangent_periods)
    return res2, classify.classify_point(res2.poincare, res2.growth, res2.period, res2.diverged, classifier,
                                samples=res2.strobe)


#: CF attributes of the per-point ``transient_used`` of sweep cubes and maps.
TRANSIENT_USED_ATTRS = {
    "units": "1",
    "long_name": "transient mesh periods integrated before the recorded ones (early stop; "
                 "transient_periods when the transient ran to its end)"}


def speed_attrs(settings) -> dict:
    """Attributes recording how the points were computed (early stop, exponent of periodic points)."""
    return {"early_stop": int(settings.early_stop), "early_stop_min_periods": settings.early_stop_min_periods,
            "early_stop_confirm": settings.early_stop_confirm, "early_stop_tol_factor": settings.early_stop_tol_factor,
            "periodic_exponent": settings.periodic_exponent, "batch": int(settings.batch)}


class _Periods(list):
    tol: np.ndarray


def _strict_periods(results, cs: classify.ClassifierSettings) -> _Periods:
    """Rule 3 (:func:`geardyn.classify.strict_period`) for every result at once (compiled); 0 for a
    diverged run or fewer than 3 points.  ``.tol``: the tolerance of each."""
    from geardyn.solve.simulate import strict_periods

    L = len(results)
    m = max([r.poincare.shape[0] for r in results] + [0])
    pts = np.zeros((L, m, 6))
    npts = np.zeros(L, np.int64)
    for i, r in enumerate(results):
        p = r.poincare
        if not r.diverged and p.shape[0] and not np.isnan(p).any():
            pts[i, :p.shape[0]] = p
            npts[i] = p.shape[0]
    out = strict_periods(pts, npts, cs.max_n, cs.atol, cs.rtol, cs.error_margin * cs.error_floor, cs.separation)
    per = _Periods(int(v) for v in out[:, 0])
    per.tol = out[:, 1]
    return per


def _floquet_label(n: int, mu: np.ndarray, period: float, tol: float) -> classify.Classification:
    """Label of a point periodic by rule 3, with the exponent from the multipliers |mu| of its cycle."""
    lam = float(np.log(np.max(mu))) / (n * period)
    nan = float("nan")
    return classify.Classification(n, n, lam, 0.0, nan, nan, -1,
                                   f"returns within {tol:.2g} after {n}; Floquet max|mu| {np.max(mu):.4g}")


def _classify_all(items, classifier: classify.ClassifierSettings, out: list) -> None:
    """``classify_point`` of every (index, result) into ``out[index]``, in threads (the 0-1 test's compiled
    loop and numpy's array work release the GIL; each call is independent, so the results do not depend on
    the threads)."""
    from geardyn.runs._threads import threaded_map

    def one(item):
        i, r = item
        return i, (r, classify.classify_point(r.poincare, r.growth, r.period, r.diverged, classifier,
                                              samples=r.strobe))

    for i, pair in threaded_map(one, items, min_items=16, chunksize=8):
        out[i] = pair


def early_stop_of(settings, classifier: classify.ClassifierSettings):
    """The early-stop criterion of ``settings`` (None when off), scaled to the classifier's tolerance:
    stop once d_n <= early_stop_tol_factor x max(atol max(|p|, 1), error_margin error_floor)."""
    from geardyn.solve.simulate import EarlyStop

    if not settings.early_stop:
        return None
    f = settings.early_stop_tol_factor
    return EarlyStop(min_periods=settings.early_stop_min_periods, confirm=settings.early_stop_confirm,
                     max_n=classifier.max_n, floor=f * classifier.error_margin * classifier.error_floor,
                     atol=f * classifier.atol, separation=classifier.separation)


def analyse_points(systems, settings, classifier: classify.ClassifierSettings = classify.ClassifierSettings(),
                   cheap: bool = False, x0=None):
    """:func:`analyse_point` for many points at once: a list of (SimulationResult, Classification).

    The points are integrated together (:func:`geardyn.solve.simulate.simulate_batch`, both cores)
    when ``settings.batch``.  With ``settings.early_stop`` a point whose stroboscopic map has
    converged to a period-n cycle ends its transient there (``transient_used``).  With
    ``settings.periodic_exponent == "floquet"``, a point periodic by rule 3 gets its exponent from the
    monodromy of its cycle (n more periods with the 6 x 6 variational matrix: lambda = log max|mu| /
    (n T), sigma 0); if that cycle is not stable (max|mu| >= 1) or the early-stopped point is not
    periodic by rule 3 on its recorded points, the point is redone by the previous method (full
    transient, tangent vector), so an early stop never decides a label on its own.

    Without early stop and with ``periodic_exponent="tangent"`` the labels are those of
    :func:`analyse_point`, bit for bit (the same orbit arithmetic).  ``settings.batch = False``:
    :func:`analyse_point` point by point (the previous method; early_stop and periodic_exponent ignored).

    Last, on either path, the slow-transient check (:mod:`geardyn.runs.settle`, ``classifier.settle_max_n``):
    a point labelled quasi-periodic or undetermined with a non-positive exponent whose run is found to
    approach a stable period-n orbit becomes period-n (``Classification.settled``).  On the cheap batch
    path the check comes first for a point that is not periodic on its record: a point that settles
    there skips the tangent continuation and the 0-1 test (its exponent is the Floquet one).
    """
    systems = list(systems)
    x0s = [None] * len(systems) if x0 is None else list(x0)
    if not settings.batch:
        out = [analyse_point(c, settings, classifier, x0=x, cheap=cheap) for c, x in zip(systems, x0s, strict=True)]
        return _settle_all(systems, out, settings, classifier)
    from geardyn.solve.simulate import lane_tables

    tables = lane_tables(systems, settings)  # every batch run below, and the check, share them
    out = _analyse_batch(systems, x0s, settings, classifier, cheap, tables)
    return _settle_all(systems, out, settings, classifier, tables)


def _settle_many(systems, items, settings, classifier: classify.ClassifierSettings, tables=None) -> list:
    """:func:`geardyn.runs.settle.settle_points` of every (index, result, classification) in ``items``
    (integrated together; each point's check is independent of the others): a list of (index, Settled).
    ``tables``: the lane tables of all ``systems``, when the caller has them."""
    from geardyn.runs.settle import settle_points

    idx = [i for i, _, _ in items]
    settled = settle_points([systems[i] for i in idx], [res for _, res, _ in items],
                            [lab.label for _, _, lab in items], [lab.lyapunov for _, _, lab in items],
                            settings, classifier, None if tables is None else tables.take(idx))
    return list(zip(idx, settled, strict=True))


def _settle_all(systems, out: list, settings, classifier: classify.ClassifierSettings, tables=None) -> list:
    """The slow-transient check (:mod:`geardyn.runs.settle`) of every point of ``out`` that needs it."""
    from geardyn.runs.settle import needs_check, settled_classification

    todo = [(i, res, lab) for i, (res, lab) in enumerate(out) if needs_check(lab.label, lab.lyapunov, classifier)]
    changed = 0
    for i, s in _settle_many(systems, todo, settings, classifier, tables):
        res, lab = out[i]
        out[i] = (res, settled_classification(lab, s, res.period))
        changed += s.after != s.before
    if todo:
        log.info("%d of %d points checked for a slow transient: %d settle on a stable periodic orbit", len(todo),
                 len(out), changed)
    return out


def _analyse_batch(systems, x0s, settings, classifier: classify.ClassifierSettings, cheap: bool, tables) -> list:
    """The batch path of :func:`analyse_points` (before the slow-transient check); ``tables``: the lane
    tables of ``systems`` at ``settings``."""
    from geardyn.solve.simulate import simulate_batch

    L = len(systems)
    es = early_stop_of(settings, classifier)
    floquet = settings.periodic_exponent == "floquet"
    out: list = [None] * L
    # phase 1: transient (early stop) and recorded periods, 8 lanes in lockstep; the full path carries
    # the tangent vector over the last tangent_periods of the nominal run, as before (a lane that
    # stops early drops it: its exponent comes from the monodromy of its cycle)
    carry = not cheap
    res1 = simulate_batch(systems, settings, x0s, tangent_periods=classifier.tangent_periods if carry else 0,
                          early_stop=es, tables=tables)
    todo_tan: list[int] = []      # cheap path: continue with the tangent vector
    todo_mono: list[tuple[int, int]] = []
    redo: list[int] = []          # redo by the previous method (full transient, tangent vector)
    periods = _strict_periods(res1, classifier)
    to_classify: list = []        # (index, result) classified by the full rules (numpy; in threads)
    for i, res in enumerate(res1):
        if res.diverged:
            growth = res.growth if carry else np.zeros(0)
            out[i] = (res, classify.classify_point(res.poincare, growth, res.period, True, classifier))
            continue
        n = periods[i]
        if n > 0 and floquet:
            todo_mono.append((i, n))
        elif res.stop_period:
            redo.append(i)        # stopped early but not periodic on the record: no label from a short run
        elif n > 0 and cheap:
            nan = float("nan")
            out[i] = (res, classify.Classification(n, n, nan, nan, nan, nan, -1, "periodic (cheap path: no exponent)"))
        elif cheap:
            todo_tan.append(i)
        else:
            to_classify.append((i, res))
    if todo_mono:
        idx = [i for i, _ in todo_mono]
        ns = [n for _, n in todo_mono]
        mono_settings = dataclasses.replace(settings, recorded_periods=0)
        rm = simulate_batch([systems[i] for i in idx], mono_settings, [res1[i].final_state for i in idx],
                            monodromy_periods=ns, transient_periods=ns, tables=tables.take(idx))
        ok = [r.monodromy is not None and not r.diverged and np.all(np.isfinite(r.monodromy)) for r in rm]
        mu = np.ones((len(rm), 6))
        if any(ok):
            mu[ok] = np.abs(np.linalg.eigvals(np.stack([r.monodromy for r, g in zip(rm, ok) if g])))
        for i, n, r, good, mui in zip(idx, ns, rm, ok, mu, strict=True):
            res = res1[i]
            if not good:
                redo.append(i)
                continue
            lab = _floquet_label(n, mui, res.period, periods.tol[i])
            if res.stop_period and not lab.lyapunov < 0.0:
                redo.append(i)    # an unstable (or neutral) cycle the orbit only lingered near
                continue
            out[i] = (res, lab)
    if todo_tan and classifier.settle_max_n > 0:
        # cheap path: a point not periodic on its record is first checked for a slow transient (shooting,
        # approach); only the points that do not settle continue with the tangent vector.  Those may be
        # checked once more after the rules (_settle_all): from a state 200 periods later, on a longer record
        from geardyn.runs.settle import settled_classification

        undecided = classify.Classification(UNDETERMINED, 0, float("nan"), float("nan"), float("nan"), float("nan"),
                                            -1, "not periodic on the record")
        early = {i: s for i, s in _settle_many(systems, [(i, res1[i], undecided) for i in todo_tan], settings,
                                               classifier, tables) if s.after != s.before and not s.possible}
        for i, s in early.items():
            out[i] = (res1[i], settled_classification(undecided, s, res1[i].period))
        todo_tan = [i for i in todo_tan if i not in early]
    if todo_tan:
        more = dataclasses.replace(settings, transient_periods=0,
                                   recorded_periods=max(settings.recorded_periods, classifier.tangent_periods))
        r2 = simulate_batch([systems[i] for i in todo_tan], more, [res1[i].final_state for i in todo_tan],
                            tangent_periods=classifier.tangent_periods, tables=tables.take(todo_tan))
        for i, res2 in zip(todo_tan, r2, strict=True):
            res2.transient_used = res1[i].transient_used
            to_classify.append((i, res2))
    _classify_all(to_classify, classifier, out)
    redone = set(redo)
    log.info("%d points: %d stopped the transient early, %d periodic with a Floquet exponent, %d redone by the "
             "previous method, %d continued with the tangent vector", L, sum(1 for r in res1 if r.stop_period),
             sum(1 for i, _ in todo_mono if i not in redone), len(redo), len(todo_tan))
    if redo:
        old = dataclasses.replace(settings, early_stop=False, periodic_exponent="tangent")
        again = _analyse_batch([systems[i] for i in redo], [x0s[i] for i in redo], old, classifier, cheap,
                               tables.take(redo))
        for i, pair in zip(redo, again, strict=True):
            out[i] = pair
    return out
