"""Every checkable statement of a paper against our results (only for designs that name the paper).

The statements and the numbers in them are data, in the paper's module of :mod:`geardyn.papers`; this
module holds the verdict rules and applies them.  A paper states its claims in one of two forms:

* about the regimes of a KHV drive (the module's ``SEQUENCE``, ``FIG08_POINTS``, ... and ``CLAIM_RUNS``),
  evaluated on labelled sweeps by :func:`evaluate` (below);
* as a tuple of plain mappings, the module's ``CLAIMS``, each naming one of our quantities, the paper's
  value, a rule (``DATA_RULES``) and a tolerance, evaluated by :func:`data_claims` on a model family's
  products (a plus planetary set's: :mod:`geardyn.plus.claims`).

Each claim gives the paper's value, ours, a verdict (``agree`` / ``borderline`` / ``disagree`` /
``not comparable``)
and the reason.  Inputs are the pipeline's products: for a KHV drive the closed graph (M, N), the stiffness
table (k along M-N), the sweep cubes with their motion labels (the labeller, :mod:`geardyn.label`) and the
dense point runs (spectra); for a plus set its tables of natural frequencies, stiffness scaling and key
elements, modal.nc, te.nc, the relief optima and the forced response.

Verdict rules (stated once, applied everywhere):

* a regime on an x1 interval agrees when at least ``RANGE_AGREE`` (80 %) of the sweep points inside
  it carry the paper's label; a single point agrees when the label at the nearest sweep point is the
  paper's;
* every verdict on a fraction (k of n points or table cells) is three-valued, :func:`fraction_verdict`: when
  the threshold lies within ``BORDERLINE_Z`` (2) binomial standard errors of the fraction,
  ``|k/n - t| <= 2 sqrt(p (1 - p) / n)`` with ``p = k/n``, the verdict is ``borderline``: neither agree
  nor disagree, because another sample of the same interval (a finer grid, another CPU's rounding of a
  chaotic orbit) could fall on either side.  The calibration objective counts a borderline claim as
  half an agreeing one (:func:`credit`), so one point near the threshold moves the score by a half;
* numbers agree within the paper's printed precision (M, N: 0.001) or the stated tolerance
  (:func:`within_verdict`: absolute, or relative to the paper's value; every cell of a table must agree);
* "not comparable" when our result cannot answer (point diverged or undetermined, data missing, or the
  statement concerns an input of our model).

One function, :func:`evaluate`, applies the rules to labelled 1-D sweeps (:class:`Track`); the
pipeline's ``claims.md`` (:func:`claims`, from the cubes) and the calibration objective
(:mod:`geardyn.khv.calibrate`, from a candidate's in-memory labels) both call it.  Claims stated as data
go through :func:`data_claim`, one claim at a time.
"""

from __future__ import annotations

import csv
import io
import itertools
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from numbers import Real
from types import ModuleType
from typing import Any

import numpy as np
import xarray as xr

from geardyn import classify
from geardyn.plots.captions import spectral_peaks
from geardyn.runs.cube import labels_of_cube

RANGE_AGREE = 0.8
#: A fraction within this many binomial standard errors of its threshold is "borderline".
BORDERLINE_Z = 2.0
VERDICTS = ("agree", "borderline", "disagree", "not comparable")
P1, QP, CHAOS = 1, classify.LABELS["quasi_periodic"], classify.LABELS["chaotic"]
_NAMES = {P1: "P1", QP: "QP", CHAOS: "chaos", 5: "P5", 6: "P6"}
_CODES = {"QP": QP, "chaos": CHAOS}


def fraction_verdict(k: int, n: int, threshold: float = RANGE_AGREE, z: float = BORDERLINE_Z) -> str:
    """``agree`` (k/n clearly >= threshold), ``disagree`` (clearly below) or ``borderline``.

    The one rule for every verdict on a fraction, in ``claims.md`` and in the calibration objective:
    with ``p = k/n`` and the binomial standard error ``se = sqrt(p (1 - p) / n)``, the verdict is
    ``borderline`` when ``|p - threshold| <= z * se`` (the threshold lies inside the normal-approximation
    interval ``p +- z se``, about 95 % for z = 2).  Unanimous fractions (p = 0 or 1) have se = 0 and are
    never borderline.  ``n`` must be positive (an empty interval is "not comparable" for the caller).
    """
    if n <= 0 or not 0 <= k <= n:
        raise ValueError(f"fraction_verdict needs 0 <= k <= n and n > 0, got k={k}, n={n}")
    p = k / n
    se = math.sqrt(p * (1.0 - p) / n)
    if abs(p - threshold) <= z * se:
        return "borderline"
    return "agree" if p >= threshold else "disagree"


def credit(verdict: str) -> float:
    """What a verdict is worth in the calibration score: agree 1, borderline 1/2, otherwise 0."""
    return {"agree": 1.0, "borderline": 0.5}.get(verdict, 0.0)


def code(label: int | str) -> int | tuple[int, ...]:
    """A paper's label (n >= 1, "QP", "chaos" or alternatives "QP|chaos") as label code(s)."""
    if isinstance(label, int):
        return label
    parts = tuple(_CODES[p] for p in label.split("|"))
    return parts if len(parts) > 1 else parts[0]


CSV_COLUMNS = ("id", "figure", "statement", "paper", "ours", "verdict", "reason")


@dataclass(frozen=True)
class Claim:
    id: str
    figure: str
    statement: str
    paper: str
    ours: str
    verdict: str
    reason: str
    #: The tolerance the verdict applied, when the claim states one apart from its reason.
    tolerance: str = ""


@dataclass(frozen=True)
class Track:
    """One labelled 1-D sweep: parameter values, motion labels and (optionally) the exponent per point.

    What a claim reads of a sweep, whether it comes from a stored cube (:func:`track_of_cube`) or
    from a calibration candidate's in-memory labels (:mod:`geardyn.khv.calibrate`).
    """

    values: np.ndarray
    labels: np.ndarray
    lyapunov: np.ndarray | None = None
    sigma: np.ndarray | None = None


def track_of_cube(cube: xr.Dataset, case: int = 0) -> Track:
    """The labelled sweep of case ``case`` of a sweep cube."""
    par = cube.attrs["control_parameter"]
    lam = cube["lyapunov"].values[case, 0] if "lyapunov" in cube else None
    sig = cube["lyapunov_sigma"].values[case, 0] if "lyapunov_sigma" in cube else None
    return Track(cube[par].values, labels_of_cube(cube)[case, 0], lam, sig)


def tracks_of_cube(cube: xr.Dataset, x1_values) -> dict[float, Track]:
    """{x1: Track} for the cases ``x1=...`` of a cube (Figs. 9 and 11)."""
    return {float(x1): track_of_cube(cube, _case_index(cube, x1)) for x1 in x1_values}


def _name(code: int) -> str:
    return classify.short_name(code)


def _case_index(cube: xr.Dataset, x1: float) -> int:
    labels = [str(c) for c in cube["case"].values]
    want = f"x1={x1:g}"
    return labels.index(want)


def range_claim(
    cid: str,
    fig: str,
    statement: str,
    values: np.ndarray,
    labels: np.ndarray,
    lo: float,
    hi: float,
    want: int,
    open_lo: bool = False,
) -> Claim:
    m = (values > lo if open_lo else values >= lo) & (values <= hi)
    if not m.any():
        return Claim(
            cid,
            fig,
            statement,
            f"{_NAMES.get(want, want)} on [{lo}, {hi}]",
            "no sweep point in range",
            "not comparable",
            "the sweep grid has no point inside the interval",
        )
    lab = labels[m]
    hits, n = int(np.sum(lab == want)), int(m.sum())
    frac = hits / n
    counts = {int(k): int(v) for k, v in zip(*np.unique(lab, return_counts=True), strict=True)}
    ours = ", ".join(f"{_name(k)} {v}/{n}" for k, v in sorted(counts.items(), key=lambda kv: -kv[1]))
    verdict = fraction_verdict(hits, n)
    reason = (
        f"{100 * frac:.0f} % ({hits}/{n}) of the sweep points in the interval are {_NAMES.get(want, want)}"
        f" (agree needs >= {100 * RANGE_AGREE:.0f} %; {_band(hits, n)})"
    )
    return Claim(cid, fig, statement, f"{_NAMES.get(want, want)} on [{lo}, {hi}]", ours, verdict, reason)


def _band(k: int, n: int) -> str:
    p = k / n
    half = BORDERLINE_Z * math.sqrt(p * (1.0 - p) / n)
    return (
        f"borderline if {100 * RANGE_AGREE:.0f} % lies in {100 * max(p - half, 0):.1f}-{100 * min(p + half, 1):.1f} %"
    )


def point_claim(
    cid: str,
    fig: str,
    statement: str,
    values: np.ndarray,
    labels: np.ndarray,
    at: float,
    want: int | tuple[int, ...],
    track: Track | None = None,
) -> Claim:
    j = int(np.argmin(np.abs(values - at)))
    got = int(labels[j])
    wants = want if isinstance(want, tuple) else (want,)
    paper = " or ".join(_NAMES.get(w, str(w)) for w in wants)
    extra = ""
    if track is not None and track.lyapunov is not None and track.sigma is not None:
        lam = float(track.lyapunov[j])
        sig = float(track.sigma[j])
        extra = f", lambda = {lam:.2e} +- {sig:.1e}"
    ours = f"{_name(got)} at {values[j]:.4g}{extra}"
    if got in (classify.LABELS["undetermined"], classify.LABELS["diverged"]):
        return Claim(cid, fig, statement, paper, ours, "not comparable", f"our point is {_name(got)}")
    verdict = "agree" if got in wants else "disagree"
    return Claim(cid, fig, statement, paper, ours, verdict, f"label at the nearest sweep point ({values[j]:.4g})")


def peaks_claim(points: xr.Dataset | None, peaks: tuple[float, ...], x1: float = 0.585, tol: float = 0.02) -> Claim:
    statement = f"Fig. 8c: five spectral peaks at {', '.join(f'{v:g}' for v in peaks)} x f_mesh for x1 = {x1}"
    paper = ", ".join(f"{v:g}" for v in peaks)
    if points is None or f"x1={x1:g}" not in [str(c) for c in points["case"].values]:
        return Claim("fig08_peaks", "Fig. 8c", statement, paper, "no dense run", "not comparable", "point missing")

    d = points.sel(case=f"x1={x1:g}")
    if int(d["diverged"]) == 1:
        return Claim("fig08_peaks", "Fig. 8c", statement, paper, "diverged", "not comparable", "our run diverged")
    ours = sorted(spectral_peaks(d["frequency"].values, d["amplitude"].values, n=8))
    matched = [any(abs(p - o) <= tol for o in ours) for p in peaks]
    verdict = "agree" if all(matched) else "disagree"
    reason = (
        f"{sum(matched)}/5 of the paper's peaks have one of our 8 highest peaks within {tol} "
        "(frequency resolution 0.01). Note: a period-5 motion has lines only at k/5 = 0.2, 0.4, 0.6, 0.8, "
        "1.0, 1.2; the paper's 0.48 and 0.57 are not of that form, so its own spectrum does not fit its P5 label"
    )
    return Claim(
        "fig08_peaks", "Fig. 8c", statement, paper, ", ".join(f"{v:.3g}" for v in ours) or "none", verdict, reason
    )


def first_non(values: np.ndarray, labels: np.ndarray, want: int) -> float:
    """First parameter value (from the start) whose label is not ``want`` (inf if none)."""
    bad = np.nonzero(labels != want)[0]
    return float(values[bad[0]]) if bad.size else float("inf")


def claims(
    paper: ModuleType,
    closed_graph: xr.Dataset,
    stiffness: xr.Dataset,
    fig07: xr.Dataset,
    fig09: xr.Dataset,
    fig11: xr.Dataset,
    fig08_points: xr.Dataset | None = None,
    p1_amplitude: Mapping[str, np.ndarray] | None = None,
) -> list[Claim]:
    """The list of claims of ``paper`` (:mod:`geardyn.papers.li2013`) from the pipeline's cubes;
    ``p1_amplitude`` = {"x1": ..., "ptp": ...} peak-to-peak X_VH of dense runs in the paper's P1 range
    (optional).  The verdicts are those of :func:`evaluate` on the cubes' labelled sweeps."""
    return evaluate(
        paper,
        track_of_cube(fig07),
        tracks_of_cube(fig09, paper.CASE_X1),
        tracks_of_cube(fig11, paper.CASE_X1),
        closed_graph,
        stiffness,
        fig08_points,
        p1_amplitude,
    )


def _missing(cid: str, fig: str, statement: str, paper_value: str) -> Claim:
    return Claim(cid, fig, statement, paper_value, "not evaluated", "not comparable", "input not given")


def evaluate(
    paper: ModuleType,
    fig07: Track,
    fig09: Mapping[float, Track],
    fig11: Mapping[float, Track],
    closed_graph: xr.Dataset | None = None,
    stiffness: xr.Dataset | None = None,
    fig08_points: xr.Dataset | None = None,
    p1_amplitude: Mapping[str, np.ndarray] | None = None,
) -> list[Claim]:
    """The claims of ``paper`` from labelled 1-D sweeps: the one function behind ``claims.md`` and the
    calibration objective.  ``fig07``: the x1 sweep at the paper's b and e; ``fig09`` / ``fig11``:
    {x1: Track} of the b and e sweeps at the paper's three x1.  Inputs that are not given make
    their claims "not comparable" (the list always has the same ids in the same order)."""
    return [
        *_fig03_claims(paper, closed_graph),
        _stiffness_claim(stiffness),
        *_fig07_claims(paper, fig07, fig08_points, p1_amplitude),
        *_fig09_claims(paper, fig09),
        *_fig11_claims(paper, fig11),
    ]


def _fig03_claims(paper: ModuleType, closed_graph: xr.Dataset | None) -> list[Claim]:
    """Fig. 3: the paper's limit points M and N lie on line 4 of the closed graph."""
    out: list[Claim] = []
    tol = paper.POINT_TOLERANCE
    if closed_graph is None:
        for pt, (px1, px2) in paper.POINTS.items():
            out.append(
                _missing(
                    f"fig03_{pt}", "Fig. 3", f"limit point {pt} = ({px1}, {px2}) lies on line 4", f"x2 = {px2:.3f}"
                )
            )
    else:
        for k, pt in enumerate(closed_graph["point"].values):
            px1 = float(closed_graph["paper_x1"].values[k])
            px2 = float(closed_graph["paper_x2"].values[k])
            cx2 = float(closed_graph["computed_x2"].values[k])
            res = cx2 - px2
            out.append(
                Claim(
                    f"fig03_{pt}",
                    "Fig. 3",
                    f"limit point {pt} = ({px1}, {px2}) lies on line 4",
                    f"x2 = {px2:.3f}",
                    f"x2 = {cx2:.5f} on G_s = 0 at x1 = {px1}",
                    "agree" if abs(res) <= tol else "disagree",
                    f"residual {res:+.5f} (paper prints 3 decimals: agree within {tol:g})",
                )
            )
    return out


def _stiffness_claim(stiffness: xr.Dataset | None) -> Claim:
    """Sec. 4.1: the meshing stiffness becomes small as x1 increases (along M-N)."""
    if stiffness is None:
        return _missing("stiffness_falls", "Sec. 4.1", "meshing stiffness becomes small as x1 increases", "falls")
    km = stiffness["k_mean"].values
    kc = stiffness["k_c"].values
    x1s = stiffness["x1"].values
    frac_down = float(np.mean(np.diff(km) < 0))
    return Claim(
        "stiffness_falls",
        "Sec. 4.1",
        "meshing stiffness becomes small as x1 increases",
        "falls",
        f"k_mean {km[0]:.4g} -> {km[-1]:.4g} N/m ({100 * (km[-1] / km[0] - 1):+.1f} %), "
        f"k_C {100 * (kc[-1] / kc[0] - 1):+.1f} %, x1 {x1s[0]:.3f} -> {x1s[-1]:.3f}",
        "agree" if frac_down == 1.0 else "disagree",
        f"k_mean falls at {100 * frac_down:.0f} % of the {len(km) - 1} steps along M-N",
    )


def _fig07_claims(
    paper: ModuleType,
    fig07: Track,
    fig08_points: xr.Dataset | None,
    p1_amplitude: Mapping[str, np.ndarray] | None,
) -> list[Claim]:
    """Fig. 7: the regime sequence along x1 (with the Fig. 8 peaks and the P1 amplitude), then the Fig. 8 points."""
    out: list[Claim] = []
    v, lab = fig07.values, fig07.labels
    seen: dict[int, int] = {}
    for i, ((lo, hi, label), text) in enumerate(zip(paper.SEQUENCE, paper.SEQUENCE_TEXT, strict=True)):
        want = code(label)
        seen[want] = seen.get(want, 0) + 1
        cid = {1: "fig07_p1", QP: "fig07_qp", 5: "fig07_p5", 6: "fig07_p6"}.get(want, f"fig07_chaos{seen[want]}")
        open_lo = i > 0 and want == CHAOS
        out.append(range_claim(cid, "Fig. 7", text, v, lab, lo, hi, want, open_lo=open_lo))
        if want == 5:
            out.append(peaks_claim(fig08_points, paper.PEAKS_0585))
        if i == 0:
            out.append(_amplitude_claim(p1_amplitude))
    for fig, x1, label in paper.FIG08_POINTS:
        want = code(label)
        out.append(point_claim(f"fig{fig}", f"Fig. {fig}", f"x1 = {x1}: {_NAMES[want]}", v, lab, x1, want, fig07))
    return out


def _fig09_claims(paper: ModuleType, fig09: Mapping[float, Track]) -> list[Claim]:
    """Fig. 9 (backlash b): the Fig. 10 points and the route from P1 into chaos at each x1."""
    out: list[Claim] = []
    b_at = paper.FIG10_B
    for fig, x1, label in paper.FIG10_LABELS:
        want = code(label)
        t = fig09[float(x1)]
        out.append(
            point_claim(
                f"fig09_b{b_at:g}_x1_{x1}",
                f"Fig. {fig}",
                f"b = {b_at:g}, x1 = {x1}: {_NAMES[want]}",
                t.values,
                t.labels,
                b_at,
                want,
                t,
            )
        )
    ok, parts = [], []
    for x1 in paper.CASE_X1:
        t = fig09[float(x1)]
        vb, lb = t.values, t.labels
        first_chaos = vb[lb == CHAOS].min() if (lb == CHAOS).any() else np.inf
        last_p1 = vb[lb == P1].max() if (lb == P1).any() else -np.inf
        starts_p1 = lb[0] == P1
        ok.append(bool(starts_p1 and np.isfinite(first_chaos)))
        parts.append(f"x1={x1}: starts {_name(lb[0])}, first chaos at b = {first_chaos:.3g}, last P1 at {last_p1:.3g}")
    out.append(
        Claim(
            "fig09_route",
            "Fig. 9",
            "the response turns from P1 into chaos as b increases (each x1)",
            "P1 at small b, chaos at larger b",
            "; ".join(parts),
            "agree" if all(ok) else "disagree",
            f"{sum(ok)}/{len(ok)} cases start P1 (b = 0) and reach chaos somewhere in the sweep",
        )
    )
    return out


def _fig11_claims(paper: ModuleType, fig11: Mapping[float, Track]) -> list[Claim]:
    """Fig. 11 (TE amplitude e): the Fig. 12 points, the route P1 -> QP -> chaos and the narrowing P1 range."""
    out: list[Claim] = []
    e_at = paper.FIG12_E
    for fig, x1, label in paper.FIG12_LABELS:
        want = code(label)
        t = fig11[float(x1)]
        text = _NAMES[want] if want == P1 else "quasi-periodic or chaotic"
        out.append(
            point_claim(
                f"fig11_e{e_at:g}_x1_{x1}",
                f"Fig. {fig}",
                f"e = {e_at:g}, x1 = {x1}: {text}",
                t.values,
                t.labels,
                e_at,
                want,
                t,
            )
        )
    ok, parts, sync = [], [], []
    for x1 in paper.CASE_X1:
        t = fig11[float(x1)]
        ve, le = t.values, t.labels
        end_p1 = first_non(ve, le, P1)
        sync.append(end_p1)
        first_qp = ve[le == QP].min() if (le == QP).any() else np.inf
        first_ch = ve[le == CHAOS].min() if (le == CHAOS).any() else np.inf
        ok.append(bool(le[0] == P1 and np.isfinite(first_ch) and first_qp <= first_ch))
        parts.append(f"x1={x1}: leaves P1 at e = {end_p1:.3g}, first QP {first_qp:.3g}, first chaos {first_ch:.3g}")
    out.append(
        Claim(
            "fig11_route",
            "Fig. 11",
            "as e grows the response goes P1 -> quasi-periodic -> chaos",
            "P1, then QP, then chaos",
            "; ".join(parts),
            "agree" if all(ok) else "disagree",
            f"{sum(ok)}/{len(ok)} cases show P1 first, then QP no later than the first chaos",
        )
    )
    narrower = all(a > b for a, b in itertools.pairwise(sync))
    out.append(
        Claim(
            "fig11_sync_range",
            "Fig. 11",
            "the range of synchronous motion narrows as x1 increases",
            "narrower for larger x1",
            "leaves P1 (from e = 0) at e = "
            + ", ".join(f"{s:.3g} (x1={x})" for s, x in zip(sync, paper.CASE_X1, strict=True)),
            "agree" if narrower else "disagree",
            "first e where the label leaves P1, compared across the paper's three x1 (inf: P1 throughout)",
        )
    )
    return out


def _amplitude_claim(p1_amplitude: Mapping[str, np.ndarray] | None) -> Claim:
    """Fig. 7: in the P1 range the amplitude falls as x1 grows (dense runs' peak-to-peak X_VH)."""
    statement = "in the P1 range the amplitude decreases as x1 increases"
    if p1_amplitude is None or len(p1_amplitude["x1"]) <= 2:
        return _missing("fig07_amplitude", "Fig. 7", statement, "decreasing")
    xa, ptp = np.asarray(p1_amplitude["x1"]), np.asarray(p1_amplitude["ptp"])
    falls, steps = int(np.sum(np.diff(ptp) < 0)), len(ptp) - 1
    return Claim(
        "fig07_amplitude",
        "Fig. 7",
        statement,
        "decreasing",
        f"peak-to-peak X_VH {ptp[0]:.3g} -> {ptp[-1]:.3g} over x1 {xa[0]:.3f}-{xa[-1]:.3f}",
        fraction_verdict(falls, steps),
        f"falls at {100 * falls / steps:.0f} % of {steps} steps (dense runs, recorded periods; {_band(falls, steps)})",
    )


# --- Claims stated as data ---------------------------------------------------------------------------------
# A paper module may state its claims as plain data, ``CLAIMS``: a tuple of mappings, one per statement, with
#   id, figure, statement   the claim's name, where the paper makes it, the statement in the paper's words;
#   quantity, args          which of our numbers answers it (a name of a quantity table such as
#                           PLUS_QUANTITIES, and its keyword arguments);
#   rule                    how the two are compared (DATA_RULES);
#   paper                   the paper's value (number, sequence, or mapping of sequences), or
#   paper_of                a table in the paper's form from which the quantity's own function derives the
#                           paper's value, so that both sides are read the same way;
#   tolerance, relative     for rule "within": absolute (in ``unit``) or relative (fraction of the paper's value);
#   bound                   for rule "at_most": the paper's statement as an upper bound on our number;
#   unit, paper_text        display: the unit, and the paper's value as the paper words it (optional);
#   why, note               why we disagree (shown unless the verdict is agree), and a remark shown always.

#: The comparison rules of claims stated as data:
#: within   every number within ``tolerance`` of the paper's (absolute or relative);
#: at_most  our number at most ``bound`` (a direction or a threshold the paper states);
#: equal    the same value (counts, orders, labels), derived from the paper's table the same way as ours;
#: matches  cell by cell (a cell agrees when the two share a name), verdict on the fraction
#:          (:func:`fraction_verdict`, threshold ``RANGE_AGREE``);
#: all      every one of our cases has the property the paper states (an exact, structural property);
#: unchecked the statement concerns something our model takes as an input or does not model.
DATA_RULES = ("within", "at_most", "equal", "matches", "all", "unchecked")
#: Keys a claim stated as data may have.
DATA_KEYS = frozenset(
    {
        "id",
        "figure",
        "statement",
        "quantity",
        "args",
        "rule",
        "paper",
        "paper_of",
        "tolerance",
        "relative",
        "bound",
        "unit",
        "paper_text",
        "why",
        "note",
    }
)


@dataclass(frozen=True)
class Measured:
    """One of our numbers: ``value`` (a number, a sequence, a mapping of sequences, or ``None`` when our
    products cannot give it) and ``text``, what it is and where it comes from, shown beside it."""

    value: Any
    text: str = ""


@dataclass(frozen=True)
class Quantity:
    """How a quantity is read: ``measure(products, **args)`` from our products; ``derive(table, **args)``
    the same quantity from a table in the paper's form (for claims that give ``paper_of``)."""

    measure: Callable[..., Measured]
    derive: Callable[..., Any] | None = None


def format_value(v: Any, unit: str = "") -> str:
    """A value for the claims table: numbers to 4 significant digits, sequences joined, mappings by key."""
    u = f" {unit}" if unit else ""
    if v is None:
        return "none"
    if isinstance(v, Mapping):
        return "; ".join(f"{k}: {format_value(x)}" for k, x in v.items()) + u
    if isinstance(v, str):
        return v + u
    if isinstance(v, bool | np.bool_):
        return "yes" if v else "no"
    if isinstance(v, Sequence | np.ndarray):
        if len(v) and all(isinstance(x, bool | np.bool_) for x in v):
            return f"{sum(bool(x) for x in v)}/{len(v)}"
        return ", ".join(format_value(x) for x in v) + u
    if isinstance(v, Real):
        return f"{float(v):.4g}{u}"
    return str(v) + u


def _cells(v: Any, keys: Sequence | None = None) -> list[tuple[str, Any]]:
    """(label, cell) pairs of a value: a mapping of sequences in ``keys`` order (``I #2``), a sequence
    (``#2``) or one cell."""
    if isinstance(v, Mapping):
        out = []
        for k in keys if keys is not None else list(v):
            out += [(f"{k} {label}".strip(), x) for label, x in _cells(v[k])]
        return out
    if isinstance(v, Sequence | np.ndarray) and not isinstance(v, str):
        return [(f"#{i}", x) for i, x in enumerate(v, start=1)]
    return [("", v)]


def _missing_value(v: Any) -> bool:
    if v is None:
        return True
    if isinstance(v, Real) and not isinstance(v, bool | np.bool_):
        return not math.isfinite(float(v))
    if isinstance(v, Mapping):
        return any(_missing_value(x) for x in v.values())
    if isinstance(v, Sequence | np.ndarray) and not isinstance(v, str):
        return any(_missing_value(x) for x in v)
    return False


def _names(cell: Any) -> set[str]:
    """A cell of a "matches" rule as a set of names: "a, b" and ("a", "b") are {"a", "b"}."""
    parts = cell.split(",") if isinstance(cell, str) else list(cell)
    return {str(p).strip() for p in parts if str(p).strip()}


def _normal(v: Any) -> Any:
    """Sequences as tuples, numbers as Python numbers, mappings recursively: for the "equal" rule."""
    if isinstance(v, Mapping):
        return {k: _normal(x) for k, x in v.items()}
    if isinstance(v, Sequence | np.ndarray) and not isinstance(v, str):
        return tuple(_normal(x) for x in v)
    if isinstance(v, np.generic):
        return v.item()
    return v


def tolerance_text(spec: Mapping[str, Any]) -> str:
    """The tolerance of a claim stated as data, as the claims table shows it."""
    rule, unit = spec["rule"], spec.get("unit", "")
    if rule == "within":
        tol = spec["tolerance"]
        return f"+-{100 * tol:.3g} %" if spec.get("relative") else f"+-{tol:.3g} {unit}".rstrip()
    if rule == "at_most":
        return f"<= {spec['bound']:g} {unit}".rstrip()
    if rule == "matches":
        return f">= {100 * RANGE_AGREE:.0f} % of the cells (borderline: {BORDERLINE_Z:g} binomial standard errors)"
    return {"equal": "exact", "all": "every case", "unchecked": "none"}[rule]


def within_verdict(ours: Any, paper: Any, tolerance: float, relative: bool = False, unit: str = "") -> tuple[str, str]:
    """Rule "within": (verdict, reason).  Every cell of ``ours`` within ``tolerance`` of the paper's cell
    (relative: ``|ours - paper| <= tolerance |paper|``); the reason names the worst cell and, for relative
    tolerances on several cells, the range of ours/paper."""
    keys = list(paper) if isinstance(paper, Mapping) else None
    o, p = _cells(ours, keys), _cells(paper, keys)
    if len(o) != len(p):
        return "not comparable", f"we have {len(o)} values, the paper {len(p)}"
    if relative:
        err = [(float(a) - float(b)) / abs(float(b)) for (_, a), (_, b) in zip(o, p, strict=True)]
    else:
        err = [float(a) - float(b) for (_, a), (_, b) in zip(o, p, strict=True)]
    worst = int(np.argmax(np.abs(err)))
    label = f" at {o[worst][0]}" if len(o) > 1 else ""
    shown = f"{100 * err[worst]:+.1f} %" if relative else f"{err[worst]:+.3g} {unit}".rstrip()
    reason = f"{'worst ' if len(o) > 1 else ''}difference {shown}{label}"
    if relative and len(o) > 1:
        ratio = [float(a) / float(b) for (_, a), (_, b) in zip(o, p, strict=True)]
        reason += f"; ours/paper {min(ratio):.3g}-{max(ratio):.3g}"
    ok = all(abs(e) <= tolerance for e in err)
    return ("agree" if ok else "disagree"), reason


def matches_verdict(ours: Any, paper: Any) -> tuple[str, str]:
    """Rule "matches": cell by cell, a cell agrees when our names and the paper's share one; the verdict on
    the fraction of agreeing cells is :func:`fraction_verdict`."""
    keys = list(paper) if isinstance(paper, Mapping) else None
    o, p = _cells(ours, keys), _cells(paper, keys)
    if len(o) != len(p) or not p:
        return "not comparable", f"we have {len(o)} cells, the paper {len(p)}"
    hits = [bool(_names(a) & _names(b)) for (_, a), (_, b) in zip(o, p, strict=True)]
    k, n = sum(hits), len(hits)
    miss = ", ".join(label for (label, _), h in zip(o, hits, strict=True) if not h)
    reason = f"{k}/{n} cells agree ({100 * k / n:.0f} %; agree needs >= {100 * RANGE_AGREE:.0f} %; {_band(k, n)})" + (
        f"; differ at {miss}" if miss else ""
    )
    return fraction_verdict(k, n), reason


def data_claim(spec: Mapping[str, Any], products: Any, quantities: Mapping[str, Quantity]) -> Claim:
    """One claim stated as data (see DATA_RULES and the keys above) evaluated on our ``products``."""
    unknown = set(spec) - DATA_KEYS
    if unknown or spec.get("rule") not in DATA_RULES or spec.get("quantity") not in quantities:
        raise ValueError(
            f"claim {spec.get('id')!r}: unknown keys {sorted(unknown)}, rule {spec.get('rule')!r} "
            f"(allowed: {DATA_RULES}) or quantity {spec.get('quantity')!r} (known: {sorted(quantities)})"
        )
    rule, unit, args = spec["rule"], spec.get("unit", ""), dict(spec.get("args", {}))
    q = quantities[spec["quantity"]]
    if "paper_of" in spec:
        if q.derive is None:
            raise ValueError(f"claim {spec['id']!r}: quantity {spec['quantity']!r} cannot be derived from a table")
        paper = q.derive(spec["paper_of"], **args)
    else:
        paper = spec.get("paper", spec.get("bound"))
    measured = q.measure(products, **args)
    ours = format_value(measured.value, unit) + (f" ({measured.text})" if measured.text else "")
    paper_shown = spec.get("paper_text") or format_value(paper, unit)
    if rule == "unchecked":
        verdict, reason = "not comparable", "the statement is not a result of our model"
    elif _missing_value(measured.value):
        verdict, reason = "not comparable", "our products do not give this number"
    elif rule == "within":
        verdict, reason = within_verdict(measured.value, paper, spec["tolerance"], spec.get("relative", False), unit)
    elif rule == "at_most":
        ok = float(measured.value) <= float(spec["bound"])
        verdict = "agree" if ok else "disagree"
        reason = f"ours {format_value(measured.value, unit)} {'<=' if ok else '>'} {spec['bound']:g} {unit}".rstrip()
    elif rule == "equal":
        same = _normal(measured.value) == _normal(paper)
        verdict, reason = ("agree", "the same") if same else ("disagree", "they differ")
    elif rule == "matches":
        verdict, reason = matches_verdict(measured.value, paper)
    else:  # all
        flags = [bool(x) for _, x in _cells(measured.value)]
        k, n = sum(flags), len(flags)
        verdict = "agree" if n and k == n else "disagree"
        reason = f"{k}/{n} of our cases"
    if verdict != "agree" and spec.get("why"):
        reason += f". {spec['why']}"
    if spec.get("note"):
        reason += f". {spec['note']}"
    return Claim(
        spec["id"], spec["figure"], spec["statement"], paper_shown, ours, verdict, reason, tolerance_text(spec)
    )


def data_claims(specs: Sequence[Mapping[str, Any]], products: Any, quantities: Mapping[str, Quantity]) -> list[Claim]:
    """Every claim of a paper stated as data (its ``CLAIMS``), in the paper module's order."""
    ids = [s.get("id") for s in specs]
    if len(set(ids)) != len(ids):
        raise ValueError(f"claim ids repeat: {sorted({i for i in ids if ids.count(i) > 1})}")
    return [data_claim(s, products, quantities) for s in specs]


def note(design: str, title: str) -> str:
    """The paragraph under the claims table's title: which design, how the labels were obtained."""
    return (
        f"Design `{design}` ({title}). Labels: the labeller's verdicts stored in the sweep cubes (geardyn.label: "
        "each point follows the attractor of the previous one; period-n certified by shooting and its Floquet "
        "multipliers, QP by the torus test, chaos by a positive exponent the torus test confirms). Paper labels "
        "compared: P1 = synchronous, QP, P5, P6, chaos."
    )


def counts(rows: list[Claim]) -> dict[str, int]:
    c = dict.fromkeys(VERDICTS, 0)
    for r in rows:
        c[r.verdict] += 1
    return c


def headline(rows: list[Claim]) -> str:
    """``11 agree, 1 borderline, 14 disagree, 0 not comparable``."""
    c = counts(rows)
    return ", ".join(f"{c[v]} {v}" for v in VERDICTS)


def columns(rows: list[Claim]) -> tuple[str, ...]:
    """The table's columns: :data:`CSV_COLUMNS`, with ``tolerance`` after ``ours`` when a row states one."""
    if not any(r.tolerance for r in rows):
        return CSV_COLUMNS
    i = CSV_COLUMNS.index("ours") + 1
    return (*CSV_COLUMNS[:i], "tolerance", *CSV_COLUMNS[i:])


def to_csv(rows: list[Claim]) -> str:
    buf = io.StringIO()
    w = csv.writer(buf)
    cols = columns(rows)
    w.writerow(cols)
    for r in rows:
        w.writerow([getattr(r, c) for c in cols])
    return buf.getvalue()


def to_markdown(rows: list[Claim], design: str, note: str = "", paper: str = "the paper") -> str:
    """The claims table in Markdown: title (``paper``: the paper's short name), headline, ``note``, one row each."""
    cols = columns(rows)
    lines = [
        f"# Claims of {paper} checked: design `{design}`",
        "",
        f"**{headline(rows)}** (of {len(rows)} claims; borderline: a fraction within "
        f"{BORDERLINE_Z:g} binomial standard errors of its threshold).",
        "",
    ]
    if note:
        lines += [note, ""]
    lines += ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for r in rows:
        cells = [f"**{r.verdict}**" if c == "verdict" else getattr(r, c) for c in cols]
        lines.append("| " + " | ".join(str(x).replace("|", "/") for x in cells) + " |")
    return "\n".join(lines) + "\n"
