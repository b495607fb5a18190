"""What the studies store: state names, the per-point variables (verdict, response measures, coexistence)
with their CF attributes, and the ONE chunk merge of sweeps and maps.

The studies fill these variables through one runner (:mod:`geardyn.runs.study`).  A chunk file holds every
variable of its run's full grid, NaN or -1 where it did not compute, and a ``computed`` flag (1 where it did).
:func:`merge_chunks` combines them, whatever the run, and refuses chunks that do not tile the grid exactly once.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from typing import Any

import numpy as np
import xarray as xr

from geardyn import classify
from geardyn.io import runtime_provenance
from geardyn.label import BIFURCATIONS, EXPONENT_METHODS, STAGES
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


#: CF attributes of the per-point ``stage``, ``bifurcation`` and ``exponent_method`` flags (geardyn.label).
STAGE_ATTRS = flags({"not_computed": 0, **STAGES}, "labeller stage that decided the label (geardyn.label)")
BIFURCATION_ATTRS = flags(
    BIFURCATIONS,
    "how the orbit followed from the previous point of the line lost stability here (leading Floquet multiplier)",
)
EXPONENT_METHOD_ATTRS = flags(
    EXPONENT_METHODS,
    "how the exponent was obtained: Floquet multipliers of the certified orbit, or a tangent vector over the record",
)


#: The fill value (dtype int16) of a motion label where no point was labelled.
LABEL_FILL = np.int16(classify.LABELS["undetermined"])


def _verdict_var(field: str, long_name: str, fill: Any = np.nan) -> tuple:
    return field, None, {"units": "1", "long_name": long_name}, fill


#: The per-point variables of a verdict (:class:`geardyn.label.Verdict`) besides its label: name -> (the
#: verdict's field, the codes of a flag or None, CF attributes, fill value: NaN, or an integer of its dtype).
VERDICT_VARIABLES = {
    "period": _verdict_var("period", "least period n in mesh periods (0: not periodic)", fill=np.int16(0)),
    "lyapunov": _verdict_var(
        "exponent",
        "largest exponent per unit dimensionless time tau = w_n t (Floquet: log max|mu| / (n T) of the certified "
        "orbit; else a tangent vector)",
    ),
    "lyapunov_sigma": _verdict_var("exponent_sigma", "uncertainty of the largest exponent (0 for Floquet exponents)"),
    "exponent_method": ("exponent_method", EXPONENT_METHODS, EXPONENT_METHOD_ATTRS, np.int8(0)),
    "multiplier": _verdict_var("multiplier", "largest Floquet multiplier modulus of the orbit over its least period"),
    "zero_one_k": _verdict_var(
        "k01", "0-1 test statistic K on stroboscopic X_VH (Gottwald-Melbourne; NaN if periodic)"
    ),
    "spectral_flatness": _verdict_var(
        "flatness", "spectral flatness of stroboscopic X_VH (0 lines, ~0.56 white; NaN if periodic)"
    ),
    "torus_digits": _verdict_var(
        "torus_digits",
        "digits of agreement of the weighted Birkhoff averages of the two halves of the record (large: a torus; "
        "NaN if periodic)",
    ),
    "crosscheck": (
        "crosscheck",
        None,
        flags({"not_applicable": -1, "one_agrees": 0, "both_agree": 1}, "0-1 test and spectrum agree with the label"),
        np.int8(-1),
    ),
    "stage": ("stage", STAGES, STAGE_ATTRS, np.int8(0)),
    "bifurcation": ("bifurcation", BIFURCATIONS, BIFURCATION_ATTRS, np.int8(0)),
}


def label_variables(
    dims: tuple[str, ...], shape: tuple[int, ...], classifier: classify.ClassifierSettings
) -> dict[str, Any]:
    """Empty per-point verdict variables: the motion label and :data:`VERDICT_VARIABLES`."""
    label = {"long_name": "motion label (geardyn.label)", **classify.flag_attrs(classifier.max_n)}
    return {
        "label": (dims, np.full(shape, LABEL_FILL), label),
        **{name: (dims, np.full(shape, fill), attrs) for name, (_, _, attrs, fill) in VERDICT_VARIABLES.items()},
    }


#: Units and long names of the per-point response measures (:class:`geardyn.solve.response.ResponseMeasures`).
RESPONSE_ATTRS = {
    "static_force": ("1", "static mesh force F_s / (k_mean b_c) (mean stiffness, no TE)"),
    "force_mean": ("1", "mean dynamic mesh force on the drive side / (k_mean b_c)"),
    "force_rms": ("1", "RMS of the dynamic mesh force's fluctuation / (k_mean b_c)"),
    "force_max": ("1", "largest dynamic mesh force on the drive side / (k_mean b_c)"),
    "dynamic_factor": ("1", "dynamic factor K_v = largest dynamic mesh force / static mesh force"),
    "dte_mean": ("1", "mean dynamic transmission error X_VH / b_c (b_c = 1 um)"),
    "dte_rms": ("1", "RMS of the dynamic transmission error's fluctuation, X_VH / b_c (b_c = 1 um)"),
    "dte_pp": ("1", "peak-to-peak dynamic transmission error X_VH / b_c (b_c = 1 um)"),
    "drive_fraction": ("1", "fraction of time in drive-side contact"),
    "separation_fraction": ("1", "fraction of time with the teeth separated (inside the backlash)"),
    "back_fraction": ("1", "fraction of time in back-side contact"),
}

#: CF attributes of the per-point ``impact_class`` flag.
IMPACT_CLASS_ATTRS = flags(
    {"not_computed_or_diverged": -1, **IMPACT_CLASSES},
    "impact class: no impact, single-sided (separation, never back-side contact), double-sided (back-side contact)",
)


def response_variables(dims: tuple[str, ...], shape: tuple[int, ...]) -> dict[str, Any]:
    """Empty per-point response variables (see :class:`geardyn.solve.response.ResponseMeasures`)."""
    data: dict[str, Any] = {
        name: (dims, np.full(shape, np.nan), {"units": units, "long_name": long_name})
        for name, (units, long_name) in RESPONSE_ATTRS.items()
    }
    data["impact_class"] = (dims, np.full(shape, -1, np.int8), IMPACT_CLASS_ATTRS)
    return data


#: CF attributes of the ``coexisting`` flag (policy ``coexistence``).
COEXISTING_ATTRS = flags(
    {"not_checked": -1, "same": 0, "coexisting": 1},
    "the follow and the fixed start end on different attractors at this point",
)


#: CF attributes of the per-point ``transient_used`` of the studies that follow attractors.
TRANSIENT_USED_ATTRS = {
    "units": "1",
    "long_name": "transient mesh periods integrated before the recorded ones (0: followed from the previous "
    "point's orbit; less than the configured transient after an early stop)",
}


def coexistence_variables(
    dims: tuple[str, ...], shape: tuple[int, ...], classifier: classify.ClassifierSettings
) -> dict[str, Any]:
    """The fixed start's label and the ``coexisting`` flag (policy ``coexistence``)."""
    label = {"long_name": "motion label from the fixed start (the static deflection)"}
    return {
        "label_fixed": (dims, np.full(shape, LABEL_FILL), {**label, **classify.flag_attrs(classifier.max_n)}),
        "coexisting": (dims, np.full(shape, -1, np.int8), COEXISTING_ATTRS),
    }


COMPUTED_ATTRS = flags({"absent": 0, "present": 1}, "1 where this file holds the point")

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

    keys = tuple(runtime_provenance())
    seen = []
    for c in chunks:
        rt = {k: str(c.attrs[k]) for k in keys if k in c.attrs}
        if rt and rt not in seen:
            seen.append(rt)
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
