"""The driver of a sweep's continuation: branches seeded by the cube's periodic points (with branch
switching at their period doublings), the CF dataset and the table of bifurcation points, and the
cross-check of the sweep's labels against the branches (:func:`label_check`, the one place the
driver reads the sweep's labels after seeding)."""

from __future__ import annotations

import logging
import time
from collections.abc import Sequence
from typing import Any

import numpy as np

from geardyn.khv import point
from geardyn.papers import paper_of
from geardyn.runs.continuation.branch import Branch, on_branch
from geardyn.runs.continuation.family import KHVFamily
from geardyn.runs.continuation.output import bifurcation_rows, branch_dataset
from geardyn.runs.continuation.spec import OrbitSpec, final_state, seeds_from_cube
from geardyn.runs.continuation.switching import add_branch
from geardyn.solve.base import SimulationSettings
from geardyn.solve.shooting import newton_shooting

log = logging.getLogger("geardyn.continuation")


def sweep_branches(families: Sequence[KHVFamily], cube: Any, spec: OrbitSpec) -> list[tuple[int, Branch]]:
    """Continue every distinct branch seeded by the cube's periodic points, case by case (one family each)."""
    out: list[tuple[int, Branch]] = []
    doubling = spec.max_period if spec.switch_period_doubling else 0
    for case, family in enumerate(families):
        mine: list[Branch] = []
        for p, x, n in seeds_from_cube(cube, case, spec.max_period, spec.max_seeds):
            r = newton_shooting(family.flow(p, n), x, n, spec.continuation.tol)
            if not r.converged:
                log.info("case %d: seed P%d at %g not converged (%s)", case, n, p, r.status)
                continue
            br = add_branch(family, p, r.state, n, mine, spec.continuation, max_period=doubling)
            if br is not None:
                ends = br.end_status
                log.info("case %d: P%d branch from %g: %d points, ends %s", case, n, p, len(br), ends)
        out.extend((case, b) for b in mine)
    return out


def label_agreement(
    cube: Any, case: int, branches: Sequence[Branch], max_period: int, tol: float = 1e-4
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


def label_check(cube: Any, branches: Sequence[tuple[int, Branch]], n_cases: int, max_period: int) -> dict[str, str]:
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
    drive: Any, spec: Any, cube: Any, orbit_spec: OrbitSpec, settings: SimulationSettings | None = None
) -> tuple[Any, list[dict[str, Any]]]:
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
