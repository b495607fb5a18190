"""Caption and table-header texts of the plus-set outputs.  The comparison with paper 2 is written
only for a design that names it (``paper`` given); a user's own design gets its own numbers only."""

from __future__ import annotations

from types import ModuleType

import numpy as np
import pandas as pd
import xarray as xr

from geardyn.plots.plus import distinct_groups

from .design import PlusDesign

MODEL = (
    "Model: 11-DOF Lagrangian lumped model built from the design's table of masses, inertias and "
    "stiffnesses, planet angles in the sun terms and the plus-set sign (docs/paper2.md). Doubled planet modes "
    "are averaged over the pair, which makes the bars independent of the basis chosen in the eigenspace."
)


def _paper_modal(paper: ModuleType | None) -> str:
    if paper is None:
        return ""
    return (
        f" {paper.SHORT}'s Figs. 6-7 come from its SimulationX model (power loss and amplitude) at 4-10x higher "
        "frequencies; compare the pattern, not the numbers."
    )


def energy_summary(ds: xr.Dataset, var: str, dim: str, n_orders: int = 6) -> str:
    """The three largest shares of each of the first ``n_orders`` distinct modes per condition."""

    lines = []
    for cond in ds.condition.values:
        sub = ds.sel(condition=cond)
        f = sub.natural_frequency.values
        for k, grp in enumerate(distinct_groups(f)[:n_orders], 1):
            vals = sub[var].isel(mode=grp).mean("mode")
            top = vals.sortby(vals, ascending=False)[:3]
            desc = ", ".join(f"{n!s} {float(v):.2f}" for n, v in zip(top[dim].values, top.values, strict=True))
            lines.append(
                f"  {cond}-{k} {f[grp[0]]:.0f} Hz ({sub.mode_type.values[grp[0]]}"
                f"{', x2' if len(grp) == 2 else ''}): {desc}"
            )
    return "\n".join(lines)


def modal_strain(ds: xr.Dataset, paper: ModuleType | None) -> str:
    return (
        "Modal strain energy: share stored in each mesh (numbering 1-9 of the element table) for the first "
        "six distinct elastic frequencies of each working condition.\n"
        + MODEL
        + _paper_modal(paper)
        + "\nLargest shares (element share):\n"
        + energy_summary(ds, "strain_energy_share", "element")
    )


def modal_kinetic(ds: xr.Dataset, paper: ModuleType | None) -> str:
    return (
        "Modal kinetic energy: share in each component (numbering 1-12: planet revolution, planet rotations, sun "
        "incl. translation, ring, carrier).\n"
        + MODEL
        + _paper_modal(paper)
        + "\nLargest shares (component share):\n"
        + energy_summary(ds, "kinetic_energy_share", "component")
    )


def mode_shapes(ds: xr.Dataset, paper: ModuleType | None) -> str:

    shared = []
    for grp in distinct_groups(ds.sel(condition=ds.condition.values[0]).natural_frequency.values)[:6]:
        if len(grp) == 2:
            shared.append(float(ds.sel(condition=ds.condition.values[0]).natural_frequency.values[grp[0]]))
    return (
        "Mode shapes: displacement of each coordinate in the first six distinct elastic modes of each condition; "
        "rotations times their lever arm (base radius; carrier: sun-planet centre distance), planets relative to "
        "the carrier, sun translation x_s, y_s; normalised to a largest |value| of 1. Doubled (planet) modes: the "
        "member with y_s = 0.\n"
        + MODEL
        + _paper_modal(paper)
        + "\nDoubled planet modes of the first condition at "
        + ", ".join(f"{v:.1f}" for v in shared)
        + " Hz keep sun, ring and carrier rotations at zero and move the sun on its bearing; overall modes move all "
        "planet sets alike."
    )


def te_assumptions(design: PlusDesign, te: xr.Dataset) -> str:
    return (
        f"Assumptions: T = {design.torque * 1e3:g} N mm on the sun shared by {design.n_planets} planets -> "
        f"W = {te.attrs['load_N']:.1f} N on the p-d mesh; Ishikawa rectangle (root to base circle) + trapezoid "
        f"(base circle to tip) teeth, shear factor {design.te.shear_coefficient:g}, Hertz 4(1-nu^2)W/(pi E b); "
        f"Ef1 = Ef2 = {design.te.ef1 * 1e6:g} um constant (shift TE only); ES = {design.te.es * 1e6:g} um as a "
        "base-pitch difference (successive pairs differ by ES; the incoming pair has the excess material)."
    )


def te_unmodified(design: PlusDesign, te: xr.Dataset, paper: ModuleType | None) -> str:
    tr0 = te.transmission_error.sel(case="unmodified").values
    text = (
        "Static transmission error TE = E - delta of the unmodified p-d pair over two mesh periods and the load "
        "on each tooth-pair slot.\n"
        + te_assumptions(design, te)
        + f"\nResult: peak-to-peak {np.ptp(tr0):.2f} um. Contact ratio {te.attrs['contact_ratio']:.3f}."
    )
    if paper is not None:
        text += f" {paper.SHORT} (Fig. 9, FE): about {paper.TE_BEFORE_UM:g} um."
    return text


def te_relief(design: PlusDesign, te: xr.Dataset, optima: pd.DataFrame, paper: ModuleType | None) -> str:
    tr0 = te.transmission_error.sel(case="unmodified").values
    r = design.relief
    lines = [
        f"  {o.shape}/{o.bounds}: amount {o.amount_um:.2f} um, length {o.length_mm:.3f} mm, ptp "
        f"{o.te_ptp_before_um:.2f} -> {o.te_ptp_after_um:.2f} um ({o.reduction_pct:+.1f} %)"
        for o in optima.itertuples()
        if not o.shape.startswith("linear (paper)")
    ]
    text = (
        "Static TE of the p-d pair (mean removed) before and after the optimal linear and parabolic tip relief, "
        f"optimised with differential evolution within the design's stated bounds (amount "
        f"{r.paper_amount[0] * 1e6:g}-{r.paper_amount[1] * 1e6:g} um, length {r.paper_length[0] * 1e3:g}-"
        f"{r.paper_length[1] * 1e3:g} mm) and within physically sensible bounds (amount "
        f"{r.physical_amount[0] * 1e6:g}-{r.physical_amount[1] * 1e6:g} um, length {r.physical_length[0] * 1e3:g}-"
        f"{r.physical_length[1] * 1e3:g} mm).\n" + te_assumptions(design, te) + "\nResults:\n" + "\n".join(lines)
    )
    if paper is not None:
        pr = paper.PAPER_RELIEF
        ours = [o for o in optima.itertuples() if o.shape.startswith("linear (paper)")]
        text += (
            f"\n{paper.SHORT}: {pr['te_before_um']:g} -> {pr['te_after_um']:g} um ({pr['reduction_pct']:+.2f} %), "
            f"linear, amount {pr['amount_mm'] * 1e3:.1f} um, length {pr['length_mm']:.3f} mm"
            + (
                f"; that relief in our model: {ours[0].ours_at_this_relief_um:.2f} um (unmodified "
                f"{np.ptp(tr0):.2f} um)."
                if ours
                else "."
            )
        )
    return text


def relief_landscape(
    te: xr.Dataset, land: xr.Dataset, design: PlusDesign, optima: pd.DataFrame, paper: ModuleType | None
) -> str:
    tr0 = te.transmission_error.sel(case="unmodified").values
    z = land.te_ptp
    text = (
        "Objective landscape of the relief optimisation: peak-to-peak static TE of the p-d pair over relief amount "
        "and length, for linear and parabolic relief applied to both tips; dashed boxes: the stated and the "
        "physical bounds; markers: the optima found.\n"
        + te_assumptions(design, te)
        + f"\nGrid {z.sizes['amount']} x {z.sizes['length']}; ptp from {float(z.min()):.2f} to "
        f"{float(z.max()):.2f} um; unmodified {np.ptp(tr0):.2f} um."
    )
    if paper is None:
        return text
    physical = optima[optima["bounds"] == "physical"]
    lower = design.relief.paper_amount[0] * 1e6
    best = float(physical["amount_um"].max()) if len(physical) else float("nan")
    where = "above" if lower > best else "not above"
    return (
        text + f" {paper.SHORT} shows no such landscape. Its lower amount bound ({lower:g} um) lies {where} "
        f"the optimum amounts within physical bounds (at most {best:.1f} um at this load), so the optima "
        "within the paper's bounds sit on that bound."
    )


# --- table headers -----------------------------------------------------------------------------


def table02_header(paper: ModuleType | None) -> str:
    if paper is None:
        return (
            "# Natural frequencies (Hz) of the 11-DOF Lagrangian model\n\n"
            "Distinct elastic frequencies per working condition; multiplicity 2 = doubled planet mode."
        )
    return (
        "# Table 2: natural frequencies (Hz), ours (11-DOF Lagrangian from Table 1) vs paper 2\n\n"
        "err_*_pct = 100 (ours - paper) / paper; orders matched by rank of the distinct elastic frequencies; "
        "multiplicity 2 = doubled planet mode."
    )


SCALING_INTRO = (
    "# Stiffness scaling needed to match paper 2's Table 2\n\n"
    "Least squares in log frequency. rank: order k vs order k; type: our doubled (planet) modes vs the "
    "paper's three frequencies shared by I-III, our overall modes vs the rest. Residuals in percent.\n\n"
)

FIXED_FACTOR_WHY = (
    "Table 1 as printed",
    "ISO 6336-1 c' b (single pair, 25 deg C_B)",
    "Ishikawa mean mesh stiffness",
    "ISO 6336-1 c_gamma b",
    "best uniform factor (rank matching, theoretical)",
)

TABLE05_HEADER = (
    "# Table 5 analogue: key element (largest modal strain-energy share) and key components "
    "(kinetic-energy share >= 0.25), beside the paper's Table 5"
)
KEY_ELEMENT_HEADER = (
    "# Key element (largest modal strain-energy share) and key components (kinetic-energy share >= 0.25) of each mode"
)


def relief_header(load_n: float, design: PlusDesign, paper: ModuleType | None) -> str:
    text = (
        "# Tip-relief optima of the p-d pair with differential evolution\n\n"
        f"Load {load_n:.1f} N per p-d mesh, ES = {design.te.es * 1e6:g} um (base-pitch model), relief on "
        f"'{design.relief.apply_to}' tip(s)."
    )
    if paper is not None:
        text += (
            " The last row is the paper's result (Sec. 4); its 'ours_at_this_relief_um' is our TE with the "
            "paper's optimum relief."
        )
    return text


STIFFNESS_HEADER = (
    "# Mesh stiffness of the p-d pair: Ishikawa vs ISO 6336-1 method B vs the design's value\n\n"
    "ISO's C1..C9 are fitted for 20 deg racks; another rack angle enters through "
    "C_B (1 - 0.02 (20 - alpha))."
)


def load_study_header(design: PlusDesign, paper: ModuleType | None) -> str:
    r = design.relief
    text = (
        "# Optimal linear tip relief against the load (sensitivity study)\n\n"
        f"Sun torque shared by {design.n_planets} planets; ES = {design.te.es * 1e6:g} um. Stated bounds: amount "
        f"{r.paper_amount[0] * 1e6:g}-{r.paper_amount[1] * 1e6:g} um, length {r.paper_length[0] * 1e3:g}-"
        f"{r.paper_length[1] * 1e3:g} mm; 'wide' bounds: amount 0-{r.paper_amount[1] * 1e6:g} um, length "
        f"0-{r.physical_length[1] * 1e3:g} mm. DE on the design's mesh positions per period."
    )
    if paper is not None:
        pr = paper.PAPER_RELIEF
        text += (
            f" Paper: {pr['amount_mm'] * 1e3:.1f} um, {pr['length_mm']:.3f} mm, {pr['reduction_pct']:+.2f} % at "
            f"T = {design.torque:g} N m."
        )
    return text


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
        + (f" Beyond {paper.SHORT}, which computes no forced response." if paper is not None else ""),
        "Natural frequencies (Hz): "
        + ", ".join(f"{f:.1f}" for f in np.unique(np.round(ds.natural_frequency.values, 1)))
        + ".",
    ]
    lost = ds.min_force_factor.sel(case="unmodified") < 0
    if bool(lost.any()):
        speeds = ds.speed.where(lost.any("mesh"), drop=True).values
        lines.append(
            f"Where the smallest force falls below zero (without relief, at speeds between {speeds.min():.0f} and "
            f"{speeds.max():.0f} rpm) "
            "the linear model would pull the teeth together: there the teeth separate and the linear result "
            "only marks a severe resonance."
        )
    for case in [c for c in ("unmodified", best) if c]:
        for kind in ("sp", "pd", "dr"):
            sub = ds.sel(case=case, mesh=f"{kind}1")
            i = int(np.argmax(sub.rms_force.values))
            j = int(np.argmax(sub.dynamic_factor.values))
            lines.append(
                f"  {case}, {kind}1 (TE ptp {float(ds.te_ptp.sel(case=case)):.2f} um): largest RMS "
                f"{float(sub.rms_force[i]):.1f} N at {float(ds.speed[i]):.0f} rpm, largest dynamic factor "
                f"{float(sub.dynamic_factor[j]):.2f} at {float(ds.speed[j]):.0f} rpm"
            )
    return "\n".join(lines)
