"""Regime probabilities under uncertain inputs (``docs/probabilities.md``): the inputs drawn by scrambled Sobol'
sampling (or, where a study asks for Sobol' indices, by Saltelli's design), each sample a line along the study's axis
that the one study runner labels as a layout, so each sample follows its attractor as a sweep does. A chunk holds whole
samples, so no result depends on the chunking; the statistics of the merged cube are
:mod:`geardyn.runs.probability_stats`'s."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import xarray as xr

from geardyn.gears import geometry
from geardyn.gears import tolerances as flank
from geardyn.io import Var
from geardyn.jsontypes import Json
from geardyn.khv import point
from geardyn.khv.design import KHVDesign
from geardyn.khv.model import Coefficients
from geardyn.label import Policy
from geardyn.runs import study
from geardyn.runs.cube import STATES
from geardyn.runs.maps import Axis

#: The operating conditions (the mesh frequency, the input speed, the torques): an axis or a fixed value of a
#: study, drawn as an input only where its config marks it ``operating: true`` (a share of the box, not a
#: probability over a drive's unknowns).
OPERATING = ("w", "speed", "T_D", "T_L")
#: The initial state as uncertain inputs: its offsets from the static deflection (units of b_c).
START_INPUTS = tuple(f"start_{s}" for s in STATES)


@dataclass(frozen=True)
class Input:
    """One uncertain input: an override (a control or a model parameter, in its override units) uniform on
    [low, high] (``log``: its logarithm uniform) or, with ``std`` > 0, a normal of ``mean`` truncated to
    [low, high]; ``source``: where its range comes from; ``operating``: an operating condition drawn on purpose
    (:data:`OPERATING`)."""

    name: str
    low: float
    high: float
    log: bool = False
    mean: float = math.nan
    std: float = 0.0
    source: str = ""
    operating: bool = False

    def values(self, u: np.ndarray) -> np.ndarray:
        """The input's values at the unit-cube coordinates ``u``: the inverse distribution function of its frozen
        ``scipy.stats`` distribution (``truncnorm``, ``loguniform`` or ``uniform``)."""
        from scipy import stats  # noqa: PLC0415 - scipy.stats: only the jobs that sample

        if self.std > 0.0:
            a, b = (self.low - self.mean) / self.std, (self.high - self.mean) / self.std
            dist = stats.truncnorm(a, b, loc=self.mean, scale=self.std)
        elif self.log:
            dist = stats.loguniform(self.low, self.high)
        else:
            dist = stats.uniform(self.low, self.high - self.low)
        return np.asarray(dist.ppf(u), dtype=float)

    @property
    def text(self) -> str:
        """``zeta uniform on [0.03, 0.15] (source)``."""
        if self.std > 0.0:
            what = f"normal {self.mean:.4g} +- {self.std:.4g} truncated to [{self.low:.4g}, {self.high:.4g}]"
        else:
            what = f"{'log-' if self.log else ''}uniform on [{self.low:.4g}, {self.high:.4g}]"
        source = "; ".join(s for s in (self.source, "operating condition: a share of the box" * self.operating) if s)
        return f"{self.name} {what}" + (f" ({source})" if source else "")


def distribution(name: str, spec: Mapping[str, Json], nominal: float) -> Input:
    """The input ``name`` of an entry of a study's ``inputs``: ``tolerance`` or ``relative_tolerance`` (uniform on
    the ``nominal`` value, the design's at the study's point, +- it), ``std`` (a normal of ``mean``, default the
    nominal value, truncated to ``low`` and ``high``, default 3 std from the mean) or ``low`` and ``high``
    (uniform; ``scale: log``: log-uniform); ``operating: true``: an operating condition drawn on purpose."""
    if spec.get("operating"):
        return dataclasses.replace(
            distribution(name, {k: v for k, v in spec.items() if k != "operating"}, nominal), operating=True
        )
    if "tolerance" in spec or "relative_tolerance" in spec:
        tol = float(spec["tolerance"]) if "tolerance" in spec else abs(nominal) * float(spec["relative_tolerance"])
        return Input(name, nominal - tol, nominal + tol, source=f"design value {nominal:.4g} +- {tol:.4g}")
    if "std" in spec:
        mean, std = float(spec.get("mean", nominal)), float(spec["std"])
        low, high = float(spec.get("low", mean - 3.0 * std)), float(spec.get("high", mean + 3.0 * std))
        return Input(name, low, high, mean=mean, std=std)
    return Input(name, float(spec["low"]), float(spec["high"]), spec.get("scale") == "log")


def tolerance_inputs(design: KHVDesign, tolerances: Mapping[str, Json]) -> list[Input]:
    """The inputs of a tolerance class (``docs/probabilities.md``): e uniform on [0, e_max], e_max half the band
    of both gears' ``te_tolerance`` of ISO 1328-1:2013 class ``grade`` added by ``combine``
    (:func:`geardyn.gears.tolerances.te_amplitude_bound`); the TE phase uniform on [0, 2 pi) (no class fixes it);
    b uniform on the stated ``backlash`` range (um) or, without one, on the range of
    ``tooth_thickness_allowances`` and ``centre_distance_allowance``
    (:func:`geardyn.gears.tolerances.backlash_range`); neither: b not drawn."""
    pair, grade = design.base, int(tolerances["grade"])
    which, combine = tolerances.get("te_tolerance", "profile"), tolerances.get("combine", "rss")
    e_max = flank.te_amplitude_bound(grade, pair.z1, pair.z2, pair.module, which, combine)
    name = {"profile": "total profile tolerance F_aT (formula 9)", "single_pitch": "single pitch tolerance f_pT (5)"}
    out = [
        Input(
            "e",
            0.0,
            e_max,
            source=f"half the {combine} band of both gears' {name[which]}, ISO 1328-1:2013 class {grade}",
        ),
        Input("te_phase", 0.0, 2.0 * math.pi, source="the TE phase, which no tolerance class fixes"),
    ]
    if "backlash" in tolerances:
        low, high = tolerances["backlash"]
        out.append(Input("b", float(low), float(high), source="the stated backlash range"))
    elif "tooth_thickness_allowances" in tolerances:
        (u1, l1), (u2, l2) = tolerances["tooth_thickness_allowances"]
        working = math.degrees(float(geometry.working_pressure_angle(pair)))
        low, high = flank.backlash_range(
            ((u1, l1), (u2, l2)),
            float(tolerances.get("centre_distance_allowance", 0.0)),
            pair.pressure_angle_deg,
            working,
        )
        out.append(Input("b", low, high, source="tooth thickness and centre distance allowances (DIN 3967)"))
    return out


def _frozen(value: Json) -> Json:
    """Lists as tuples, at every depth (a spec is hashable)."""
    return tuple(_frozen(v) for v in value) if isinstance(value, list | tuple) else value


def _pairs(mapping: Mapping[str, Json] | None) -> tuple[tuple[str, Json], ...]:
    return tuple(sorted((k, _frozen(v)) for k, v in (mapping or {}).items()))


@dataclass(frozen=True)
class ProbabilitySpec(study.StudySpec):
    """One study as declared in ``config.yaml`` under ``probabilities:`` (the shared fields: :class:`StudySpec`).
    ``axis``: the operating axis (None: the study's one point); ``inputs``: name -> distribution (as pairs);
    ``tolerances``: "design" (the design file's block), a tolerance class (as pairs) or None; ``box``: the half
    widths (displacements, velocities; units of b_c) of the initial state's box, or None (the static deflection);
    ``sensitivity``: method, indicators, points, resamples (as pairs); ``claims``: a role of the paper's
    ``CLAIM_LINES`` whose claims are checked per sample; ``classes``: a class study's tolerance classes (each
    replaces the tolerance block's grade; :func:`class_samples`) and ``limits`` its limits
    (:mod:`geardyn.runs.tolerance_classes`); ``given``: (parameter, values) of a study conditioned on each of
    those values of an operating condition (:func:`given_samples`)."""

    axis: Axis | None = None
    inputs: tuple[tuple[str, tuple[tuple[str, Json], ...]], ...] = ()
    tolerances: str | tuple[tuple[str, Json], ...] | None = None
    box: tuple[float, float] | None = None
    samples: int = 256
    seed: int = 0
    scramblings: int = 4
    sensitivity: tuple[tuple[str, Json], ...] = ()
    claims: str = ""
    classes: tuple[int, ...] = ()
    limits: tuple[tuple[str, float], ...] = ()
    given: tuple[str, tuple[float, ...]] | None = None

    @classmethod
    def own_fields(cls, spec: Mapping[str, Json]) -> dict[str, Json]:
        a, tol, box = spec.get("axis"), spec.get("tolerances"), spec.get("initial_state")
        return {
            **super().own_fields(spec),
            "axis": None if a is None else Axis(a["parameter"], float(a["start"]), float(a["stop"]), int(a["num"])),
            "inputs": tuple((k, _pairs(v)) for k, v in (spec.get("inputs") or {}).items()),
            "tolerances": tol if tol is None or isinstance(tol, str) else _pairs(tol),
            "box": None if box is None else (float(box["box_x"]), float(box["box_v"])),
            "sensitivity": _pairs(spec.get("sensitivity")),
            "classes": tuple(int(c) for c in spec.get("classes") or ()),
            "limits": tuple(sorted((k, float(v)) for k, v in (spec.get("limits") or {}).items())),
            "given": None
            if "given" not in spec
            else (spec["given"]["parameter"], tuple(map(float, spec["given"]["values"]))),
        }

    @property
    def method(self) -> str:
        """The sensitivity method: rbd_fast or pawn (given data, on the samples) or sobol (Saltelli's design)."""
        return str(dict(self.sensitivity).get("method", "rbd_fast"))

    @property
    def index_samples(self) -> int:
        """The points of the given-data indices' Latin hypercube (``sensitivity.samples``); none under ``sobol``
        and none for a class study or a study given values of an operating condition (their samples are stacked
        per class or value, and an index pooled over classes or values would name what the study holds)."""
        if self.method == "sobol" or self.classes or self.given:
            return 0
        return int(dict(self.sensitivity).get("samples", 128))

    @property
    def dim(self) -> str:
        """The name of the operating axis (``point`` for a study of one point)."""
        return "point" if self.axis is None else self.axis.parameter

    @property
    def n_chunks(self) -> int:
        """Number of chunk jobs: the configured count, at most one per sample."""
        return max(1, min(self.chunks, self.samples))

    def uncertain(self, design: KHVDesign, grade: int | None = None) -> list[Input]:
        """The study's inputs: those of its tolerance class (e, te_phase, b; but those the study holds fixed or
        puts on its axis; ``grade``: of that class instead of the block's), then its own ``inputs``, which
        replace a tolerance class's input of the same name."""
        block = design.raw.get("tolerances") if self.tolerances == "design" else dict(self.tolerances or ())  # type: ignore[arg-type]
        block = block if grade is None or not block else {**block, "grade": grade}
        held = {*dict(self.fixed), self.dim}
        out = {i.name: i for i in tolerance_inputs(design, block) if i.name not in held} if block else {}
        for name, spec in self.inputs:
            out[name] = distribution(name, dict(spec), point.nominal(design, name, dict(self.fixed)))
        return list(out.values())


class Samples(NamedTuple):
    """A study's samples: the inputs (the initial state's components last), their unit-cube coordinates and
    their values (n, D), the initial state's as offsets from the static deflection; the inputs themselves; each
    sample's block (n): the scrambling it belongs to (0 .. R - 1: the samples of the probabilities) or -1 (the
    design of the sensitivity indices only)."""

    names: tuple[str, ...]
    unit: np.ndarray
    values: np.ndarray
    inputs: tuple[Input, ...]
    block: np.ndarray


def unit_cube(dim: int, n: int, seed: int, scramblings: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """n points in [0, 1)^dim and the scrambling of each: ``scramblings`` R independent scramblings of the Sobol'
    sequence (``scipy.stats.qmc.Sobol``, seeded by the first R children of ``numpy.random.SeedSequence(seed)``),
    the n points split across them (np.array_split: the first n mod R blocks one point more), each block the
    first points of its own sequence (n / R a power of 2 keeps every block a (t, m, d)-net)."""
    from scipy.stats import qmc  # noqa: PLC0415

    sizes = [len(s) for s in np.array_split(np.arange(n), max(1, min(scramblings, n)))]
    seeds = np.random.SeedSequence(seed).spawn(len(sizes))
    blocks = [
        qmc.Sobol(dim, scramble=True, seed=np.random.default_rng(s)).random_base2(max(0, math.ceil(math.log2(m))))[:m]
        for s, m in zip(seeds, sizes, strict=True)
    ]
    return np.concatenate(blocks), np.repeat(np.arange(len(sizes)), sizes)


def index_design(dim: int, n: int, seed: int) -> np.ndarray:
    """The design of the given-data sensitivity indices: a Latin hypercube of n points in [0, 1)^dim
    (``scipy.stats.qmc.LatinHypercube``), independent of the probabilities' scramblings: seeded by the child
    2^16 of ``SeedSequence(seed)``, theirs being the children 0 .. R - 1."""
    from scipy.stats import qmc  # noqa: PLC0415

    rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(2**16,)))
    return qmc.LatinHypercube(dim, seed=rng).random(n)


def saltelli(dim: int, n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Saltelli's design for first-order and total Sobol' indices (no second order): n base points, n (dim + 2)
    rows (``SALib.sample.sobol``, seeded; n a power of 2), and each row's block: 0 for the base sample A (every
    (dim + 2)-th row, the probabilities' sample), -1 for the others."""
    from SALib.sample import sobol  # noqa: PLC0415 - SALib: only the jobs that sample for Sobol' indices

    problem = {"num_vars": dim, "names": [f"u{k}" for k in range(dim)], "bounds": [[0.0, 1.0]] * dim}
    unit = np.asarray(sobol.sample(problem, n, calc_second_order=False, seed=seed))
    return unit, np.where(np.arange(unit.shape[0]) % (dim + 2) == 0, 0, -1)


def samples(design: KHVDesign, spec: ProbabilitySpec) -> Samples:
    """Every sample of a study (each chunk draws them all: the same on every machine, whatever the chunking):
    under ``sobol`` Saltelli's design; otherwise the probabilities' R scramblings of ``samples`` Sobol' points,
    then the ``sensitivity.samples`` points of the indices' Latin hypercube."""
    inputs = spec.uncertain(design)
    names = (*(i.name for i in inputs), *(START_INPUTS if spec.box else ()))
    if spec.method == "sobol":
        unit, block = saltelli(len(names), spec.samples, spec.seed)
    else:
        unit, block = unit_cube(len(names), spec.samples, spec.seed, spec.scramblings)
        extra = index_design(len(names), spec.index_samples, spec.seed)
        unit, block = np.concatenate([unit, extra]), np.concatenate([block, np.full(len(extra), -1)])
    cols = [inp.values(unit[:, k]) for k, inp in enumerate(inputs)]
    if spec.box:
        half = np.repeat(np.asarray(spec.box, dtype=float), 3)
        cols += list(((2.0 * unit[:, len(inputs) :] - 1.0) * half).T)
    return Samples(names, unit, np.column_stack(cols), tuple(inputs), block)


def class_samples(design: KHVDesign, spec: ProbabilitySpec) -> Samples:
    """A class study's samples: the same unit-cube points at each of ``spec.classes`` (common random numbers: the
    classes differ only in their inputs' ranges), stacked class by class (sample c N + i, N = ``spec.samples``);
    the inputs those of the coarsest class."""
    one = samples(design, spec)
    inputs = [spec.uncertain(design, c) for c in spec.classes]
    values = [np.column_stack([inp.values(one.unit[:, k]) for k, inp in enumerate(ins)]) for ins in inputs]
    values = [np.hstack([v, one.values[:, v.shape[1] :]]) for v in values]  # the initial state's: every class's
    block = np.tile(one.block, len(values))
    return Samples(one.names, np.vstack([one.unit] * len(values)), np.vstack(values), tuple(inputs[-1]), block)


def given_samples(design: KHVDesign, spec: ProbabilitySpec) -> Samples:
    """A study conditioned on values of an operating condition (``given``): the same samples at each value, stacked
    value by value (sample c N + i), the condition one more column among the inputs (held at the value; its
    unit-cube coordinate the value's place (c + 1/2) / C), so each value's share is a probability given it."""
    one, (name, held) = samples(design, spec), spec.given or ("", ())
    k, c = len(one.inputs), len(held)
    text = f"held at each of {', '.join(f'{v:g}' for v in held)}: the claims are given each"
    cond = Input(name, min(held), max(held), source=text, operating=True)
    at = np.repeat(np.asarray(held, dtype=float), one.values.shape[0])[:, None]
    place = np.repeat((np.arange(c) + 0.5) / c, one.values.shape[0])[:, None]
    stack = [np.tile(one.values[:, :k], (c, 1)), at, np.tile(one.values[:, k:], (c, 1))]
    unit = [np.tile(one.unit[:, :k], (c, 1)), place, np.tile(one.unit[:, k:], (c, 1))]
    names = (*one.names[:k], name, *one.names[k:])
    return Samples(names, np.hstack(unit), np.hstack(stack), (*one.inputs, cond), np.tile(one.block, c))


def study_samples(design: KHVDesign, spec: ProbabilitySpec) -> Samples:
    """Every sample of a study: :func:`class_samples` for a class study, :func:`given_samples` for one given
    values of an operating condition, else :func:`samples`."""
    if spec.classes:
        return class_samples(design, spec)
    return given_samples(design, spec) if spec.given else samples(design, spec)


def layout(design: KHVDesign, spec: ProbabilitySpec, chunk: int, table: Samples) -> study.Layout:
    """The lines of chunk ``chunk``: one per sample of its share (whole samples), each along the study's axis
    (increasing) at the sample's inputs and the study's fixed overrides, from the static deflection at its first
    point moved by the sample's initial state."""
    if not 0 <= chunk < spec.n_chunks:
        raise ValueError(f"chunk {chunk} outside 0..{spec.n_chunks - 1} for probabilities {spec.name}")
    n, k = table.values.shape[0], len(table.inputs)
    axis = [None] if spec.axis is None else [float(x) for x in spec.axis.values]
    lines, starts = [], []
    for i in np.array_split(np.arange(n), spec.n_chunks)[chunk]:
        own = dict(spec.fixed) | {n: float(v) for n, v in zip(table.names[:k], table.values[i, :k], strict=True)}
        line: list[tuple[study.Index, Coefficients]] = [
            ((int(i), j), point.point_coefficients(design, own if x is None else {**own, spec.dim: x}))
            for j, x in enumerate(axis)
        ]
        lines.append(study.damped(line, f"probabilities {spec.name}"))
        starts.append(line[0][1].static_state() + table.values[i, k:] if spec.box else None)
    return study.Layout(("sample", spec.dim), (n, len(axis)), lines, computed=True, starts=starts)


def coordinates(spec: ProbabilitySpec, n: int) -> dict[str, Json]:
    """The sample numbers and the operating axis."""
    if spec.axis is None:
        axis = Var("point", "point", "1", "the study's one operating point")(np.zeros(1, np.int32))
    else:
        units, long_name = point.CONTROLS.get(spec.dim, (point.units_of(spec.dim), spec.dim))
        axis = Var(spec.dim, spec.dim, units, long_name)(spec.axis.values)
    sample = Var("sample", "sample", "1", "sample of the inputs", dtype=np.int32)
    return {"sample": sample(np.arange(n)), spec.dim: axis}


def attributes(spec: ProbabilitySpec, table: Samples, policy: Policy) -> dict[str, Json]:
    """What a study's files record of it: its inputs, sampling, initial state and labelling."""
    if spec.method == "sobol":
        rows = spec.samples * (len(table.names) + 2)
        sampling = (
            f"Saltelli's design for first-order and total Sobol' indices (SALib.sample.sobol, {spec.samples} base "
            f"points, {rows} lines; the probabilities from the base sample only, n = {spec.samples})"
        )
    else:
        r = int(table.block.max()) + 1
        sampling = f"{spec.samples} points of the scrambled Sobol' sequence in {r} independent scramblings " + (
            f"(scipy.stats.qmc, the probabilities), and a Latin hypercube of {spec.index_samples} more lines (the "
            "sensitivity indices)"
            if spec.index_samples
            else "(scipy.stats.qmc), the same at every class or given value; no index lines, no sensitivity indices"
        )
    start = "the static deflection at each sample's first point"
    if spec.box:
        start = f"uniform in {start} +- {spec.box[0]:g} (displacements), +- {spec.box[1]:g} (velocities), units b_c"
    return {
        "probabilities": spec.name,
        "design": spec.design,
        "axis_parameter": spec.dim,
        "inputs": "; ".join(i.text for i in table.inputs),
        "sampling": f"{sampling}; seed {spec.seed}",
        "initial_state": start,
        "fixed_overrides": spec.fixed_overrides,
        "operating_inputs": " ".join(i.name for i in table.inputs if i.operating),
        **study.study_attrs(policy),
    }


def run_chunk(design: KHVDesign, spec: ProbabilitySpec, chunk: int) -> xr.Dataset:
    """Label the samples of one chunk: a cube (sample, axis) of every point of the study, ``computed`` 1 on the
    chunk's samples, with CF attributes and the chunk's wall time."""
    policy, table = spec.policy(design), study_samples(design, spec)
    result = study.run(layout(design, spec, chunk, table), policy, f"{spec.name} chunk {chunk}")
    attrs = {**attributes(spec, table, policy), "wall_time_s": result.wall_time_s}
    return xr.Dataset(result.data, coords=coordinates(spec, table.values.shape[0]), attrs=attrs)
