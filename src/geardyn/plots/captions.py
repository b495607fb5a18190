"""Caption and table-header texts of every figure and table: what is shown, how it was computed and what we
measured; for a design that names a paper the paper's text about the same figure beside ours (its ``CAPTIONS``,
through :func:`geardyn.plots.paper_says`), for a user's own design none."""

from __future__ import annotations

from types import ModuleType
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd
import xarray as xr

from geardyn.label import STAGE_NAMES, vocabulary
from geardyn.plots import paper_says
from geardyn.plots.plus import ENERGY_BARS, orders
from geardyn.plus.modal import MESH_TYPES
from geardyn.runs.bands import bands
from geardyn.runs.cube import STATES, fractions, labels_of_cube
from geardyn.runs.spectrum import spectral_peaks

if TYPE_CHECKING:
    from geardyn.plus.design import PlusDesign

_METHOD = (
    "Model: the corrected KHV equations of docs/model.md with the parameters of the design file. Motion labels "
    "(geardyn.label, docs/classify.md): along each line the attractor of the previous point is followed; a "
    "period-n label is a stable orbit found by Newton shooting and certified by its Floquet multipliers; "
    "quasi-periodic needs weighted Birkhoff averages that converge (a torus); chaotic needs a positive "
    "Lyapunov exponent that the same test confirms; undetermined where the indicators disagree. The points "
    "drawn lie on the attractor found, never on a transient."
)


def verdict_notes(ds: xr.Dataset) -> list[str]:
    """The lines a study's file needs beside its labels: no damping (its ``undamped`` attribute), the long-cycle
    search's reach on its quasi-periodic points (``period_searched``) and its growing records (``transient``)."""
    lines = []
    if int(ds.attrs.get("undamped", 0)) == 1:
        lines.append(f"No damping: {ds.attrs['undamped_note']}.")
    label = ds["label"].values if "label" in ds else np.zeros(0)
    qp = label == vocabulary.LABELS["quasi_periodic"]
    if "period_searched" in ds and qp.any():
        n = ds["period_searched"].values[qp]
        reach = f"{int(n.min())}" if n.min() == n.max() else f"{int(n.min())}-{int(n.max())}"
        lines.append(
            f"Quasi-periodic ({int(qp.sum())} points): a torus or cycle longer than {reach} mesh periods (the "
            "long-cycle search's reach on each point's record, period_searched)."
        )
    grow = int(np.sum(label == vocabulary.LABELS["transient"]))
    if grow:
        lines.append(
            f"Transient ({grow} points): the record's amplitude still grows at the record cap (growth test, "
            "docs/classify.md): no attractor is claimed there."
        )
    return lines


def _tail(name: str, paper: ModuleType | None) -> list[str]:
    """The closing lines: the paper's statement and its assumptions (``FIGURE_ASSUMPTIONS``; paper designs),
    then the method."""
    if paper is None:
        return [_METHOD]
    claim = paper_says(paper, name[:5]) or f"Paper ({paper.SHORT}): no statement in the paper"
    return [claim, paper.FIGURE_ASSUMPTIONS, _METHOD]


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
            runs = bands(cube[par].values, periods[i, j])
            text = "; ".join(f"{vocabulary.label_name(lab)} on [{a:.4g}, {b:.4g}]" for a, b, lab in runs[:12])
            more = f" (+{len(runs) - 12} more bands)" if len(runs) > 12 else ""
            lines.append(f"Ours, {case}{'' if direction == 'none' else ', ' + direction}: {text}{more}.")
    lines += verdict_notes(cube) + _tail(name, paper)
    return "\n".join(lines)


def points(name: str, ds: xr.Dataset, paper: ModuleType | None = None) -> str:
    lines = [
        f"{name}: phase trajectory (X_VH, dX_VH/dtau), Poincare map and amplitude spectrum of X_VH over the "
        f"{ds.attrs.get('recorded_periods')} recorded mesh periods ({ds.attrs.get('fixed_overrides')})."
    ]
    for case in ds["case"].values:
        d = ds.sel(case=case)
        pts = d[[f"poincare_{s}" for s in STATES]].to_array().values.T
        pts = pts[~np.isnan(pts).any(axis=1)]
        # the labeller's verdict of this point (as in the sweeps)
        n = int(d["label"])
        stage = STAGE_NAMES.get(int(d["stage"]), "")
        how = f" ({stage.replace('_', ' ')})" if stage else ""
        peaks = spectral_peaks(d["frequency"].values, d["amplitude"].values)
        peak_text = (", peaks at " + ", ".join(f"{v:.3g}" for v in peaks) + " x f_mesh") if peaks else ""
        lines.append(f"Ours, {case}: {vocabulary.label_name(n)}{how}{peak_text}.")
    lines += verdict_notes(ds) + _tail(name, paper)
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
        + "".join(f" {line}" for line in verdict_notes(ds))
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
        + "".join(f" {line}" for line in verdict_notes(ds))
    )


# --- plus planetary set ---------------------------------------------------------------------------------


PLUS_MODEL = (
    "Model: 11-DOF Lagrangian lumped model built from the design's table of masses, inertias and "
    "stiffnesses, planet angles in the sun terms and the plus-set sign (docs/paper2.md). Doubled planet modes "
    "are averaged over the pair, which makes the bars independent of the basis chosen in the eigenspace."
)


#: What the energy bars show (:data:`geardyn.plots.plus.ENERGY_BARS`), by kind.
ENERGY_WHAT = {
    "strain": "Modal strain energy: share stored in each mesh (numbering 1-9 of the element table) for the first "
    "six distinct elastic frequencies of each working condition.",
    "kinetic": "Modal kinetic energy: share in each component (numbering 1-12: planet revolution, planet rotations, "
    "sun incl. translation, ring, carrier).",
}


def modal_energy(ds: xr.Dataset, paper: ModuleType | None, kind: str, n_orders: int = 6) -> str:
    """Caption of the strain or kinetic energy bars (``kind``): the three largest shares of each of the first
    ``n_orders`` distinct modes per condition."""
    var, dim = ENERGY_BARS[kind][:2]
    lines = []
    for cond, sub, f, groups in orders(ds, n_orders):
        for k, grp in enumerate(groups, 1):
            vals = sub[var].isel(mode=grp).mean("mode")
            top = vals.sortby(vals, ascending=False)[:3]
            desc = ", ".join(f"{n!s} {float(v):.2f}" for n, v in zip(top[dim].values, top.values, strict=True))
            lines.append(
                f"  {cond}-{k} {f[grp[0]]:.0f} Hz ({sub.mode_type.values[grp[0]]}"
                f"{', x2' if len(grp) == 2 else ''}): {desc}"
            )
    summary = "\n".join(lines)
    return f"{ENERGY_WHAT[kind]}\n{PLUS_MODEL}{paper_says(paper, 'modal')}\nLargest shares ({dim} share):\n{summary}"


def mode_shapes(ds: xr.Dataset, paper: ModuleType | None) -> str:
    """Caption of the mode shapes, with the doubled planet modes of the first condition."""
    _, _, f, groups = next(orders(ds))
    shared = [float(f[grp[0]]) for grp in groups if len(grp) == 2]
    return (
        "Mode shapes: displacement of each coordinate in the first six distinct elastic modes of each condition; "
        "rotations times their lever arm (base radius; carrier: sun-planet centre distance), planets relative to "
        "the carrier, sun translation x_s, y_s; normalised to a largest |value| of 1. Doubled (planet) modes: the "
        f"member with y_s = 0.\n{PLUS_MODEL}{paper_says(paper, 'modal')}\nDoubled planet modes of the first "
        "condition at " + ", ".join(f"{v:.1f}" for v in shared) + " Hz keep sun, ring and carrier rotations at "
        "zero and move the sun on its bearing; overall modes move all planet sets alike."
    )


def te_assumptions(design: PlusDesign, te: xr.Dataset) -> str:
    """The load, tooth model and deviations behind a TE caption."""
    return (
        f"Assumptions: T = {design.torque * 1e3:g} N mm on the sun shared by {design.n_planets} planets -> "
        f"W = {te.attrs['load_N']:.1f} N on the p-d mesh; Ishikawa rectangle (root to base circle) + trapezoid "
        f"(base circle to tip) teeth, shear factor {design.te.shear_coefficient:g}, Hertz 4(1-nu^2)W/(pi E b); "
        f"Ef1 = Ef2 = {design.te.ef1 * 1e6:g} um constant (shift TE only); ES = {design.te.es * 1e6:g} um as a "
        "base-pitch difference (successive pairs differ by ES; the incoming pair has the excess material)."
    )


def te_unmodified(design: PlusDesign, te: xr.Dataset, paper: ModuleType | None) -> str:
    """Caption of the TE of the unmodified pair."""
    tr0 = te.transmission_error.sel(case="unmodified").values
    return (
        "Static transmission error TE = E - delta of the unmodified p-d pair over two mesh periods and the load "
        f"on each tooth-pair slot.\n{te_assumptions(design, te)}\nResult: peak-to-peak {np.ptp(tr0):.2f} um. "
        f"Contact ratio {te.attrs['contact_ratio']:.3f}." + paper_says(paper, "te_unmodified")
    )


def _bounds(amount: tuple[float, float], length: tuple[float, float]) -> str:
    return f"amount {amount[0] * 1e6:g}-{amount[1] * 1e6:g} um, length {length[0] * 1e3:g}-{length[1] * 1e3:g} mm"


def te_relief(design: PlusDesign, te: xr.Dataset, optima: pd.DataFrame, paper: ModuleType | None) -> str:
    """Caption of the TE before and after the optimal reliefs, with the optima (and the paper's)."""
    tr0 = te.transmission_error.sel(case="unmodified").values
    r = design.relief
    lines = [
        f"  {o.shape}/{o.bounds}: amount {o.amount_um:.2f} um, length {o.length_mm:.3f} mm, ptp "
        f"{o.te_ptp_before_um:.2f} -> {o.te_ptp_after_um:.2f} um ({o.reduction_pct:+.1f} %)"
        for o in optima.itertuples()
        if not o.shape.startswith("linear (paper)")
    ]
    ours = [o for o in optima.itertuples() if o.shape.startswith("linear (paper)")]
    at_paper = (
        f"; that relief in our model: {ours[0].ours_at_this_relief_um:.2f} um (unmodified {np.ptp(tr0):.2f} um)."
        if ours
        else "."
    )
    return (
        "Static TE of the p-d pair (mean removed) before and after the optimal linear and parabolic tip relief, "
        f"optimised with differential evolution within the design's stated bounds "
        f"({_bounds(r.paper_amount, r.paper_length)}) and within physically sensible bounds "
        f"({_bounds(r.physical_amount, r.physical_length)}).\n{te_assumptions(design, te)}\nResults:\n"
        + "\n".join(lines)
        + paper_says(paper, "te_relief", at_paper=at_paper)
    )


def relief_landscape(
    te: xr.Dataset, land: xr.Dataset, design: PlusDesign, optima: pd.DataFrame, paper: ModuleType | None
) -> str:
    """Caption of the objective landscape of the relief optimisation."""
    tr0 = te.transmission_error.sel(case="unmodified").values
    z = land.te_ptp
    physical = optima[optima["bounds"] == "physical"]
    lower = design.relief.paper_amount[0] * 1e6
    best = float(physical["amount_um"].max()) if len(physical) else float("nan")
    return (
        "Objective landscape of the relief optimisation: peak-to-peak static TE of the p-d pair over relief amount "
        "and length, for linear and parabolic relief applied to both tips; dashed boxes: the stated and the "
        f"physical bounds; markers: the optima found.\n{te_assumptions(design, te)}\nGrid {z.sizes['amount']} x "
        f"{z.sizes['length']}; ptp from {float(z.min()):.2f} to {float(z.max()):.2f} um; unmodified "
        f"{np.ptp(tr0):.2f} um."
        + paper_says(paper, "relief_landscape", lower=lower, best=best, where="above" if lower > best else "not above")
    )


def table02_header(paper: ModuleType | None) -> str:
    """Header of the natural-frequency table."""
    return paper_says(paper, "table02") or (
        "# Natural frequencies (Hz) of the 11-DOF Lagrangian model\n\n"
        "Distinct elastic frequencies per working condition; multiplicity 2 = doubled planet mode."
    )


FIXED_FACTOR_WHY = (
    "Table 1 as printed",
    "ISO 6336-1 c' b (single pair, 25 deg C_B)",
    "Ishikawa mean mesh stiffness",
    "ISO 6336-1 c_gamma b",
    "best uniform factor (rank matching, theoretical)",
)
KEY_ELEMENT_HEADER = (
    "# Key element (largest modal strain-energy share) and key components (kinetic-energy share >= 0.25) of each mode"
)
STIFFNESS_HEADER = (
    "# Mesh stiffness of the p-d pair: Ishikawa vs ISO 6336-1 method B vs the design's value\n\n"
    "ISO's C1..C9 are fitted for 20 deg racks; another rack angle enters through "
    "C_B (1 - 0.02 (20 - alpha))."
)


def relief_header(load_n: float, design: PlusDesign, paper: ModuleType | None) -> str:
    """Header of the relief-optima table."""
    return (
        "# Tip-relief optima of the p-d pair with differential evolution\n\n"
        f"Load {load_n:.1f} N per p-d mesh, ES = {design.te.es * 1e6:g} um (base-pitch model), relief on "
        f"'{design.relief.apply_to}' tip(s)." + paper_says(paper, "relief_header")
    )


def load_study_header(design: PlusDesign, paper: ModuleType | None) -> str:
    """Header of the relief-against-load table."""
    r = design.relief
    return (
        "# Optimal linear tip relief against the load (sensitivity study)\n\n"
        f"Sun torque shared by {design.n_planets} planets; ES = {design.te.es * 1e6:g} um. Stated bounds: "
        f"{_bounds(r.paper_amount, r.paper_length)}; 'wide' bounds: amount 0-{r.paper_amount[1] * 1e6:g} um, "
        f"length 0-{r.physical_length[1] * 1e3:g} mm. DE on the design's mesh positions per period."
        + paper_says(paper, "load_study", torque=design.torque)
    )


def forced_response(design: PlusDesign, ds: xr.Dataset, paper: ModuleType | None = None) -> str:
    """Caption of the forced-response figure, with the largest forces measured (``paper``: the study goes
    beyond that paper, which is said)."""
    best = ds.attrs.get("best_relief_case") or ""
    lines = [
        "Forced response of the linear model (mass and stiffness of the modal model, working condition "
        f"{ds.attrs['condition']}, modal damping zeta = {ds.attrs['damping_ratio']:g} in every elastic mode) to the "
        f"static TE of the p-d meshes: harmonics 1-{int(ds.harmonic.max())} of its Fourier series excite each p-d mesh "
        f"spring as a displacement ({ds.attrs['phasing']} mesh phasing of the planets; the s-p and d-r meshes carry "
        "no TE), solved in the frequency domain by modal superposition. Top: RMS of the fluctuating mesh force; "
        "bottom: largest mesh force over a mesh period / static mesh force "
        f"({ds.attrs['static_force_N']:.1f} N, the same in every mesh). Solid: unmodified teeth; dashed: the optimal "
        "tip relief with the smallest TE. Grey lines: natural frequencies divided by the harmonic "
        "(h = 1 solid, 2 dashed, 3 dotted). Method: docs/paper2.md, 'Forced response across speed'."
        + paper_says(paper, "forced_response"),
        "Natural frequencies (Hz): "
        + ", ".join(f"{f:.1f}" for f in np.unique(np.round(ds.natural_frequency.values, 1)))
        + ".",
    ]
    lost = ds.min_force_factor.sel(case="unmodified") < 0
    if bool(lost.any()):
        speeds = ds.speed.where(lost.any("mesh"), drop=True).values
        lines.append(
            f"Where the smallest force falls below zero (without relief, at speeds between {speeds.min():.0f} and "
            f"{speeds.max():.0f} rpm) the linear model would pull the teeth together: there the teeth separate and the "
            "linear result only marks a severe resonance."
        )
    for case in [c for c in ("unmodified", best) if c]:
        for kind in MESH_TYPES:
            sub = ds.sel(case=case, mesh=f"{kind}1")
            i, j = int(np.argmax(sub.rms_force.values)), int(np.argmax(sub.dynamic_factor.values))
            lines.append(
                f"  {case}, {kind}1 (TE ptp {float(ds.te_ptp.sel(case=case)):.2f} um): largest RMS "
                f"{float(sub.rms_force[i]):.1f} N at {float(ds.speed[i]):.0f} rpm, largest dynamic factor "
                f"{float(sub.dynamic_factor[j]):.2f} at {float(ds.speed[j]):.0f} rpm"
            )
    return "\n".join(lines)
