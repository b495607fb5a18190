"""Dense runs at single operating points: phase trajectory, Poincaré map and amplitude spectrum.

Only the points drawn in Figs. 8, 10 and 12 of paper 1 need the dense trajectory, so it is
computed here, for those points only, and never inside a sweep.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping

import numpy as np
import xarray as xr

from geardyn.khv import point
from geardyn.khv.design import KHVDesign
from geardyn.solve import SimulationSettings, simulate
from geardyn import classify
from geardyn.runs.cube import STATE_NAMES, STATES


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
                 settings: SimulationSettings, samples_per_period: int = 64) -> xr.Dataset:
    """:func:`dense_point` for each case, concatenated along ``case`` (labels like ``x1=0.5``)."""
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
