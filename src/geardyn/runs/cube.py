"""What the studies store: the state names, the per-point variables in one table (:data:`VARIABLES`) with
one writer (:func:`empty`), and the ONE chunk merge of sweeps and maps (:func:`merge_chunks`: a chunk holds
its run's full grid, a ``computed`` flag where it computed; the chunks must tile the grid exactly once).
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np
import xarray as xr

from geardyn.io.provenance import distinct_runtimes
from geardyn.label import BIFURCATIONS, EXPONENT_METHODS, STAGES, classify
from geardyn.solve.response import IMPACT_CLASSES

STATES = ("x_dh", "x_vh", "x_vl", "v_dh", "v_vh", "v_vl")
STATE_NAMES = {
    "x_dh": "relative displacement X_DH / b_c (drive - carrier)",
    "x_vh": "mesh deflection X_VH / b_c (planet - carrier - TE)",
    "x_vl": "relative displacement X_VL / b_c (planet - load)",
    "v_dh": "dimensionless velocity dX_DH/dtau / b_c",
    "v_vh": "dimensionless velocity dX_VH/dtau / b_c",
    "v_vl": "dimensionless velocity dX_VL/dtau / b_c",
}


def flags(codes: dict[str, int], long_name: str) -> dict[str, Any]:
    """CF attributes of a flag variable (int8) with ``codes`` (meaning -> value)."""
    return {
        "long_name": long_name,
        "flag_values": np.array(list(codes.values()), np.int8),
        "flag_meanings": " ".join(codes),
    }


def _num(long_name: str, fill: Any = np.nan) -> tuple[Any, dict[str, Any]]:
    return fill, {"units": "1", "long_name": long_name}


def _flag(codes: dict[str, int], long_name: str, fill: int = -1) -> tuple[Any, dict[str, Any]]:
    return np.int8(fill), flags(codes, long_name)


#: The fill value (dtype int16) of a motion label where no point was labelled.
LABEL_FILL = np.int16(classify.LABELS["undetermined"])

#: The per-point variables of a verdict (:class:`geardyn.label.Verdict`) besides its label: name -> (fill
#: value, NaN or an integer of the variable's dtype; CF attributes).
VERDICT: dict[str, tuple[Any, dict[str, Any]]] = {
    "period": _num("least period n in mesh periods (0: not periodic)", np.int16(0)),
    "lyapunov": _num(
        "largest exponent per unit dimensionless time tau = w_n t (Floquet: log max|mu| / (n T) of the certified "
        "orbit; else a tangent vector)"
    ),
    "lyapunov_sigma": _num("uncertainty of the largest exponent (0 for Floquet exponents)"),
    "exponent_method": _flag(
        EXPONENT_METHODS,
        "how the exponent was obtained: Floquet multipliers of the certified orbit, or a tangent vector over the "
        "record",
        0,
    ),
    "multiplier": _num("largest Floquet multiplier modulus of the orbit over its least period"),
    "zero_one_k": _num("0-1 test statistic K on stroboscopic X_VH (Gottwald-Melbourne; NaN if periodic)"),
    "spectral_flatness": _num("spectral flatness of stroboscopic X_VH (0 lines, ~0.56 white; NaN if periodic)"),
    "torus_digits": _num(
        "digits of agreement of the weighted Birkhoff averages of the two halves of the record (large: a torus; "
        "NaN if periodic)"
    ),
    "crosscheck": _flag(
        {"not_applicable": -1, "one_agrees": 0, "both_agree": 1}, "0-1 test and spectrum agree with the label"
    ),
    "stage": _flag({"not_computed": 0, **STAGES}, "labeller stage that decided the label (geardyn.label)", 0),
    "bifurcation": _flag(
        BIFURCATIONS,
        "how the orbit followed from the previous point of the line lost stability here (leading Floquet multiplier)",
        0,
    ),
}
#: The response measures of a point (:class:`geardyn.solve.response.ResponseMeasures`), likewise.
RESPONSE = {
    "static_force": _num("static mesh force F_s / (k_mean b_c) (mean stiffness, no TE)"),
    "force_mean": _num("mean dynamic mesh force on the drive side / (k_mean b_c)"),
    "force_rms": _num("RMS of the dynamic mesh force's fluctuation / (k_mean b_c)"),
    "force_max": _num("largest dynamic mesh force on the drive side / (k_mean b_c)"),
    "dynamic_factor": _num("dynamic factor K_v = largest dynamic mesh force / static mesh force"),
    "dte_mean": _num("mean dynamic transmission error X_VH / b_c (b_c = 1 um)"),
    "dte_rms": _num("RMS of the dynamic transmission error's fluctuation, X_VH / b_c (b_c = 1 um)"),
    "dte_pp": _num("peak-to-peak dynamic transmission error X_VH / b_c (b_c = 1 um)"),
    "drive_fraction": _num("fraction of time in drive-side contact"),
    "separation_fraction": _num("fraction of time with the teeth separated (inside the backlash)"),
    "back_fraction": _num("fraction of time in back-side contact"),
}
#: Every per-point variable the studies store besides the motion labels, likewise: :func:`empty` makes them.
VARIABLES = {
    **VERDICT,
    **RESPONSE,
    "impact_class": _flag(
        {"not_computed_or_diverged": -1, **IMPACT_CLASSES},
        "impact class: no impact, single-sided (separation, never back-side contact), double-sided (back-side contact)",
    ),
    # policy coexistence (label_fixed, a motion label: LABELS)
    "coexisting": _flag(
        {"not_checked": -1, "same": 0, "coexisting": 1},
        "the follow and the fixed start end on different attractors at this point",
    ),
    "transient_used": _num(
        "transient mesh periods integrated before the recorded ones (0: followed from the previous "
        "point's orbit; less than the configured transient after an early stop)",
        np.int32(-1),
    ),
    "diverged": _flag({"not_computed": -1, "bounded": 0, "diverged": 1}, "unbounded growth detected"),
    "computed": _flag({"absent": 0, "present": 1}, "1 where this file holds the point", 0),
    # a sweep's own (besides the Poincare sections and the coefficients)
    "diverged_period": _num("mesh period at which the state exceeded the threshold (-1: never)", np.int32(-1)),
    "n_events": _num("number of contact-switch events located (rk4_event)", np.int64(-1)),
    # a map's own
    "x_vh_mean": _num("mean Poincare X_VH / b_c"),
    "x_vh_spread": _num("peak-to-peak of Poincare X_VH / b_c"),
}

#: The verdict's field of each of its variables.
VERDICT_FIELDS = {name: name for name in VERDICT} | {
    "lyapunov": "exponent",
    "lyapunov_sigma": "exponent_sigma",
    "zero_one_k": "k01",
    "spectral_flatness": "flatness",
}
#: The verdict's fields stored as codes: name -> (field value -> code).
VERDICT_CODES = {"exponent_method": EXPONENT_METHODS, "stage": STAGES, "bifurcation": BIFURCATIONS}


#: The motion labels' long names: from the study's own start, and from the fixed start (policy ``coexistence``).
LABELS = {
    "label": "motion label (geardyn.label)",
    "label_fixed": "motion label from the fixed start (the static deflection)",
}
#: The per-point variables every study stores: the verdict's and the response measures.
COMMON = ("label", *VERDICT, *RESPONSE, "impact_class")


def empty(
    names: Iterable[str], dims: tuple[str, ...], shape: tuple[int, ...], max_n: int = 12, **long_names: str
) -> dict[str, Any]:
    """The one writer of the per-point variables: those of :data:`VARIABLES` and :data:`LABELS` named, as
    :class:`xarray.Dataset` takes them, filled with their fill values (``max_n``: the labels' largest period;
    ``long_names`` replace the table's)."""
    out = {}
    for name in names:
        if name in LABELS:
            fill, attrs = LABEL_FILL, {"long_name": LABELS[name], **classify.flag_attrs(max_n)}
        else:
            fill, attrs = VARIABLES[name]
        attrs = {**attrs, "long_name": long_names[name]} if name in long_names else dict(attrs)
        out[name] = (dims, np.full(shape, fill), attrs)
    return out


#: Attributes that describe one chunk (its number, its wall time), not the merged result.
CHUNK_ATTRS = ("chunk", "n_chunks", "wall_time_s")


def labels_of_cube(cube: xr.Dataset) -> np.ndarray:
    """The motion labels stored in a sweep cube or map (``label``)."""
    return cube["label"].values.astype(np.int16)


def merge_chunks(chunks: Sequence[xr.Dataset]) -> xr.Dataset:
    """Combine chunk files of one sweep or map; each point must be present exactly once.

    The chunks' own attributes (:data:`CHUNK_ATTRS`) are dropped; their wall times are kept as
    ``chunk_wall_time_s`` where the chunks recorded them.
    """
    if not chunks:
        raise ValueError("no chunks to merge")
    present = sum(c["computed"].values.astype(int) for c in chunks)
    if np.any(present != 1):
        missing = int(np.sum(present == 0))
        twice = int(np.sum(present > 1))
        raise ValueError(f"chunks do not tile the grid: {missing} points missing, {twice} computed twice")
    out = chunks[0].drop_vars("computed").copy(deep=True)
    for c in chunks[1:]:
        mask = c["computed"].values.astype(bool)
        for name in out.data_vars:
            out[name].values[mask] = c[name].values[mask]
    for key in CHUNK_ATTRS:
        out.attrs.pop(key, None)
    # where the chunks were computed (a cluster may run them on different CPUs); the merged file's own
    # runtime attributes are those of the merge job (geardyn.io.write_netcdf)
    seen = [rt for rt, _ in distinct_runtimes(c.attrs for c in chunks)]
    if seen:
        out.attrs["chunks_runtime"] = json.dumps(seen, sort_keys=True)
    if any("wall_time_s" in c.attrs for c in chunks):
        out.attrs["chunk_wall_time_s"] = ",".join(f"{float(c.attrs.get('wall_time_s', np.nan)):.1f}" for c in chunks)
    return out


def fractions(ds: xr.Dataset) -> dict[str, float]:
    """Share of each label over a cube (a map or a sweep)."""
    lab = ds["label"].values.ravel()
    codes, n = np.unique(lab, return_counts=True)
    return {classify.short_name(int(c)): float(k) / lab.size for c, k in zip(codes, n, strict=True)}
