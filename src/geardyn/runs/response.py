"""The frequency response of a KHV design: the response measures against the mesh frequency w, swept up and
down as two lines of the labeller (``start_from: follow``), with hysteresis (the two sweeps end on different
attractors, :func:`different_attractors`), jumps (:func:`find_jumps`) and the RMS values' standard errors.

Definitions and what the shipped designs show: ``docs/response.md``.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import xarray as xr

from geardyn import io
from geardyn.io import Var
from geardyn.jsontypes import Json
from geardyn.khv import point
from geardyn.khv.design import KHVDesign
from geardyn.khv.model import COEFFICIENT_ATTRS, Coefficients, natural_frequencies
from geardyn.label import Policy, Verdict
from geardyn.label.compare import same, same_attractor
from geardyn.label.vocabulary import LABELS
from geardyn.runs import cube, study
from geardyn.solve.base import Lane, System
from geardyn.solve.response import RMS_BLOCKS, rms_errors_many
from geardyn.solve.run import simulate_batch

DIRECTIONS = ("up", "down")

#: Mesh periods two non-periodic verdicts that the labeller's comparison separates are integrated on, at
#: most, in pieces of :data:`CONTINUE_PIECE`, before they count as two attractors (:func:`different_attractors`;
#: the slow escapes below the Neimark-Sacker bifurcation that set it: ``docs/response.md``).
CONTINUE_PERIODS = 40000
CONTINUE_PIECE = 1000


@dataclass(frozen=True)
class ResponseSpec(study.StudySpec, study.Grid):
    """One frequency response as declared in ``config.yaml`` under ``responses:`` (the shared fields:
    :class:`StudySpec`; a response follows the attractor, ``start_from: follow``, in one job).  Its limits are the
    config schema's (0 < start < stop, num >= 3, jump_threshold > 0, jump_floor >= 0; :func:`frequency_response`
    refuses a grid that does not ascend)."""

    start: float
    stop: float
    num: int
    jump_threshold: float = 0.25
    jump_floor: float = 0.05


def find_jumps(
    rms: np.ndarray, threshold: float, floor: float, split: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Jumps of the up and down RMS-DTE curves ``rms`` (2, n) on one ascending grid: ``(jump, split)``, ``jump``
    (2, n) on the higher point of a step |a - b| > threshold max(a, b, floor) where the sweeps are ``split`` (n,;
    default: where the two curves differ so) at one of its two points (``docs/response.md``, Jumps)."""
    rms = np.asarray(rms, dtype=float)
    if rms.ndim != 2 or rms.shape[0] != 2:
        raise ValueError("find_jumps: rms must be (2, n): the up and the down curve")
    rms = np.where(np.isfinite(rms), rms, 0.0)

    def differ(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        return np.abs(a - b) > threshold * np.maximum(np.maximum(a, b), floor)

    if split is None:
        split = differ(rms[0], rms[1])
    else:
        split = np.asarray(split, dtype=bool)
        if split.shape != rms.shape[1:]:
            raise ValueError("find_jumps: split must be (n,): one flag per frequency")
    jump = np.zeros(rms.shape, dtype=bool)
    jump[:, 1:] = differ(rms[:, 1:], rms[:, :-1]) & (split[1:] | split[:-1])
    return jump, split


def different_attractors(
    systems: Sequence[System],
    up: list[Verdict],
    down: list[Verdict],
    policy: Policy,
    continue_periods: int = CONTINUE_PERIODS,
) -> tuple[np.ndarray, np.ndarray]:
    """Where the up and down sweeps (verdicts in ascending order at ``systems``) end on different attractors by
    :func:`geardyn.label.compare.same`, two non-periodic verdicts of one label (or one of them a record that shows
    no attractor: transient or undetermined, compared as the other's label) integrated on and compared again
    up to ``continue_periods`` (``docs/response.md``, Hysteresis).  Returns ``(differ, continued)`` (n,): the
    flags, and the periods integrated on before the records agreed (all where they never did; 0: not)."""
    n = len(systems)
    differ = np.array([not same(a, b) for a, b in zip(up, down, strict=True)])
    continued = np.zeros(n, np.int64)
    todo = [j for j in map(int, np.flatnonzero(differ)) if _integrate_on(up[j], down[j])]
    # a record that shows no attractor (transient, undetermined) is compared as the other sweep's label
    labels = {j: down[j].label if up[j].label in _NO_ATTRACTOR else up[j].label for j in todo}
    keep = max(1, policy.integration.recorded_periods)
    piece = max(CONTINUE_PIECE, keep)
    settings = dataclasses.replace(policy.integration, transient_periods=piece - keep, recorded_periods=keep)
    states = {j: (up[j].final_state, down[j].final_state) for j in todo}
    while todo and continue_periods > 0 and continued[todo[0]] < continue_periods:
        runs = simulate_batch([Lane(systems[j], y) for j in todo for y in states[j]], settings)
        left = []
        for k, j in enumerate(todo):
            ra, rb = runs[2 * k], runs[2 * k + 1]
            continued[j] += piece
            if ra.diverged or rb.diverged:
                continue  # one of them leaves the bounded region: two different ends
            if same_attractor(labels[j], ra.poincare, labels[j], rb.poincare):
                differ[j] = False
            else:
                states[j] = (ra.final_state, rb.final_state)
                left.append(j)
        todo = left
    return differ, continued


#: The labels of records that show no attractor: a growing record (``transient``) and an undetermined one.
_NO_ATTRACTOR = (LABELS["transient"], LABELS["undetermined"])


def _integrate_on(a: Verdict, b: Verdict) -> bool:
    """Whether two verdicts the comparison separates are integrated on before they count as two attractors: both
    non-periodic and bounded, of one label or one of them showing no attractor (:data:`_NO_ATTRACTOR`)."""
    if a.periodic or b.periodic or a.diverged or b.diverged:
        return False
    return a.label == b.label or a.label in _NO_ATTRACTOR or b.label in _NO_ATTRACTOR


def jump_frequencies(w: np.ndarray, flags: np.ndarray, direction: str) -> np.ndarray:
    """The frequencies of a line's jumps: the mid-points of the flagged steps, in the order of travel."""
    j = np.flatnonzero(flags)
    mids = 0.5 * (w[j] + w[j - 1])
    return mids if direction == "up" else mids[::-1]


def rms_error_variables(systems: Sequence[System], verdicts: list[list[Verdict]], policy: Policy) -> dict[str, Json]:
    """The standard errors of ``dte_rms`` and ``force_rms`` (dims direction x w; ``verdicts`` of both sweeps in
    ascending order, at ``systems``): 0 where periodic, NaN where diverged, else the batch-means error of the
    record whose sums gave them (:func:`geardyn.solve.response.rms_errors_many`, ``docs/response.md``)."""
    shape = (len(verdicts), len(systems))
    dte, force = np.full(shape, np.nan), np.full(shape, np.nan)
    todo = []
    for d, vs in enumerate(verdicts):
        for j, v in enumerate(vs):
            if v.periodic:
                dte[d, j] = force[d, j] = 0.0
            elif not v.diverged:
                todo.append((d, j))
    chosen = [verdicts[d][j] for d, j in todo]
    errors = rms_errors_many(
        [systems[j] for _, j in todo],
        [v.poincare for v in chosen],
        [v.response for v in chosen],  # type: ignore[misc]  # a bounded run's verdict has its measures
        policy.integration,
    )
    for (d, j), e in zip(todo, errors, strict=True):
        dte[d, j], force[d, j] = e.dte_rms_error, e.force_rms_error
    how = (
        f"batch means over {RMS_BLOCKS} blocks of whole mesh periods of the very record the RMS is summed over, at a "
        "non-periodic point; 0 for a periodic one, averaged over one whole cycle"
    )
    dims = ("direction", "w")
    table = [Var(f"{k}_rms_error", dims, "1", f"standard error of {k}_rms ({how})") for k in ("dte", "force")]
    return io.variables(table, (dte, force))


def variables(threshold: float, floor: float, continue_periods: int) -> tuple[Var, ...]:
    """The variables of a frequency response besides the study's per-point ones and the RMS values' standard
    errors (:func:`rms_error_variables`), and its coordinates; ``threshold``, ``floor``: of the jumps."""
    jump = (
        f"a jump: the RMS DTE steps by more than {threshold:g} x max(its two values, {floor:g}) from the next "
        "lower frequency of the same line, where the up and down sweeps end on different attractors at one of "
        "the two frequencies"
    )
    split = (
        "the up and down sweeps end on different attractors: other labels, or Poincare sets apart by more than "
        "the labeller's tolerance (geardyn.label.compare), two non-periodic ones still after integrating both on "
        "(hysteresis_continued_periods)"
    )
    continued = (
        "mesh periods two non-periodic verdicts the labeller's comparison separates were integrated on before "
        f"their Poincare sets agreed (at most {continue_periods}: still different); 0: not integrated on"
    )
    final = "state at phase 0 on the attractor at the end of the record (a restart)"
    return (
        Var("final_state", ("direction", "w", "state"), "1", final),
        Var("jump", ("direction", "w"), None, jump, {"smooth": 0, "jump": 1}),
        Var("hysteresis", "w", None, split, {"same": 0, "different": 1}),
        Var("hysteresis_continued_periods", "w", "1", continued, dtype=np.int32),
        Var("natural_frequency", "mode", "1", "undamped natural frequency of the linearised system in contact / w_n"),
        Var("direction", "direction", None, "sweep direction (line of the labeller)"),
        Var("w", "w", "1", "dimensionless mesh frequency w_m / w_n"),
        Var("state", "state", None, "state component (geardyn.runs.cube.STATE_NAMES)"),
        Var("mode", "mode", "1", "mode number", dtype=np.int32),
        Var("mesh_frequency_hz", "w", "Hz", "mesh frequency w_m / (2 pi)"),
    )


def frequency_response(
    base: Coefficients,
    w: np.ndarray,
    policy: Policy,
    threshold: float,
    floor: float,
    continue_periods: int = CONTINUE_PERIODS,
) -> xr.Dataset:
    """Label and measure ``base`` at every mesh frequency of ``w`` (ascending), swept up and down;
    ``continue_periods``: of :func:`different_attractors`."""
    w = np.asarray(w, dtype=float)
    if w.ndim != 1 or w.size < 3 or not np.all(np.diff(w) > 0.0):
        raise ValueError("frequency response: w must be an ascending grid of at least 3 frequencies")
    dims, n = ("direction", "w"), w.size
    up = [base.replace(omega=float(v)) for v in w]
    lines = [[((0, j), s) for j, s in enumerate(up)], [((1, j), up[j]) for j in reversed(range(n))]]
    data, verdicts, _, damping = study.run(study.Layout(dims, (2, n), lines), policy, "frequency response")
    ordered = [verdicts[0], verdicts[1][::-1]]  # both sweeps in ascending w
    final = np.array([[v.final_state for v in vs] for vs in ordered], dtype=float)
    data["dte_rms"][2]["ancillary_variables"] = "dte_rms_error"
    data["force_rms"][2]["ancillary_variables"] = "force_rms_error"
    differ, continued = different_attractors(up, ordered[0], ordered[1], policy, continue_periods)
    jumps, split = find_jumps(data["dte_rms"][1], threshold, floor, differ)
    nat = natural_frequencies(base)
    values: dict[str, object] = {
        "final_state": final,
        "jump": jumps,
        "hysteresis": split,
        "hysteresis_continued_periods": continued,
    }
    values |= {"natural_frequency": nat, "direction": list(DIRECTIONS), "w": w, "state": list(cube.STATES)}
    values |= {"mode": np.arange(nat.size), "mesh_frequency_hz": w * base.omega_n / (2.0 * math.pi)}
    own = io.variables(variables(threshold, floor, continue_periods), values)
    coords = {k: own.pop(k) for k in ("direction", "w", "state", "mode", "mesh_frequency_hz")}
    data |= {"final_state": own.pop("final_state"), **rms_error_variables(up, ordered, policy), **own}
    attrs = {
        "jump_threshold": threshold,
        "jump_floor": floor,
        "hysteresis_continue_periods": continue_periods,
        "rms_error_blocks": RMS_BLOCKS,
        "jumps_up": ",".join(f"{v:.4g}" for v in jump_frequencies(w, jumps[0], "up")) or "none",
        "jumps_down": ",".join(f"{v:.4g}" for v in jump_frequencies(w, jumps[1], "down")) or "none",
        **study.study_attrs(policy),
        **damping,
        **{f"coef_{k}": v for k, v in base.as_dict().items() if k in COEFFICIENT_ATTRS and k != "omega"},
    }
    return xr.Dataset(data, coords=coords, attrs=attrs)


def run(design: KHVDesign, spec: ResponseSpec) -> xr.Dataset:
    """The frequency response of ``design`` at its point (with the study's fixed overrides)."""
    base = point.point_coefficients(design, dict(spec.fixed))
    ds = frequency_response(base, spec.values, spec.policy(design), spec.jump_threshold, spec.jump_floor)
    teeth = int(point.point_model(design)[0].z_annulus)
    ds.attrs.update(
        response=spec.name,
        design=spec.design,
        fixed_overrides=spec.fixed_overrides,
        speed_per_w_rpm=float(base.omega_n) * 60.0 / (2.0 * math.pi * teeth),
    )
    return ds
