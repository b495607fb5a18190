"""Caption texts for the KHV dynamic figures: what is shown, how it was computed and what we
measured.  For a design that names a paper (``paper`` given), the paper's statement about the same
figure is set beside ours; a user's own design gets no paper text."""

from __future__ import annotations

from types import ModuleType

import numpy as np
import xarray as xr

from geardyn import classify
from geardyn.label import STAGE_NAMES
from geardyn.runs.cube import STATES, fractions, labels_of_cube

_METHOD = (
    "Model: the corrected KHV equations of docs/model.md with the parameters of the design file. Motion labels "
    "(geardyn.label, docs/classify.md): along each line the attractor of the previous point is followed; a "
    "period-n label is a stable orbit found by Newton shooting and certified by its Floquet multipliers; "
    "quasi-periodic needs weighted Birkhoff averages that converge (a torus); chaotic needs a positive "
    "Lyapunov exponent that the same test confirms; undetermined where the indicators disagree. The points "
    "drawn lie on the attractor found, never on a transient."
)


def _tail(name: str, paper: ModuleType | None) -> list[str]:
    """The closing lines: the paper's statement and its assumptions (``FIGURE_ASSUMPTIONS``; paper designs),
    then the method."""
    if paper is None:
        return [_METHOD]
    claim = paper.FIGURE_CLAIMS.get(name[:5], "no statement in the paper")
    return [f"Paper ({paper.SHORT}): {claim}", paper.FIGURE_ASSUMPTIONS, _METHOD]


def bifurcation(name: str, cube: xr.Dataset, paper: ModuleType | None = None) -> str:
    par = cube.attrs["control_parameter"]
    periods = labels_of_cube(cube)
    lines = [
        f"{name}: Poincare points of X_VH / b_c over {par} ({cube.sizes[par]} values, "
        f"{cube.sizes['section']} sections after {cube.attrs['transient_periods']} transient mesh periods, "
        f"{cube.attrs['integrator']} with {cube.attrs['steps_per_period']} steps per period)."
    ]
    for i, case in enumerate(cube["case"].values):
        for j, direction in enumerate(cube["direction"].values):
            runs = classify.bands(cube[par].values, periods[i, j])
            text = "; ".join(f"{classify.label_name(lab)} on [{a:.4g}, {b:.4g}]" for a, b, lab in runs[:12])
            more = f" (+{len(runs) - 12} more bands)" if len(runs) > 12 else ""
            lines.append(f"Ours, {case}{'' if direction == 'none' else ', ' + direction}: {text}{more}.")
    lines += _tail(name, paper)
    return "\n".join(lines)


def spectral_peaks(freq, amp, n: int = 5, fmax: float = 3.0) -> list[float]:
    """The ``n`` highest local maxima of a spectrum below ``fmax`` (>= 2 % of the largest), by height."""

    keep = (freq > 0.02) & (freq <= fmax)
    if keep.sum() < 3:
        return []
    f, a = freq[keep], amp[keep]
    from scipy.signal import find_peaks  # noqa: PLC0415 - 0.3 s to import: only the captions with spectra

    idx, _ = find_peaks(a, height=0.02 * a.max())
    return [float(f[i]) for i in idx[np.argsort(-a[idx], kind="stable")[:n]]]  # ties: the lower frequency first


def points(name: str, ds: xr.Dataset, paper: ModuleType | None = None) -> str:
    lines = [
        f"{name}: phase trajectory (X_VH, dX_VH/dtau), Poincare map and amplitude spectrum of X_VH over the "
        f"{ds.attrs.get('recorded_periods')} recorded mesh periods ({ds.attrs.get('fixed_overrides')})."
    ]
    for case in ds["case"].values:
        d = ds.sel(case=case)
        pts = d[[f"poincare_{s}" for s in STATES]].to_array().values.T
        pts = pts[~np.isnan(pts).any(axis=1)]
        how = ""
        if "label" in d:  # the labeller's verdict of this point (as in the sweeps)
            n = int(d["label"])
            stage = STAGE_NAMES.get(int(d["stage"]), "")
            how = f" ({stage.replace('_', ' ')})" if stage else ""
        else:
            n = classify.LABELS["diverged"] if int(d["diverged"]) == 1 else classify.LABELS["undetermined"]
        peaks = spectral_peaks(d["frequency"].values, d["amplitude"].values)
        peaks = (", peaks at " + ", ".join(f"{v:.3g}" for v in peaks) + " x f_mesh") if peaks else ""
        lines.append(f"Ours, {case}: {classify.label_name(n)}{how}{peaks}.")
    lines += _tail(name, paper)
    return "\n".join(lines)


def regime_map(name: str, ds: xr.Dataset) -> str:
    """Caption of a two-parameter regime map: grid, settings, classifier path and the label shares."""

    shares = ", ".join(f"{k} {100 * v:.1f} %" for k, v in sorted(fractions(ds).items(), key=lambda kv: -kv[1]))
    return (
        f"{name}: motion label over ({ds.attrs['x_parameter']}, {ds.attrs['y_parameter']}), "
        f"{ds.sizes['x']} x {ds.sizes['y']} points, fixed {ds.attrs['fixed_overrides']}; "
        f"{ds.attrs['steps_per_period']} steps per period, {ds.attrs['transient_periods']} transient + "
        f"{ds.attrs['recorded_periods']} recorded periods; each row a line along x whose points follow the "
        f"attractor of their left neighbour (start_from: {ds.attrs.get('start', 'follow')}; geardyn.label). "
        f"Label shares: {shares}. Lines: the configured 1-D cuts (the sweeps of the same design)."
        + (
            " Lower panels: the dynamic factor K_v = largest dynamic mesh force / static mesh force and the impact "
            "class (no impact, single-sided: the teeth separate, double-sided: they strike on the back side), "
            "over the recorded periods of each point's attractor (docs/response.md)."
            if "dynamic_factor" in ds
            else ""
        )
    )


def frequency_response(name: str, ds: xr.Dataset) -> str:
    """Caption of a frequency response: grid, settings, jumps, impact classes, natural frequencies."""
    w = ds.w.values
    nat = ", ".join(f"{f:.3f}" for f in ds.natural_frequency.values)
    kv = float(np.nanmax(ds.dynamic_factor.values)) if np.isfinite(ds.dynamic_factor.values).any() else float("nan")
    j = np.unravel_index(np.nanargmax(ds.dte_rms.values), ds.dte_rms.shape) if kv == kv else (0, 0)
    return (
        f"{name}: RMS dynamic transmission error (X_VH / b_c, um) and dynamic factor K_v against the mesh frequency "
        f"w = w_m / w_n from {w[0]:g} to {w[-1]:g} ({w.size} frequencies), swept up and down, each direction a "
        f"line along which every point starts from its neighbour's attractor (geardyn.label); "
        f"{ds.attrs['steps_per_period']} steps per period, measures over each attractor's recorded periods "
        f"(one cycle of a periodic one). Fixed overrides: {ds.attrs.get('fixed_overrides', 'none')}. "
        f"Hysteresis (hatched): the up and down sweeps end on different attractors (other labels, or Poincare sets "
        f"apart by more than the labeller's tolerance) at {int(ds.hysteresis.sum())} frequencies. Jumps (RMS DTE "
        f"steps by more than {ds.attrs['jump_threshold']:g} x the larger value at a hysteresis frequency): up at "
        f"w = {ds.attrs['jumps_up']}, down at w = {ds.attrs['jumps_down']}. Largest RMS DTE "
        f"{float(ds.dte_rms.values[j]):.3g} at w = {float(w[j[1]]):.3g}; largest K_v {kv:.3g}. "
        f"Linear natural frequencies (in contact, mean stiffness): {nat}. Shading: impact classes."
    )
