"""The continuation of a sweep: its ``orbits:`` settings (:class:`OrbitSpec`), branches seeded by the labeller's
periodic points of the cube (with branch switching at their period doublings), the CF dataset and the table of
bifurcation points, and the cross-check of the sweep's labels against the branches (:func:`label_check`)."""

from __future__ import annotations

import logging
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

from geardyn.config import settings_from
from geardyn.jsontypes import Json
from geardyn.khv import point
from geardyn.khv.design import KHVDesign
from geardyn.papers import paper_of
from geardyn.runs.bands import bands
from geardyn.runs.continuation.branch import Branch, on_branch
from geardyn.runs.continuation.corrector import ContinuationSettings
from geardyn.runs.continuation.family import KHVFamily
from geardyn.runs.continuation.output import bifurcation_rows, branch_dataset
from geardyn.runs.continuation.switching import add_branch
from geardyn.runs.cube import STATES
from geardyn.solve.base import SimulationSettings

#: How near a branch a sweep point's last Poincare point must lie to agree with it (:func:`label_agreement`,
#: relative to max(1, max |x|)): above the Poincare errors of the shipped step counts (1.9e-5 at 128 steps per
#: period and less).
AGREEMENT_TOL = 1e-4

if TYPE_CHECKING:  # for the annotations only
    from geardyn.runs.sweep import SweepSpec

log = logging.getLogger("geardyn.continuation")


@dataclass(frozen=True)
class OrbitSpec:
    """One ``orbits:`` entry of the configuration (its keys in the config schema): ``nodes`` of the
    :class:`~geardyn.runs.continuation.KHVFamily`, ``attractors`` for :mod:`geardyn.runs.attractors`."""

    max_period: int = 6
    max_seeds: int = 6
    nodes: int = 101
    continuation: ContinuationSettings = ContinuationSettings()
    attractors: tuple[tuple[str, Json], ...] = ()
    switch_period_doubling: bool = True

    @classmethod
    def from_config(cls, spec: Mapping[str, Json] | None) -> OrbitSpec:
        values = {k: v for k, v in (spec or {}).items() if k != "designs"}
        values["continuation"] = ContinuationSettings.from_mapping(values.get("continuation"))
        values["attractors"] = tuple(sorted((values.get("attractors") or {}).items()))
        return settings_from(cls, values, "orbits settings")


def final_state(cube: xr.Dataset, case: int, j: int) -> np.ndarray:
    """The last Poincare point of sweep point j of ``case`` (first direction of the cube)."""
    return np.array([float(cube[v].values[case, 0, j, -1]) for v in STATES])


def seeds_from_cube(
    cube: xr.Dataset, case: int, max_period: int, max_seeds: int
) -> list[tuple[float, np.ndarray, int]]:
    """(p, final state, n) at the middle of each run of equal label P1..P<max_period> along the sweep
    (first direction of the cube), longest runs first, at most ``max_seeds``."""
    par = cube.attrs["control_parameter"]
    values = np.asarray(cube[par].values, dtype=float)
    seeds = []
    for j, n in run_middles(np.asarray(cube["label"].values[case, 0], dtype=int), max_period)[:max_seeds]:
        x = final_state(cube, case, j)
        if np.all(np.isfinite(x)):
            seeds.append((float(values[j]), x, n))
    return seeds


def run_middles(labels: np.ndarray, max_period: int) -> list[tuple[int, int]]:
    """(middle index, n) of every run of equal label P1..P<max_period>, longest runs first."""
    runs = [
        (int(last) - int(first) + 1, int(first), n)
        for first, last, n in bands(np.arange(labels.size), labels)
        if 1 <= n <= max_period
    ]
    return [(first + length // 2, n) for length, first, n in sorted(runs, key=lambda r: (-r[0], r[1]))]


def sweep_branches(families: Sequence[KHVFamily], cube: xr.Dataset, spec: OrbitSpec) -> list[tuple[int, Branch]]:
    """Continue every distinct branch seeded by the cube's periodic points (the labeller's final states, shot by
    :func:`~geardyn.runs.continuation.stepping.continue_branch`), case by case (one family each)."""
    out: list[tuple[int, Branch]] = []
    doubling = spec.max_period if spec.switch_period_doubling else 0
    for case, family in enumerate(families):
        mine: list[Branch] = []
        for p, x, n in seeds_from_cube(cube, case, spec.max_period, spec.max_seeds):
            br = add_branch(family, p, x, n, mine, spec.continuation, doubling)
            if br is not None:
                ends = br.end_status
                log.info("case %d: P%d branch from %g: %d points, ends %s", case, n, p, len(br), ends)
        out.extend((case, b) for b in mine)
    return out


def label_agreement(
    cube: xr.Dataset, case: int, branches: Sequence[Branch], max_period: int, tol: float = AGREEMENT_TOL
) -> tuple[int, int, list[float]]:
    """Consistency of the simulated labels with the branches: of the sweep points labelled P1..P<max_period>,
    how many have their last Poincare point on a *stable* part of a branch of that period (within
    tol * max(1, max|x|)).  Returns (checked, agreeing, parameter values that disagree)."""
    par = cube.attrs["control_parameter"]
    values = np.asarray(cube[par].values, dtype=float)
    labels = np.asarray(cube["label"].values[case, 0], dtype=int)
    checked, agree, bad = 0, 0, []
    for j, lab in enumerate(labels):
        if not 1 <= lab <= max_period:
            continue
        x = final_state(cube, case, j)
        if not np.all(np.isfinite(x)):
            continue
        checked += 1
        ok = any(on_branch(br, values[j], x[None], tol, 0.0, True) for br in branches if br.n == lab)
        agree += int(ok)
        if not ok:
            bad.append(float(values[j]))
    return checked, agree, bad


def label_check(
    cube: xr.Dataset, branches: Sequence[tuple[int, Branch]], n_cases: int, max_period: int
) -> dict[str, str]:
    """The cross-check of the sweep's simulated labels against the branches, as dataset attributes
    ``case_<k>_label_agreement`` (see :func:`label_agreement`): how many simulated P-n points lie on
    a stable branch, and which do not (at most 20 listed).  The one place where the driver compares
    with the sweep's labels."""
    attrs: dict[str, str] = {}
    for c in range(n_cases):
        n_chk, n_ok, bad = label_agreement(cube, c, [b for cc, b in branches if cc == c], max_period)
        attrs[f"case_{c}_label_agreement"] = f"{n_ok} of {n_chk} simulated P-n points lie on a stable branch" + (
            f"; not: {', '.join(f'{v:g}' for v in bad[:20])}" if bad else ""
        )
        log.info("case %d: %s", c, attrs[f"case_{c}_label_agreement"])
    return attrs


def sweep_orbits(
    drive: KHVDesign,
    spec: SweepSpec,
    cube: xr.Dataset,
    orbit_spec: OrbitSpec,
    settings: SimulationSettings | None = None,
) -> tuple[xr.Dataset, list[dict[str, Json]]]:
    """Branches of one sweep (a :class:`geardyn.runs.sweep.SweepSpec` and its merged cube): the CF
    dataset and the bifurcation table rows.  The paper's transitions are named only for a design
    that names its paper and only along x1 (the paper's Fig. 7 sequence)."""

    settings = settings or point.integration_settings(drive, **dict(spec.integration))
    fams: dict[int, KHVFamily] = {}
    for c, case in enumerate(spec.cases):
        fixed = {**dict(spec.fixed), **dict(case)}
        fams[c] = KHVFamily(drive, spec.parameter, fixed, spec.start, spec.stop, settings, orbit_spec.nodes)
        log.info("case %d: coefficient interpolation error %.2e", c, fams[c].interpolation_error)
    t0 = time.perf_counter()
    branches = sweep_branches(list(fams.values()), cube, orbit_spec)
    log.info("%d branches in %.1f s", len(branches), time.perf_counter() - t0)
    labels = [spec.case_label(i) for i in range(len(spec.cases))]
    ds = branch_dataset(branches, fams, spec.parameter, labels)
    ds.attrs.update(
        {
            "sweep": spec.name,
            "design": spec.design,
            "interpolation_error": max((f.interpolation_error for f in fams.values()), default=0.0),
            "continuation_ds_max": orbit_spec.continuation.ds_max,
            "shooting_tol": orbit_spec.continuation.tol,
            "steps_per_period": settings.steps_per_period,
            "integrator": "rk4_event",
        }
    )
    ds.attrs.update(label_check(cube, branches, len(spec.cases), orbit_spec.max_period))
    mod = paper_of(getattr(drive, "paper", None))
    transitions = getattr(mod, "TRANSITIONS", None) if (mod is not None and spec.parameter == "x1") else None
    rows = bifurcation_rows(branches, spec.parameter, labels, transitions)
    return ds, rows
