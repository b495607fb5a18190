"""The verdict rules of geardyn.claims on constructed label arrays and cubes whose verdicts are known."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
import xarray as xr

from geardyn import claims as C
from geardyn.papers import li2013 as paper

P1, QP, CH, UND, DIV = 1, C.QP, C.CHAOS, -1, -2
X1 = np.linspace(0.416, 0.835, 120)
B = np.linspace(0.0, 2.25, 10)
E = np.linspace(0.0, 6.3, 19)


def paper_labels(x1: np.ndarray) -> np.ndarray:
    """The paper's sequence along x1, as label codes (chaos windows open at their lower end)."""
    out = np.full(x1.shape, CH, dtype=np.int16)
    for lo, hi, lab in paper.SEQUENCE:
        c = C.code(lab)
        out[(x1 >= lo) & (x1 <= hi)] = c
    return out


def tracks(f07, b_labels=None, e_labels=None):
    b_labels = b_labels or {x: np.where(B < 0.3, P1, CH if x > 0.7 else P1) for x in paper.CASE_X1}
    e_labels = e_labels or {}
    f09 = {x: C.Track(B, np.asarray(b_labels[x])) for x in paper.CASE_X1}
    f11 = {x: C.Track(E, np.asarray(e_labels.get(x, np.full(E.size, P1)))) for x in paper.CASE_X1}
    return C.Track(X1, np.asarray(f07)), f09, f11


def verdicts(rows):
    return {r.id: r.verdict for r in rows}


def test_the_paper_own_labels_agree_on_every_fig07_claim():
    v = verdicts(C.evaluate(paper, *tracks(paper_labels(X1))))
    for cid in (
        "fig07_p1",
        "fig07_qp",
        "fig07_p5",
        "fig07_chaos1",
        "fig07_p6",
        "fig07_chaos2",
        "fig8a",
        "fig8c",
        "fig8d",
        "fig8e",
        "fig8f",
    ):
        assert v[cid] == "agree", cid
    # x1 = 0.565 (Fig. 8b, QP) is also the end of the paper's own P1 range; the sweep point nearest
    # to it (0.5638) lies inside that P1 range, so even the paper's labels fail the nearest-point rule
    assert v["fig8b"] == "disagree"
    # inputs not given: not comparable, but the list keeps all 26 ids in order
    assert len(v) == 26
    assert v["fig03_M"] == v["stiffness_falls"] == v["fig07_amplitude"] == v["fig08_peaks"] == "not comparable"


def test_range_rule_needs_80_percent():
    x = np.linspace(0.0, 1.0, 10)
    lab = np.full(10, P1)
    assert C.range_claim("r", "f", "s", x, lab, 0.0, 1.0, P1).verdict == "agree"  # 10/10
    lab[:2] = QP  # 8/10 = 80 % P1: the threshold itself, within 2 standard errors (0.25): borderline
    assert C.range_claim("r", "f", "s", x, lab, 0.0, 1.0, P1).verdict == "borderline"
    lab[:] = QP
    lab[:2] = P1  # 20 %: 2 se = 0.25, 0.2 + 0.25 < 0.8: disagree
    c = C.range_claim("r", "f", "s", x, lab, 0.0, 1.0, P1)
    assert c.verdict == "disagree" and "20 % (2/10)" in c.reason
    assert C.range_claim("r", "f", "s", x, lab, 0.31, 0.32, P1).verdict == "not comparable"
    # open lower end: the point at lo itself is excluded
    lab2 = np.full(10, CH)
    lab2[3] = P1
    assert C.range_claim("r", "f", "s", x, lab2, x[3], 1.0, CH, open_lo=True).verdict == "agree"


def test_fraction_verdict_band_is_two_binomial_standard_errors():
    # the second machine's fig07_chaos2: 127 of 160 chaotic against 80 %, p = 0.79375,
    # se = sqrt(p (1 - p) / 160) = 0.03199, 2 se = 0.0640 > 0.00625: borderline, and so is 128/160
    assert C.fraction_verdict(127, 160) == C.fraction_verdict(128, 160) == "borderline"
    # the band's edges for n = 160, worked by hand: 138/160 = 0.8625, 2 se = 0.05449 -> lower 0.8080 > 0.8;
    # 137/160 = 0.85625, 2 se = 0.05547 -> lower 0.80078 > 0.8; 136/160 = 0.85, 2 se = 0.05646 -> 0.7935
    assert C.fraction_verdict(138, 160) == C.fraction_verdict(137, 160) == "agree"
    assert C.fraction_verdict(136, 160) == "borderline"
    # 117/160 = 0.73125, 2 se = 0.07009 -> upper 0.80134 (borderline); 116/160 = 0.725, 2 se = 0.07060 -> 0.7956
    assert C.fraction_verdict(117, 160) == "borderline" and C.fraction_verdict(116, 160) == "disagree"
    # unanimous fractions have no spread: 1/1 agrees, 0/1 disagrees
    assert C.fraction_verdict(1, 1) == "agree" and C.fraction_verdict(0, 1) == "disagree"
    # no single point turns agree into disagree anywhere on n = 20..200
    for n in range(20, 201):
        v = [C.fraction_verdict(k, n) for k in range(n + 1)]
        assert all({a, b} != {"agree", "disagree"} for a, b in itertools.pairwise(v))
    for bad in ((1, 0), (-1, 5), (6, 5)):
        with pytest.raises(ValueError, match="fraction_verdict"):
            C.fraction_verdict(*bad)


def test_headline_counts_borderline_and_calibration_gives_it_half_credit():
    rows = [
        C.Claim(str(i), "f", "s", "p", "o", v, "r")
        for i, v in enumerate(["agree"] * 11 + ["borderline"] + ["disagree"] * 14)
    ]
    assert C.headline(rows) == "11 agree, 1 borderline, 14 disagree, 0 not comparable"
    assert "**11 agree, 1 borderline, 14 disagree, 0 not comparable**" in C.to_markdown(rows, "d")
    assert sum(C.credit(r.verdict) for r in rows) == 11.5


def test_point_rule_nearest_point_alternatives_and_not_comparable():
    x = np.array([0.0, 0.5, 1.0])
    assert C.point_claim("p", "f", "s", x, np.array([P1, QP, CH]), 0.4, QP).verdict == "agree"
    assert C.point_claim("p", "f", "s", x, np.array([P1, CH, CH]), 0.4, (QP, CH)).verdict == "agree"
    assert C.point_claim("p", "f", "s", x, np.array([P1, P1, CH]), 0.4, (QP, CH)).verdict == "disagree"
    assert C.point_claim("p", "f", "s", x, np.array([P1, UND, CH]), 0.4, QP).verdict == "not comparable"
    assert C.point_claim("p", "f", "s", x, np.array([P1, DIV, CH]), 0.4, QP).verdict == "not comparable"
    t = C.Track(x, np.array([P1, QP, CH]), np.array([-3e-3, 1e-5, 3e-2]), np.array([1e-4, 1e-4, 1e-3]))
    assert "lambda = 1.00e-05" in C.point_claim("p", "f", "s", x, t.labels, 0.5, QP, t).ours


def test_fig09_route_needs_p1_start_and_chaos_in_every_case():
    f07 = paper_labels(X1)
    ok = {x: np.where(B < 1.0, P1, CH) for x in paper.CASE_X1}
    assert verdicts(C.evaluate(paper, *tracks(f07, ok)))["fig09_route"] == "agree"
    bad = dict(ok)
    bad[0.83] = np.where(B < 1.0, P1, QP)  # no chaos at x1 = 0.83
    assert verdicts(C.evaluate(paper, *tracks(f07, bad)))["fig09_route"] == "disagree"
    bad[0.83] = np.where(B < 1.0, QP, CH)  # does not start P1
    assert verdicts(C.evaluate(paper, *tracks(f07, bad)))["fig09_route"] == "disagree"
    # b = 0.5 points: P1, QP, chaos expected at the three x1
    pts = {
        0.5: np.where(B < 1.0, P1, CH),
        0.761: np.where(B < 0.3, P1, np.where(B < 1.0, QP, CH)),
        0.83: np.where(B < 0.3, P1, CH),
    }
    v = verdicts(C.evaluate(paper, *tracks(f07, pts)))
    assert v["fig09_b0.5_x1_0.5"] == v["fig09_b0.5_x1_0.761"] == v["fig09_b0.5_x1_0.83"] == "agree"


def test_fig11_route_order_and_sync_range():
    f07 = paper_labels(X1)
    # leaves P1 at 3.5, 2.8, 2.1: narrowing; QP before chaos everywhere
    e_lab = {
        x: np.where(E < s, P1, np.where(E < s + 1.0, QP, CH))
        for x, s in zip(paper.CASE_X1, (3.5, 2.8, 2.1), strict=True)
    }
    v = verdicts(C.evaluate(paper, *tracks(f07, None, e_lab)))
    assert v["fig11_route"] == "agree" and v["fig11_sync_range"] == "agree"
    # chaos before QP at one x1: route disagrees
    e_lab[0.761] = np.where(E < 2.8, P1, np.where(E < 4.0, CH, QP))
    assert verdicts(C.evaluate(paper, *tracks(f07, None, e_lab)))["fig11_route"] == "disagree"
    # a wider synchronous range at the larger x1: sync range disagrees
    e_lab = {
        x: np.where(E < s, P1, np.where(E < s + 1.0, QP, CH))
        for x, s in zip(paper.CASE_X1, (2.1, 2.8, 3.5), strict=True)
    }
    assert verdicts(C.evaluate(paper, *tracks(f07, None, e_lab)))["fig11_sync_range"] == "disagree"
    assert C.first_non(E, np.full(E.size, P1), P1) == float("inf")


def _cube(par: str, values: np.ndarray, labels: np.ndarray, cases: list[str]) -> xr.Dataset:
    lab = np.asarray(labels, dtype=np.int16).reshape(len(cases), 1, values.size)
    ds = xr.Dataset(
        {"label": (("case", "direction", par), lab)}, coords={"case": cases, "direction": ["up"], par: values}
    )
    ds.attrs["control_parameter"] = par
    return ds


def test_cube_path_gives_the_same_verdicts_as_the_arrays(monkeypatch):
    """claims() (cubes, what writes claims.md) and evaluate() (arrays, the calibration objective) agree."""
    monkeypatch.setattr(C, "labels_of_cube", lambda cube: cube["label"].values)
    f07 = paper_labels(X1)
    b_lab = {x: np.where(B < 1.0, P1, CH) for x in paper.CASE_X1}
    e_lab = {
        x: np.where(E < s, P1, np.where(E < s + 1.0, QP, CH))
        for x, s in zip(paper.CASE_X1, (3.5, 2.8, 2.1), strict=True)
    }
    cases = [f"x1={x:g}" for x in paper.CASE_X1]
    cg = xr.Dataset(
        {
            "paper_x1": ("point", [0.416, 0.835]),
            "paper_x2": ("point", [0.601, 0.995]),
            "computed_x2": ("point", [0.6012, 0.9930]),
        },
        coords={"point": ["M", "N"]},
    )
    st = xr.Dataset({"k_mean": ("x1", [3.0, 2.9, 2.8]), "k_c": ("x1", [1.0, 1.0, 0.99]), "x1": ("x1", [0.4, 0.6, 0.8])})
    rows = C.claims(
        paper,
        cg,
        st,
        _cube("x1", X1, f07, ["base"]),
        _cube("b", B, np.stack([b_lab[x] for x in paper.CASE_X1]), cases),
        _cube("e", E, np.stack([e_lab[x] for x in paper.CASE_X1]), cases),
    )
    arrays = C.evaluate(paper, *tracks(f07, b_lab, e_lab), cg, st)
    assert [(r.id, r.verdict) for r in rows] == [(r.id, r.verdict) for r in arrays]
    v = verdicts(rows)
    assert v["fig03_M"] == "agree" and v["fig03_N"] == "disagree"  # residual 0.0002 vs 0.002
    assert v["stiffness_falls"] == "agree"
    # 2 static + 6 Fig. 7 ranges + 5 Fig. 8 points + b = 0.5 at x1 = 0.5 + both routes + 2 e = 4.55 points + sync
    assert C.counts(rows) == {"agree": 19, "borderline": 0, "disagree": 5, "not comparable": 2}
    assert "| fig07_p1 |" in C.to_markdown(rows, "d")
