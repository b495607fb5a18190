"""Dense runs at single operating points (Figs. 8, 10 and 12 of paper 1): phase trajectory, Poincaré map and
amplitude spectrum, started on the attractor the labeller found from the static deflection."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping

import numpy as np
import xarray as xr

from geardyn import io
from geardyn.io import Var
from geardyn.khv import point
from geardyn.khv.design import KHVDesign
from geardyn.label import Policy
from geardyn.runs import study
from geardyn.runs.cube import STATE_NAMES, STATES
from geardyn.runs.spectrum import amplitude_spectrum
from geardyn.solve import SimulationSettings, simulate

_STATE_AT = (("", "time", ""), ("poincare_", "section", "Poincare section: "))
#: The variables of a dense run (:func:`dense_point`): each state over the record and at the Poincare sections, and
#: the amplitude spectrum of X_VH.
VARIABLES = (
    *(Var(f"{p}{name}", dims, "1", f"{t}{STATE_NAMES[name]}") for name in STATES for p, dims, t in _STATE_AT),
    Var("amplitude", "frequency", "1", "amplitude spectrum of X_VH / b_c (Hann)"),
    Var("time", "time", "1", "time since the start of the record, in mesh periods"),
    Var("section", "section", "1", "index of the recorded mesh period", dtype=np.int32),
    Var("frequency", "frequency", "1", "frequency / mesh frequency"),
)


def dense_point(
    design: KHVDesign,
    overrides: Mapping[str, float],
    settings: SimulationSettings,
    samples_per_period: int = 64,
    x0: np.ndarray | None = None,
) -> xr.Dataset:
    """Trajectory over the recorded periods (uniform, ``samples_per_period``), Poincaré points, spectrum.
    ``x0``: the start (default: the static deflection, after the settings' transient); with a state on
    the attractor (a verdict's final state) no transient is integrated."""
    coeffs = point.point_coefficients(design, overrides)
    if x0 is not None:
        settings = dataclasses.replace(settings, transient_periods=0)
    res = simulate(coeffs, settings, x0=x0, dense=True)
    tau, states = (np.zeros(0), np.zeros((0, 6))) if res.diverged else res.uniform(samples_per_period)
    values = {name: states[:, k] for k, name in enumerate(STATES)}
    values |= {f"poincare_{name}": res.poincare[:, k] for k, name in enumerate(STATES)}
    spectrum = amplitude_spectrum(states[:, 1], samples_per_period) if states.shape[0] > 8 else (np.zeros(0),) * 2
    values["frequency"], values["amplitude"] = spectrum
    values["time"] = (tau - (tau[0] if tau.size else 0.0)) / coeffs.period
    values["section"] = np.arange(res.poincare.shape[0])
    attrs = {f"coef_{k}": (float(v) if not isinstance(v, str) else v) for k, v in coeffs.as_dict().items()}
    attrs.update({f"override_{k}": float(v) for k, v in overrides.items()})
    attrs.update(study.integration_attrs(settings))
    return io.dataset(VARIABLES, values, **attrs)


def dense_points(
    design: KHVDesign,
    fixed: Mapping[str, float],
    cases: list[Mapping[str, float]],
    policy: Policy,
    samples_per_period: int = 64,
) -> xr.Dataset:
    """:func:`dense_point` for each case, concatenated along ``case`` (labels like ``x1=0.5``), each case
    labelled by the labeller from the static deflection (the sweeps' labels: variables ``label``,
    ``period``, ``lyapunov``, ``stage``, ...) and its dense run started on the attractor it found."""
    systems = [point.point_coefficients(design, {**fixed, **case}) for case in cases]
    layout = study.Layout(("case",), (len(cases),), [[((k,), s)] for k, s in enumerate(systems)], transient=False)
    labelled, lines, _, damping = study.run(layout, policy, "points")  # each point a line of its own
    verdicts = [v for (v,) in lines]
    parts = []
    for case, v in zip(cases, verdicts, strict=True):
        x0 = None if v.diverged else v.final_state
        ds = dense_point(design, {**fixed, **case}, policy.integration, samples_per_period, x0=x0)
        label = point.override_text(case, "base")
        attrs = ds.attrs
        ds = ds.expand_dims(case=[label])
        for key, value in attrs.items():
            if key.startswith(("coef_", "override_")):
                ds[key] = Var(key, "case", "1", f"point parameter {key}")([value])
        parts.append(ds)
    out = xr.concat(
        parts, dim="case", join="outer", data_vars="all", coords="different", compat="equals", combine_attrs="override"
    )
    out["case"].attrs["long_name"] = "operating point (overrides)"
    out = out.assign(labelled)
    out.attrs = study.integration_attrs(policy.integration) | {
        "record_starts": "on the attractor found by the labeller (its final state)",
        "fixed_overrides": point.override_text(fixed, ""),
        **damping,
    }
    return out
