"""Where the labeller's periods go (``python -m benchmarks.bench stages``): the mesh periods integrated per point
by stage and by final label, the Newton shots and the candidate periods tried, and how long a record each
non-periodic verdict needs at the least against how long it is today (``docs/performance.md``).  The
labeller's runs are counted where its modules call the solver; nothing is timed."""

from __future__ import annotations

import collections
import copy
import dataclasses
import functools
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np

import geardyn.label._nonperiodic as nonperiodic
import geardyn.solve.run as run
from benchmarks.common import load_design, map_lines, workflow_config
from geardyn.label import label_lines, vocabulary
from geardyn.runs import maps, sweep
from geardyn.solve import Monodromy, Tangent, shooting, warm_up

#: the labeller's functions that name a stage, innermost first wins (the stage a run is counted under)
STAGES = {
    "_chord": "follow: chord",
    "_certify_states": "follow: monodromy",
    "follow": "follow: Newton",
    "integrate": "run from the previous attractor",
    "settle_points": "slow transients",
    "exponents": "tangent run",
    "long_periods": "search: returns (rule 3 to 240)",
    "_doubled": "search: period doubled",
    "locked": "search: gathered cycles",
    "_at_circle": "search: circled orbit",
    "longer_record": "record growth",
}
QP, CHAOS, UNDET = (vocabulary.LABELS[k] for k in ("quasi_periodic", "chaotic", "undetermined"))


def _stage() -> str:
    f = sys._getframe(2)
    while f is not None:
        name = STAGES.get(f.f_code.co_name)
        if name is not None:
            return name
        f = f.f_back
    return "other"


def _kind(v) -> str:
    if v.period == 1:
        return "P1"
    if 1 < v.period <= 12:
        return "P2-P12"
    if v.period > 12:
        return "long cycle"
    return {QP: "QP", CHAOS: "chaos", UNDET: "undetermined"}.get(v.label, "diverged")


#: the batch shooting iterations whose iterations are counted
_SHOOTERS = ("newton_shooting_batch", "chord_shooting_batch", "deflated_shooting_batch")


def _kind(variational) -> str:
    """The kind of run a lane's variational part makes."""
    return {Monodromy: "monodromy", Tangent: "tangent"}.get(type(variational), "plain")


class _Counter:
    """Counts the periods of every run the labeller asks for (by stage, kind of run and point), the Newton
    iterations and the candidate periods shot for."""

    def __init__(self) -> None:
        self.periods: list[tuple[str, str, int, int]] = []  # (stage, run kind, id of the system, periods)
        self.shots: list[tuple[str, int, int]] = []  # (stage, id of the system, iterations)
        self.sb, self.sim = run.simulate_batch, run.simulate
        self.shooters = {name: getattr(shooting, name) for name in _SHOOTERS}
        self.counted = {name: functools.partial(self.shooting_batch, f) for name, f in self.shooters.items()}

    def simulate_batch(self, lanes, settings=None, **kw):
        out = self.sb(lanes, settings or run.SimulationSettings(), **kw)
        stage = _stage()
        for q, r in zip(lanes, out, strict=True):
            n = r.diverged_period + 1 if r.diverged else r.transient_used + r.poincare.shape[0]
            self.periods.append((stage, _kind(q.variational), id(q.system), int(n)))
        return out

    def simulate(self, system, settings=None, x0=None, dense=False, variational=None):
        settings = settings or run.SimulationSettings()
        r = self.sim(system, settings, x0, dense, variational)
        n = r.diverged_period + 1 if r.diverged else settings.transient_periods + settings.recorded_periods
        self.periods.append((_stage(), _kind(variational), id(system), int(n)))
        return r

    def shooting_batch(self, shoot, shots, *args, **kw):
        out = shoot(shots, *args, **kw)
        stage = _stage()
        self.shots += [(stage, id(s.system), r.iterations + 1) for s, r in zip(shots, out, strict=True)]
        return out

    def __enter__(self) -> _Counter:
        own = {self.shooters[name]: self.counted[name] for name in _SHOOTERS}
        self._patch({self.sb: self.simulate_batch, self.sim: self.simulate, **own})
        return self

    def __exit__(self, *exc) -> None:
        own = {self.counted[name]: self.shooters[name] for name in _SHOOTERS}
        self._patch({self.simulate_batch: self.sb, self.simulate: self.sim, **own})

    @staticmethod
    def _patch(swap: dict) -> None:
        """Every geardyn module's name bound to a key of ``swap`` rebound to its value."""
        for mod in list(sys.modules.values()):
            if getattr(mod, "__name__", "").startswith("geardyn."):
                for name in ("simulate_batch", "simulate", *_SHOOTERS):
                    new = swap.get(getattr(mod, name, None))
                    if new is not None:
                        setattr(mod, name, new)


def _least(points: list, policy) -> None:
    """For each finished record labelled quasi-periodic or chaotic by the torus and exponent tests: the least
    record (from the labeller's first, every 50 periods to 1600, then every 200) on which those tests give
    that label."""
    for p in points:
        r, v = p.run, p.verdict
        if v.label not in (QP, CHAOS) or p.held is not None:
            continue
        first = r.growth.size
        lengths = [*range(first, min(r.poincare.shape[0], 1600) + 1, 50), *range(1800, r.poincare.shape[0], 200)]
        for n in [*lengths, r.poincare.shape[0]]:
            q = copy.copy(p)
            q.notes = []
            q.run = dataclasses.replace(r, poincare=r.poincare[:n], growth=r.growth[:n], strobe=r.strobe[:n])
            if nonperiodic._nonperiodic_verdict(q, policy).label == v.label:
                _LEAST.append((_kind(v), r.poincare.shape[0], n))
                break


_LEAST: list[tuple[str, int, int]] = []


def profile(lines: Sequence[Sequence], policy) -> tuple[list[list], _Counter, list[tuple[str, int, int]]]:
    """Label ``lines`` counting the runs, the shots and the least records (:func:`_least`)."""
    finish = nonperiodic.finish
    nonperiodic.finish = lambda points, pol: (finish(points, pol), _least(points, pol))[0]
    _LEAST.clear()
    try:
        with _Counter() as counter:
            verdicts = label_lines(lines, policy)
    finally:
        nonperiodic.finish = finish
    return verdicts, counter, list(_LEAST)


KINDS = ("P1", "P2-P12", "long cycle", "QP", "chaos", "undetermined")


def markdown(lines: Sequence[Sequence], verdicts: list[list], counter: _Counter, least: list) -> str:
    """The tables of :func:`profile`'s counts: periods per point by stage and label, shots, least records."""
    kind = {id(s): _kind(v) for line, vs in zip(lines, verdicts, strict=True) for s, v in zip(line, vs, strict=True)}
    points = collections.Counter(kind.values())
    cols = [k for k in KINDS if points[k]]
    per: dict[tuple[str, str], float] = collections.defaultdict(float)
    for stage, run_kind, sid, n in counter.periods:
        per[(f"{stage} ({run_kind})", kind.get(sid, "?"))] += n
    rows = sorted({r for r, _ in per}, key=lambda r: -sum(per[(r, c)] for c in cols))
    head = "| periods per point, by stage | " + " | ".join(f"{c} ({points[c]})" for c in cols) + " | all (M) |\n"
    out = head + "|---|" + "---:|" * (len(cols) + 1) + "\n"
    for r in rows:
        total = sum(per[(r, c)] for c in cols) / 1e6
        out += f"| {r} | " + " | ".join(f"{per[(r, c)] / points[c]:.1f}" for c in cols) + f" | {total:.2f} |\n"
    tot = {c: sum(per[(r, c)] for r in rows) for c in cols}
    out += "| **all** | " + " | ".join(f"**{tot[c] / points[c]:.0f}**" for c in cols)
    out += f" | **{sum(tot.values()) / 1e6:.2f}** |\n"
    shots: dict[tuple[str, str], list[int]] = collections.defaultdict(lambda: [0, 0])
    for stage, sid, it in counter.shots:
        cell = shots[(stage, kind.get(sid, "?"))]
        cell[0] += 1
        cell[1] += it
    srows = sorted({s for s, _ in shots})
    out += "\n| shots (attempts / iterations) per point | " + " | ".join(cols) + " |\n|---|" + "---:|" * len(cols)
    for s in srows:
        cells = (f"{shots[(s, c)][0] / points[c]:.2f} / {shots[(s, c)][1] / points[c]:.1f}" for c in cols)
        out += f"\n| {s} | " + " | ".join(cells) + " |"
    out += "\n\n| record (periods) | points | mean today | mean least | least <= 200 / 400 / 800 |\n"
    out += "|---|---:|---:|---:|---|\n"
    for k in ("QP", "chaos"):
        rec = [(n, m) for kk, n, m in least if kk == k]
        if rec:
            n, m = np.array(rec).T
            shares = " / ".join(f"{100 * np.mean(m <= b):.0f} %" for b in (200, 400, 800))
            out += f"| {k} | {len(rec)} | {n.mean():.0f} | {m.mean():.0f} | {shares} |\n"
    return out


def stages_benchmark(config_path: Path, what: str, rows: str = "0:200:10", log=print) -> str:
    """``what``: a map (``map_x1_e``; its rows ``rows``, start:stop:step) or ``design/sweep`` (chunk 0)."""
    config = workflow_config(config_path)
    root = config_path.resolve().parent.parent
    if "/" in what:
        dname, name = what.split("/")
        d = load_design(dname, config, root)
        spec = sweep.SweepSpec.from_config(name, config["sweeps"][name], dname, d.segment)
        policy = spec.policy(d)
        lines = [[s for _, s in line] for line in sweep.layout(d, spec, 0, policy).lines]
    else:
        raw = config["maps"][what]
        d = load_design(raw["designs"][0], config, root)
        spec = maps.MapSpec.from_config(what, raw, raw["designs"][0], d.segment)
        policy = spec.policy(d)
        lines = map_lines(d, spec, range(*map(int, rows.split(":"))))
    warm_up(lines[0][0])
    verdicts, counter, least = profile(lines, policy)
    md = f"{what}: {sum(map(len, lines))} points, lines: {len(lines)}\n\n" + markdown(lines, verdicts, counter, least)
    log(md)
    return md
