"""Tables of a plus set (natural frequencies, key elements, stiffness scaling, TE, relief optima) as DataFrames and
CF Datasets; with ``paper`` (a module of :mod:`geardyn.papers`) the paper's columns and rows beside ours."""

from __future__ import annotations

from dataclasses import replace
from types import ModuleType

import numpy as np
import pandas as pd
import xarray as xr
from scipy.optimize import minimize_scalar

from geardyn import io, libm
from geardyn.io import Var
from geardyn.jsontypes import Json

from . import modal
from .design import PlusDesign
from .ishikawa import (
    design_grid,
    design_te,
    iso_single_stiffness,
    material,
    pd_mesh_load,
    single_pair_stiffness_pitch,
    spur_pair,
)
from .relief import SHAPES, ReliefOptimum, landscape, landscape_axes

COMPONENT_LABELS = {
    "revolution": "planet revolution",
    "planet_p": "planet gear p",
    "planet_d": "planet gear d",
    "sun": "sun gear",
    "ring": "gear ring",
    "carrier": "planet carrier",
}
WORKING: tuple[modal.Condition, ...] = ("I", "II", "III")


#: The CF variables of the plus set's datasets, one table per dataset (:func:`geardyn.io.dataset`).
_CM = ("condition", "mode")
MODAL_VARIABLES = (
    Var("natural_frequency", _CM, "Hz", "undamped natural frequency"),
    Var("damped_frequency", _CM, "Hz", "damped natural frequency"),
    Var("damping_ratio", _CM, "1", "modal damping ratio"),
    Var(
        "mode_shape",
        (*_CM, "coordinate"),
        "kg-1/2",
        "mass-normalised mode shape (0 on the fixed coordinate)",
        attrs={"comment": "translations in kg-1/2; rotations in rad kg-1/2 m-1"},
    ),
    Var("strain_energy_share", (*_CM, "element"), "1", "share of the modal strain energy per spring"),
    Var("kinetic_energy_share", (*_CM, "component"), "1", "share of the modal kinetic energy per component"),
    Var("mode_type", _CM, "1", "mode class: rigid, planet (doubled) or overall (axisymmetric)"),
    Var(
        "lever_arm",
        "coordinate",
        "m",
        "radius turning a rotation into a displacement (base radius; carrier: a_sp; 1 for x_s, y_s)",
    ),
    Var("condition", "condition", "1", "working condition (I carrier, II ring, III sun fixed)"),
    Var("mode", "mode", "1", "mode number including the rigid-body mode"),
    Var("coordinate", "coordinate", "1", "generalised coordinate"),
    Var("element", "element", "1", "spring (Table 3 meshes, sun bearing)"),
    Var("component", "component", "1", "kinetic-energy component (Table 4)"),
)
TE_VARIABLES = (
    Var(
        "transmission_error",
        ("case", "mesh_phase"),
        "um",
        "static transmission error TE = E - delta (Eq. 9) of the p-d pair",
    ),
    Var("mesh_stiffness", "mesh_phase", "N m-1", "quasi-static mesh stiffness of the unmodified pair"),
    Var("load_per_pair", ("slot", "mesh_phase"), "N", "normal load on each tooth pair slot (unmodified)"),
    Var("case", "case", "1", "relief case"),
    Var("mesh_phase", "mesh_phase", "1", "mesh phase in base pitches"),
    Var("slot", "slot", "1", "tooth pair slot (0 = newest)"),
)
LANDSCAPE_VARIABLES = (
    Var("te_ptp", ("shape", "amount", "length"), "um", "peak-to-peak static transmission error of the p-d pair"),
    Var("shape", "shape", "1", "tip relief shape"),
    Var("amount", "amount", "um", "tip relief amount along the line of action"),
    Var("length", "length", "mm", "tip relief length along the path of contact"),
)


def distinct_frequencies(design: PlusDesign, condition: modal.Condition) -> list[dict]:
    """One record per distinct elastic frequency: Hz, damped Hz, zeta, multiplicity, type, energies."""
    md = modal.modes(design, condition)
    types = modal.classify(md)
    strain, kinetic = modal.energy_shares(design, md)
    se, ke = modal.group_strain(strain), modal.group_kinetic(kinetic)
    out = []
    for order, grp in enumerate(modal.distinct_groups(md.omega2), start=1):
        rec = {
            "condition": condition,
            "order": order,
            "freq_hz": float(md.freq_hz[grp[0]]),
            "damped_hz": float(md.damped_hz[grp[0]]),
            "zeta": float(md.zeta[grp[0]]),
            "multiplicity": len(grp),
            "mode_type": types[grp[0]],
        }
        rec.update({f"strain_{k}": float(np.mean(v[grp])) for k, v in se.items()})
        rec.update({f"kinetic_{k}": float(np.mean(v[grp])) for k, v in ke.items()})
        out.append(rec)
    return out


def frequency_table(design: PlusDesign, paper: ModuleType | None) -> pd.DataFrame:
    """Our distinct elastic frequencies (the first six per condition), beside the paper's Table 2 when
    ``paper`` is given: matched by order, ``err_*_pct`` = 100 (ours - paper) / paper."""
    rows = []
    for cond in WORKING:
        recs = distinct_frequencies(design, cond)
        for rec in recs[:6]:
            row = {
                k: rec[k] for k in ("condition", "order", "freq_hz", "damped_hz", "zeta", "multiplicity", "mode_type")
            }
            if paper is not None:
                for src in ("theoretical", "simulated", "experimental"):
                    pv = paper.PAPER_TABLE2[cond][src][rec["order"] - 1]
                    row[f"paper_{src}_hz"] = pv
                    row[f"err_{src}_pct"] = 100.0 * (rec["freq_hz"] - pv) / pv
                row["paper_over_ours"] = row["paper_theoretical_hz"] / rec["freq_hz"]
            rows.append(row)
    return pd.DataFrame(rows)


def _matched_pairs(
    design: PlusDesign, paper: ModuleType, reference: str, matching: str
) -> tuple[np.ndarray, np.ndarray]:
    """(paper, ours) frequency pairs: ``rank`` order k against order k (Table 2); ``type`` our doubled (planet)
    frequencies against the paper's ``PAPER_SHARED``, our overall ones against the rest, each ascending."""
    t = frequency_table(design, paper)
    if matching == "rank":
        return t[f"paper_{reference}_hz"].to_numpy(float), t["freq_hz"].to_numpy(float)
    if matching != "type":
        raise ValueError(f"unknown matching {matching!r}; allowed: 'rank', 'type'")
    theirs, ours = [], []
    for cond in WORKING:
        sub = t[t.condition == cond]
        theo = np.array(paper.PAPER_TABLE2[cond]["theoretical"], float)
        ref = np.array(paper.PAPER_TABLE2[cond][reference], float)
        shared = np.isin(theo, paper.PAPER_SHARED)
        ours_planet = np.sort(sub.loc[sub.mode_type == "planet", "freq_hz"].to_numpy(float))
        ours_overall = np.sort(sub.loc[sub.mode_type == "overall", "freq_hz"].to_numpy(float))
        theirs += list(np.sort(ref[shared])) + list(np.sort(ref[~shared]))
        ours += list(ours_planet) + list(ours_overall)
    return np.array(theirs), np.array(ours)


def _matched_log_residual(design: PlusDesign, paper: ModuleType, reference: str, matching: str) -> np.ndarray:
    theirs, ours = _matched_pairs(design, paper, reference, matching)
    return libm.log(theirs) - libm.log(ours)


def _pct(log_value: float) -> float:
    return float(100 * (libm.exp(log_value) - 1))


def stiffness_scaling(
    design: PlusDesign, paper: ModuleType, reference: str = "theoretical", matching: str = "rank"
) -> dict[str, float | str]:
    """Uniform stiffness factor s that best matches the paper in log frequency (exactly log s = 2 mean(log
    f_paper - log f_ours), as frequencies scale with sqrt(s)), a mesh-only factor fitted numerically, and the
    remaining RMS and worst residuals in percent."""
    r = _matched_log_residual(design, paper, reference, matching)
    shift = float(np.mean(r))
    res_u = r - shift
    out: dict[str, float | str] = {
        "reference": reference,
        "matching": matching,
        "uniform_factor": float(libm.exp(2 * shift)),
        "uniform_rms_pct": _pct(np.sqrt(np.mean(res_u**2))),
        "uniform_max_pct": _pct(np.max(np.abs(res_u))),
        "unscaled_rms_pct": _pct(np.sqrt(np.mean(r**2))),
    }

    def mesh_only(log_s: float) -> float:
        k = design.stiffness  # the meshes scaled, the sun bearing kept
        d2 = replace(design, stiffness=replace(k.scaled(libm.exp(log_s)), sun_bearing=k.sun_bearing))
        return float(np.mean(_matched_log_residual(d2, paper, reference, matching) ** 2))

    opt = minimize_scalar(mesh_only, bounds=(0.0, 8.0), method="bounded", options={"xatol": 1e-6})
    out["mesh_only_factor"] = float(libm.exp(opt.x))
    out["mesh_only_rms_pct"] = _pct(np.sqrt(opt.fun))
    return out


def fixed_factor_residual(design: PlusDesign, paper: ModuleType, factor: float) -> dict[str, float]:
    """RMS and worst log-residual (in %) against the paper's theoretical values (rank matching) with every
    stiffness times ``factor``."""
    r = _matched_log_residual(design.with_stiffness_scale(factor), paper, "theoretical", "rank")
    return {
        "factor": factor,
        "rms_pct": _pct(np.sqrt(np.mean(r**2))),
        "max_pct": _pct(np.max(np.abs(r))),
        "mean_log_ratio_pct": _pct(np.mean(r)),
    }


def scaling_table(design: PlusDesign, paper: ModuleType) -> pd.DataFrame:
    """:func:`stiffness_scaling` against the paper's theoretical, simulated and experimental values."""
    return pd.DataFrame(
        [
            stiffness_scaling(design, paper, ref, m)
            for m in ("rank", "type")
            for ref in ("theoretical", "simulated", "experimental")
        ]
    )


def scaled_frequency_table(design: PlusDesign, paper: ModuleType | None, factor: float) -> pd.DataFrame:
    """:func:`frequency_table` recomputed with every stiffness multiplied by ``factor``."""
    t = frequency_table(design.with_stiffness_scale(factor), paper)
    t.insert(2, "stiffness_factor", factor)
    return t


def key_element_table(design: PlusDesign, paper: ModuleType | None, threshold: float = 0.25) -> pd.DataFrame:
    """Key elements in the form of the paper's Table 5: the mesh type with the largest strain-energy share
    and the components with a kinetic-energy share >= ``threshold`` for each condition and order, beside
    the paper's when ``paper`` is given."""
    rows = []
    for cond in WORKING:
        for rec in distinct_frequencies(design, cond)[:6]:
            key = max(modal.MESH_TYPES, key=lambda t: rec[f"strain_{t}"])
            kin = {c: rec[f"kinetic_{c}"] for c in modal.COMPONENT_GROUPS}
            comps = [c for c in sorted(kin, key=lambda c: kin[c], reverse=True) if kin[c] >= threshold]
            row = {k: rec[k] for k in ("condition", "order", "freq_hz", "mode_type")}
            row["key_element"] = modal.MESH_LABELS[key]
            row["key_element_share"] = rec[f"strain_{key}"]
            row["key_elements_no"] = {"sp": "1, 2, 3", "pd": "4, 5, 6", "dr": "7, 8, 9"}[key]
            row["key_components"] = ", ".join(COMPONENT_LABELS[c] for c in comps)
            if paper is not None:
                theirs = paper.PAPER_TABLE5_ELEMENT[cond][rec["order"] - 1]
                row["paper_key_element"] = modal.MESH_LABELS[theirs]
                row["paper_key_components"] = paper.PAPER_TABLE5_COMPONENTS[cond][rec["order"] - 1]
                row["element_agrees"] = key == theirs
            rows.append(row | {k: v for k, v in rec.items() if k.startswith(("strain_", "kinetic_"))})
    return pd.DataFrame(rows)


def modal_dataset(design: PlusDesign) -> xr.Dataset:
    """All modes of conditions I-III: frequencies, damping, shapes, energy shares (CF attrs)."""
    conds = list(WORKING)
    el_names, comp_names = [el.name for el in modal.elements(design)], list(modal.mass_components(design))
    per_condition = []  # (frequencies, damped, zeta, shapes, strain and kinetic shares, types) of each condition
    for c in conds:
        md = modal.modes(design, c)
        s_fr, k_fr = modal.energy_shares(design, md)
        se, ke = np.column_stack([s_fr[k] for k in el_names]), np.column_stack([k_fr[k] for k in comp_names])
        per_condition.append((md.freq_hz, md.damped_hz, md.zeta, md.full_shapes.T, se, ke, modal.classify(md)))
    stacked = tuple(np.array(v) for v in zip(*per_condition, strict=True))
    n = stacked[0].shape[1]
    arms = {"theta_s": design.sun.base_radius, "theta_r": design.ring.base_radius, "x_s": 1.0, "y_s": 1.0}
    arms |= {f"theta_{g}{j}": getattr(design, f"planet_{g}").base_radius for g in "pd" for j in (1, 2, 3)}
    arms["theta_c"] = modal.geometry(design).a_sp
    values = (*stacked, np.array([arms[c] for c in modal.COORDS]), conds, np.arange(1, n + 1))
    values = (*values, list(modal.COORDS), el_names, comp_names)
    variant = f"planet angles in sun terms={design.planet_angles_in_sun_terms}; plus-set sign={design.plus_set_sign}"
    title = f"Modal analysis of the plus planetary set {design.name}"
    return io.dataset(MODAL_VARIABLES, values, title=title, model_variant=f"11-DOF Lagrangian; {variant}")


def stiffness_comparison(design: PlusDesign) -> pd.DataFrame:
    """Ishikawa single-pair pitch-point stiffness and mean mesh stiffness of the p-d pair vs ISO 6336-1 and Table 1."""
    pair, mat = spur_pair(design), material(design)
    iso = iso_single_stiffness(pair, design.facewidth * 1e3)
    k_ish = single_pair_stiffness_pitch(pair, mat)
    te0 = design_te(replace(design, te=replace(design.te, es=0.0)))
    eps = pair.contact_ratio
    rows = [
        ("single-pair stiffness at the pitch point, Ishikawa", k_ish),
        ("ISO 6336-1 c' b with C_M C_R C_B cos(beta) = 0.8 (20 deg rack)", iso["k_iso_0.8"]),
        ("ISO 6336-1 c' b with C_B(25 deg, h_fP = 1.25 m) = 1.0725", iso["k_iso_CB"]),
        ("mean mesh stiffness, Ishikawa (no errors, static load sharing)", float(np.mean(te0.stiffness))),
        ("ISO 6336-1 c_gamma b = c' b (0.75 eps + 0.25)", iso["k_iso_CB"] * (0.75 * eps + 0.25)),
        ("Table 1 mesh stiffness k_pd", design.stiffness.planet_planet),
    ]
    t = pd.DataFrame(rows, columns=["quantity", "value_N_per_m"])
    t["value_N_per_mm_um"] = t["value_N_per_m"] * 1e-6 / (design.facewidth * 1e3)
    t["ratio_to_table1"] = t["value_N_per_m"] / design.stiffness.planet_planet
    return t


def te_dataset(design: PlusDesign, optima: list[ReliefOptimum]) -> xr.Dataset:
    """TE over one mesh period before relief and with each optimum (um), CF attrs."""
    base = design_te(design)
    relieved = [design_te(design, relief_amount=o.amount, relief_length=o.length, relief_shape=o.shape) for o in optima]
    curves = np.array([r.te * 1e6 for r in (base, *relieved)])
    labels = ["unmodified", *(f"{o.shape}_{o.bounds}" for o in optima)]
    values = (curves, base.stiffness, base.loads, labels, base.s, np.arange(base.loads.shape[0]))
    return io.dataset(
        TE_VARIABLES,
        values,
        title=f"Static TE of the p-d pair, design {design.name}",
        contact_ratio=spur_pair(design).contact_ratio,
        load_N=pd_mesh_load(design),
        model_variant="Ishikawa rectangle+trapezoid, base-pitch error model",
    )


def relief_table(optima: list[ReliefOptimum], paper: ModuleType | None) -> pd.DataFrame:
    """The relief optima, with the paper's result (its ``RELIEF_ROW``) as the last row when ``paper`` is given."""
    rows = [
        {
            "shape": o.shape,
            "bounds": o.bounds,
            "amount_bounds_um": f"{o.amount_bounds[0] * 1e6:g}-{o.amount_bounds[1] * 1e6:g}",
            "length_bounds_mm": f"{o.length_bounds[0] * 1e3:g}-{o.length_bounds[1] * 1e3:g}",
            "amount_um": o.amount * 1e6,
            "length_mm": o.length * 1e3,
            "te_ptp_before_um": o.ptp_unmodified * 1e6,
            "te_ptp_after_um": o.ptp * 1e6,
            "reduction_pct": 100 * o.reduction,
            "evaluations": o.nfev,
        }
        for o in optima
    ]
    return pd.DataFrame(rows if paper is None else [*rows, paper.RELIEF_ROW])


def to_markdown(df: pd.DataFrame, floatfmt: str = ".4g") -> str:
    """The table in Markdown (:func:`geardyn.io.markdown_table`): floats in ``floatfmt``, NaN empty."""

    def fmt(v: Json) -> str:
        return ("" if np.isnan(v) else format(float(v), floatfmt)) if isinstance(v, (float, np.floating)) else str(v)

    return io.markdown_table(list(df.columns), [[fmt(v) for v in row] for row in df.itertuples(index=False)]) + "\n"


def landscape_dataset(design: PlusDesign, n: int | None = None) -> xr.Dataset:
    """Peak-to-peak TE over (amount, length) for both relief shapes, CF attrs (um, mm)."""
    amounts, lengths = landscape_axes(design, n)
    grid = design_grid(design)
    z = np.array([landscape(design, sh, amounts, lengths, grid=grid) for sh in SHAPES]) * 1e6
    return io.dataset(
        LANDSCAPE_VARIABLES,
        (z, list(SHAPES), amounts * 1e6, lengths * 1e3),
        title=f"Objective landscape of the tip-relief optimisation, design {design.name}",
        relief_applied_to=design.relief.apply_to,
        load_N=pd_mesh_load(design),
    )


def write_table(df: pd.DataFrame, csv: str, md: str | None = None, header: str = "", floatfmt: str = ".4g") -> None:
    """CSV (full precision) and, if asked, a Markdown version with a header paragraph."""
    io.write_text(df.to_csv(index=False, float_format="%.6g"), csv)
    if md is not None:
        io.write_text((header + "\n\n" if header else "") + to_markdown(df, floatfmt), md)
