"""Paper 2's claims, stated as data (geardyn.papers.yue2014.CLAIMS) and evaluated by the generic rules of
geardyn.claims: the rules on given numbers, the paper's values derived from its printed tables, the claims on
the pipeline's own products of the shipped design, and no claims for a plus design of your own."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pandas as pd
import pytest
import yaml

import _workflow as wf
from geardyn import claims as C
from geardyn.claims import verdicts as V
from geardyn.papers import yue2014 as paper
from geardyn.plus import claims as PC

ROOT = Path(__file__).resolve().parents[1]
#: A quantity that returns the "products" it is given: the rules on numbers chosen by the test.
GIVEN = {"given": C.Quantity(lambda products: C.Measured(products), lambda table: table)}


def verdict(products, **spec):
    base = {"id": "c", "figure": "f", "statement": "s", "quantity": "given"}
    return C.data_claim({**base, **spec}, products, GIVEN)


# --- the rules on given numbers ----------------------------------------------------------------------------


def test_relative_tolerance_is_the_papers_12_1_percent():
    spec = {"rule": "within", "paper": 1295.0, "tolerance": 0.121, "relative": True, "unit": "Hz"}
    # 1295 * (1 - 0.121) = 1138.3: 1140 Hz (-12.0 %) lies inside, 1137 Hz (-12.2 %) outside
    assert verdict(1140.0, **spec).verdict == "agree"
    assert verdict(1137.0, **spec).verdict == "disagree"
    # our first mode, 339.8 Hz: -73.8 %
    c = verdict(339.8, **spec)
    assert c.verdict == "disagree" and "-73.8 %" in c.reason and c.tolerance == "+-12.1 %"


def test_absolute_tolerance_on_the_te():
    spec = {"rule": "within", "paper": 9.0, "tolerance": 0.5, "unit": "um", "why": "WHY"}
    agree = verdict(8.978, **spec)
    assert agree.verdict == "agree" and "-0.022 um" in agree.reason and "WHY" not in agree.reason
    off = verdict(9.6, **spec)  # 0.6 um above "about 9 um"
    assert off.verdict == "disagree" and off.reason.endswith("WHY") and off.tolerance == "+-0.5 um"


def test_a_table_agrees_only_when_every_cell_does_and_the_worst_cell_is_named():
    theoretical = {c: paper.PAPER_TABLE2[c]["theoretical"] for c in paper.PAPER_TABLE2}
    spec = {"rule": "within", "paper": theoretical, "tolerance": 0.121, "relative": True}
    scaled = {c: tuple(0.95 * f for f in v) for c, v in theoretical.items()}  # every cell -5 %
    assert verdict(scaled, **spec).verdict == "agree"
    scaled["II"] = (*scaled["II"][:1], 0.8 * theoretical["II"][1], *scaled["II"][2:])  # one cell -20 %
    c = verdict(scaled, **spec)
    assert c.verdict == "disagree" and "-20.0 % at II #2" in c.reason and "ours/paper 0.8-0.95" in c.reason
    # a table of another length cannot be compared cell by cell
    assert verdict({c: v[:5] for c, v in scaled.items()}, **spec).verdict == "not comparable"


def test_at_most_a_bound():
    spec = {"rule": "at_most", "bound": paper.NOISE_DROP_DB, "unit": "dB"}
    assert verdict(-2.06, **spec).verdict == "agree"
    assert verdict(+0.33, **spec).verdict == "disagree"
    assert verdict(-1.0, **spec).verdict == "agree"  # the bound itself
    assert verdict(-2.06, **spec).tolerance == "<= -1 dB"


def test_cell_matches_use_the_fraction_rule():
    cells = paper.PAPER_TABLE5_ELEMENT
    flat = [(c, i) for c in cells for i in range(6)]

    def with_misses(n):
        ours = {c: list(v) for c, v in cells.items()}
        for c, i in flat[:n]:
            ours[c][i] = "xx"
        return ours

    # 18 cells against 80 %: 17/18 = 0.944, 2 se = 0.108 -> agree; 15/18 = 0.833, 2 se = 0.176 -> borderline;
    # 12/18 = 0.667, 2 se = 0.222 -> borderline; 11/18 = 0.611, 2 se = 0.230 -> 0.841 > 0.8, borderline;
    # 6/18 = 0.333, 2 se = 0.222 -> 0.556 < 0.8, disagree
    got = {n: verdict(with_misses(n), rule="matches", paper=cells).verdict for n in (1, 3, 6, 7, 12)}
    assert got == {1: "agree", 3: "borderline", 6: "borderline", 7: "borderline", 12: "disagree"}
    c = verdict(with_misses(12), rule="matches", paper=cells)
    assert "6/18 cells agree" in c.reason and "differ at I #1" in c.reason
    # a cell agrees when our name is one of the paper's names ("a, b", the form of a Table 5 cell)
    assert verdict({"I": ("planet gear d",)}, rule="matches", paper={"I": ("planet gear d, sun gear",)}).verdict == (
        "agree"
    )
    assert verdict({"I": ("gear ring",)}, rule="matches", paper={"I": ("planet gear d, sun gear",)}).verdict == (
        "disagree"
    )


def test_equal_all_unchecked_and_missing_numbers():
    assert verdict((1, 3, 4), rule="equal", paper=(1, 3, 4)).verdict == "agree"
    assert verdict([1, 3, 5], rule="equal", paper=(1, 3, 4)).verdict == "disagree"
    # paper_of: the paper's value derived from its table by the quantity's own function
    assert verdict({"I": 2}, rule="equal", paper_of={"I": 2}).verdict == "agree"
    assert verdict((True, True, True), rule="all").verdict == "agree"
    c = verdict((True, False, True), rule="all")
    assert c.verdict == "disagree" and c.ours == "2/3" and "2/3" in c.reason
    assert verdict(10.0, rule="unchecked", paper=10.0).verdict == "not comparable"
    for missing in (None, math.nan, (1.0, math.nan)):
        assert verdict(missing, rule="within", paper=1.0, tolerance=0.5).verdict == "not comparable"


def test_a_malformed_claim_is_refused():
    with pytest.raises(ValueError, match="unknown keys"):
        verdict(1.0, rule="within", paper=1.0, tolerance=0.1, tolerence=0.2)
    with pytest.raises(ValueError, match="rule"):
        verdict(1.0, rule="near", paper=1.0)
    with pytest.raises(ValueError, match="repeat"):
        spec = {"id": "a", "figure": "f", "statement": "s", "quantity": "given", "rule": "all"}
        C.data_claims([spec, spec], (True,), GIVEN)


# --- the paper's values, derived from its printed tables ---------------------------------------------------


def test_the_papers_shared_frequencies_and_key_element_counts_read_from_its_tables():
    theoretical = {c: paper.PAPER_TABLE2[c]["theoretical"] for c in paper.PAPER_TABLE2}
    # Table 2 prints 1295, 6456, 6559 Hz under every condition, as orders 1, 3, 4
    assert PC.shared_frequencies(theoretical) == paper.PAPER_SHARED
    assert PC.shared_orders(theoretical) == {"I": (1, 3, 4), "II": (1, 3, 4), "III": (1, 3, 4)}
    # Table 5: each mesh type is the key element of two orders in every condition
    counts = PC.key_element_counts(paper.PAPER_TABLE5_ELEMENT)
    assert counts == {c: {"sp": 2, "pd": 2, "dr": 2} for c in ("I", "II", "III")}
    # the shared values of our model, equal to 1e-10 across conditions, are shared; 1 % apart are not
    assert PC.shared_orders({"I": (339.8, 430.4), "II": (339.8, 482.4), "III": (154.4, 339.8)}) == {
        "I": (1,),
        "II": (1,),
        "III": (2,),
    }
    assert PC.shared_frequencies({"I": (100.0,), "II": (101.0,)}) == ()


# --- the claims on the pipeline's own products of the shipped design --------------------------------------


@pytest.fixture(scope="module")
def shipped_claims(tmp_path_factory):
    """claims.csv of design yue2014 from its plus scripts' products (a smaller relief search, as in
    test_plus_workflow; the rest as shipped)."""
    tmp = tmp_path_factory.mktemp("claims_yue2014")
    raw = yaml.safe_load((ROOT / "config" / "designs" / "yue2014.yaml").read_text())
    raw["relief"].update(landscape_points=5, maxiter=20, popsize=8, load_study_torques_Nm=[43.0])
    design = tmp / "design.yaml"
    design.write_text(yaml.safe_dump(raw))
    f = {k: tmp / k for k in ("modal.nc", "t2.csv", "sc.csv", "t5.csv", "te.nc", "opt.csv", "forced.nc")}
    scripts = ROOT / "workflow" / "scripts"
    wf.run_script(
        scripts / "plus_modal.py",
        wf.Job(
            input={"design": design},
            log=[tmp / "m.log"],
            output=dict(
                modal=f["modal.nc"],
                table02_csv=f["t2.csv"],
                table02_md=tmp / "t2.md",
                scaling_csv=f["sc.csv"],
                scaling_md=tmp / "sc.md",
                table05_csv=f["t5.csv"],
                table05_md=tmp / "t5.md",
            ),
        ),
    )
    wf.run_script(
        scripts / "plus_relief.py",
        wf.Job(
            input={"design": design},
            log=[tmp / "r.log"],
            output=dict(
                te=f["te.nc"],
                optima_csv=f["opt.csv"],
                optima_md=tmp / "opt.md",
                stiffness_csv=tmp / "st.csv",
                stiffness_md=tmp / "st.md",
                load_csv=tmp / "load.csv",
                load_md=tmp / "load.md",
            ),
        ),
    )
    wf.run_script(
        scripts / "plus_forced_response.py",
        wf.Job(
            input={"design": design, "te": f["te.nc"]},
            log=[tmp / "fr.log"],
            output=dict(data=f["forced.nc"], figure=tmp / "forced.png"),
        ),
    )
    out = {"md": tmp / "claims.md", "csv": tmp / "claims.csv"}
    wf.run_script(
        scripts / "plus_claims.py",
        wf.Job(
            input=dict(
                design=design,
                frequencies=f["t2.csv"],
                scaling=f["sc.csv"],
                key_elements=f["t5.csv"],
                modal=f["modal.nc"],
                te=f["te.nc"],
                optima=f["opt.csv"],
                forced=f["forced.nc"],
            ),
            log=[tmp / "c.log"],
            output=out,
        ),
    )
    return pd.read_csv(out["csv"]).set_index("id"), out["md"].read_text()


def test_every_claim_of_the_paper_gets_a_verdict_in_the_papers_order(shipped_claims):
    table, md = shipped_claims
    assert list(table.index) == [c["id"] for c in paper.CLAIMS] and len(table) >= 10
    assert list(table.columns) == ["figure", "statement", "paper", "ours", "tolerance", "verdict", "reason"]
    assert set(table.verdict) <= set(V.VERDICTS)
    assert md.startswith(f"# Claims of {paper.SHORT} checked: design `yue2014`")
    counts = table.verdict.value_counts()
    assert f"**{counts.get('agree', 0)} agree, " in md


def test_table2_frequencies_are_several_times_lower_than_the_papers(shipped_claims):
    table, _ = shipped_claims
    for c in ("I", "II", "III"):
        assert table.loc[f"table2_{c}", "verdict"] == "disagree"
    # condition I: 339.8 / 1295 = 0.262 ... 430.4 / 4519 = 0.0952 (docs/paper2.md, Sec. 2)
    assert "ours/paper 0.0952-0.262" in table.loc["table2_I", "reason"]
    assert table.loc["table2_I", "ours"].startswith("339.8, 430.4, 877.6, 1079, 1314, 1500 Hz")
    # the pattern of three shared (planet-mode) frequencies agrees; their orders do not
    assert table.loc["table2_shared", "verdict"] == "agree"
    assert table.loc["table2_shared", "ours"].startswith("3 (339.8, 877.6, 1314 Hz")
    assert table.loc["table2_shared_orders", "ours"] == "I: 1, 3, 5; II: 1, 3, 5; III: 2, 4, 6"
    assert table.loc["table2_shared_orders", "verdict"] == "disagree"
    # best uniform stiffness factor 41.3, RMS 29 % left (table02b)
    assert table.loc["table2_pattern", "verdict"] == "disagree" and "x 41.3" in table.loc["table2_pattern", "ours"]


def test_mode_statements_and_table5(shipped_claims):
    v = shipped_claims[0].verdict
    assert v["modes_doubled"] == v["modes_two_types"] == v["overall_modes_alike"] == "agree"
    assert v["planet_modes_central_rotation"] == "agree"
    # the floating sun carries 61 % of the first planet mode's kinetic energy
    assert v["planet_modes_sun_static"] == "disagree"
    assert shipped_claims[0].loc["planet_modes_sun_static", "ours"].startswith("0.6135")
    assert v["table5_counts"] == "agree"
    assert v["table5_order1"] == v["table5_order3"] == "disagree"
    assert "6/18 cells agree" in shipped_claims[0].loc["table5_elements", "reason"]
    assert v["table5_elements"] == "disagree"


def test_te_and_relief(shipped_claims):
    table, _ = shipped_claims
    v = table.verdict
    # 8.98 um against "about 9 um" (docs/paper2.md, Sec. 3)
    assert v["te_ptp"] == "agree" and table.loc["te_ptp", "ours"].startswith("8.97")
    assert v["te_zones"] == v["te_interference"] == "not comparable"
    # within the paper's bounds the optimum sits on the 20 um amount bound: far from 32.5 um, little gain
    assert v["relief_amount"] == "disagree" and "on the bound" in table.loc["relief_amount", "ours"]
    assert v["relief_reduction"] == v["relief_te_after"] == v["relief_paper_optimum"] == "disagree"
    amount = float(re.match(r"([\d.]+) um", table.loc["relief_amount", "ours"]).group(1))
    assert amount == pytest.approx(20.0, abs=0.5)  # the paper's lower bound, 20 um
    # the optimum within the paper's bounds does not lower the mesh force over 1000-3000 r/min by 1 dB
    assert v["noise_relief"] == "disagree" and "linear_physical" in table.loc["noise_relief", "ours"]
    assert float(table.loc["noise_relief", "ours"].split()[0]) > paper.NOISE_DROP_DB


# --- who gets claims ---------------------------------------------------------------------------------------


def _planned(run) -> list[str]:
    out = []
    for line in run.stdout.splitlines():
        m = re.match(r"\s+output: (.*)$", line)
        if m:
            out += [f.strip() for f in m.group(1).split(",")]
    return out


def test_a_plus_design_of_your_own_gets_no_claims(tmp_path):
    cfg = wf.shipped("config/config.yaml")
    cfg["designs"] = {"yue2014": "config/designs/yue2014.yaml", "myplus": "config/designs/myplus.yaml"}
    for section in ("sweeps", "points", "maps", "orbits", "calibration", "probabilities"):
        cfg[section] = {}
    cfg["claims"] = {"designs": []}
    raw = wf.shipped("config/designs/yue2014.yaml")
    raw.update(name="myplus", paper=None)
    work = wf.workflow_copy(tmp_path / "w", config=cfg, designs={"myplus": raw})
    everything = _planned(wf.snakemake(work, "-n"))
    assert {"results/yue2014/claims.md", "results/yue2014/claims.csv"} <= set(everything)
    assert [f for f in everything if f.startswith("results/myplus/") and "claims" in f] == []
    assert len([f for f in everything if f.startswith("results/myplus/")]) >= 25  # its own studies are planned
    # and no rule can make one for it
    run = wf.snakemake(work, "-n", "results/myplus/claims.md", check=False)
    assert run.returncode != 0 and "MissingRuleException" in run.stderr + run.stdout
