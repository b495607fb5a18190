"""Every checkable statement of a paper (data: a paper module's ``CLAIMS``) against our results, for designs that
name the paper: the engine that reads a paper's claims and lines and hands each claim to its rule
(:mod:`geardyn.claims.sweep`; the rules, the keys of a claim and the thresholds: docs/claims.md)."""

from __future__ import annotations

from collections.abc import Mapping
from types import ModuleType

from geardyn.claims.sweep import SWEEP_RULES, missing, track_of_cube
from geardyn.claims.verdicts import Claim, unique_ids
from geardyn.jsontypes import Json
from geardyn.khv import point


def lines_of_runs(lines: Mapping[str, Mapping[str, Json]], runs: Mapping[str, Json]) -> dict[str, Json]:
    """The labelled lines (``lines``: a paper's ``CLAIM_LINES``) of the sweep cubes ``runs`` (by role): a
    :class:`Track`, or {case value: Track} for a family of lines; the roles ``runs`` lacks are left out."""
    out: dict[str, Json] = {}
    for role, spec in lines.items():
        cube = runs.get(role)
        if cube is None:
            continue
        if spec.get("cases") is None:
            out[role] = track_of_cube(cube)
        else:  # a family: {value: Track} of the cases ``<case_parameter>=<value>``
            names = [str(c) for c in cube["case"].values]
            index = {float(v): names.index(point.override_text({spec["case_parameter"]: v}, "")) for v in spec["cases"]}
            out[role] = {v: track_of_cube(cube, i) for v, i in index.items()}
    return out


def claims(paper: ModuleType, products: Mapping[str, Json]) -> list[Claim]:
    """:func:`evaluate` on the pipeline's products (``closed_graph``, ``stiffness``, ``amplitude`` = {"x1", "ptp"} of
    dense runs, the sweep cubes and point runs of the paper's ``CLAIM_RUNS`` roles) and the cubes' labelled lines."""
    return evaluate(paper, {**products, **lines_of_runs(paper.CLAIM_LINES, products)})


def evaluate(paper: ModuleType, inputs: Mapping[str, Json]) -> list[Claim]:
    """The claims of ``paper`` (its ``CLAIMS``, in order) from ``inputs`` (a ``line``: a :class:`Track`, or
    {case value: Track} for a family; an ``input``: a product), behind ``claims.md`` and the calibration objective;
    a claim whose input is not given is "not comparable"."""
    unique_ids(paper.CLAIMS)
    return [sweep_claim(spec, inputs, paper.CLAIM_LINES) for spec in paper.CLAIMS]


def sweep_claim(spec: Mapping[str, Json], inputs: Mapping[str, Json], lines: Mapping[str, Mapping[str, Json]]) -> Claim:
    """One claim about a KHV drive's regimes (:data:`SWEEP_RULES`) from ``inputs``."""
    if spec.get("rule") not in SWEEP_RULES:
        raise ValueError(f"claim {spec.get('id')!r}: rule {spec.get('rule')!r} (allowed: {sorted(SWEEP_RULES)})")
    rule, needs_line = SWEEP_RULES[spec["rule"]]
    role = spec["line"] if needs_line else spec["input"]
    got = inputs.get(role)
    if got is not None and needs_line and "case" in spec:
        got = got.get(float(spec["case"]))
    if got is None and spec["rule"] != "peaks":  # a dense run missing is the peaks rule's own answer
        return missing(spec, "input not given")
    return rule(spec, got, lines.get(role, {})) if needs_line else rule(spec, got)


def note(design: str, title: str, paper: ModuleType) -> str:
    """The paragraph under the claims table's title: which design, how the labels were obtained, and the
    paper's labels compared (its ``CLAIM_LABELS``)."""
    return (
        f"Design `{design}` ({title}). Labels: the labeller's verdicts stored in the sweep cubes (geardyn.label: "
        "each point follows the attractor of the previous one; period-n certified by shooting and its Floquet "
        f"multipliers, QP by the torus test, chaos by a positive exponent the torus test confirms). Paper labels "
        f"compared: {paper.CLAIM_LABELS}."
    )
