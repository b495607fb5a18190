"""The one study runner: sweeps, maps, frequency responses and point runs are layouts of it.

A :class:`Layout` says what one run computes (its lines, each point's index, its own variables); :func:`run`
labels the lines and stores every point's verdict and response measures (``docs/classify.md``, Studies).
"""

from __future__ import annotations

import dataclasses
import logging
import time
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, NamedTuple, Protocol, Self, TypeVar

import numpy as np

from geardyn import label  # label.label_lines on first use: the workflow's DAG reads the specs without the solver
from geardyn.jsontypes import Json
from geardyn.khv import point
from geardyn.khv.design import KHVDesign, resolve_fractions
from geardyn.label import Policy, Verdict, vocabulary
from geardyn.label.compare import same
from geardyn.label.policy import Same
from geardyn.runs.cube import COMMON, RESPONSE, VERDICT, VERDICT_FIELDS, empty
from geardyn.solve import SimulationSettings, System
from geardyn.solve.response import IMPACT_CLASSES, ResponseMeasures

if TYPE_CHECKING:  # for the annotations only
    import xarray as xr

log = logging.getLogger("geardyn.study")

#: A point's place in the arrays of its study.
Index = tuple[int, ...]


class Chunked(Protocol):
    """A study whose points are computed in chunks (a sweep, a map, a probabilities study)."""

    name: str

    @property
    def n_chunks(self) -> int: ...


#: Variables as :class:`xarray.Dataset` takes them: name -> (dims, array, attributes).
Variables = dict[str, tuple[Json, ...]]


def _pairs(spec: Mapping[str, Json], key: str) -> tuple[tuple[str, Json], ...]:
    return tuple(sorted((spec.get(key) or {}).items()))


@dataclass(frozen=True, kw_only=True)
class StudySpec:
    """What every study of ``config.yaml`` declares (a sweep, a map, a frequency response); a study's own spec
    adds its grid (:meth:`own_fields`).  ``fixed``: overrides held at every point; ``chunks``: the jobs asked
    for; ``integration``: changes to the design's integration settings; ``classifier``, ``start_from`` and
    ``coexistence``: the labelling policy's (:meth:`geardyn.label.Policy.from_spec`)."""

    name: str
    design: str
    fixed: tuple[tuple[str, float], ...] = ()
    chunks: int = 1
    integration: tuple[tuple[str, Json], ...] = ()
    classifier: tuple[tuple[str, Json], ...] = ()
    start_from: str = "follow"
    coexistence: bool = False

    @classmethod
    def from_config(cls, name: str, spec: Mapping[str, Json], design: str, segment: tuple[float, float]) -> Self:
        """The study ``name`` of the config for ``design``, whose admissible segment (x1_min, x1_max)
        resolves percentages of x1 (:func:`geardyn.khv.design.resolve_fractions`)."""
        spec = resolve_fractions(spec, segment)
        return cls(
            name=name,
            design=design,
            fixed=_pairs(spec, "fixed"),
            chunks=int(spec.get("chunks", 1)),
            integration=_pairs(spec, "integration"),
            classifier=_pairs(spec, "classifier"),
            start_from=spec.get("start_from", "follow"),
            coexistence=bool(spec.get("coexistence", False)),
            **cls.own_fields(spec),
        )

    @classmethod
    def own_fields(cls, spec: Mapping[str, Json]) -> dict[str, Json]:
        """The fields of a study's own spec that its config entry (percentages resolved) sets: those of type
        ``float``, ``int`` or ``str`` converted to it (a study converts its others itself)."""
        convert: dict[Json, Callable[[Json], Json]] = {"float": float, "int": int, "str": str}
        common = {f.name for f in dataclasses.fields(StudySpec)}
        own = [f for f in dataclasses.fields(cls) if f.name not in common and f.type in convert and f.name in spec]
        return {f.name: convert[f.type](spec[f.name]) for f in own}

    def policy(self, design: KHVDesign) -> Policy:
        """The labelling policy: the design's integration with the study's changes, its classifier settings,
        start and coexistence."""
        return Policy.from_spec(
            point.integration_settings(design, **dict(self.integration)),
            {"classifier": dict(self.classifier), "start_from": self.start_from, "coexistence": self.coexistence},
        )

    @property
    def fixed_overrides(self) -> str:
        return point.override_text(self.fixed)


class Grid:
    """The ``values`` of a study's axis: ``num`` values from ``start`` to ``stop``, both included (the fields
    of the dataclass that takes it)."""

    @property
    def values(self) -> np.ndarray:
        return np.linspace(self.start, self.stop, self.num)  # type: ignore[attr-defined]


@dataclass
class Layout:
    """What one run of a study computes.

    ``lines``: the lines of points, each point its index in the arrays and its system; consumed once, by
    :func:`run` (which times building them).  ``dims`` and ``shape``: of the per-point arrays.  Which common
    variables the study keeps: ``transient`` (``transient_used``) and ``computed`` (a chunk's flag of the points it
    holds).  ``own``: the study's own per-point variables, written by ``store_own(arrays, index, system,
    verdict)``.  ``starts``: each line's start (None: the static deflection; :func:`geardyn.label.label_lines`)."""

    dims: tuple[str, ...]
    shape: tuple[int, ...]
    lines: Iterable[Sequence[tuple[Index, System]]]
    transient: bool = True
    computed: bool = False
    own: Variables = field(default_factory=dict)
    store_own: Callable[[dict[str, np.ndarray], Index, System, Verdict], None] | None = None
    starts: Sequence[np.ndarray | None] | None = None


class Result(NamedTuple):
    """A run's variables (filled), its verdicts (line by line, in the order of travel), its wall time and the file
    attributes its systems decide (:func:`damping_attrs`)."""

    data: Variables
    verdicts: list[list[Verdict]]
    wall_time_s: float
    attrs: dict[str, Json]


#: A line's kind of system (``damped`` hands back the line it was given).
S = TypeVar("S", bound=System)

#: What a file of points without damping says (``docs/classify.md``, "Systems without damping").
UNDAMPED_NOTE = (
    "no damping in any mode (zeta = eta = 0): the Poincare map preserves phase volume, so there are no attractors; "
    "each label describes the single orbit run from that point's start (an island's cycle, an invariant circle or "
    "a chaotic sea), and a line's points start from the previous point's final state, so they describe the orbits "
    "through that state, not the only motion at those parameters"
)


def undamped(system: System) -> bool:
    """Whether ``system`` has no damping in any mode (mesh and both shafts: c_m = c_DH = c_VL = 0)."""
    return system.c_m == 0.0 and system.c_DH == 0.0 and system.c_VL == 0.0


def damping_attrs(systems: Iterable[System]) -> dict[str, Json]:
    """The file attributes of a study's points: ``undamped`` 1 where every point has no damping in any mode (with
    ``undamped_note``, :data:`UNDAMPED_NOTE`), else 0."""
    if all(map(undamped, systems)):
        return {"undamped": 1, "undamped_note": UNDAMPED_NOTE}
    return {"undamped": 0}


def damped(line: list[tuple[Index, S]], what: str) -> list[tuple[Index, S]]:
    """``line`` unchanged, or one line of refusal where a point has no damping in any mode: a study that needs
    attractors (basin stability) has none to count there."""
    for idx, system in line:
        if undamped(system):
            raise ValueError(
                f"{what}: point {idx} has c_m = c_DH = c_VL = 0 (zeta = eta = 0); allowed: damping > 0 in some mode "
                "(without damping the Poincare map preserves volume: no attractors, no basin stability)"
            )
    return line


def variables(layout: Layout, policy: Policy) -> Variables:
    """The empty per-point variables of a study (:func:`geardyn.runs.cube.empty`): the verdict's and the response
    measures, the fixed start's label and the ``coexisting`` flag with the policy's ``coexistence``, the
    layout's own, ``transient_used`` and ``computed``, as the layout keeps them."""
    dims, shape = layout.dims, layout.shape
    names = [*COMMON, *(("label_fixed", "coexisting") if policy.coexistence else ())]
    data = {**empty(names, dims, shape, policy.classifier.max_n), **layout.own}
    tail = [name for name, keep in (("transient_used", layout.transient), ("computed", layout.computed)) if keep]
    return data | empty(tail, dims, shape)


def store(
    arrays: dict[str, np.ndarray],
    idx: Index,
    v: Verdict,
    r: ResponseMeasures,
    fixed: Verdict | None,
    tol: Same = Same(),
) -> None:
    """Write one point into the arrays of :func:`variables`: its verdict, its response measures, with ``fixed``
    (policy ``coexistence``) the fixed start's label and whether the two differ (tolerances ``tol``), and the
    transient and computed flag where the study keeps them."""
    a = arrays
    a["label"][idx] = v.label
    for name, attr in VERDICT_FIELDS.items():
        value = getattr(v, attr)
        a[name][idx] = VERDICT[name].flags[value] if isinstance(value, str) else value  # type: ignore[index]  # flags
    for name in RESPONSE:
        a[name][idx] = getattr(r, name)
    a["impact_class"][idx] = IMPACT_CLASSES.get(r.impact_class, vocabulary.NOT_COMPUTED)
    if fixed is not None:
        a["label_fixed"][idx], a["coexisting"][idx] = fixed.label, int(not same(v, fixed, tol))
    for name, value in (("transient_used", v.transient_used), ("computed", 1)):
        if name in a:
            a[name][idx] = value


def line_responses(verdicts: Sequence[Sequence[Verdict]]) -> list[list[ResponseMeasures]]:
    """The response measures of every point of labelled lines: those the labeller summed in its own runs
    (:attr:`geardyn.label.Verdict.response`: over one cycle of a periodic verdict from its final state, over
    the last recorded periods of the record that ends at it otherwise; not computed where it saw divergence)."""
    out = [[v.response for v in vs] for vs in verdicts]
    if any(r is None for rs in out for r in rs):
        raise ValueError("a verdict without its response measures")
    return out  # type: ignore[return-value]


def run(layout: Layout, policy: Policy, progress: str = "") -> Result:
    """Label the layout's lines by ``policy`` (and from the fixed start too with its ``coexistence``), with the
    verdicts' response measures, and store every point (:func:`store`, then the layout's ``store_own``).
    ``progress``: a name for the log."""
    t0 = time.perf_counter()
    points = list(layout.lines)
    lines = [[system for _, system in line] for line in points]
    data = variables(layout, policy)
    verdicts = label.label_lines(lines, policy, layout.starts, progress=progress)
    fixed = label.label_lines(lines, policy.with_start("fixed")) if policy.coexistence else None
    responses = line_responses(verdicts)
    arrays = {name: var[1] for name, var in data.items()}
    for k, line in enumerate(points):
        for m, (idx, system) in enumerate(line):
            store(arrays, idx, verdicts[k][m], responses[k][m], None if fixed is None else fixed[k][m], policy.same)
            if layout.store_own is not None:
                layout.store_own(arrays, idx, system, verdicts[k][m])
    el, n = time.perf_counter() - t0, sum(map(len, lines))
    log.info("%s: %d points in %.1f s (%.2f ms/point)", progress, n, el, 1e3 * el / max(1, n))
    return Result(data, verdicts, el, damping_attrs(s for line in lines for s in line))


def integration_attrs(settings: SimulationSettings) -> dict[str, Json]:
    """Attributes recording the integration of a study's runs."""
    return {
        k: getattr(settings, k) for k in ("integrator", "steps_per_period", "transient_periods", "recorded_periods")
    }


def study_attrs(policy: Policy) -> dict[str, Json]:
    """Attributes recording how the points were labelled: the integration, start, coexistence, transients,
    early stop, the classifier and the growth test's settings."""
    s, p = policy.integration, policy
    return {
        **integration_attrs(s),
        **{"start": p.start, "coexistence": int(p.coexistence), "follow_transient_periods": p.follow_transient_periods},
        **{"newton_tol": p.newton_tol, "stability_margin": p.stability_margin, "early_stop": int(s.early_stop)},
        **{k: getattr(s, k) for k in ("early_stop_min_periods", "early_stop_confirm", "early_stop_tol_factor")},
        **{f"classifier_{k}": v for k, v in dataclasses.asdict(p.classifier).items()},
        **{f"growth_{k}": v for k, v in dataclasses.asdict(p.growth).items()},
    }


def write_chunk(
    ds: xr.Dataset, drive: KHVDesign, spec: Chunked, chunk: int, key: str, raw: Mapping[str, Json], path: str
) -> None:
    """Write chunk ``chunk`` of the study ``spec`` (its config entry ``raw`` under ``key``) with its provenance and
    Fletcher-32 checksums (a damaged chunk is found before its merge)."""
    from geardyn import io  # noqa: PLC0415 - netCDF: only the jobs that write
    from geardyn.io import provenance  # noqa: PLC0415

    attrs = provenance.attributes(
        title=f"{spec.name} chunk {chunk}",
        paper=drive.paper,
        config={"design": drive.raw, key: raw},
        model_variant=drive.stiffness.label,
        extra={"chunk": chunk, "n_chunks": spec.n_chunks},
    )
    io.write_netcdf(ds, path, attrs, checksum=True)
