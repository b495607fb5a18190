"""What the studies store: the state names, the per-point variables in one table (:data:`VARIABLES`) with one
writer (:func:`empty`), the name of a case, and the one chunk merge of sweeps and maps (:func:`merge_chunks`)."""

from __future__ import annotations

import json
from collections.abc import Iterable, Sequence
from dataclasses import replace

import numpy as np
import xarray as xr
from numpy.typing import DTypeLike

from geardyn.io import Var
from geardyn.io.provenance import distinct_runtimes
from geardyn.jsontypes import Json
from geardyn.label import BIFURCATIONS, EXPONENT_METHODS, STAGES, vocabulary
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


def _num(name: str, long_name: str, fill: Json = np.nan, dtype: DTypeLike | None = None) -> Var:
    return Var(name, (), "1", long_name, dtype=dtype, fill=fill)


def _flag(name: str, codes: dict[str, int], long_name: str, fill: int = vocabulary.NOT_COMPUTED) -> Var:
    return Var(name, (), None, long_name, flags=codes, fill=fill)


def _table(*rows: Var) -> dict[str, Var]:
    return {v.name: v for v in rows}


def label_var(name: str, long_name: str, max_n: int = 12, dims: tuple[str, ...] = ()) -> Var:
    """A motion label (int16 codes, :data:`geardyn.label.vocabulary.LABELS` and period-n for n = 1..``max_n``;
    ``long_period``: a certified orbit of a longer period, in ``period``), ``undetermined`` where not labelled."""
    codes = {**vocabulary.LABELS, **{f"period_{n}": n for n in range(1, max_n + 1)}}
    return Var(name, dims, None, long_name, codes, np.int16, vocabulary.LABELS["undetermined"])


#: The per-point variables of a verdict (:class:`geardyn.label.Verdict`) besides its label, on the study's dims.
VERDICT = _table(
    _num("period", "least period n in mesh periods (0: not periodic)", 0, np.int16),
    _num(
        "lyapunov",
        "largest exponent per unit dimensionless time tau = w_n t (Floquet: log max|mu| / (n T) of the "
        "certified orbit; else a tangent vector)",
    ),
    _num("lyapunov_sigma", "uncertainty of the largest exponent (0 for Floquet exponents)"),
    _flag(
        "exponent_method",
        EXPONENT_METHODS,
        "how the exponent was obtained: Floquet multipliers of the certified orbit, or a tangent vector over "
        "the record",
        0,
    ),
    _num("multiplier", "largest Floquet multiplier modulus of the orbit over its least period"),
    _num(
        "period_searched",
        "quasi-periodic: the longest period in mesh periods the long-cycle search excluded (a torus or a cycle "
        "longer than this); 0 otherwise",
        0,
        np.int16,
    ),
    _num("zero_one_k", "0-1 test statistic K on stroboscopic X_VH (Gottwald-Melbourne; NaN if periodic)"),
    _num("spectral_flatness", "spectral flatness of stroboscopic X_VH (0 lines, ~0.56 white; NaN if periodic)"),
    _num(
        "torus_digits",
        "digits of agreement of the weighted Birkhoff averages of the two halves of the record (large: a "
        "torus; NaN if periodic)",
    ),
    _flag(
        "crosscheck",
        {"not_applicable": -1, "one_agrees": 0, "both_agree": 1},
        "0-1 test and spectrum agree with the label",
    ),
    _flag(
        "stage",
        {"not_computed": vocabulary.NOT_COMPUTED, **STAGES},
        "labeller stage that decided the label (geardyn.label)",
    ),
    _flag(
        "bifurcation",
        BIFURCATIONS,
        "how the orbit followed from the previous point of the line lost stability here (leading Floquet multiplier)",
        0,
    ),
)
#: The response measures of a point (:class:`geardyn.solve.response.ResponseMeasures`), likewise.
RESPONSE = _table(
    _num("static_force", "static mesh force F_s / (k_mean b_c) (mean stiffness, no TE)"),
    _num("force_mean", "mean dynamic mesh force on the drive side / (k_mean b_c)"),
    _num("force_rms", "RMS of the dynamic mesh force's fluctuation / (k_mean b_c)"),
    _num("force_max", "largest dynamic mesh force on the drive side / (k_mean b_c)"),
    _num("dynamic_factor", "dynamic factor K_v = largest dynamic mesh force / static mesh force"),
    _num("dte_mean", "mean dynamic transmission error X_VH / b_c (b_c = 1 um)"),
    _num("dte_rms", "RMS of the dynamic transmission error's fluctuation, X_VH / b_c (b_c = 1 um)"),
    _num("dte_pp", "peak-to-peak dynamic transmission error X_VH / b_c (b_c = 1 um)"),
    _num("drive_fraction", "fraction of time in drive-side contact"),
    _num("separation_fraction", "fraction of time with the teeth separated (inside the backlash)"),
    _num("back_fraction", "fraction of time in back-side contact"),
)
#: Every per-point variable the studies store, likewise (the motion labels of :data:`LABELS` too, up to period
#: 12): :func:`empty` makes them.
VARIABLES = _table(
    *VERDICT.values(),
    *RESPONSE.values(),
    _flag(
        "impact_class",
        {"not_computed": vocabulary.NOT_COMPUTED, **IMPACT_CLASSES},
        "impact class: no impact, single-sided (separation, never back-side contact), double-sided (back-side "
        "contact); not computed where the run diverged (label)",
    ),
    # policy coexistence: the fixed start's label and whether it differs
    label_var("label_fixed", "motion label from the fixed start (the static deflection)"),
    _flag(
        "coexisting",
        {"not_checked": -1, "same": 0, "coexisting": 1},
        "the follow and the fixed start end on different attractors at this point",
    ),
    label_var("label", "motion label (geardyn.label)"),
    _num(
        "transient_used",
        "transient mesh periods integrated before the recorded ones (0: followed from the previous "
        "point's orbit; less than the configured transient after an early stop)",
        -1,
        np.int32,
    ),
    _flag("computed", {"absent": 0, "present": 1}, "1 where this file holds the point", 0),
    # a sweep's own (besides the Poincare sections and the coefficients)
    _num("diverged_period", "mesh period at which the state exceeded the threshold (-1: never)", -1, np.int32),
    _num("n_events", "number of contact-switch events located (rk4_event)", -1, np.int64),
    # a map's own
    _num("x_vh_mean", "mean Poincare X_VH / b_c"),
    _num("x_vh_spread", "peak-to-peak of Poincare X_VH / b_c"),
)

#: The verdict's field of each of its variables (a string field stored as its code in the variable's flags).
VERDICT_FIELDS = {name: name for name in VERDICT} | {
    "lyapunov": "exponent",
    "lyapunov_sigma": "exponent_sigma",
    "zero_one_k": "k01",
    "spectral_flatness": "flatness",
}


#: The motion labels: from the study's own start, and from the fixed start (policy ``coexistence``).
LABELS = ("label", "label_fixed")
#: The per-point variables every study stores: the verdict's and the response measures.
COMMON = ("label", *VERDICT, *RESPONSE, "impact_class")


def empty(
    names: Iterable[str], dims: tuple[str, ...], shape: tuple[int, ...], max_n: int = 12, **long_names: str
) -> dict[str, Json]:
    """The one writer of the per-point variables: those of :data:`VARIABLES` named, on ``dims``, as
    :class:`xarray.Dataset` takes them, filled with their fill values (``max_n``: the labels' largest period;
    ``long_names`` replace the table's)."""
    out = {}
    for name in names:
        var = label_var(name, VARIABLES[name].long_name, max_n) if name in LABELS else VARIABLES[name]
        out[name] = replace(var, dims=dims, long_name=long_names.get(name, var.long_name)).empty(shape)
    return out


#: Attributes that describe one chunk (its number, its wall time), not the merged result.
CHUNK_ATTRS = ("chunk", "n_chunks", "wall_time_s")


def labels_of_cube(cube: xr.Dataset) -> np.ndarray:
    """The motion labels stored in a sweep cube or map (``label``)."""
    return cube["label"].values.astype(np.int16)


def merge_chunks(chunks: Sequence[xr.Dataset]) -> xr.Dataset:
    """Combine the chunk files of one sweep or map, each holding the full grid and a ``computed`` flag: every point
    computed exactly once; the chunks' own attributes go, their wall times kept as ``chunk_wall_time_s``;
    ``undamped`` 1 only where every chunk says so."""
    if not chunks:
        raise ValueError("no chunks to merge")
    present = sum(c["computed"].values.astype(int) for c in chunks)
    if np.any(present != 1):
        missing, twice = int(np.sum(present == 0)), int(np.sum(present > 1))
        raise ValueError(f"chunks do not tile the grid: {missing} points missing, {twice} computed twice")
    out = chunks[0].drop_vars("computed").copy(deep=True)
    for c in chunks[1:]:
        mask = c["computed"].values.astype(bool)
        for name in out.data_vars:
            out[name].values[mask] = c[name].values[mask]
    for key in CHUNK_ATTRS:
        out.attrs.pop(key, None)
    # undamped only where every chunk's points are
    if "undamped" in out.attrs and any(int(c.attrs.get("undamped", 0)) == 0 for c in chunks):
        out.attrs["undamped"] = 0
        out.attrs.pop("undamped_note", None)
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
    return {vocabulary.short_name(int(c)): float(k) / lab.size for c, k in zip(codes, n, strict=True)}
