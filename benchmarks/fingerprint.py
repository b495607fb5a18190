"""The fingerprint: a small fixed study whose numbers two machines compare by reading one line each.

``python -m benchmarks.bench fingerprint`` runs it and prints one hash per stage, then the machine's CPU
and the process settings that decide the bits (the C library's math build, OpenBLAS's kernels, numpy's
dispatch, numba's target).  ``tests/test_fingerprint.py`` runs the same study and compares it with the
committed reference (``benchmarks/fingerprint.txt``) stage by stage, naming the first stage that differs.

The stages, in the order the numbers flow:

* ``coefficients``: every shipped design's model coefficients.  A KHV design: the dimensionless
  coefficients, the static state and the step tables at one point of its segment; a plus set: its mass and
  stiffness matrices, natural frequencies and the static TE.
* ``records``: the Poincare records and final states of the non-chaotic lines labelled (a periodic line,
  a followed torus, a long cycle).
* ``torus_digits``, ``order_gaps``, ``candidate_periods``: what the torus test, the order test and the
  long-cycle search computed on those records, call by call.
* ``verdicts``: label, period, stage, multiplier and exponent of every non-chaotic verdict.
* ``chaos_statistics``: a chaotic line is compared by its statistics, not its bits (a last-bit difference
  anywhere upstream moves a chaotic orbit to another one on the same attractor): its labels, and its
  exponents and record spread rounded to two significant digits.  The test compares these with a tolerance.
* ``response``: the response measures (RMS, peak, impact fractions ...) of frequency-response points.
* ``continuation``: a short continuation of the period-1 orbit of ``li2013`` over e, with its typed and
  located events.

Every hash is the first 16 hex digits of a sha256 of float64 / int64 arrays in a fixed order, so two
machines agree on a stage only if every bit of it agrees.  The study takes about 20 s on one core.
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = Path(__file__).with_name("fingerprint.txt")

#: The stages whose bits are compared, in the order the numbers flow; ``chaos_statistics`` is compared by
#: value (:data:`CHAOS_RTOL`).
STAGES = (
    "coefficients",
    "records",
    "torus_digits",
    "order_gaps",
    "candidate_periods",
    "verdicts",
    "chaos_statistics",
    "response",
    "continuation",
)
CHAOS_RTOL = 0.25  # chaotic statistics from 150-200 periods: different orbits on one attractor agree so far

#: A row of ``li2013_calibrated``'s map over (x1, e) (row 72 of 200, b = 2): from x1 = 0.416 the followed
#: line is a torus for seven points, then locks to a stable period-31 cycle that shooting certifies.
TORUS_ROW = {"design": "li2013_calibrated", "x1": np.linspace(0.416, 0.835, 200)[:9], "e": 5.5 * 72 / 199}
#: ``li2013`` at the paper's b = 2, e = 5: period-1 motion.
PERIODIC_LINE = {"design": "li2013", "x1": np.linspace(0.45, 0.8, 4), "e": 5.0}
#: ``li2013_route`` past its P12 window: chaotic motion.
CHAOTIC_LINE = {"design": "li2013_route", "x1": np.array([0.80, 0.805, 0.81]), "e": 5.0}
#: frequency-response points of ``li2013`` (x1 = 0.5, b = 2, e = 5) over the mesh frequency
RESPONSE_W = np.array([0.7, 0.9, 1.1, 1.3])


def _h(*arrays: Any) -> str:
    """sha256 (16 hex digits) of the arrays' bytes as float64, or int64 for integer data, in order."""
    h = hashlib.sha256()
    for a in arrays:
        a = np.asarray(a)
        a = a.astype(np.int64) if a.dtype.kind in "iub" else a.astype(np.float64)
        h.update(str(a.shape).encode())
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()[:16]


def _text_hash(items: list[str]) -> str:
    return hashlib.sha256("\n".join(items).encode()).hexdigest()[:16]


@contextmanager
def _recording(module: Any, name: str, into: list[bytes], keep: Callable[[tuple, Any], Any]) -> Iterator[None]:
    """Record every call of ``module.name`` while the block runs: its first argument's bytes (an array) and
    ``keep(args, result)`` as float64 or int64 bytes.  The calls may come from several threads in any order
    (the labeller tests the points of a round in a thread pool), so the stage hashes them sorted."""
    original = getattr(module, name)

    def wrapped(*args: Any, **kwargs: Any) -> Any:
        out = original(*args, **kwargs)
        given = np.ascontiguousarray(args[0]).tobytes() if isinstance(args[0], np.ndarray) else b""
        kept = np.asarray(keep(args, out))
        kept = kept.astype(np.int64 if kept.dtype.kind in "iub" else np.float64)
        into.append(hashlib.sha256(given).digest() + kept.tobytes())
        return out

    setattr(module, name, wrapped)
    try:
        yield
    finally:
        setattr(module, name, original)


def _calls_hash(calls: list[bytes]) -> str:
    return hashlib.sha256(b"".join(sorted(calls))).hexdigest()[:16] if calls else "none"


#: The designs shipped in ``config/designs/`` (a user's own design files beside them do not enter).
SHIPPED_DESIGNS = ("li2013", "li2013_calibrated", "li2013_printed", "li2013_route", "yue2014")


def _design_hashes() -> list[str]:
    """One hash per shipped design (:data:`SHIPPED_DESIGNS`), of its coefficients (module docstring)."""
    import yaml  # noqa: PLC0415

    from geardyn.khv import design as khv_design  # noqa: PLC0415
    from geardyn.khv import point  # noqa: PLC0415
    from geardyn.plus import design as plus_design  # noqa: PLC0415
    from geardyn.plus import ishikawa, modal  # noqa: PLC0415
    from geardyn.solve import SimulationSettings  # noqa: PLC0415
    from geardyn.solve.run import lane_tables  # noqa: PLC0415

    out = []
    for path in (ROOT / "config" / "designs" / f"{name}.yaml" for name in SHIPPED_DESIGNS):
        kind = yaml.safe_load(path.read_text()).get("kind", "khv")
        if kind == "khv":
            d = khv_design.load(path)
            lo, hi = d.segment
            c = point.point_coefficients(d, {"x1": 0.5 * (lo + hi), "b": 2.0, "e": 5.0})
            tabs = lane_tables([c], SimulationSettings(steps_per_period=128))
            arrays = [c.kernel_array(), c.static_state(), c.stiffness_polys()]
            arrays += [getattr(tabs, k) for k in ("C", "H", "S", "SEG", "K", "P", "POLY")]
        else:
            d = plus_design.load(path)
            arrays = []
            for condition in modal.CONDITIONS:
                m = modal.matrices(d, condition)
                arrays += [m.M, m.K, m.C, modal.modes(d, condition).omega2]
            te = ishikawa.design_te(d)
            arrays += [np.asarray(v) for v in dataclasses.asdict(te).values() if isinstance(v, np.ndarray)]
        out.append(f"{path.stem}:{_h(*arrays)}")
    return out


def _line(spec: dict[str, Any], **fixed: float) -> list[Any]:
    from geardyn.khv import design, point  # noqa: PLC0415

    d = design.load(ROOT / "config" / "designs" / f"{spec['design']}.yaml")
    return [point.point_coefficients(d, {"x1": float(x), "b": 2.0, "e": float(spec["e"]), **fixed}) for x in spec["x1"]]


def study() -> dict[str, str]:
    """Run the study; the stage names (:data:`STAGES`) mapped to their hashes (``chaos_statistics`` to its
    values as text)."""
    import geardyn  # noqa: F401, PLC0415 - first: the process settings
    from geardyn.khv import design, point  # noqa: PLC0415
    from geardyn.label import (  # noqa: PLC0415
        Policy,
        indicators,
        label_lines,
    )
    from geardyn.label import _cycles as cycles  # noqa: PLC0415
    from geardyn.label import _nonperiodic as nonperiodic  # noqa: PLC0415
    from geardyn.runs import continuation as C  # noqa: PLC0415
    from geardyn.solve import SimulationSettings, simulate  # noqa: PLC0415
    from geardyn.solve.response import response_measures_many  # noqa: PLC0415

    out: dict[str, str] = {"coefficients": _text_hash(_design_hashes())}

    settings = SimulationSettings(steps_per_period=128, transient_periods=400, recorded_periods=50)
    cs = dataclasses.replace(
        indicators.ClassifierSettings(error_floor=1.9e-5, tangent_periods=200), torus_max_periods=16000
    )
    lines = [_line(PERIODIC_LINE), _line(TORUS_ROW), _line(CHAOTIC_LINE)]
    digits: list[bytes] = []
    gaps: list[bytes] = []
    tried: list[bytes] = []
    with (
        _recording(nonperiodic, "torus_digits", digits, lambda a, r: np.asarray(r, dtype=float)),
        _recording(nonperiodic, "order_test", gaps, lambda a, r: np.asarray(r.gaps, dtype=np.int64)),
        _recording(cycles, "order_test", gaps, lambda a, r: np.asarray(r.gaps, dtype=np.int64)),
        _recording(cycles, "_try_periods", tried, lambda a, r: [n for n in a[1] if n > 0]),
    ):
        periodic, torus, chaotic = label_lines(lines, Policy(settings, cs))
    regular = periodic + torus
    out["records"] = _h(*[v.poincare for v in regular], *[v.final_state for v in regular])
    out["torus_digits"] = _calls_hash(digits)
    out["order_gaps"] = _calls_hash(gaps)
    out["candidate_periods"] = _calls_hash(tried)
    out["verdicts"] = (
        _h(
            [v.label for v in regular],
            [v.period for v in regular],
            [v.multiplier for v in regular],
            [v.exponent for v in regular],
        )
        + ":"
        + _text_hash([v.stage for v in regular])
    )
    out["chaos_statistics"] = " ".join(
        f"{v.label}/{_sig2(v.exponent)}/{_sig2(float(np.max(np.std(v.poincare, axis=0))))}" for v in chaotic
    )

    li2013 = design.load(ROOT / "config" / "designs" / "li2013.yaml")
    response_line = [
        point.point_coefficients(li2013, {"x1": 0.5, "b": 2.0, "e": 5.0, "w": float(w)}) for w in RESPONSE_W
    ]
    verdicts = label_lines([response_line], Policy(settings, cs))[0]
    measures = response_measures_many(response_line, [v.final_state for v in verdicts], settings)
    numbers = [[x for x in dataclasses.astuple(m) if not isinstance(x, str)] for m in measures]
    words = [x for m in measures for x in dataclasses.astuple(m) if isinstance(x, str)]
    out["response"] = _h(*[np.asarray(n, dtype=float) for n in numbers]) + ":" + _text_hash(words)

    fam = C.KHVFamily(li2013, "e", {"x1": 0.5, "b": 2.0}, 0.0, 1.0, nodes=5)
    r = simulate(fam.coefficients(0.05), SimulationSettings(transient_periods=2000, recorded_periods=1))
    br = C.continue_branch(fam, 0.05, r.final_state, 1, 0.0, 1.0, C.ContinuationSettings(ds=0.02, ds_max=0.02))
    events = [(b.kind, b.p, b.located) for b in br.bifurcations] if br is not None else []
    out["continuation"] = (
        _h(br.p, br.states, br.multipliers.real, br.multipliers.imag, [p for _, p, _ in events])
        + ":"
        + _text_hash([f"{k}/{loc}" for k, _, loc in events])
        if br is not None
        else "none"
    )
    return {k: out[k] for k in STAGES}


def _sig2(x: float) -> str:
    return "nan" if not math.isfinite(x) else f"{x:.1e}"


def machine() -> dict[str, str]:
    """The CPU and the process settings that decide the bits (from the provenance)."""
    from geardyn.io import provenance  # noqa: PLC0415

    p = provenance.runtime()
    keys = ("cpu_model", "libm_variant", "numpy_blas_core", "scipy_blas_core", "numpy_cpu_dispatch", "numba_cpu_name")
    return {k: p[k] for k in keys}


def format_lines(stages: dict[str, str]) -> str:
    """The fingerprint as ``stage: hash`` lines, then the one line two machines compare: the hash of every
    stage compared bit for bit (all but ``chaos_statistics``, which is compared by value)."""
    body = "".join(f"{k}: {v}\n" for k, v in stages.items())
    bits = "".join(f"{k}: {v}\n" for k, v in stages.items() if k != "chaos_statistics")
    return body + f"fingerprint: {hashlib.sha256(bits.encode()).hexdigest()[:16]}\n"


def read_reference(path: Path = REFERENCE) -> dict[str, str]:
    """The committed reference's stages (lines ``stage: value``; ``#`` comments and ``fingerprint:`` skipped)."""
    out = {}
    for line in path.read_text().splitlines():
        if line.startswith("#") or not line.strip():
            continue
        k, _, v = line.partition(": ")
        if k in STAGES:
            out[k] = v
    return out


def first_difference(found: dict[str, str], reference: dict[str, str]) -> str | None:
    """The first stage (in :data:`STAGES` order) whose value differs from the reference, or None.  The
    chaotic statistics are compared by value, within :data:`CHAOS_RTOL` (labels exactly)."""
    for k in STAGES:
        a, b = found.get(k), reference.get(k)
        if k == "chaos_statistics" and a is not None and b is not None:
            if not _chaos_close(a, b):
                return k
        elif a != b:
            return k
    return None


def _chaos_close(a: str, b: str) -> bool:
    xs, ys = a.split(), b.split()
    if len(xs) != len(ys):
        return False
    for x, y in zip(xs, ys, strict=True):
        (lx, *vx), (ly, *vy) = x.split("/"), y.split("/")
        if lx != ly or len(vx) != len(vy):
            return False
        if not all(math.isclose(float(p), float(q), rel_tol=CHAOS_RTOL) for p, q in zip(vx, vy, strict=True)):
            return False
    return True
