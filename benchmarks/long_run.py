"""Independent check of the labeller: random map points run long from their follow start."""

from __future__ import annotations

import dataclasses
import math
import time
from pathlib import Path
from typing import Any

import numpy as np

from benchmarks.common import map_lines, map_study
from geardyn.io import markdown_table
from geardyn.label import indicators, label_lines, vocabulary
from geardyn.label.compare import directed_distance, hausdorff
from geardyn.solve import SimulationSettings
from geardyn.solve.base import Lane, Tangent
from geardyn.solve.run import simulate_batch


def long_run_check(
    config_path: Path, map_name: str = "map_x1_b", n_points: int = 200, periods: int = 20000, seed: int = 0, log=print
) -> str:
    """Independent check of the labeller: ``n_points`` random points of a regime map, each run ``periods``
    mesh periods (plain RK4, no labeller) from the state its follow start used (the previous point's
    final state on its row, the static deflection for a row's first point).  A periodic verdict must be
    met by the long run's end: the same least period (rule 3 on its last periods, at least three cycles;
    up to ``long_max_n`` for a long cycle) and the same orbit within 1e-6 (every point the verdict stores, at
    most ``recorded_periods`` of a longer cycle, within 1e-6 of the long run's cycle).  A non-periodic verdict must
    not end on a cycle (rule 3 up to ``long_max_n`` on three of its longest periods)."""

    dname, design, spec, policy = map_study(config_path, map_name)
    rng = np.random.default_rng(seed)
    picks = sorted({(int(rng.integers(spec.y.num)), int(rng.integers(spec.x.num))) for _ in range(n_points)})
    rows = sorted({j for j, _ in picks})
    t0 = time.perf_counter()
    lines = map_lines(design, spec, rows)

    verdicts = dict(zip(rows, label_lines(lines, policy), strict=True))
    systems, starts, want = [], [], []
    for j, i in picks:
        row, line = verdicts[j], lines[rows.index(j)]
        systems.append(line[i])
        starts.append(row[i - 1].final_state if i > 0 and not row[i - 1].diverged else None)
        want.append(row[i])
    s = SimulationSettings(
        steps_per_period=policy.integration.steps_per_period,
        transient_periods=periods - 64,
        recorded_periods=64,
        early_stop=False,
    )
    # rule 3 up to the longest cycle the labeller looks for, on three of its periods (a periodic verdict: its
    # own period), so that a non-periodic verdict whose run ends on a long cycle is seen too
    cs = policy.classifier
    long_cs = dataclasses.replace(cs, max_n=cs.long_max_n)
    records = [max(64, 3 * (v.period if v.period > 0 else cs.long_max_n)) for v in want]
    runs = simulate_batch([Lane(c, x, recorded_periods=m) for c, x, m in zip(systems, starts, records, strict=True)], s)
    cells = []
    counts = {"periodic": [0, 0], "other": [0, 0]}
    for (j, i), v, r in zip(picks, want, runs, strict=True):
        n = 0 if r.diverged else indicators.strict_period(r.poincare, cs if 0 < v.period <= cs.max_n else long_cs)
        if v.period > 0:
            # the verdict keeps the newest ``recorded_periods`` points: a cycle longer than that is stored in
            # part, so every stored point must lie on the long run's cycle (with the same least period, the
            # same cycle); a shorter cycle is compared whole
            ours = v.poincare[: v.period]
            theirs = r.poincare[-v.period :]
            dist = float("inf")
            if not r.diverged:
                dist = hausdorff(theirs, ours) if ours.shape[0] == v.period else directed_distance(ours, theirs)
            ok = n == v.period and dist < 1e-6
            counts["periodic"][0] += ok
            counts["periodic"][1] += 1
        else:
            dist = float("nan")
            ok = n == 0 if v.label != vocabulary.LABELS["diverged"] else r.diverged
            counts["other"][0] += ok
            counts["other"][1] += 1
        if not ok or v.period == 0:
            at = (f"{spec.x.values[i]:.4g}", f"{spec.y.values[j]:.4g}")
            cells.append((*at, vocabulary.short_name(v.label), v.stage, n, f"{dist:.2g}", ok))
    head = (
        f"{map_name} of {dname}: {len(picks)} random points, {periods} periods each "
        f"({time.perf_counter() - t0:.0f} s). Periodic verdicts met by the long run (same least period, orbit "
        f"within 1e-6): {counts['periodic'][0]} of {counts['periodic'][1]}. Non-periodic verdicts whose long "
        f"run is still not periodic: {counts['other'][0]} of {counts['other'][1]}.\n\n"
    )
    log(head)
    header = ("x", "y", "verdict", "stage", "long run: rule-3 period", "orbit distance", "agrees")
    return head + markdown_table(header, cells, "rr--rr-") + "\n"


#: What a long run from a verdict's state ends on (:func:`ending`).
ENDINGS = ("torus", "short cycle", "long cycle", "chaos", "diverged")


def ending(
    poincare: np.ndarray, growth: np.ndarray, period: float, cs: indicators.ClassifierSettings
) -> tuple[str, int, float]:
    """What a long run ends on, from its newest Poincare points and its tangent vector's growth, without
    the labeller: a cycle when its newest points return after n periods (rule 3 up to ``long_max_n``, at
    least three cycles; "short" for n <= ``max_n``), chaos when the exponent over the run's newest half
    exceeds the zero tolerance ``lam_tol`` and three standard errors, else a torus.  Also the largest return
    distance after n periods over the newest points, relative to their size (:data:`CYCLE_RETURN`: below it
    the run has converged onto its cycle; above it rule 3's tolerance also admits a thin torus about an
    unstable cycle, which :func:`sweep_check` tells apart by shooting)."""
    if poincare.shape[0] == 0 or not np.all(np.isfinite(poincare)) or not np.all(np.isfinite(growth)):
        return "diverged", 0, math.nan
    n = indicators.strict_period(poincare, dataclasses.replace(cs, max_n=min(cs.long_max_n, poincare.shape[0] // 3)))
    if n > 0:
        size = float(np.max(poincare.std(axis=0))) or 1.0
        d = float(np.max(np.abs(poincare[n:] - poincare[:-n]))) / size
        return ("short cycle" if n <= cs.max_n else "long cycle"), n, d
    lam, sigma = indicators.lyapunov_estimate(growth[growth.size // 2 :], period, skip=0)
    return ("chaos" if lam > max(cs.lam_tol, 3.0 * sigma) else "torus"), 0, math.nan


#: :func:`ending`: a run whose newest points return after n periods closer than this (relative to their
#: size) has converged onto its period-n cycle
CYCLE_RETURN = 1e-8


def _unconverged_cycles(systems, runs, ends, settings) -> dict[int, float]:
    """The spectral radius of the period-n orbit that Newton shooting finds from the final state of every run
    that ends within rule 3's tolerance of a cycle but has not converged onto it (``ends[i]``: (ending, n,
    return distance)); NaN where shooting does not converge."""
    from geardyn.solve.shooting import Shot, newton_shooting_batch  # noqa: PLC0415

    todo: dict[int, list[int]] = {}
    for i, (_, n, d) in enumerate(ends):
        if n > 0 and not d < CYCLE_RETURN:
            todo.setdefault(n, []).append(i)
    out: dict[int, float] = {}
    for n, idx in sorted(todo.items()):
        shots = newton_shooting_batch([Shot(systems[i], runs[i].final_state) for i in idx], n, settings)
        for i, r in zip(idx, shots, strict=True):
            out[i] = r.spectral_radius if r.converged else math.nan
    return out


def _expected(label: int, period: int) -> str:
    """The ending a verdict promises."""
    if period > 0:
        return "short cycle" if label > 0 else "long cycle"
    return {vocabulary.LABELS["chaotic"]: "chaos", vocabulary.LABELS["quasi_periodic"]: "torus"}.get(label, "")


def sweep_check(
    config_path: Path,
    results: Path,
    labels: tuple[str, ...] = ("quasi_periodic",),
    n_points: int = 500,
    periods: int = 20000,
    seed: int = 0,
    log=print,
    designs: tuple[str, ...] = (),
) -> str:
    """Independent check of the labels of the built sweeps: ``n_points`` random points with one of
    ``labels`` (names of :data:`geardyn.label.vocabulary.LABELS`; ``periodic`` for P1 ... P12, ``all``) drawn from
    every sweep cube of every design the config lists under ``results``, each run ``periods`` mesh periods
    (plain RK4 with a tangent vector, no labeller) from its newest stored Poincare point.  The run's newest
    points and exponent say what it ends on (:func:`ending`); a verdict holds when that is what it promises
    (a periodic verdict: its own least period, and the stored points on the run's cycle within 1e-6 of the
    state's size).  ``designs``: only these designs' cubes (default: all).  The table holds a row per design and
    verdict: a share held in one design is not hidden by another's many points."""
    import xarray as xr  # noqa: PLC0415

    from benchmarks.common import load_design, workflow_config  # noqa: PLC0415
    from geardyn.khv import point  # noqa: PLC0415
    from geardyn.runs import sweep  # noqa: PLC0415

    config = workflow_config(config_path)
    root = config_path.resolve().parent.parent
    wanted = set(labels)
    pool: list[tuple[str, str, Any, int, int, int]] = []  # (design, sweep, spec, case, direction, index)
    cubes: dict[tuple[str, str], Any] = {}
    for name, raw in sorted(config["sweeps"].items()):
        for dname in designs or config["designs"]:  # the designs the sweep ran for are those with its cube
            path = results / dname / "sweeps" / f"{name}.nc"
            if not path.exists():
                continue
            d = load_design(dname, config, root)
            spec = sweep.SweepSpec.from_config(name, dict(raw), dname, d.segment)
            cube = xr.open_dataset(path).load()
            cubes[dname, name] = (d, spec, cube)
            for idx in zip(*np.nonzero(np.isin(cube["label"].values, _label_codes(wanted))), strict=True):
                pool.append((dname, name, spec, *map(int, idx)))
    rng = np.random.default_rng(seed)
    picks = [pool[k] for k in sorted(rng.choice(len(pool), size=min(n_points, len(pool)), replace=False))]
    log(f"{len(picks)} of {len(pool)} points with labels {sorted(wanted)} in {len(cubes)} sweep cubes")
    t0 = time.perf_counter()
    systems, starts, verdicts = [], [], []
    for dname, name, spec, case, direction, j in picks:
        d, _, cube = cubes[dname, name]
        value = float(cube[spec.parameter].values[j])
        systems.append(point.point_coefficients(d, sweep.point_overrides(spec, case, value)))
        stored = np.stack([cube[v].values[case, direction, j] for v in sweep.STATES], axis=1)
        stored = stored[np.all(np.isfinite(stored), axis=1)]
        starts.append(stored[-1])
        verdicts.append(
            (int(cube["label"].values[case, direction, j]), int(cube["period"].values[case, direction, j]), stored)
        )
    cs = indicators.ClassifierSettings()
    keep = 3 * cs.long_max_n
    # each point with its sweep's own integration (steps per period, contact switches located), no early stop
    settings = [
        dataclasses.replace(
            p[2].policy(cubes[p[:2]][0]).integration,
            transient_periods=periods - keep,
            recorded_periods=keep,
            early_stop=False,
        )
        for p in picks
    ]
    runs: list[Any] = [None] * len(picks)
    ends: list[Any] = [None] * len(picks)
    radius: dict[int, float] = {}
    for s in dict.fromkeys(settings):  # one batch per integration setting
        idx = [k for k, sk in enumerate(settings) if sk == s]
        group = simulate_batch([Lane(systems[k], starts[k], variational=Tangent(periods)) for k in idx], s)
        group_ends = [ending(r.poincare, r.growth, systems[k].period, cs) for k, r in zip(idx, group, strict=True)]
        for k, r, e in zip(idx, group, group_ends, strict=True):
            runs[k], ends[k] = r, e
        group_radius = _unconverged_cycles([systems[k] for k in idx], group, group_ends, s)
        radius.update({idx[i]: v for i, v in group_radius.items()})
    table: dict[str, dict[str, int]] = {}
    failed = []
    for k, (pick, (lab, per, stored), r) in enumerate(zip(picks, verdicts, runs, strict=True)):
        end, n, _ = ends[k]
        if k in radius and not radius[k] < 1.0:  # a thin torus about an unstable (or no) cycle
            end = "torus"
        want = _expected(lab, per)
        ok = end == want
        if ok and per > 0:  # the stored points on the run's cycle, within 1e-6 of the state's size
            scale = max(1.0, float(np.max(np.abs(stored))))
            ok = (
                n == per
                and directed_distance(stored[-min(per, stored.shape[0]) :], r.poincare[-3 * per :]) < 1e-6 * scale
            )
        kind = vocabulary.short_name(lab) if per <= 0 or lab > 0 else "long cycle"
        row = table.setdefault((pick[0], kind), dict.fromkeys(("held", *ENDINGS), 0))
        row["held" if ok else end] += 1
        if not ok:
            dname, name, spec, case, direction, j = pick
            value = float(cubes[dname, name][2][spec.parameter].values[j])
            where = (dname, name, spec.case_label(case), f"{value:.5g}")
            failed.append((*where, vocabulary.short_name(lab), f"{end} {n or ''}", f"{radius.get(k, math.nan):.6g}"))
    head = (
        f"{len(picks)} points of the sweeps under {results} ({', '.join(sorted(wanted))}), {periods} periods "
        f"each from the newest stored point ({time.perf_counter() - t0:.0f} s).\n\n"
    )
    cells = [
        (*k, sum(v.values()), v["held"], f"{100 * v['held'] / sum(v.values()):.1f} %", *(v[e] for e in ENDINGS))
        for k, v in sorted(table.items())
    ]
    header = ("design", "verdict", "points", "held", "share", *ENDINGS)
    body = markdown_table(header, cells, "--rrr" + "r" * len(ENDINGS)) + "\n"
    fails = ""
    if failed:
        header = ("design", "sweep", "case", "parameter", "verdict", "long run ends on", "shooting: spectral radius")
        fails = "\n" + markdown_table(header, failed, "---r--r") + "\n"
    log(head + body)
    return head + body + fails


def _label_codes(names: set[str]) -> list[int]:
    codes = dict(vocabulary.LABELS)
    out: list[int] = []
    for name in names:
        if name == "all":
            out += [codes[k] for k in ("long_period", "chaotic", "quasi_periodic")] + list(range(1, 13))
        elif name == "periodic":
            out += list(range(1, 13))
        else:
            out.append(codes[name])
    return out


#: :func:`growth_check`: the long run's findings ("bounded late": its envelope reaches its final level only after the
#: labeller's record cap)
FINDINGS = ("diverged", "still growing", "bounded late", "bounded")

#: :func:`settled_at`: blocks of the long run, and the envelope's tolerance about its final level
SETTLE_BLOCKS, SETTLE_TOL = 80, 0.1


def settled_at(poincare: np.ndarray) -> int:
    """The period from which a bounded run's envelope stays within :data:`SETTLE_TOL` of its final level: the
    amplitude of each point is its distance (max norm) from the median of the run's newest half, over that half's
    size (the largest standard deviation of a component); each of :data:`SETTLE_BLOCKS` blocks has its largest
    amplitude as envelope; the final level is the median envelope of the newest half's blocks."""
    p = np.asarray(poincare, dtype=float)
    newest = p[p.shape[0] // 2 :]
    size = float(np.max(newest.std(axis=0))) or 1.0
    amp = np.max(np.abs(p - np.median(newest, axis=0)), axis=1) / size
    length = p.shape[0] // SETTLE_BLOCKS
    env = amp[p.shape[0] - SETTLE_BLOCKS * length :].reshape(SETTLE_BLOCKS, length).max(axis=1)
    off = np.flatnonzero(np.abs(env / np.median(env[SETTLE_BLOCKS // 2 :]) - 1.0) > SETTLE_TOL)
    return int(off[-1] + 1) * length + p.shape[0] - SETTLE_BLOCKS * length if off.size else 0


@dataclasses.dataclass(frozen=True)
class _Changed:
    """A point whose label differs between two builds: where it is, its labels and the line it lies on (its
    systems in the order of travel, up to and with the point)."""

    design: str
    study: str
    index: tuple[int, ...]
    old: tuple[int, int]  # (label, period)
    new: tuple[int, int]
    line: tuple[str, int]  # (study, line number within it)
    position: int


@dataclasses.dataclass(frozen=True)
class _Study:
    """A map, sweep or frequency response as lines: its labelling policy, the line (key) and position of a cube
    index and back, and the systems of a line's positions [start, stop)."""

    policy: Any
    where: Any  # cube index -> (line key, position)
    index: Any  # (line key, position) -> cube index
    systems: Any  # (line key, start, stop) -> systems


def _study_lines(config: dict, root: Path, dname: str, kind: str, name: str) -> _Study:
    """A map's rows (x increasing), a sweep's lines (case, direction; in the direction's order) or a frequency
    response's two sweeps (up, down) as the runners build them."""
    from benchmarks.common import load_design  # noqa: PLC0415
    from geardyn.khv import point  # noqa: PLC0415
    from geardyn.runs import maps, response, sweep  # noqa: PLC0415

    d = load_design(dname, config, root)
    if kind == "maps":
        spec = maps.MapSpec.from_config(name, dict(config["maps"][name]), dname, d.segment)
        xs, ys = spec.x.values, spec.y.values
        bases = [point.point_coefficients(d, {**dict(spec.fixed), spec.x.parameter: float(x)}) for x in xs]
        return _Study(
            spec.policy(d),
            lambda idx: ((idx[0],), idx[1]),
            lambda key, pos: (key[0], pos),
            lambda key, a, b: [maps.point_coefficients(d, spec, xs[i], ys[key[0]], bases[i]) for i in range(a, b)],
        )
    if kind == "sweeps":
        sw = sweep.SweepSpec.from_config(name, dict(config["sweeps"][name]), dname, d.segment)

        def order(key: tuple[int, ...]) -> list[int]:
            return list(range(sw.num))[:: -1 if sw.directions[key[1]] == "down" else 1]

        return _Study(
            sw.policy(d),
            lambda idx: ((idx[0], idx[1]), order(idx[:2]).index(idx[2])),
            lambda key, pos: (*key, order(key)[pos]),
            lambda key, a, b: [
                point.point_coefficients(d, sweep.point_overrides(sw, key[0], sw.values[j])) for j in order(key)[a:b]
            ],
        )
    rs = response.ResponseSpec.from_config(name, dict(config["responses"][name]), dname, d.segment)
    base, w = point.point_coefficients(d, dict(rs.fixed)), rs.values

    def at(key: tuple[int, ...], pos: int) -> tuple[int, int]:
        return (key[0], pos if key[0] == 0 else w.size - 1 - pos)

    return _Study(
        rs.policy(d),
        lambda idx: ((idx[0],), at((idx[0],), idx[1])[1]),
        at,
        lambda key, a, b: [base.replace(omega=float(w[at(key, k)[1]])) for k in range(a, b)],
    )


def _finding(r, system, policy, periods: int, cap: int) -> tuple[str, int, str, str]:
    """What a long run ``r`` of ``system`` shows: one of :data:`FINDINGS` ("still growing": the growth test of
    ``policy`` on its newest half; "bounded late": its envelope settles (:func:`settled_at`) after the record cap
    ``cap``), the least period of a bounded run (rule 3 up to the long search's reach ``long_max_n``, on its newest
    3 ``long_max_n`` periods; 0: none), what :func:`ending` reads where the run carried a tangent vector (""
    otherwise), and the detail in words."""
    from geardyn.label.growth import growth_test  # noqa: PLC0415

    if r.diverged:
        return "diverged", 0, "diverged", f"diverges in period {r.diverged_period}"
    half = periods // 2
    last = growth_test(r.poincare[-half:], policy.growth)
    if last.growing:
        return "still growing", 0, "", f"newest {half} periods: {last.describe()}"
    cs = policy.classifier
    tail = r.poincare[-3 * cs.long_max_n :]
    n = indicators.strict_period(tail, dataclasses.replace(cs, max_n=cs.long_max_n))
    end = ending(tail, r.growth, system.period, cs)[0] if r.growth is not None and r.growth.size else ""
    cycle = f"a cycle of period {n}" if n else f"no cycle up to {cs.long_max_n}"
    at = settled_at(r.poincare)
    settle = f"envelope within {100 * SETTLE_TOL:.0f} % of its final level from period {at} (cap {cap})"
    return ("bounded late" if at > cap else "bounded"), n, end, f"{cycle}; {settle}"


def _consistent(label: int, period: int, finding: str, n: int, end: str) -> bool | None:
    """Whether a verdict agrees with its long run: transient with a run still growing, diverging or bounded
    only late; undetermined with anything; diverged with a diverged run; a cycle with the long run's least
    period; QP and chaos with :func:`ending`'s torus and chaos (None where the run carried no tangent vector)."""
    L = vocabulary.LABELS
    if label == L["undetermined"]:
        return True
    if label == L["transient"]:
        return finding != "bounded"
    if label == L["diverged"]:
        return finding == "diverged"
    if finding in ("diverged", "still growing"):
        return False
    if period > 0:
        return n == period
    if n > 0:
        return False
    if not end:
        return None
    return end == {L["chaotic"]: "chaos", L["quasi_periodic"]: "torus"}.get(label, "")


def changed_points(config_path: Path, old: Path, new: Path) -> tuple[list[_Changed], dict[str, Any]]:
    """Every point of the maps, sweeps and frequency responses of the workflow config whose label differs between
    the builds ``old`` and ``new`` (``results/`` directories), and each study's lines (:func:`_study_lines`)."""
    import xarray as xr  # noqa: PLC0415

    from benchmarks.common import workflow_config  # noqa: PLC0415

    config = workflow_config(config_path)
    root = config_path.resolve().parent.parent
    out: list[_Changed] = []
    studies: dict[str, Any] = {}
    for dname in config["designs"]:
        for kind, section in (("maps", "maps"), ("sweeps", "sweeps"), ("response", "responses")):
            for name in config.get(section, {}):
                a, b = old / dname / kind / f"{name}.nc", new / dname / kind / f"{name}.nc"
                if not (a.exists() and b.exists()):
                    continue
                x, y = xr.open_dataset(a).load(), xr.open_dataset(b).load()
                moved = np.argwhere(x["label"].values != y["label"].values)
                if not moved.size:
                    continue
                key = f"{dname}/{kind}/{name}"
                # drift: a periodic point whose label stays but whose record (its orbit) differs between the builds
                same = np.ones(x["label"].shape, bool)
                for v in ("final_state", "x_dh", "lyapunov", "dte_rms"):
                    if v in x and v in y:
                        a_, b_ = x[v].values, y[v].values
                        eq = (a_ == b_) | (np.isnan(a_) & np.isnan(b_))
                        same &= eq.reshape(*same.shape, -1).all(axis=-1)
                drift = ~same & (x["label"].values == y["label"].values) & (y["period"].values > 0)
                studies[key] = (_study_lines(config, root, dname, kind, name), x["label"].values, drift)
                for idx in map(tuple, moved.tolist()):
                    line, pos = studies[key][0].where(idx)
                    before = (int(x["label"].values[idx]), int(x["period"].values[idx]))
                    after = (int(y["label"].values[idx]), int(y["period"].values[idx]))
                    out.append(_Changed(dname, f"{kind}/{name}", idx, before, after, (key, *line), pos))
    return out, studies


def new_build_start(study: _Study, drift: np.ndarray, c: _Changed) -> bool:
    """Whether the follow start of ``c`` labelled again is the new build's: no periodic point before it on its line
    keeps its label on another orbit (``drift``: label alike, record unlike).  A point whose record grew hands the
    line the verdict before the growth test (``Point.handed``), whatever it ends on; a periodic point on another
    orbit (another point of the same cycle within the shooting tolerance) does not."""
    return not any(drift[study.index(c.line[1:], q)] for q in range(c.position))


def growth_check(
    config_path: Path,
    old: Path,
    new: Path,
    map_points: int = 300,
    periods: int = 20000,
    seed: int = 0,
    log=print,
    csv: Path | None = None,
) -> str:
    """Independent check of the points whose label differs between the builds ``old`` and ``new``: each run
    ``periods`` mesh periods by the plain RK4 integrator (the study's steps per period, no labeller) from the
    state its follow start used (the previous point's final state on its line, labelled again with the growth
    test off, as the line goes on from the verdict before the test; the static deflection for a line's first
    point or after a diverged one).  Every changed point of the sweeps and frequency responses, a uniform
    random sample of ``map_points`` per map (``seed``).  The long run shows :data:`FINDINGS`; a verdict holds
    as :func:`_consistent` says.  The start is the new build's where no earlier periodic point of the line keeps its
    label with another record (its final state, Poincare section, exponent and RMS DTE as stored,
    :func:`new_build_start`); elsewhere (a line that goes on from another point of the same orbit) the check tests
    the old build's start.  Returns the tables per study and per label move, with the share
    held and its 95 % Clopper-Pearson interval; ``csv``: the per-point list."""
    from scipy import stats  # noqa: PLC0415

    from geardyn.label.policy import GrowthSettings  # noqa: PLC0415

    t0 = time.perf_counter()
    points, studies = changed_points(config_path, old, new)
    rng = np.random.default_rng(seed)
    picks: list[_Changed] = []
    sampled: dict[str, tuple[int, int]] = {}
    for key in studies:
        mine = [c for c in points if c.line[0] == key]
        if "/maps/" in key and len(mine) > map_points:
            mine = [mine[k] for k in sorted(rng.choice(len(mine), size=map_points, replace=False))]
        sampled[key] = (len(mine), sum(c.line[0] == key for c in points))
        picks += mine
    log(f"{len(picks)} of {len(points)} changed points: " + ", ".join(f"{k} {a}/{b}" for k, (a, b) in sampled.items()))
    # the follow starts: each line labelled again up to its last picked point, with the growth test off
    starts: dict[_Changed, Any] = {}
    relabelled = [0, 0]  # previous points labelled again, of them with the old build's label
    alike: dict[_Changed, bool] = {}  # the previous point's record alike in both builds: the new build's start
    for key, (study, old_labels, drift) in studies.items():
        lines: dict[tuple, int] = {}
        for c in picks:
            if c.line[0] == key and c.position > 0:
                lines[c.line] = max(lines.get(c.line, 0), c.position)
        keys = sorted(lines)
        off = dataclasses.replace(study.policy, growth=GrowthSettings(blocks=0))
        t1 = time.perf_counter()
        rows = label_lines([study.systems(k[1:], 0, lines[k]) for k in keys], off) if keys else []
        log(f"{key}: {len(keys)} lines, {sum(lines.values())} points labelled again ({time.perf_counter() - t1:.0f} s)")
        verdicts = dict(zip(keys, rows, strict=True))
        for c in picks:
            if c.line[0] != key:
                continue
            prev = verdicts[c.line][c.position - 1] if c.position > 0 else None
            starts[c] = None if prev is None or prev.diverged else prev.final_state
            alike[c] = new_build_start(study, drift, c)
            if prev is not None:
                relabelled[0] += 1
                relabelled[1] += prev.label == int(old_labels[study.index(c.line[1:], c.position - 1)])
    # the long runs, one batch per integration (and tangent vector: where a verdict claims a cycle, QP or chaos)
    L = vocabulary.LABELS
    plain = {L["transient"], L["undetermined"], L["diverged"]}
    groups: dict[tuple, list[_Changed]] = {}
    for c in picks:
        s = dataclasses.replace(
            studies[c.line[0]][0].policy.integration, transient_periods=0, recorded_periods=periods, early_stop=False
        )
        groups.setdefault((s, not {c.old[0], c.new[0]} <= plain), []).append(c)
    found: dict[_Changed, tuple[str, int, str, str]] = {}
    for (s, tangent), group in groups.items():
        for k in range(0, len(group), 64):  # 64 records of ``periods`` periods at a time
            part = group[k : k + 64]
            systems = [studies[c.line[0]][0].systems(c.line[1:], c.position, c.position + 1)[0] for c in part]
            t1 = time.perf_counter()
            runs = simulate_batch(systems, s, [starts[c] for c in part], tangent_periods=periods if tangent else 0)
            for c, sy, r in zip(part, systems, runs, strict=True):
                pol = studies[c.line[0]][0].policy
                found[c] = _finding(r, sy, pol, periods, pol.classifier.torus_max_periods)
            log(f"{len(found)} of {len(picks)} long runs ({time.perf_counter() - t1:.0f} s for {len(part)})")
    rows_out = []
    tally: dict[tuple[str, str, str], list[int]] = {}
    for c in picks:
        word, n, end, detail = found[c]
        ok_new = _consistent(*c.new, word, n, end)
        ok_old = _consistent(*c.old, word, n, end)
        old_name, new_name = vocabulary.short_name(c.old[0]), vocabulary.short_name(c.new[0])
        where = (c.design, c.study, " ".join(map(str, c.index)))
        rows_out.append((*where, old_name, new_name, word, end, detail, ok_new, ok_old, alike[c]))
        t = tally.setdefault((c.design, c.study, f"{old_name} -> {new_name}"), [0, 0, 0, 0])
        t[0] += 1
        t[1] += ok_new is True
        t[2] += ok_old is True
        t[3] += alike[c]
    if csv is not None:
        header = "design,study,index,old_label,new_label,long_run,ending,detail,new_consistent,old_consistent,"
        header += "start_as_new_build\n"
        body = "".join(
            ",".join(f'"{v}"' if isinstance(v, str) and "," in v else str(v) for v in r) + "\n" for r in rows_out
        )
        csv.write_text(header + body)

    def share(k: int, n: int) -> str:
        lo, hi = stats.binomtest(k, n).proportion_ci(0.95) if n else (math.nan, math.nan)
        return f"{k} of {n} ({100 * k / n:.0f} %, {100 * lo:.0f}-{100 * hi:.0f} %)"

    cells = [(*k, *(share(v[i], v[0]) for i in (1, 2)), v[3]) for k, v in sorted(tally.items())]
    counts = {}
    for r in rows_out:
        counts.setdefault((r[0], r[1], f"{r[3]} -> {r[4]}"), dict.fromkeys(FINDINGS, 0))[r[5]] += 1
    cells = [(*c, *counts[c[:3]].values()) for c in cells]
    head = (
        f"{len(picks)} of the {len(points)} points whose label differs between {old} and {new} (all of the sweeps' "
        f"and responses', of each map's all or a random {map_points}, seed {seed}), each run {periods} mesh periods "
        f"by the plain RK4 integrator from its follow start (the previous points labelled again with the growth test "
        f"off keep the old build's label at {relabelled[1]} of {relabelled[0]}; "
        f"{time.perf_counter() - t0:.0f} s).\n\n"
    )
    header = ("design", "study", "move", "new verdict holds (95 % CI)", "old verdict holds", "start as new", *FINDINGS)
    body = markdown_table(header, cells, "---rrr" + "r" * len(FINDINGS)) + "\n"
    log(head + body)
    return head + body
