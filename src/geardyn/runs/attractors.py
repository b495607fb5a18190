"""Coexisting attractors at single operating points: several starts (static, the sweep's neighbours, the branches'
orbits, random states in a box), one label each by the one labeller, deduplicated by
:func:`geardyn.label.compare.same_attractor`, with basin fractions over the random starts (``docs/orbits.md`` 4)."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

from geardyn import io
from geardyn.config import settings_from
from geardyn.io import Var
from geardyn.jsontypes import Json
from geardyn.khv import point
from geardyn.khv.design import KHVDesign
from geardyn.label import Policy, compare, indicators, label_points
from geardyn.label.policy import Same
from geardyn.runs.continuation import branches_from_dataset
from geardyn.runs.continuation.branch import Branch
from geardyn.runs.cube import STATES, label_var
from geardyn.solve.base import SimulationSettings, System

if TYPE_CHECKING:  # imported for the annotations only (the module imports this one)
    from geardyn.runs.sweep import SweepSpec


@dataclass(frozen=True)
class AttractorSettings:
    """Starts and tolerances of :func:`find_attractors` (lengths in units of b_c)."""

    n_random: int = 8
    seed: int = 0
    box_x: float = 20.0
    box_v: float = 20.0
    transient_periods: int = 1000
    recorded_periods: int = 100
    distance_tol: float = Same.distance_tol
    chaotic_distance_tol: float = Same.chaotic_distance_tol


@dataclass
class Attractor:
    """One attractor: label (classify codes), Poincaré points of the first run that reached it,
    centroid and size of those points, the starts that reached it."""

    label: int
    poincare: np.ndarray
    lyapunov: float
    starts: list[str] = field(default_factory=list)

    @property
    def centroid(self) -> np.ndarray:
        return np.mean(self.poincare, axis=0) if self.poincare.size else np.full(6, np.nan)

    @property
    def size(self) -> float:
        return float(np.max(np.ptp(self.poincare, axis=0))) if self.poincare.shape[0] > 1 else 0.0

    @property
    def n_random(self) -> int:
        return sum(s.startswith("random") for s in self.starts)


def random_starts(system: System, settings: AttractorSettings) -> dict[str, np.ndarray]:
    """``n_random`` states uniformly in the box around the static state (reproducible)."""
    rng = np.random.default_rng(settings.seed)
    centre = system.static_state()
    half = np.array([settings.box_x] * 3 + [settings.box_v] * 3)
    return {f"random_{k}": centre + rng.uniform(-1.0, 1.0, 6) * half for k in range(settings.n_random)}


def find_attractors(
    system: System,
    starts: Mapping[str, np.ndarray],
    settings: AttractorSettings,
    integration: SimulationSettings,
    classifier: indicators.ClassifierSettings = indicators.ClassifierSettings(),
) -> tuple[list[Attractor], dict[str, int]]:
    """Label the run from every start (the labeller, fixed starts), deduplicate.  Returns (attractors,
    start -> attractor index)."""
    sim = dataclasses.replace(
        integration, transient_periods=settings.transient_periods, recorded_periods=settings.recorded_periods
    )
    names = list(starts)
    verdicts = label_points(
        [system] * len(names),
        Policy(sim, classifier, start="fixed"),
        [np.asarray(starts[k], dtype=float) for k in names],
    )
    found: list[Attractor] = []
    where: dict[str, int] = {}
    tol = Same(settings.distance_tol, settings.chaotic_distance_tol)
    for name, v in zip(names, verdicts, strict=True):
        p = compare.attractor_points(v)
        for k, att in enumerate(found):
            if compare.same_attractor(att.label, att.poincare, v.label, p, tol):
                att.starts.append(name)
                where[name] = k
                break
        else:
            found.append(Attractor(int(v.label), p, float(v.exponent), [name]))
            where[name] = len(found) - 1
    return found, where


# --- along a sweep ---


def branch_starts(branches: Sequence[Branch], p: float, perturb: float = 1e-3) -> dict[str, np.ndarray]:
    """Starts on the continued branches at p: the orbit itself where it is stable, the orbit moved by
    ``perturb`` (every state) where it is unstable (to find what it loses stability to, e.g. a torus)."""
    out: dict[str, np.ndarray] = {}
    k = 0
    for br in branches:
        for i in range(len(br) - 1):
            a, b = br.p[i], br.p[i + 1]
            if min(a, b) <= p <= max(a, b) and a != b:
                w = (p - a) / (b - a)
                x = br.states[i] + w * (br.states[i + 1] - br.states[i])
                if bool(br.stable[i] and br.stable[i + 1]):
                    out[f"orbit_{k}"] = x
                else:
                    out[f"near_unstable_{k}"] = x + perturb
                k += 1
    return out


@dataclass
class PointStarts:
    """One point to examine: its case and sweep index, parameter value, system and the starts other
    than the static state and the random ones (neighbour states, branch orbits)."""

    case: int
    index: int
    p: float
    system: System
    extra: dict[str, np.ndarray] = field(default_factory=dict)


def sweep_points(
    system_of: Callable[[float], System],
    values: np.ndarray,
    indices: Sequence[int],
    case: int,
    neighbour_state: Callable[[int], np.ndarray | None],
    branches: Sequence[Branch],
) -> list[PointStarts]:
    """The :class:`PointStarts` of one case: ``up`` / ``down`` are the final states of the sweep
    points below / above (a sweep continued upwards / downwards arrives from there), then the branch
    starts of :func:`branch_starts`.  system_of(p): coefficients; neighbour_state(j): state or None."""
    out = []
    for j in indices:
        p = float(values[j])
        extra: dict[str, np.ndarray] = {}
        for name, jj in (("up", j - 1), ("down", j + 1)):
            if 0 <= jj < values.size:
                x = neighbour_state(jj)
                if x is not None and np.all(np.isfinite(x)):
                    extra[name] = np.asarray(x, dtype=float)
        extra.update(branch_starts(branches, p))
        out.append(PointStarts(case, int(j), p, system_of(p), extra))
    return out


def slot_variables(max_n: int = 12) -> tuple[Var, ...]:
    """The variables of each attractor slot at a point (labels up to period ``max_n``), filled in this order from
    an :class:`Attractor` by :func:`attractors_dataset`."""
    pa, per_unit_tau = ("point", "attractor"), "(Floquet for periodic attractors, tangent vector otherwise)"
    reached = "attractor index reached from the named start (-1: start not used)"
    return (
        label_var("attractor_label", "motion label of the attractor (classify)", max_n, pa),
        Var("attractor_found", pa, None, "attractor slot used", {"empty": 0, "found": 1}, fill=0),
        Var("centroid", (*pa, "state"), "1", "centroid of the attractor's Poincare points (x / b_c, dx/dtau / b_c)"),
        Var("attractor_size", pa, "1", "largest extent of the Poincare points"),
        Var("attractor_lyapunov", pa, "1", f"largest exponent per unit tau {per_unit_tau}"),
        Var("basin_fraction", pa, "1", "share of the random starts in the box that reach the attractor"),
        Var("starts_reaching", pa, "1", "number of starts (all kinds) reaching it", dtype=np.int32, fill=0),
        Var("reached_from", ("point", "start"), "1", reached, dtype=np.int16, fill=-1),
    )


def attractors_dataset(
    points: Sequence[PointStarts],
    settings: AttractorSettings,
    integration: SimulationSettings,
    classifier: indicators.ClassifierSettings,
    parameter: str,
    units: str,
    long_name: str,
    case_labels: Sequence[str] = ("base",),
):
    """Attractors at each of ``points`` as one CF dataset (dimension ``point``, the slots of
    :func:`slot_variables` as many as the most attractors at one point)."""
    fixed_names = ["static", "up", "down"] + [f"random_{k}" for k in range(settings.n_random)]
    starts = [{"static": q.system.static_state(), **q.extra, **random_starts(q.system, settings)} for q in points]
    found = [
        find_attractors(q.system, s, settings, integration, classifier) for q, s in zip(points, starts, strict=True)
    ]
    na = max([len(atts) for atts, _ in found], default=1)
    per_point = (
        Var("parameter", "point", units, long_name, dtype=np.float64),
        Var("case_index", "point", "1", "index of the sweep case (fixed overrides)", dtype=np.int32),
        Var("sweep_index", "point", "1", "index of the point in the sweep", dtype=np.int32),
        Var("n_attractors", "point", "1", "number of distinct attractors found", dtype=np.int16),
        Var("n_starts", "point", "1", "number of initial conditions integrated", dtype=np.int16),
    )
    counts = ([len(atts) for atts, _ in found], [len(s) for s in starts])
    data = io.variables(
        per_point, ([q.p for q in points], [q.case for q in points], [q.index for q in points], *counts)
    )
    sizes = {"point": len(points), "attractor": na, "state": len(STATES), "start": len(fixed_names)}
    slots = slot_variables(classifier.max_n)
    data |= {var.name: var.empty(tuple(sizes[d] for d in var.dims)) for var in slots}
    for r, (atts, where) in enumerate(found):
        for k, a in enumerate(atts):
            # the share of the random starts that reached it (NaN without random starts)
            basin = a.n_random / settings.n_random if settings.n_random > 0 else np.nan
            values = (a.label, 1, a.centroid, a.size, a.lyapunov, basin, len(a.starts))
            for var, value in zip(slots[:-1], values, strict=True):  # reached_from: per start
                data[var.name][1][r, k] = value
        data["reached_from"][1][r] = [where.get(name, -1) for name in fixed_names]
    coords = (
        Var("state", "state", None, "state component"),
        Var("start", "start", None, "named initial condition"),
        Var("attractor", "attractor", "1", "attractor slot", dtype=np.int32),
        Var("case", "case", None, "case (fixed overrides)"),
    )
    coords_values = (list(STATES), fixed_names, np.arange(na), list(case_labels))
    s = settings
    attrs = {"control_parameter": parameter, "n_random": s.n_random, "random_seed": s.seed}
    attrs["box"] = f"static state +- {s.box_x:g} (displacements), +- {s.box_v:g} (velocities), units b_c"
    attrs |= {
        k: getattr(s, k) for k in ("transient_periods", "recorded_periods", "distance_tol", "chaotic_distance_tol")
    }
    return xr.Dataset(data, coords=io.variables(coords, coords_values), attrs=attrs)


def sweep_attractors(
    drive: KHVDesign,
    spec: SweepSpec,
    cube: xr.Dataset,
    branches_ds: xr.Dataset | None,
    attractor_spec: Mapping[str, Json],
    settings: SimulationSettings | None = None,
    classifier: indicators.ClassifierSettings | None = None,
):
    """Attractors at a subset of a sweep's points (``every`` / ``at`` in ``attractor_spec``, the rest
    are :class:`AttractorSettings`), every case; the branches come from the orbits dataset."""
    spec_map = dict(attractor_spec)
    every, at = spec_map.pop("every", None), spec_map.pop("at", None)
    if not every and not at:
        every = max(1, spec.num // 10)
    aset = settings_from(AttractorSettings, spec_map, "attractor settings")
    settings = settings or point.integration_settings(drive, **dict(spec.integration))
    classifier = classifier or indicators.ClassifierSettings.from_mapping(dict(spec.classifier))
    values = spec.values  # every ``every``-th point (the last too) and the points nearest the values ``at``
    some = set(range(0, values.size, int(every))) | {values.size - 1} if every else set()
    idx = sorted(some | {int(np.argmin(np.abs(values - float(v)))) for v in at or ()})
    par = spec.parameter
    allb = branches_from_dataset(branches_ds) if branches_ds is not None else []
    pts: list[PointStarts] = []
    for case in range(len(spec.cases)):
        fixed = {**dict(spec.fixed), **dict(spec.cases[case])}

        def system_of(p: float, fixed=fixed):
            return point.point_coefficients(drive, {**fixed, par: float(p)})

        def neighbour(j: int, case=case):
            x = np.array([float(cube[v].values[case, 0, j, -1]) for v in STATES])
            return x if np.all(np.isfinite(x)) else None

        pts += sweep_points(system_of, values, idx, case, neighbour, [b for c, b in allb if c == case])
    units, long_name = point.CONTROLS.get(par, (point.units_of(par), par))
    ds = attractors_dataset(
        pts, aset, settings, classifier, par, units, long_name, [spec.case_label(i) for i in range(len(spec.cases))]
    )
    ds.attrs.update({"sweep": spec.name, "design": spec.design})
    return ds
