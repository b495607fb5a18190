"""What sweeps and maps store: state names, per-point label variables, and the ONE chunk merge.

A chunk file holds every variable of its run's full grid, NaN or -1 where it did not compute, and
a ``computed`` flag (1 where it did).  :func:`merge_chunks` combines them, whatever the run, and
refuses chunks that do not tile the grid exactly once.
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Sequence
from typing import Any

import numpy as np
import xarray as xr

from geardyn import classify

STATES = ("x_dh", "x_vh", "x_vl", "v_dh", "v_vh", "v_vl")
STATE_NAMES = {
    "x_dh": "relative displacement X_DH / b_c (drive - carrier)",
    "x_vh": "mesh deflection X_VH / b_c (planet - carrier - TE)",
    "x_vl": "relative displacement X_VL / b_c (planet - load)",
    "v_dh": "dimensionless velocity dX_DH/dtau / b_c",
    "v_vh": "dimensionless velocity dX_VH/dtau / b_c",
    "v_vl": "dimensionless velocity dX_VL/dtau / b_c",
}
#: CF attributes of the per-point ``settled`` flag (geardyn.runs.settle)
SETTLED_ATTRS = {
    "long_name": "label decided by the slow-transient check (geardyn.runs.settle): the rules said quasi-periodic "
                 "or undetermined; 1: the run approaches a stable period-n orbit; 2: a stable orbit exists whose "
                 "multiplier is too close to 1 to see the run approach it (label undetermined)",
    "flag_values": np.array([0, 1, 2], np.int8),
    "flag_meanings": "by_the_rules settled_by_shooting possible_slow_transient"}


def label_variables(dims: tuple[str, ...], shape: tuple[int, ...],
                    classifier: classify.ClassifierSettings) -> dict[str, Any]:
    """Empty per-point classification variables (see :func:`geardyn.classify.classify_point`)."""
    return {
        "label": (dims, np.full(shape, classify.LABELS["undetermined"], np.int16), {
            "long_name": "motion label (classify.classify_point)", **classify.flag_attrs(classifier.max_n)}),
        "period": (dims, np.zeros(shape, np.int16), {
            "units": "1", "long_name": "period n in mesh periods (0: not periodic)"}),
        "lyapunov": (dims, np.full(shape, np.nan), {
            "units": "1", "long_name": "largest Lyapunov exponent per unit dimensionless time tau = w_n t "
                                       "(tangent vector over the last tangent_periods)"}),
        "lyapunov_sigma": (dims, np.full(shape, np.nan), {
            "units": "1", "long_name": "uncertainty of the largest Lyapunov exponent (batch means / half-run drift)"}),
        "zero_one_k": (dims, np.full(shape, np.nan), {
            "units": "1", "long_name": "0-1 test statistic K on stroboscopic X_VH (Gottwald-Melbourne; NaN if periodic)"}),
        "spectral_flatness": (dims, np.full(shape, np.nan), {
            "units": "1", "long_name": "spectral flatness of stroboscopic X_VH (0 lines, ~0.56 white; NaN if periodic)"}),
        "crosscheck": (dims, np.full(shape, -1, np.int8), {
            "long_name": "0-1 test and spectrum agree with the label",
            "flag_values": np.array([-1, 0, 1], np.int8), "flag_meanings": "not_applicable one_agrees both_agree"}),
        "settled": (dims, np.zeros(shape, np.int8), SETTLED_ATTRS),
    }


def store_label(ds: xr.Dataset, idx: tuple, lab: classify.Classification) -> None:
    ds["label"].values[idx] = lab.label
    ds["period"].values[idx] = lab.period
    ds["lyapunov"].values[idx] = lab.lyapunov
    ds["lyapunov_sigma"].values[idx] = lab.lyapunov_sigma
    ds["zero_one_k"].values[idx] = lab.k01
    ds["spectral_flatness"].values[idx] = lab.flatness
    ds["crosscheck"].values[idx] = lab.crosscheck
    ds["settled"].values[idx] = int(lab.settled)


def classifier_attrs(classifier: classify.ClassifierSettings) -> dict[str, Any]:
    return {f"classifier_{k}": v for k, v in dataclasses.asdict(classifier).items()}


COMPUTED_ATTRS = {"long_name": "1 where this file holds the point", "flag_values": np.array([0, 1], np.int8),
                  "flag_meanings": "absent present"}

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
    from geardyn.io import runtime_provenance

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
