"""The labels of two builds compared cube by cube, and the differing points labelled again."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import xarray as xr

from benchmarks.common import load_design, workflow_config
from geardyn.io import markdown_table
from geardyn.khv import point
from geardyn.label import STAGE_NAMES, label_points
from geardyn.label.vocabulary import LABELS, short_name
from geardyn.runs import maps, sweep

# ----------------------------------------------------------------------------------------------
# the labeller's starts compared (one run), two builds' labels compared, long-run check
# ----------------------------------------------------------------------------------------------


def confusion(old_labels, new_labels) -> tuple[list[int], np.ndarray]:
    """Confusion matrix (rows: the first labels, columns: the second) over the codes present."""
    codes = sorted(set(old_labels) | set(new_labels))
    m = np.zeros((len(codes), len(codes)), np.int64)
    pos = {c: k for k, c in enumerate(codes)}
    for a, b in zip(old_labels, new_labels, strict=True):
        m[pos[a], pos[b]] += 1
    return codes, m


def confusion_markdown(codes, m, first: str = "previous", second: str = "new") -> str:

    head = (f"{first} \\ {second}", *(short_name(c) for c in codes))
    cells = [(short_name(c), *(int(v) for v in m[k])) for k, c in enumerate(codes)]
    return markdown_table(head, cells, "-" + "r" * len(codes))


def compare_builds(old: Path, new: Path) -> str:
    """The labels of every sweep cube and map that two builds' ``results/`` share, compared point by point
    (by data content): a confusion matrix per cube, the share of the earlier build's decided labels the
    new one repeats (points flagged ``coexisting`` left out), the new build's undetermined share and the
    stages that decided it."""

    cells, parts = [], []
    for path in sorted(list(new.glob("*/sweeps/*.nc")) + list(new.glob("*/maps/*.nc"))):
        rel = path.relative_to(new)
        if path.name.startswith("chunk_") or not (old / rel).exists():
            continue
        with xr.open_dataset(old / rel) as a, xr.open_dataset(path) as b:
            lo, ln = a["label"].values.ravel(), b["label"].values.ravel()
            coex = b["coexisting"].values.ravel() == 1 if "coexisting" in b else np.zeros(ln.size, bool)
            stage = b["stage"].values.ravel() if "stage" in b else None
        und = LABELS["undetermined"]
        decided = (lo != und) & ~coex
        same_dec = int(np.sum((lo == ln) & decided))
        same = f"{int(np.sum(lo == ln))} ({np.mean(lo == ln):.1%})"
        kept = f"{same_dec} of {int(decided.sum())} ({same_dec / max(1, int(decided.sum())):.2%})"
        cells.append((rel, lo.size, same, kept, f"{np.mean(lo == und):.1%}", f"{np.mean(ln == und):.1%}"))
        codes, m = confusion(lo.tolist(), ln.tolist())
        parts += ["", f"### {rel}", "", confusion_markdown(codes, m)]
        if stage is not None:
            u, c = np.unique(stage, return_counts=True)
            parts.append(
                "\nstages now: "
                + ", ".join(f"{STAGE_NAMES.get(int(k), 'not computed')} {int(n)}" for k, n in zip(u, c, strict=True))
            )
    head = ("cube", "points", "same label", "decided before, same now (no coexistence)", "undetermined before")
    return "\n".join([markdown_table((*head, "undetermined now"), cells, "-rrrrr"), *parts]) + "\n"


#: the class of a point whose fixed start gives the earlier label and whose follow start another attractor
COEXISTENCE = "coexistence: the fixed start ends on the earlier label, the follow start on another attractor"


def explain_differences(config_path: Path, old: Path, new: Path, design: str, kind: str, name: str, log=print) -> str:
    """Every point of one cube (``kind`` sweeps or maps) whose earlier label was decided and differs from the
    new one, labelled again from the fixed start (the static deflection) by the new labeller: where that
    gives the earlier label, the follow start found another attractor at the same point (coexistence, as
    a run with ``coexistence: true`` would flag it); else the class of the change (the earlier label was a
    slow transient or undetermined, a boundary point, ...)."""

    root = config_path.resolve().parent.parent
    config = workflow_config(config_path)
    d = load_design(design, config, root)
    rel = Path(design) / kind / f"{name}.nc"
    with xr.open_dataset(old / rel) as a, xr.open_dataset(new / rel) as b:
        lo, ln = a["label"].values, b["label"].values
    where = np.argwhere((lo != ln) & (lo != LABELS["undetermined"]))
    if kind == "maps":
        spec = maps.MapSpec.from_config(name, config["maps"][name], design, d.segment)
        policy = spec.policy(d)
        systems = [maps.point_coefficients(d, spec, spec.x.values[i], spec.y.values[j]) for j, i in where]
    else:
        spec = sweep.SweepSpec.from_config(name, config["sweeps"][name], design, d.segment)
        policy = spec.policy(d)
        systems = [point.point_coefficients(d, sweep.point_overrides(spec, c, spec.values[j])) for c, _, j in where]
    t0 = time.perf_counter()
    fixed = label_points(systems, policy.with_start("fixed"))
    classes: dict[str, int] = {}
    examples: dict[str, str] = {}
    for idx, v in zip(where, fixed, strict=True):
        before, now = int(lo[tuple(idx)]), int(ln[tuple(idx)])
        if v.label == before:
            key = COEXISTENCE
        elif now == LABELS["undetermined"]:
            key = "now undetermined: the indicators disagree on the follow start"
        elif v.label == now:
            key = "both starts now agree on the new label (the earlier path decided otherwise)"
        else:
            key = "three different labels (a boundary point or a third attractor)"
        classes[key] = classes.get(key, 0) + 1
        examples.setdefault(
            key,
            f"{tuple(int(k) for k in idx)}: before {short_name(before)}, follow {short_name(now)}, "
            f"fixed {short_name(v.label)} ({v.stage})",
        )
    log(f"[{rel}] {len(where)} differing points relabelled from the fixed start in {time.perf_counter() - t0:.0f} s")
    decided = int(np.sum(lo != LABELS["undetermined"]))
    same = int(np.sum((lo == ln) & (lo != LABELS["undetermined"])))
    coexisting = classes.get(COEXISTENCE, 0)
    lines = [
        f"### {rel}: {len(where)} points decided before and labelled otherwise now",
        "",
        f"Decided before and the same now: {same} of {decided} ({same / max(1, decided):.2%}); with the "
        f"{coexisting} coexisting points left out: {same} of {decided - coexisting} "
        f"({same / max(1, decided - coexisting):.2%}). A run with `coexistence: true` flags these and may flag "
        "more, among points whose label is the same; leaving k such points out gives (same - k) / (decided - "
        f"{coexisting} - k), at least 99 % while k <= {max(0, int((same - 0.99 * (decided - coexisting)) / 0.01))}.",
        "",
    ]
    cells = [(k, n, examples[k]) for k, n in sorted(classes.items(), key=lambda kv: -kv[1])]
    return "\n".join([*lines, markdown_table(("class", "points", "example (index: labels)"), cells, "-r")]) + "\n"
