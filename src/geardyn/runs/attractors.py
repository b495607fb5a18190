"""Coexisting attractors at single operating points: several starts, one label each, deduplicated.

At one point (design + overrides) the motion is integrated from

* ``static``: the static deflection (what a sweep without continuation starts from),
* ``up`` / ``down``: the final states of the neighbouring sweep points (what a sweep continued
  upwards or downwards would start from), when given,
* ``orbit_k``: the stable periodic orbits of the continued branches at that point, when given,
* ``random_k``: ``n_random`` states drawn uniformly (numpy ``default_rng(seed)``) from the box
  static state +- (``box_x`` for the three displacements, ``box_v`` for the three velocities),
  in units of b_c.

Every start is labelled by the one labeller (:func:`geardyn.label.label_points`, all starts of a point
together).  Two runs reached the same attractor when :func:`geardyn.label.compare.same_attractor` says
so: their labels agree and

* periodic: their cycles lie within ``distance_tol`` of each other (symmetric Hausdorff distance, max
  norm) relative to max(1, size), size the largest extent of the two sets (two phases of one orbit agree
  to 1e-8; two distinct P1 orbits do not);
* otherwise (quasi-periodic, chaotic, undetermined): centroids and bounding boxes of the Poincaré
  sets agree within ``chaotic_distance_tol`` * max(1, size) (two finite samples of one cloud).  The basin fraction of
  an attractor is the share of the *random* starts that
reach it (a Monte-Carlo estimate over the box; with ``n_random`` starts its standard error is about
sqrt(f (1 - f) / n_random)).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import xarray as xr

from geardyn import classify
from geardyn.config import settings_from
from geardyn.khv import point
from geardyn.label import Policy, compare, label_points
from geardyn.runs.continuation import branches_from_dataset
from geardyn.solve.base import SimulationSettings, System


@dataclass(frozen=True)
class AttractorSettings:
    """Starts and tolerances of :func:`find_attractors` (lengths in units of b_c)."""

    n_random: int = 8
    seed: int = 0
    box_x: float = 20.0
    box_v: float = 20.0
    transient_periods: int = 1000
    recorded_periods: int = 100
    distance_tol: float = 1e-3
    chaotic_distance_tol: float = 0.2

    @classmethod
    def from_mapping(cls, spec: Mapping[str, Any] | None) -> AttractorSettings:
        return settings_from(cls, spec, "attractor settings")


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


def same_attractor(label_a: int, pa: np.ndarray, label_b: int, pb: np.ndarray, settings: AttractorSettings) -> bool:
    """Same label and Poincaré sets within the settings' tolerances (:func:`geardyn.label.compare.same_attractor`)."""
    return compare.same_attractor(label_a, pa, label_b, pb, settings.distance_tol, settings.chaotic_distance_tol)


def find_attractors(
    system: System,
    starts: Mapping[str, np.ndarray],
    settings: AttractorSettings,
    integration: SimulationSettings,
    classifier: classify.ClassifierSettings = classify.ClassifierSettings(),
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
    for name, v in zip(names, verdicts, strict=True):
        p = compare.attractor_points(v)
        for k, att in enumerate(found):
            if same_attractor(att.label, att.poincare, v.label, p, settings):
                att.starts.append(name)
                where[name] = k
                break
        else:
            found.append(Attractor(int(v.label), p, float(v.exponent), [name]))
            where[name] = len(found) - 1
    return found, where


def basin_fractions(attractors: Sequence[Attractor], n_random: int) -> np.ndarray:
    """Share of the random starts that reached each attractor (NaN without random starts)."""
    if n_random <= 0:
        return np.full(len(attractors), np.nan)
    return np.array([a.n_random / n_random for a in attractors], dtype=float)


# ----------------------------------------------------------------------------------------------
# along a sweep
# ----------------------------------------------------------------------------------------------

STATE_VARS = ("x_dh", "x_vh", "x_vl", "v_dh", "v_vh", "v_vl")


def subset_indices(values: np.ndarray, every: int | None = None, at: Sequence[float] | None = None) -> list[int]:
    """Sweep indices to examine: every ``every``-th point (first and last included) and/or the points
    nearest to the values ``at``."""
    idx: set[int] = set()
    if every:
        idx.update(range(0, values.size, int(every)))
        idx.add(values.size - 1)
    for v in at or ():
        idx.add(int(np.argmin(np.abs(values - float(v)))))
    return sorted(idx)


def branch_starts(branches: Sequence[Any], p: float, perturb: float = 1e-3) -> dict[str, np.ndarray]:
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
    system: Any
    extra: dict[str, np.ndarray] = field(default_factory=dict)


def sweep_points(
    system_of: Any, values: np.ndarray, indices: Sequence[int], case: int, neighbour_state: Any, branches: Sequence[Any]
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


def attractors_dataset(
    points: Sequence[PointStarts],
    settings: AttractorSettings,
    integration: SimulationSettings,
    classifier: classify.ClassifierSettings,
    parameter: str,
    units: str,
    long_name: str,
    case_labels: Sequence[str] = ("base",),
):
    """Attractors at each of ``points`` as one CF dataset (dimension ``point``)."""

    fixed_names = ["static", "up", "down"] + [f"random_{k}" for k in range(settings.n_random)]
    per_point = [_attractors_of(q, settings, integration, classifier) for q in points]
    label, valid, cen, size, lyap, frac, nst, reach = _attractor_arrays(per_point, settings.n_random, fixed_names)
    na = label.shape[1]
    one = {"units": "1"}
    data = {
        "parameter": ("point", np.array([q.p for q, *_ in per_point]), {"units": units, "long_name": long_name}),
        "case_index": (
            "point",
            np.array([q.case for q, *_ in per_point], np.int32),
            {**one, "long_name": "index of the sweep case (fixed overrides)"},
        ),
        "sweep_index": (
            "point",
            np.array([q.index for q, *_ in per_point], np.int32),
            {**one, "long_name": "index of the point in the sweep"},
        ),
        "n_attractors": (
            "point",
            np.array([len(a) for _, a, _, _ in per_point], np.int16),
            {**one, "long_name": "number of distinct attractors found"},
        ),
        "n_starts": (
            "point",
            np.array([n for *_, n in per_point], np.int16),
            {**one, "long_name": "number of initial conditions integrated"},
        ),
        "attractor_label": (
            ("point", "attractor"),
            label,
            {"long_name": "motion label of the attractor (classify)", **classify.flag_attrs(classifier.max_n)},
        ),
        "attractor_found": (
            ("point", "attractor"),
            valid,
            {
                "long_name": "attractor slot used",
                "flag_values": np.array([0, 1], np.int8),
                "flag_meanings": "empty found",
            },
        ),
        "centroid": (
            ("point", "attractor", "state"),
            cen,
            {**one, "long_name": "centroid of the attractor's Poincare points (x / b_c, dx/dtau / b_c)"},
        ),
        "attractor_size": (("point", "attractor"), size, {**one, "long_name": "largest extent of the Poincare points"}),
        "attractor_lyapunov": (
            ("point", "attractor"),
            lyap,
            {
                **one,
                "long_name": (
                    "largest exponent per unit tau (Floquet for periodic attractors, tangent vector otherwise)"
                ),
            },
        ),
        "basin_fraction": (
            ("point", "attractor"),
            frac,
            {**one, "long_name": "share of the random starts in the box that reach the attractor"},
        ),
        "starts_reaching": (
            ("point", "attractor"),
            nst,
            {**one, "long_name": "number of starts (all kinds) reaching it"},
        ),
        "reached_from": (
            ("point", "start"),
            reach,
            {**one, "long_name": "attractor index reached from the named start (-1: start not used)"},
        ),
    }
    coords = {
        "state": ("state", list(STATE_VARS), {"long_name": "state component"}),
        "start": ("start", fixed_names, {"long_name": "named initial condition"}),
        "attractor": ("attractor", np.arange(na, dtype=np.int32), {**one, "long_name": "attractor slot"}),
        "case": ("case", list(case_labels), {"long_name": "case (fixed overrides)"}),
    }
    return xr.Dataset(data, coords=coords, attrs=_settings_attrs(parameter, settings))


def _settings_attrs(parameter: str, settings: AttractorSettings) -> dict[str, Any]:
    """Global attributes of an attractors dataset: the control parameter and the search settings."""
    return {
        "control_parameter": parameter,
        "n_random": settings.n_random,
        "random_seed": settings.seed,
        "box": f"static state +- {settings.box_x:g} (displacements), +- {settings.box_v:g} (velocities), units b_c",
        "transient_periods": settings.transient_periods,
        "recorded_periods": settings.recorded_periods,
        "distance_tol": settings.distance_tol,
        "chaotic_distance_tol": settings.chaotic_distance_tol,
    }


def _attractors_of(
    q: PointStarts,
    settings: AttractorSettings,
    integration: SimulationSettings,
    classifier: classify.ClassifierSettings,
) -> tuple[PointStarts, list, dict, int]:
    """The attractors one point's starts reach: (point, attractors, start name -> attractor, starts used)."""
    starts: dict[str, np.ndarray] = {"static": q.system.static_state(), **q.extra}
    starts.update(random_starts(q.system, settings))
    atts, where = find_attractors(q.system, starts, settings, integration, classifier)
    return q, atts, where, len(starts)


def _attractor_arrays(per_point: Sequence[tuple], n_random: int, fixed_names: Sequence[str]) -> tuple[np.ndarray, ...]:
    """(label, found, centroid, size, exponent, basin fraction, starts reaching, reached from) per point and
    attractor slot (slots as many as the most attractors at one point)."""
    na = max([len(a) for _, a, _, _ in per_point], default=1)
    npnt = len(per_point)
    label = np.full((npnt, na), classify.LABELS["undetermined"], np.int16)
    valid = np.zeros((npnt, na), np.int8)
    cen = np.full((npnt, na, 6), np.nan)
    size = np.full((npnt, na), np.nan)
    lyap = np.full((npnt, na), np.nan)
    frac = np.full((npnt, na), np.nan)
    nst = np.zeros((npnt, na), np.int32)
    reach = np.full((npnt, len(fixed_names)), -1, np.int16)
    for r, (_, atts, where, _) in enumerate(per_point):
        fr = basin_fractions(atts, n_random)
        for k, a in enumerate(atts):
            label[r, k], valid[r, k] = a.label, 1
            cen[r, k], size[r, k], lyap[r, k], frac[r, k], nst[r, k] = (
                a.centroid,
                a.size,
                a.lyapunov,
                fr[k],
                len(a.starts),
            )
        for s_, name in enumerate(fixed_names):
            reach[r, s_] = where.get(name, -1)
    return label, valid, cen, size, lyap, frac, nst, reach


def sweep_attractors(
    drive: Any,
    spec: Any,
    cube: Any,
    branches_ds: Any,
    attractor_spec: Mapping[str, Any],
    settings: SimulationSettings | None = None,
    classifier: classify.ClassifierSettings | None = None,
):
    """Attractors at a subset of a sweep's points (``every`` / ``at`` in ``attractor_spec``, the rest
    are :class:`AttractorSettings`), every case; the branches come from the orbits dataset."""

    spec_map = dict(attractor_spec)
    every = spec_map.pop("every", None)
    at = spec_map.pop("at", None)
    if not every and not at:
        every = max(1, spec.num // 10)
    aset = AttractorSettings.from_mapping(spec_map)
    settings = settings or point.integration_settings(drive, **dict(spec.integration))
    classifier = classifier or classify.ClassifierSettings.from_mapping(dict(spec.classifier))
    values = spec.values
    idx = subset_indices(values, every, at)
    par = spec.parameter
    allb = branches_from_dataset(branches_ds) if branches_ds is not None else []
    pts: list[PointStarts] = []
    for case in range(len(spec.cases)):
        fixed = {**dict(spec.fixed), **dict(spec.cases[case])}

        def system_of(p: float, fixed=fixed):
            return point.point_coefficients(drive, {**fixed, par: float(p)})

        def neighbour(j: int, case=case):
            x = np.array([float(cube[v].values[case, 0, j, -1]) for v in STATE_VARS])
            return x if np.all(np.isfinite(x)) else None

        pts += sweep_points(system_of, values, idx, case, neighbour, [b for c, b in allb if c == case])
    units, long_name = point.CONTROLS.get(par, (point.units_of(par), par))
    ds = attractors_dataset(
        pts, aset, settings, classifier, par, units, long_name, [spec.case_label(i) for i in range(len(spec.cases))]
    )
    ds.attrs.update({"sweep": spec.name, "design": spec.design})
    return ds
