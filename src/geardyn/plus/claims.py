"""The quantities of a plus planetary set that a paper's claims (stated as data) name, read from the pipeline's products
(:class:`PlusProducts`), and those claims evaluated by the generic engine (:func:`geardyn.claims.data_claims`)."""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from types import ModuleType

import numpy as np
import pandas as pd
import xarray as xr

from geardyn.claims import Claim, Measured, Quantity, data_claims, format_value
from geardyn.plus import modal as plus_modal


@dataclass(frozen=True)
class PlusProducts:
    """What the claims of a plus-set design read: the tables (natural frequencies, stiffness scaling, key elements,
    relief optima) and datasets (modal.nc, te.nc, forced_response.nc) its plus rules wrote."""

    frequencies: pd.DataFrame
    scaling: pd.DataFrame
    key_elements: pd.DataFrame
    modal: xr.Dataset
    te: xr.Dataset
    optima: pd.DataFrame
    forced: xr.Dataset | None = None


#: Two frequencies are "the same" in two working conditions within this relative difference.
SHARED_RTOL = 1e-4
#: A displacement counts as zero below this fraction of the mode's largest displacement.
SHAPE_ATOL = 1e-6
_MESH_CODES = {label: code for code, label in plus_modal.MESH_LABELS.items()}


def by_condition(df: pd.DataFrame, column: str) -> dict[str, tuple]:
    """{condition: column values in order} of a table with columns condition and order (first-seen order)."""
    return {str(c): tuple(g.sort_values("order")[column].tolist()) for c, g in df.groupby("condition", sort=False)}


def shared_frequencies(table: Mapping[str, Sequence[float]], rtol: float = SHARED_RTOL) -> tuple[float, ...]:
    """The frequencies of the first condition that every other condition lists too (within ``rtol``)."""
    first, *rest = (np.asarray(v, float) for v in table.values())
    return tuple(float(f) for f in first if all(np.any(np.abs(other - f) <= rtol * abs(f)) for other in rest))


def shared_orders(table: Mapping[str, Sequence[float]], rtol: float = SHARED_RTOL) -> dict[str, tuple[int, ...]]:
    """{condition: orders (1-based) at which the shared frequencies (:func:`shared_frequencies`) appear}."""
    shared = np.array(shared_frequencies(table, rtol))
    return {
        c: tuple(i for i, f in enumerate(v, start=1) if np.any(np.abs(shared - f) <= rtol * abs(f)))
        for c, v in table.items()
    }


def key_element_counts(elements: Mapping[str, Sequence[str]]) -> dict[str, dict[str, int]]:
    """{condition: {mesh type: number of orders it is the key element of}} (every mesh type listed)."""
    return {c: {t: list(v).count(t) for t in plus_modal.MESH_TYPES} for c, v in elements.items()}


def _frequencies(p: PlusProducts) -> dict[str, tuple]:
    return by_condition(p.frequencies, "freq_hz")


def _q_frequencies(p: PlusProducts, condition: str | None = None) -> Measured:
    table = _frequencies(p)
    if condition is None:
        return Measured(table, "first six distinct elastic frequencies of each condition")
    return Measured(table[condition], f"condition {condition}, orders 1-{len(table[condition])}")


def _q_scaled_rms(p: PlusProducts, reference: str = "theoretical", matching: str = "rank") -> Measured:
    row = p.scaling[(p.scaling.reference == reference) & (p.scaling.matching == matching)].iloc[0]
    f = float(row.uniform_factor)
    return Measured(
        float(row.uniform_rms_pct),
        f"RMS after every stiffness x {f:.3g} (frequencies x {math.sqrt(f):.3g}), worst {row.uniform_max_pct:.0f} %",
    )


def _q_shared_count(p: PlusProducts) -> Measured:
    shared = shared_frequencies(_frequencies(p))
    return Measured(len(shared), f"{format_value(shared, 'Hz')} in every condition")


def _q_planet_doubled(p: PlusProducts) -> Measured:
    t = p.frequencies[p.frequencies.mode_type == "planet"]
    flags = tuple(bool(m == 2) for m in t.multiplicity)
    return Measured(flags, "planet-mode frequencies of orders 1-6, every condition, that are twofold")


def _elastic(p: PlusProducts):
    """(condition index, mode index, type, displacement per coordinate) of every elastic mode of modal.nc."""
    ds = p.modal
    arm = ds["lever_arm"].values
    for ci in range(ds.sizes["condition"]):
        for mi in range(ds.sizes["mode"]):
            kind = str(ds["mode_type"].values[ci, mi])
            if kind != "rigid":
                yield ci, mi, kind, ds["mode_shape"].values[ci, mi] * arm


def _q_mode_classes(p: PlusProducts) -> Measured:
    kinds = [k for _, _, k, _ in _elastic(p)]
    counts = {k: kinds.count(k) for k in sorted(set(kinds))}
    return Measured(
        tuple(k in ("planet", "overall") for k in kinds),
        "elastic modes of every condition that are planet or overall: "
        + ", ".join(f"{v} {k}" for k, v in counts.items()),
    )


def _coord_index(p: PlusProducts, names: Sequence[str]) -> list[int]:
    coords = [str(c) for c in p.modal["coordinate"].values]
    return [coords.index(n) for n in names]


def _q_planet_central_rotation(p: PlusProducts) -> Measured:
    central = _coord_index(p, ("theta_s", "theta_r", "theta_c"))
    ratios = [float(np.max(np.abs(d[central])) / np.max(np.abs(d))) for _, _, k, d in _elastic(p) if k == "planet"]
    return Measured(
        max(ratios) if ratios else None,
        "largest rotation of sun, ring or carrier in a planet mode / the mode's largest displacement",
    )


def _q_planet_component_share(p: PlusProducts, component: str = "sun") -> Measured:
    ds = p.modal
    share = ds["kinetic_energy_share"].sel(component=component).values
    f = ds["natural_frequency"].values
    best = max(
        ((float(share[ci, mi]), float(f[ci, mi])) for ci, mi, k, _ in _elastic(p) if k == "planet"), default=None
    )
    if best is None:
        return Measured(None, "no planet mode")
    return Measured(
        best[0], f"largest share of the {component} in the kinetic energy of a planet mode, at {best[1]:.1f} Hz"
    )


def _q_overall_alike(p: PlusProducts) -> Measured:
    coords = [str(c) for c in p.modal["coordinate"].values]
    groups = [[i for i, c in enumerate(coords) if c.startswith(f"theta_{g}") and c[-1].isdigit()] for g in "pd"]
    sun = _coord_index(p, ("x_s", "y_s"))
    flags = []
    for _, _, kind, d in _elastic(p):
        if kind != "overall":
            continue
        scale = np.max(np.abs(d))
        spread = max(float(np.ptp(d[g])) for g in groups)
        flags.append(spread <= SHAPE_ATOL * scale and float(np.max(np.abs(d[sun]))) <= SHAPE_ATOL * scale)
    return Measured(tuple(flags), "overall modes in which every planet pair moves alike and the sun does not translate")


def _q_key_elements(p: PlusProducts) -> Measured:
    labels = by_condition(p.key_elements, "key_element")
    return Measured({c: tuple(_MESH_CODES[x] for x in v) for c, v in labels.items()}, "largest modal strain energy")


def _q_key_element_of_order(p: PlusProducts, order: int) -> Measured:
    codes = _q_key_elements(p).value
    return Measured(tuple(v[order - 1] for v in codes.values()), f"conditions {', '.join(codes)}")


def _q_dominant_component(p: PlusProducts) -> Measured:
    comps = by_condition(p.key_elements.fillna({"key_components": ""}), "key_components")
    return Measured(
        {c: tuple(str(x).split(",")[0].strip() for x in v) for c, v in comps.items()},
        "component with the largest modal kinetic energy",
    )


def _q_te_ptp(p: PlusProducts, case: str = "unmodified") -> Measured:
    te = p.te["transmission_error"].sel(case=case).values
    return Measured(float(np.ptp(te)), f"static TE, {case}, load {p.te.attrs.get('load_N', float('nan')):.0f} N")


def _q_te_zone_difference(p: PlusProducts, case: str = "unmodified") -> Measured:
    loads = p.te["load_per_pair"].values
    n_loaded = np.sum(loads > 1e-9 * np.max(loads), axis=0)
    te = p.te["transmission_error"].sel(case=case).values
    double, single = n_loaded >= 2, n_loaded == 1
    text = f"two pairs loaded at {100 * np.mean(double):.0f} % of the mesh phases"
    if not double.any() or not single.any():
        return Measured(None, text)
    return Measured(float(np.mean(te[double]) - np.mean(te[single])), text + "; mean TE two pairs - one pair")


def _q_design_input(p: PlusProducts, section: str, key: str) -> Measured:
    raw = json.loads(p.te.attrs["config_json"])
    return Measured(raw[section][key], f"the design's {section}.{key}, an input of the model")


def _q_relief_optimum(p: PlusProducts, shape: str, bounds: str, field: str) -> Measured:
    row = p.optima[(p.optima["shape"] == shape) & (p.optima["bounds"] == bounds)].iloc[0]
    text = f"{shape} relief, {bounds} bounds ({row.amount_bounds_um} um, {row.length_bounds_mm} mm)"
    span = {"amount_um": row.amount_bounds_um, "length_mm": row.length_bounds_mm}.get(field)
    if span is not None:
        lo, hi = (float(x) for x in str(span).split("-"))
        if min(abs(row[field] - lo), abs(row[field] - hi)) <= 0.01 * (hi - lo):
            text += ", on the bound"
    return Measured(float(row[field]), text)


def _q_relief_shape_gain(p: PlusProducts, bounds: str) -> Measured:
    after = p.optima.set_index(["shape", "bounds"])["te_ptp_after_um"]
    both = [b for b in sorted(set(p.optima["bounds"])) if {("linear", b), ("parabolic", b)} <= set(after.index)]
    parts = [f"{b} bounds: linear {after['linear', b]:.3g}, parabolic {after['parabolic', b]:.3g} um" for b in both]
    return Measured(
        float(after["linear", bounds]) - float(after["parabolic", bounds]),
        f"TE after the linear optimum - after the parabolic one, {bounds} bounds; " + "; ".join(parts),
    )


def _q_te_at_relief(p: PlusProducts, shape: str) -> Measured:
    row = p.optima[p.optima["shape"] == shape].iloc[0]
    return Measured(
        float(row.ours_at_this_relief_um), f"our TE with amount {row.amount_um:.4g} um, length {row.length_mm:.4g} mm"
    )


def _band_rms(forced: xr.Dataset, case: str, band: Sequence[float]) -> float:
    sp = forced["speed"].values
    return float(np.sqrt(np.mean(forced["rms_force"].sel(case=case).values[(sp >= band[0]) & (sp <= band[1])] ** 2)))


def _q_force_band_change(p: PlusProducts, case: str, band_rpm: Sequence[float]) -> Measured:
    if p.forced is None:
        return Measured(None, "no forced response")
    ref = _band_rms(p.forced, "unmodified", band_rpm)
    db = {str(c): 20 * math.log10(_band_rms(p.forced, str(c), band_rpm) / ref) for c in p.forced["case"].values}
    others = ", ".join(f"{c} {v:+.2f} dB" for c, v in db.items() if c not in (case, "unmodified"))
    return Measured(
        db[case],
        f"RMS mesh-force fluctuation over the nine meshes at {band_rpm[0]:g}-{band_rpm[1]:g} rpm, {case} against "
        f"unmodified ({ref:.3g} N); {others}",
    )


#: The quantities of a plus set that claims stated as data may name, read from :class:`PlusProducts`.
PLUS_QUANTITIES: dict[str, Quantity] = {
    "frequencies_hz": Quantity(_q_frequencies),
    "scaled_rms_pct": Quantity(_q_scaled_rms),
    "shared_count": Quantity(_q_shared_count, lambda table: len(shared_frequencies(table))),
    "shared_orders": Quantity(lambda p: Measured(shared_orders(_frequencies(p))), shared_orders),
    "planet_modes_doubled": Quantity(_q_planet_doubled),
    "mode_classes": Quantity(_q_mode_classes),
    "planet_central_rotation": Quantity(_q_planet_central_rotation),
    "planet_component_share": Quantity(_q_planet_component_share),
    "overall_planets_alike": Quantity(_q_overall_alike),
    "key_elements": Quantity(_q_key_elements),
    "key_element_of_order": Quantity(_q_key_element_of_order),
    "key_element_counts": Quantity(
        lambda p: Measured(key_element_counts(_q_key_elements(p).value)), key_element_counts
    ),
    "dominant_component": Quantity(_q_dominant_component),
    "te_ptp_um": Quantity(_q_te_ptp),
    "te_zone_difference_um": Quantity(_q_te_zone_difference),
    "design_input": Quantity(_q_design_input),
    "relief_optimum": Quantity(_q_relief_optimum),
    "relief_shape_gain_um": Quantity(_q_relief_shape_gain),
    "te_at_relief_um": Quantity(_q_te_at_relief),
    "force_band_change_db": Quantity(_q_force_band_change),
}


def plus_claims(paper: ModuleType, products: PlusProducts) -> list[Claim]:
    """The claims of ``paper`` (its ``CLAIMS``, stated as data) on a plus-set design's products."""
    return data_claims(paper.CLAIMS, products, PLUS_QUANTITIES)


def products_note(design: str, title: str, paper: ModuleType) -> str:
    """The paragraph under the claims table of claims stated as data: which design, which paper, what is read."""
    return (
        f"Design `{design}` ({title}), compared with {paper.REFERENCE} Our numbers are read from the design's "
        "own tables and datasets under results/ (natural frequencies, stiffness scaling, key elements, modal.nc, "
        "te.nc, relief optima, forced_response.nc). Tolerance: what the paper's printed precision or its own "
        "stated accuracy allows (see each claim)."
    )
