"""Caption texts for paper 1's dynamic figures: what is shown, the assumptions, the paper's claim
and what we measured, side by side."""

from __future__ import annotations

import xarray as xr

from geardyn import classify

#: What the paper states about each figure (Sec. 4), quoted as closely as the text allows.
PAPER_CLAIMS = {
    "fig07": "P1 for x1 in [0.416, 0.565] with amplitude falling; quasi-periodic on [0.565, 0.568]; period-5 on "
             "[0.568, 0.593]; chaos above 0.593; period-6 near 0.761; chaos again above 0.768.",
    "fig08": "(a) x1 = 0.5 P1; (b) 0.565 quasi-periodic; (c) 0.585 P5 with peaks 0.48, 0.57, 0.81, 1, 1.2 x f_mesh; "
             "(d) 0.63 chaos; (e) 0.761 P6; (f) 0.8 chaos.",
    "fig09": "At b = 0.5: P1 for x1 = 0.5, quasi-periodic for 0.761, chaotic for 0.83; the response goes from P1 "
             "to chaos as b grows.",
    "fig10": "b = 0.5: (a) x1 = 0.5 P1; (b) 0.761 quasi-periodic; (c) 0.83 chaotic.",
    "fig11": "P1 at e = 4.55 for x1 = 0.5; synchronous, then quasi-periodic, then chaotic as e grows; the "
             "synchronous range narrows as x1 grows.",
    "fig12": "e = 4.55: P1 for x1 = 0.5, quasi-periodic and chaotic as x1 grows (0.761, 0.83).",
}

_ASSUMPTIONS = (
    "Assumptions (paper silent, see config/designs/<design>.yaml and docs/model.md): shaft stiffnesses, planet "
    "mass, carrier radius a cos(alpha), dimensionless mesh frequency, TE phase; corrected Eq. (4) damping and "
    "Eq. (9) stiffness. Motion labels (geardyn.classify.classify_point): period-n (n <= 12) from the Poincare "
    "return distance; otherwise quasi-periodic or chaotic from the largest Lyapunov exponent, cross-checked by "
    "the 0-1 test and the spectral flatness of the stroboscopic samples."
)


def _claim(name: str) -> str:
    return PAPER_CLAIMS.get(name[:5], "no statement in the paper")


def bifurcation(name: str, cube: xr.Dataset) -> str:
    par = cube.attrs["control_parameter"]
    periods = classify.labels_of_cube(cube)
    lines = [f"{name}: Poincare points of X_VH / b_c over {par} ({cube.sizes[par]} values, "
             f"{cube.sizes['section']} sections after {cube.attrs['transient_periods']} transient mesh periods, "
             f"{cube.attrs['integrator']} with {cube.attrs['steps_per_period']} steps per period)."]
    for i, case in enumerate(cube["case"].values):
        for j, direction in enumerate(cube["direction"].values):
            runs = classify.bands(cube[par].values, periods[i, j])
            text = "; ".join(f"{classify.label_name(lab)} on [{a:.4g}, {b:.4g}]" for a, b, lab in runs[:12])
            more = f" (+{len(runs) - 12} more bands)" if len(runs) > 12 else ""
            lines.append(f"Ours, {case}{'' if direction == 'none' else ', ' + direction}: {text}{more}.")
    lines.append(f"Paper: {_claim(name)}")
    lines.append(_ASSUMPTIONS)
    return "\n".join(lines)


def spectral_peaks(freq, amp, n: int = 5, fmax: float = 3.0) -> list[float]:
    """The ``n`` highest local maxima of a spectrum below ``fmax`` (>= 2 % of the largest), by height."""
    from scipy.signal import find_peaks

    keep = (freq > 0.02) & (freq <= fmax)
    if keep.sum() < 3:
        return []
    f, a = freq[keep], amp[keep]
    idx, _ = find_peaks(a, height=0.02 * a.max())
    return [float(f[i]) for i in idx[a[idx].argsort()[::-1][:n]]]


def points(name: str, ds: xr.Dataset) -> str:
    lines = [f"{name}: phase trajectory (X_VH, dX_VH/dtau), Poincare map and amplitude spectrum of X_VH over the "
             f"{ds.attrs.get('recorded_periods')} recorded mesh periods ({ds.attrs.get('fixed_overrides')})."]
    for case in ds["case"].values:
        d = ds.sel(case=case)
        pts = d[[f"poincare_{s}" for s in ("x_dh", "x_vh", "x_vl", "v_dh", "v_vh", "v_vl")]].to_array().values.T
        n = classify.poincare_period(pts) if int(d["diverged"]) == 0 else classify.LABELS["diverged"]
        peaks = spectral_peaks(d["frequency"].values, d["amplitude"].values)
        peaks = (", peaks at " + ", ".join(f"{v:.3g}" for v in peaks) + " x f_mesh") if peaks else ""
        lines.append(f"Ours, {case}: {classify.label_name(n)}{peaks}.")
    lines.append(f"Paper: {_claim(name)}")
    lines.append(_ASSUMPTIONS)
    return "\n".join(lines)
