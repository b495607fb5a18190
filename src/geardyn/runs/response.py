"""The frequency response of a KHV design: the response measures against the mesh frequency w, swept up
and down (definitions: ``docs/response.md``).

The sweep holds the design's point (its own x1, b, e unless ``fixed`` overrides them) and sets the
dimensionless mesh frequency w = w_m / w_n on its coefficients (whatever the design's ``frequency_mode``: the
input speed that gives w is stored beside it).  The up and the down sweep are two *lines* of
:func:`geardyn.label.label_lines` with ``start_from: follow``: each point starts from the attractor of its
neighbour, so the two curves part where two attractors coexist (hysteresis).  A *jump* is a step of the RMS
DTE between neighbours of a line larger than ``jump_threshold`` times the larger of the two (and of the
``jump_floor``) where the up and down curves disagree by as much (:func:`find_jumps`).
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Mapping
from dataclasses import dataclass
from types import SimpleNamespace
from typing import Any

import numpy as np
import xarray as xr

from geardyn.khv import point
from geardyn.khv.design import KHVDesign, resolve_fractions
from geardyn.khv.model import COEFFICIENT_ATTRS, Coefficients, natural_frequencies
from geardyn.label import Policy, label_lines
from geardyn.runs.cube import (
    STATES,
    TRANSIENT_USED_ATTRS,
    label_variables,
    line_responses,
    policy_attrs,
    response_variables,
    store_response,
    store_verdict,
)

log = logging.getLogger("geardyn.response")

DIRECTIONS = ("up", "down")


@dataclass(frozen=True)
class ResponseSpec:
    """One frequency response as declared in ``config.yaml`` under ``responses:``."""

    name: str
    design: str
    start: float
    stop: float
    num: int
    jump_threshold: float = 0.25
    jump_floor: float = 0.05
    fixed: tuple[tuple[str, float], ...] = ()
    integration: tuple[tuple[str, Any], ...] = ()
    classifier: tuple[tuple[str, Any], ...] = ()

    def __post_init__(self) -> None:
        if not (0.0 < self.start < self.stop) or self.num < 3:
            raise ValueError(f"frequency response: need 0 < start < stop and num >= 3, got {self}")
        if not (self.jump_threshold > 0.0 and self.jump_floor >= 0.0):
            raise ValueError("frequency response: jump_threshold > 0 and jump_floor >= 0")

    @classmethod
    def from_config(cls, name: str, spec: Mapping[str, Any], design: str, segment: tuple[float, float]) -> ResponseSpec:
        """The response ``name`` of ``config["responses"]`` for ``design`` (x1 overrides may be percentages of
        its admissible segment, :func:`geardyn.khv.design.resolve_fractions`)."""
        spec = resolve_fractions(spec, segment)
        return cls(
            name=name,
            design=design,
            start=float(spec["start"]),
            stop=float(spec["stop"]),
            num=int(spec["num"]),
            jump_threshold=float(spec.get("jump_threshold", 0.25)),
            jump_floor=float(spec.get("jump_floor", 0.05)),
            fixed=tuple(sorted((spec.get("fixed") or {}).items())),
            integration=tuple(sorted((spec.get("integration") or {}).items())),
            classifier=tuple(sorted((spec.get("classifier") or {}).items())),
        )

    @property
    def values(self) -> np.ndarray:
        return np.linspace(self.start, self.stop, self.num)


def find_jumps(rms: np.ndarray, threshold: float, floor: float) -> tuple[np.ndarray, np.ndarray]:
    """Jumps of the up and down RMS-DTE curves ``rms`` (2, n) on one ascending frequency grid.

    Two values differ *by a jump* when |a - b| > threshold max(a, b, floor).  Returns ``(jump, split)``:
    ``split`` (n,) where the up and down curves differ so (two attractors: hysteresis), and ``jump`` (2, n)
    where a curve differs so from its lower neighbour and the curves are split at one of the two points (a
    step of a single curve on a coarse grid, e.g. across a narrow resonance, is not a jump).  The flag
    sits on the higher-frequency point of the pair, whatever the direction of travel."""
    rms = np.asarray(rms, dtype=float)
    if rms.ndim != 2 or rms.shape[0] != 2:
        raise ValueError("find_jumps: rms must be (2, n): the up and the down curve")
    rms = np.where(np.isfinite(rms), rms, 0.0)

    def differ(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        return np.abs(a - b) > threshold * np.maximum(np.maximum(a, b), floor)

    split = differ(rms[0], rms[1])
    jump = np.zeros(rms.shape, dtype=bool)
    jump[:, 1:] = differ(rms[:, 1:], rms[:, :-1]) & (split[1:] | split[:-1])
    return jump, split


def jump_frequencies(w: np.ndarray, flags: np.ndarray, direction: str) -> np.ndarray:
    """The frequencies of a line's jumps: the mid-points of the flagged steps, in the order of travel."""
    j = np.flatnonzero(flags)
    mids = 0.5 * (w[j] + w[j - 1])
    return mids if direction == "up" else mids[::-1]


def frequency_response(base: Coefficients, w: np.ndarray, policy: Policy, threshold: float, floor: float) -> xr.Dataset:
    """Label and measure ``base`` at every mesh frequency of ``w`` (ascending), swept up and down."""
    w = np.asarray(w, dtype=float)
    if w.ndim != 1 or w.size < 3 or not np.all(np.diff(w) > 0.0):
        raise ValueError("frequency response: w must be an ascending grid of at least 3 frequencies")
    dims, shape = ("direction", "w"), (2, w.size)
    up = [base.replace(omega=float(v)) for v in w]
    lines = [up, up[::-1]]
    t0 = time.perf_counter()
    verdicts = label_lines(lines, policy, progress="frequency response")
    data: dict[str, Any] = {**label_variables(dims, shape, policy.classifier), **response_variables(dims, shape)}
    data["transient_used"] = (dims, np.full(shape, -1, np.int32), TRANSIENT_USED_ATTRS)
    data["final_state"] = (
        (*dims, "state"),
        np.full((*shape, len(STATES)), np.nan),
        {"units": "1", "long_name": "state at phase 0 on the attractor at the end of the record (a restart)"},
    )
    arrays = {name: SimpleNamespace(values=spec[1]) for name, spec in data.items()}  # numpy views
    responses = line_responses(lines, verdicts, policy.integration)
    for d, vs in enumerate(verdicts):
        for k, v in enumerate(vs):
            j = k if d == 0 else w.size - 1 - k
            store_verdict(arrays, (d, j), v)
            store_response(arrays, (d, j), responses[d][k])
            arrays["transient_used"].values[d, j] = v.transient_used
            arrays["final_state"].values[d, j] = v.final_state
    rms = data["dte_rms"][1]
    jumps, split = find_jumps(rms, threshold, floor)
    data["jump"] = (
        dims,
        jumps.astype(np.int8),
        {
            "long_name": f"a jump: the RMS DTE steps by more than {threshold:g} x max(its two values, {floor:g}) "
            "from the next lower frequency of the same line, where the up and down curves differ as much",
            "flag_values": np.array([0, 1], np.int8),
            "flag_meanings": "smooth jump",
        },
    )
    data["hysteresis"] = (
        ("w",),
        split.astype(np.int8),
        {
            "long_name": "the up and down sweeps end on different attractors (RMS DTE differs as a jump does)",
            "flag_values": np.array([0, 1], np.int8),
            "flag_meanings": "same different",
        },
    )
    nat = natural_frequencies(base)
    data["natural_frequency"] = (
        ("mode",),
        nat,
        {"units": "1", "long_name": "undamped natural frequency of the linearised system in contact / w_n"},
    )
    omega_n = float(base.omega_n)
    coords = {
        "direction": ("direction", list(DIRECTIONS), {"long_name": "sweep direction (line of the labeller)"}),
        "w": ("w", w, {"units": "1", "long_name": "dimensionless mesh frequency w_m / w_n"}),
        "state": ("state", list(STATES), {"long_name": "state component (geardyn.runs.cube.STATE_NAMES)"}),
        "mode": ("mode", np.arange(nat.size, dtype=np.int32), {"units": "1", "long_name": "mode number"}),
        "mesh_frequency_hz": (
            "w",
            w * omega_n / (2.0 * math.pi),
            {"units": "Hz", "long_name": "mesh frequency w_m / (2 pi)"},
        ),
    }
    attrs = {
        "jump_threshold": threshold,
        "jump_floor": floor,
        "jumps_up": ",".join(f"{v:.4g}" for v in jump_frequencies(w, jumps[0], "up")) or "none",
        "jumps_down": ",".join(f"{v:.4g}" for v in jump_frequencies(w, jumps[1], "down")) or "none",
        "integrator": policy.integration.integrator,
        "steps_per_period": policy.integration.steps_per_period,
        "transient_periods": policy.integration.transient_periods,
        "recorded_periods": policy.integration.recorded_periods,
        **policy_attrs(policy),
        **{f"coef_{k}": v for k, v in base.as_dict().items() if k in COEFFICIENT_ATTRS and k != "omega"},
    }
    log.info("frequency response: %d points in %.1f s", 2 * w.size, time.perf_counter() - t0)
    return xr.Dataset(data, coords=coords, attrs=attrs)


def response_policy(design: KHVDesign, spec: ResponseSpec) -> Policy:
    """The labelling policy: the design's integration with the study's changes, start ``follow``."""
    return Policy.from_spec(
        point.integration_settings(design, **dict(spec.integration)), {"classifier": dict(spec.classifier)}
    )


def run(design: KHVDesign, spec: ResponseSpec) -> xr.Dataset:
    """The frequency response of ``design`` at its point (with the study's fixed overrides)."""
    base = point.point_coefficients(design, dict(spec.fixed))
    ds = frequency_response(base, spec.values, response_policy(design, spec), spec.jump_threshold, spec.jump_floor)
    ds.attrs.update(
        {
            "response": spec.name,
            "design": spec.design,
            "fixed_overrides": ",".join(f"{k}={v:g}" for k, v in spec.fixed) or "none",
            "speed_per_w_rpm": float(base.omega_n) * 60.0 / (2.0 * math.pi * _annulus_teeth(design)),
        }
    )
    return ds


def _annulus_teeth(design: KHVDesign) -> int:
    phys, _, _ = point.point_model(design)
    return int(phys.z_annulus)
