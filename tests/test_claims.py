"""The verdict rules of geardyn.claims on constructed label arrays and cubes whose verdicts are known, and paper 1's
claims as data (geardyn.papers.li2013.CLAIMS) read by those generic rules."""

from __future__ import annotations

import itertools
import types

import numpy as np
import pytest
import xarray as xr

from geardyn import claims as C
from geardyn.claims import sweep
from geardyn.claims import verdicts as V
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
    """The inputs of evaluate(): the Fig. 7 line and the Fig. 9 and 11 families, by the roles of CLAIM_LINES."""
    b_labels = b_labels or {x: np.where(B < 0.3, P1, CH if x > 0.7 else P1) for x in paper.CASE_X1}
    e_labels = e_labels or {}
    f09 = {x: C.Track(B, np.asarray(b_labels[x])) for x in paper.CASE_X1}
    f11 = {x: C.Track(E, np.asarray(e_labels.get(x, np.full(E.size, P1)))) for x in paper.CASE_X1}
    return {"fig07": C.Track(X1, np.asarray(f07)), "fig09": f09, "fig11": f11}


def verdicts(rows):
    return {r.id: r.verdict for r in rows}


def one(rule, track, **keys):
    """One claim of rule ``rule`` on the line ``track``."""
    spec = {"id": "r", "figure": "f", "statement": "s", "rule": rule, "line": "l", **keys}
    return C.sweep_claim(spec, {"l": track}, {"l": {"parameter": "x"}})


def test_the_paper_own_labels_agree_on_every_fig07_claim():
    rows = C.evaluate(paper, tracks(paper_labels(X1)))
    v = verdicts(rows)
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
    # inputs not given: not comparable, but the list keeps every claim of the paper, once, in the paper's order
    assert [r.id for r in rows] == [c["id"] for c in paper.CLAIMS]
    assert v["fig03_M"] == v["stiffness_falls"] == v["fig07_amplitude"] == v["fig08_peaks"] == "not comparable"


def test_range_rule_needs_80_percent():
    x = np.linspace(0.0, 1.0, 10)
    lab = np.full(10, P1)
    assert one("range", C.Track(x, lab), interval=(0.0, 1.0), label=1).verdict == "agree"  # 10/10
    lab[:2] = QP  # 8/10 = 80 % P1: the threshold itself, within 2 standard errors (0.25): borderline
    assert one("range", C.Track(x, lab), interval=(0.0, 1.0), label=1).verdict == "borderline"
    lab[:] = QP
    lab[:2] = P1  # 20 %: 2 se = 0.25, 0.2 + 0.25 < 0.8: disagree
    c = one("range", C.Track(x, lab), interval=(0.0, 1.0), label=1)
    assert c.verdict == "disagree" and "20 % (2/10)" in c.reason and c.paper == "P1 on [0.0, 1.0]"
    assert one("range", C.Track(x, lab), interval=(0.31, 0.32), label=1).verdict == "not comparable"
    # open lower end: the point at lo itself is excluded
    lab2 = np.full(10, CH)
    lab2[3] = P1
    assert one("range", C.Track(x, lab2), interval=(x[3], 1.0), label="chaos", open_below=True).verdict == "agree"
    assert one("range", C.Track(x, lab2), interval=(x[3], 1.0), label="chaos").verdict == "borderline"  # 7/8


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
    assert V.headline(rows) == "11 agree, 1 borderline, 14 disagree, 0 not comparable"
    assert "**11 agree, 1 borderline, 14 disagree, 0 not comparable**" in V.to_markdown(rows, "d")
    assert sum(V.credit(r.verdict) for r in rows) == 11.5


def test_point_rule_nearest_point_alternatives_and_not_comparable():
    x = np.array([0.0, 0.5, 1.0])

    def at(labels, label, t=None):
        return one("label_at", t or C.Track(x, np.array(labels)), at=0.4, label=label)

    assert at([P1, QP, CH], "QP").verdict == "agree"
    assert at([P1, CH, CH], "QP|chaos").verdict == "agree"
    assert at([P1, CH, CH], "QP|chaos").paper == "QP or chaos"
    assert at([P1, P1, CH], "QP|chaos").verdict == "disagree"
    assert at([P1, UND, CH], "QP").verdict == "not comparable"
    assert at([P1, DIV, CH], "QP").verdict == "not comparable"
    t = C.Track(x, np.array([P1, QP, CH]), np.array([-3e-3, 1e-5, 3e-2]), np.array([1e-4, 1e-4, 1e-3]))
    assert "lambda = 1.00e-05" in at(None, "QP", t).ours


def test_fig09_route_needs_p1_start_and_chaos_in_every_case():
    f07 = paper_labels(X1)
    ok = {x: np.where(B < 1.0, P1, CH) for x in paper.CASE_X1}
    assert verdicts(C.evaluate(paper, tracks(f07, ok)))["fig09_route"] == "agree"
    bad = dict(ok)
    bad[0.83] = np.where(B < 1.0, P1, QP)  # no chaos at x1 = 0.83
    assert verdicts(C.evaluate(paper, tracks(f07, bad)))["fig09_route"] == "disagree"
    bad[0.83] = np.where(B < 1.0, QP, CH)  # does not start P1
    assert verdicts(C.evaluate(paper, tracks(f07, bad)))["fig09_route"] == "disagree"
    # b = 0.5 points: P1, QP, chaos expected at the three x1
    pts = {
        0.5: np.where(B < 1.0, P1, CH),
        0.761: np.where(B < 0.3, P1, np.where(B < 1.0, QP, CH)),
        0.83: np.where(B < 0.3, P1, CH),
    }
    v = verdicts(C.evaluate(paper, tracks(f07, pts)))
    assert v["fig09_b0.5_x1_0.5"] == v["fig09_b0.5_x1_0.761"] == v["fig09_b0.5_x1_0.83"] == "agree"


def test_fig11_route_order_and_sync_range():
    f07 = paper_labels(X1)
    # leaves P1 at 3.5, 2.8, 2.1: narrowing; QP before chaos everywhere
    e_lab = {
        x: np.where(E < s, P1, np.where(E < s + 1.0, QP, CH))
        for x, s in zip(paper.CASE_X1, (3.5, 2.8, 2.1), strict=True)
    }
    v = verdicts(C.evaluate(paper, tracks(f07, None, e_lab)))
    assert v["fig11_route"] == "agree" and v["fig11_sync_range"] == "agree"
    # chaos before QP at one x1: route disagrees
    e_lab[0.761] = np.where(E < 2.8, P1, np.where(E < 4.0, CH, QP))
    assert verdicts(C.evaluate(paper, tracks(f07, None, e_lab)))["fig11_route"] == "disagree"
    # a wider synchronous range at the larger x1: sync range disagrees
    e_lab = {
        x: np.where(E < s, P1, np.where(E < s + 1.0, QP, CH))
        for x, s in zip(paper.CASE_X1, (2.1, 2.8, 3.5), strict=True)
    }
    assert verdicts(C.evaluate(paper, tracks(f07, None, e_lab)))["fig11_sync_range"] == "disagree"
    assert C.first_non(E, np.full(E.size, P1), P1) == float("inf")


def _cube(par: str, values: np.ndarray, labels: np.ndarray, cases: list[str]) -> xr.Dataset:
    lab = np.asarray(labels, dtype=np.int16).reshape(len(cases), 1, values.size)
    ds = xr.Dataset(
        {"label": (("case", "direction", par), lab)}, coords={"case": cases, "direction": ["up"], par: values}
    )
    ds.attrs["control_parameter"] = par
    return ds


def test_cube_path_gives_the_same_verdicts_as_the_arrays(monkeypatch):
    """claims() (cubes, what writes claims.md) and evaluate() (arrays, the calibration objective) agree, and each
    claim's verdict is the one its rule gives on the constructed labels and products."""
    monkeypatch.setattr(sweep, "labels_of_cube", lambda cube: cube["label"].values)
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
    cubes = {
        "fig07": _cube("x1", X1, f07, ["base"]),
        "fig09": _cube("b", B, np.stack([b_lab[x] for x in paper.CASE_X1]), cases),
        "fig11": _cube("e", E, np.stack([e_lab[x] for x in paper.CASE_X1]), cases),
    }
    rows = C.claims(paper, {"closed_graph": cg, "stiffness": st, **cubes})
    arrays = C.evaluate(paper, {**tracks(f07, b_lab, e_lab), "closed_graph": cg, "stiffness": st})
    assert rows == arrays
    # each claim's verdict as its rule gives it on the data above: every other claim agrees (the static ones,
    # the Fig. 7 ranges and points on the paper's own labels, both routes, the e = 4.55 points past the QP band
    # at x1 = 0.761 and 0.83, the synchronous range ending at e = 3.5, 2.8, 2.1)
    disagree = {
        "fig03_N",  # residual 0.002 against the printed precision 0.0011 (M: 0.0002)
        "fig8b",  # the sweep point nearest 0.565 lies in the paper's own P1 range (the test above)
        "fig09_b0.5_x1_0.761",  # P1 below b = 1 at every x1, not QP
        "fig09_b0.5_x1_0.83",  # nor chaos
        "fig11_e4.55_x1_0.5",  # e = 4.55 is past 3.5 + 1 at x1 = 0.5: chaos, not P1
    }
    not_comparable = {"fig07_amplitude", "fig08_peaks"}  # the amplitude and the point runs are not given
    assert verdicts(rows) == {
        c["id"]: "disagree" if c["id"] in disagree else "not comparable" if c["id"] in not_comparable else "agree"
        for c in paper.CLAIMS
    }
    assert "| fig07_p1 |" in V.to_markdown(rows, "d")


def test_paper_1_claims_are_data_read_by_the_generic_rules():
    """Every claim of paper 1 is one mapping: its id, figure, statement, a rule of the engine and what the rule
    reads (a line of CLAIM_LINES, with a case of a family, or a product); the ids are unique and the claims table
    lists each once, in the module's order; the regime sequence and the calibration's main line are read from the
    same data."""
    ids = [c["id"] for c in paper.CLAIMS]
    assert len(ids) == len(set(ids)) and [r.id for r in C.evaluate(paper, {})] == ids
    products = {"closed_graph", "stiffness", "amplitude", *paper.CLAIM_RUNS}
    for c in paper.CLAIMS:
        assert {"id", "figure", "statement", "rule"} <= set(c) and c["rule"] in C.SWEEP_RULES, c["id"]
        if C.SWEEP_RULES[c["rule"]][1]:
            line = paper.CLAIM_LINES[c["line"]]
            if c["rule"] in ("route", "narrows"):  # across a family of lines
                assert "cases" in line and "case" not in c, c["id"]
            else:  # along one line: of a family, the case names which
                assert ("case" in c) == ("cases" in line) and c.get("case", 0) in line.get("cases", [0]), c["id"]
        else:
            assert c["input"] in products, c["id"]
    assert set(paper.CLAIM_LINES) <= set(paper.CLAIM_RUNS) and paper.CALIBRATION["line"] in paper.CLAIM_LINES
    assert paper.SEQUENCE[0] == (0.416, 0.565, 1) and [s[2] for s in paper.SEQUENCE] == [
        1,
        "QP",
        5,
        "chaos",
        6,
        "chaos",
    ]
    # the paper's value as the table shows it: derived from the label and interval where the claim states none
    rows = C.evaluate(paper, tracks(paper_labels(X1)))
    shown = {r.id: r.paper for r in rows}
    assert shown["fig07_p1"] == "P1 on [0.416, 0.565]" and shown["fig8e"] == "P6"
    assert shown["fig11_e4.55_x1_0.83"] == "QP or chaos" and shown["fig08_peaks"] == "0.48, 0.57, 0.8099, 1, 1.2"
    assert shown["fig03_N"] == "x2 = 0.995"


def test_the_rules_know_no_paper():
    """Another paper's claims on other lines and parameters, through the same engine: a family of lines along
    w at three speeds, a single line along b; a line not given is "not comparable"."""
    w = np.linspace(0.5, 1.5, 11)
    other = types.SimpleNamespace(
        CLAIM_LINES={
            "along_w": {"parameter": "w", "fixed": {}, "case_parameter": "speed", "cases": (100.0, 200.0, 300.0)},
            "along_b": {"parameter": "b", "fixed": {}},
        },
        CLAIMS=(
            {
                "id": "narrow",
                "figure": "Fig. 2",
                "statement": "s",
                "paper": "p",
                "rule": "narrows",
                "line": "along_w",
                "label": 1,
            },
            {
                "id": "route",
                "figure": "Fig. 2",
                "statement": "s",
                "paper": "p",
                "rule": "route",
                "line": "along_w",
                "start": 1,
                "end": "chaos",
            },
            {
                "id": "window",
                "figure": "Fig. 3",
                "statement": "s",
                "rule": "range",
                "line": "along_b",
                "interval": (0.0, 1.0),
                "label": 2,
            },
        ),
    )
    fam = {s: C.Track(w, np.where(w < 1.3 - s / 1000, P1, CH)) for s in (100.0, 200.0, 300.0)}
    rows = C.evaluate(other, {"along_w": fam})
    assert [(r.id, r.verdict) for r in rows] == [("narrow", "agree"), ("route", "agree"), ("window", "not comparable")]
    assert rows[0].ours == "leaves P1 (from w = 0.5) at w = 1.2 (speed=100.0), 1.1 (speed=200.0), 1 (speed=300.0)"
    assert rows[0].reason.endswith("compared across the paper's three speed (inf: P1 throughout)")
    assert rows[1].reason == "3/3 cases start P1 (w = 0.5) and reach chaos somewhere in the sweep"
    assert rows[2].paper == "P2 on [0.0, 1.0]" and rows[2].reason == "input not given"
    with pytest.raises(ValueError, match="rule 'nope'"):
        C.sweep_claim({"id": "x", "rule": "nope"}, {}, {})
