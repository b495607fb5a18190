"""Caption texts for the KHV dynamic figures: what is shown, how it was computed and what we
measured.  For a design that names a paper (``paper`` given), the paper's statement about the same
figure is set beside ours; a user's own design gets no paper text."""

from __future__ import annotations

from types import ModuleType

import numpy as np
import xarray as xr
from scipy.signal import find_peaks

from geardyn import classify
from geardyn.label import STAGE_NAMES
from geardyn.runs.cube import STATES, labels_of_cube
from geardyn.runs.maps import fractions

_METHOD = (
    "Model: the corrected KHV equations of docs/model.md with the parameters of the design file. Motion labels "
    "(geardyn.label, docs/classify.md): along each line the attractor of the previous point is followed; a "
    "period-n label is a stable orbit found by Newton shooting and certified by its Floquet multipliers; "
    "quasi-periodic needs weighted Birkhoff averages that converge (a torus); chaotic needs a positive "
    "Lyapunov exponent that the same test confirms; undetermined where the indicators disagree. The points "
    "drawn lie on the attractor found, never on a transient."
)
_PAPER_ASSUMPTIONS = (
    "Assumptions where the paper is silent (see the design file and docs/model.md): shaft stiffnesses, planet "
    "mass, carrier radius a cos(alpha), dimensionless mesh frequency, TE phase; corrected Eq. (4) damping and "
    "Eq. (9) stiffness."
)


def _tail(name: str, paper: ModuleType | None) -> list[str]:
    """The closing lines: the paper's statement and its assumptions (paper designs), then the method."""
    if paper is None:
        return [_METHOD]
    claim = paper.FIGURE_CLAIMS.get(name[:5], "no statement in the paper")
    return [f"Paper ({paper.SHORT}): {claim}", _PAPER_ASSUMPTIONS, _METHOD]


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
    idx, _ = find_peaks(a, height=0.02 * a.max())
    return [float(f[i]) for i in idx[a[idx].argsort()[::-1][:n]]]


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
    )
