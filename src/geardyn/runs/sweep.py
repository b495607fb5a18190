"""Parameter sweeps: bifurcation cubes of one control parameter for one or more cases (fixed overrides), in
chunks that run in any order, anywhere, each a layout of :mod:`geardyn.runs.study` holding whole lines (``start_from:
follow``) or contiguous points (``fixed``), so no result depends on the chunking."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import xarray as xr

from geardyn import io
from geardyn.io import Var
from geardyn.jsontypes import Json
from geardyn.khv import point
from geardyn.khv.design import KHVDesign
from geardyn.khv.model import COEFFICIENT_ATTRS
from geardyn.label import Policy, Verdict
from geardyn.runs import study
from geardyn.runs.cube import STATE_NAMES, STATES, empty
from geardyn.solve import System

#: The lines of a sweep: (case index, direction index, parameter indices in the order of travel).
Work = list[tuple[int, int, list[int]]]


@dataclass(frozen=True)
class SweepSpec(study.StudySpec, study.Grid):
    """One sweep as declared in ``config.yaml`` under ``sweeps:`` (the shared fields: :class:`StudySpec`)."""

    parameter: str
    start: float
    stop: float
    num: int
    cases: tuple[tuple[tuple[str, float], ...], ...] = ((),)
    continuation: str = "none"

    @classmethod
    def own_fields(cls, spec: Mapping[str, Json]) -> dict[str, Json]:
        """:meth:`StudySpec.own_fields` and the cases (each a tuple of sorted overrides; one without)."""
        return {**super().own_fields(spec), "cases": tuple(tuple(sorted(c.items())) for c in spec.get("cases") or [{}])}

    @property
    def directions(self) -> tuple[str, ...]:
        return ("up", "down") if self.continuation == "both" else (self.continuation,)

    @property
    def n_lines(self) -> int:
        return len(self.cases) * len(self.directions)

    @property
    def n_chunks(self) -> int:
        """Number of chunk jobs: the configured count, at most one per line (``follow``) or per point."""
        return max(1, min(self.chunks, self.n_lines if self.start_from == "follow" else self.n_lines * self.num))

    def case_label(self, i: int) -> str:
        return point.override_text(self.cases[i], "base")


def chunk_work(spec: SweepSpec, chunk: int) -> Work:
    """Which points chunk ``chunk`` (0-based) computes; deterministic and covering each point once.  With
    ``start_from: follow`` a chunk holds whole lines (case, direction), each in its direction's order."""
    if not 0 <= chunk < spec.n_chunks:
        raise ValueError(f"chunk {chunk} outside 0..{spec.n_chunks - 1} for sweep {spec.name}")
    nd = len(spec.directions)
    if spec.start_from == "follow":
        whole = [divmod(int(line), nd) for line in np.array_split(np.arange(spec.n_lines), spec.n_chunks)[chunk]]
        return [(case, d, list(range(spec.num))[:: -1 if spec.directions[d] == "down" else 1]) for case, d in whole]
    lines: dict[int, list[int]] = {}  # the chunk's points of each line, in order
    for i in np.array_split(np.arange(spec.n_lines * spec.num), spec.n_chunks)[chunk]:
        lines.setdefault(int(i) // spec.num, []).append(int(i) % spec.num)
    return [(*divmod(line, nd), idx) for line, idx in lines.items()]


def point_overrides(spec: SweepSpec, case: int, value: float) -> dict[str, float]:
    """Overrides of one point: fixed values, then the case's, then the swept parameter."""
    return {**dict(spec.fixed), **dict(spec.cases[case]), spec.parameter: float(value)}


def layout(design: KHVDesign, spec: SweepSpec, chunk: int, policy: Policy) -> study.Layout:
    """The lines of chunk ``chunk`` on the cube (case, direction, parameter), and the sweep's own per-point
    variables: the Poincare sections (the recorded periods) and the point's coefficients."""
    dims, shape = ("case", "direction", spec.parameter), (len(spec.cases), len(spec.directions), spec.num)
    ns = policy.integration.recorded_periods
    sections = [Var(name, (*dims, "section"), "1", f"Poincare section: {STATE_NAMES[name]}") for name in STATES]
    own = {v.name: v.empty((*shape, ns)) for v in sections} | empty(("diverged_period", "n_events"), dims, shape)
    own |= {f"coef_{k}": Var(f"coef_{k}", dims, *cf).empty(shape) for k, cf in COEFFICIENT_ATTRS.items()}
    values = spec.values
    lines = (
        [((case, d, j), point.point_coefficients(design, point_overrides(spec, case, values[j]))) for j in order]
        for case, d, order in chunk_work(spec, chunk)
    )
    return study.Layout(dims, shape, lines, computed=True, own=own, store_own=_store)


def _store(arrays: dict[str, np.ndarray], idx: study.Index, system: System, v: Verdict) -> None:
    ns = arrays[STATES[0]].shape[-1]
    p = v.poincare[max(0, v.poincare.shape[0] - ns) :]  # the newest the axis holds (a diverged run: its whole record)
    for k, name in enumerate(STATES):
        arrays[name][(*idx, slice(0, p.shape[0]))] = p[:, k]  # type: ignore[index]  # numpy takes the mixed tuple
    arrays["diverged_period"][idx] = v.diverged_period
    arrays["n_events"][idx] = v.n_events
    values = system.as_dict()
    for cname in COEFFICIENT_ATTRS:
        arrays[f"coef_{cname}"][idx] = float(values[cname])


def run_chunk(design: KHVDesign, spec: SweepSpec, chunk: int) -> xr.Dataset:
    """Label the points of one chunk: a cube of every point of the sweep, NaN (float) / -1 (int) where the
    chunk did not compute, ``computed`` 1 where it did, with CF attributes."""
    policy = spec.policy(design)
    result = study.run(layout(design, spec, chunk, policy), policy, f"{spec.name} chunk {chunk}")
    data = result.data
    first = (*STATES, "diverged_period", "n_events", "transient_used")  # the cube's order of variables
    data = {**{name: data[name] for name in first}, **data}
    coords = (
        Var("case", "case", None, "case (fixed overrides)"),
        Var("direction", "direction", None, "continuation direction of the sweep"),
        Var(spec.parameter, spec.parameter, *point.CONTROLS.get(spec.parameter, ("1", spec.parameter))),
        Var(
            "section", "section", "1", "index of the recorded mesh period (Poincare section at phase 0)", dtype=np.int32
        ),
    )
    cases = [spec.case_label(i) for i in range(len(spec.cases))]
    values = (cases, list(spec.directions), spec.values, np.arange(policy.integration.recorded_periods))
    attrs = {
        "sweep": spec.name,
        "design": spec.design,
        "control_parameter": spec.parameter,
        "divergence_threshold": policy.integration.divergence_threshold,
        "continuation": spec.continuation,
        **study.study_attrs(policy),
        **result.attrs,
        "fixed_overrides": spec.fixed_overrides,
    }
    return xr.Dataset(data, coords=io.variables(coords, values), attrs=attrs)
