"""A user's own designs, end to end through config alone: `geardyn new-design` writes a KHV and a plus
design, config.yaml lists them, and `snakemake --cores 2` builds every study derived from them under
results/<design>/, with no paper attribution anywhere; `snakemake --report` then works too.

The studies are the standard ones of config/config.yaml (designs: own) at small sizes.
"""

import math
import re

import pytest
import xarray as xr
import yaml

import _results_build
import _workflow as wf
from geardyn import cli

PAPER_WORDS = re.compile(r"Li et al|Yue et al|paper 1|paper 2|Paper \(|li2013|yue2014|0\.416|0\.835", re.I)


def _own_config(shipped):
    cfg = {k: v for k, v in shipped.items() if k in ("closed_graph", "stiffness_table", "presets")}
    cfg["closed_graph"] = {"x1": {"start": -0.2, "stop": 1.6, "num": 19}, "x2": {"start": 0.0, "stop": 2.4, "num": 25}}
    cfg["stiffness_table"] = {"points": 11, "phase_points": 32}
    cfg["designs"] = {"mydrive": "config/designs/mydrive.yaml", "myplus": "config/designs/myplus.yaml"}
    own = {name: spec for name, spec in shipped["sweeps"].items() if spec.get("designs") == "own"}
    for spec in own.values():
        spec.update(num=4, chunks=1, integration=dict(wf.FAST))  # one job a sweep: chunking is test_faults's
    cfg["sweeps"] = own
    cfg["points"] = {
        n: {**s, "samples_per_period": 16} for n, s in shipped["points"].items() if s.get("designs") == "own"
    }
    cfg["maps"] = {n: s for n, s in shipped["maps"].items() if s.get("designs") == "own"}
    for spec in cfg["maps"].values():
        spec["x"]["num"], spec["y"]["num"], spec["chunks"] = 3, 3, 1
        spec["integration"] = dict(wf.FAST)
        spec["classifier"] = {"error_floor": 3e-4, "tangent_periods": 30}
        spec["curves"] = {**spec.get("curves", {}), **_results_build.CURVES}  # few seeds, as the notebook's build
    cfg["responses"] = {n: dict(s) for n, s in shipped["responses"].items() if s.get("designs") in ("all", "own")}
    for spec in cfg["responses"].values():
        spec.update(num=5, integration=dict(wf.FAST), classifier={"error_floor": 3e-4, "tangent_periods": 30})
        spec.pop("preset", None)
    cfg["probabilities"] = {n: dict(s) for n, s in shipped["probabilities"].items() if s.get("designs") == "own"}
    for spec in cfg["probabilities"].values():
        spec.update(
            samples=8, chunks=1, integration=dict(wf.FAST), classifier={"error_floor": 3e-4, "tangent_periods": 30}
        )
        spec["sensitivity"] = {**spec.get("sensitivity", {}), "samples": 8}  # 8 index lines, not 128
        spec["axis"] = {**spec["axis"], "num": 4}
        spec.pop("preset", None)
    cfg["probabilities"]["classes_w"]["classes"] = [5, 9]  # two classes, worked by hand below
    cfg["calibration"], cfg["claims"], cfg["benchmarks"] = {}, {"designs": []}, {"work_precision": False}
    return cfg


def _build(work):
    wf.workflow_copy(work)
    shipped = yaml.safe_load((work / "config/config.yaml").read_text())
    for kind, name in (("khv", "mydrive"), ("plus", "myplus")):
        assert cli.main(["new-design", "--kind", kind, name, "--out", str(work / f"config/designs/{name}.yaml")]) == 0
    plus = yaml.safe_load((work / "config/designs/myplus.yaml").read_text())
    plus["relief"].update(landscape_points=5, maxiter=10, popsize=6, load_study_torques_Nm=[43.0])
    plus["transmission_error"]["points_per_period"] = 60
    (work / "config/designs/myplus.yaml").write_text(yaml.safe_dump(plus))
    drive = yaml.safe_load((work / "config/designs/mydrive.yaml").read_text())
    drive["dynamics"] = {"integration": dict(wf.FAST)}
    (work / "config/designs/mydrive.yaml").write_text(yaml.safe_dump(drive))
    (work / "config/config.yaml").write_text(yaml.safe_dump(_own_config(shipped)))
    wf.snakemake(work, "--cores", "2", timeout=900)
    wf.snakemake(work, "--report", "results/report.html", timeout=300)


@pytest.fixture(scope="module")
def own(tmp_path_factory):
    return wf.shared(tmp_path_factory, "own_designs", _build)


def test_every_standard_study_is_built_under_the_designs_own_names(own):
    res = own / "results"
    for rel in (
        "data/closed_graph.nc",
        "data/stiffness_table.nc",
        "figures/closed_graph.png",
        "figures/single_tooth_stiffness.png",
        "figures/mesh_stiffness.png",
        "figures/backlash.png",
        "sweeps/bifurcation_x1.nc",
        "sweeps/bifurcation_b.nc",
        "sweeps/bifurcation_e.nc",
        "points/points_x1.nc",
        "maps/map_own_w_e.nc",
        "tables/bifurcation_x1_bands.md",
        "figures/bifurcation_b.png",
        "figures/map_own_w_e.png",
        "response/frequency_response.nc",
        "figures/frequency_response.png",
        "probabilities/regimes_w.nc",  # at the tolerance class new-design writes
        "figures/regimes_w.png",
        "tables/regimes_w.md",
    ):
        assert (res / "mydrive" / rel).exists(), rel
    for rel in (
        "data/modal.nc",
        "data/te.nc",
        "data/forced_response.nc",
        "tables/natural_frequencies.csv",
        "tables/stiffness_scaling.md",
        "tables/key_elements.csv",
        "tables/relief_optima.csv",
        "tables/mesh_stiffness.csv",
        "tables/relief_vs_load.csv",
        "figures/te_unmodified.png",
        "figures/modal_strain_energy.png",
        "figures/modal_kinetic_energy.png",
        "figures/mode_shapes.png",
        "figures/te_relief.png",
        "figures/relief_landscape.png",
        "figures/forced_response.png",
    ):
        assert (res / "myplus" / rel).exists(), rel
    assert not (res / "li2013").exists() and not (res / "yue2014").exists()  # only listed designs are built
    assert not (res / "mydrive" / "claims.md").exists()  # claims are a paper's


def test_no_paper_figure_or_table_numbers_in_the_file_names(own):
    # a design of your own has no paper: no fig03_, table02_, sec4_ ... in the names of its outputs
    numbered = re.compile(r"^(fig|table|sec)\d")
    for design in ("mydrive", "myplus"):
        names = [p.name for p in (own / "results" / design).rglob("*") if p.is_file()]
        assert len(names) >= 20
        assert [n for n in names if numbered.match(n)] == [], design


def test_the_studies_run_on_the_designs_own_segment(own):
    drive = yaml.safe_load((own / "config/designs/mydrive.yaml").read_text())
    lo, hi = drive["admissible"]["x1_min"], drive["admissible"]["x1_max"]
    with xr.open_dataset(own / "results/mydrive/sweeps/bifurcation_x1.nc") as cube:
        x1 = cube["x1"].values
    assert x1[0] == pytest.approx(lo) and x1[-1] == pytest.approx(hi)
    with xr.open_dataset(own / "results/mydrive/sweeps/bifurcation_b.nc") as cube:
        cases = [str(c) for c in cube["case"].values]
    assert cases == [f"x1={lo + f * (hi - lo):g}" for f in (0.1, 0.5, 0.9)]


def test_no_paper_attribution_in_any_output(own):
    res = own / "results"
    checked = 0
    for path in sorted(res.rglob("*")):
        if path.suffix == ".nc":
            with xr.open_dataset(path) as ds:
                assert "paper" not in ds.attrs, path
                text = " ".join(str(v) for k, v in ds.attrs.items() if k not in ("config_json",))
        elif path.suffix in (".txt", ".md", ".csv"):
            text = path.read_text()
        else:
            continue
        checked += 1
        found = PAPER_WORDS.search(text)
        assert found is None, f"{path.relative_to(res)}: {found.group(0) if found else ''}"
    assert checked >= 30


def test_the_report_files_the_designs_under_their_own_names(own):
    html = (own / "results/report.html").read_text(errors="replace")
    assert "Design mydrive" in html and "Design myplus" in html
    assert "Paper 1" not in html and "Paper 2" not in html


def test_check_design_prints_the_geometry_of_an_infeasible_design(own, capsys):
    path = own / "config/designs/mydrive.yaml"
    raw = yaml.safe_load(path.read_text())
    raw["pair"]["x2"] = 0.3  # fixed x2 far off line 4
    bad = path.with_name("bad.yaml")
    bad.write_text(yaml.safe_dump(raw))
    assert cli.main(["check-design", str(bad)]) == 1
    out = capsys.readouterr().out
    assert "contact_ratio" in out and "NOT FEASIBLE" in out and "nan" not in out.lower().split("not feasible")[0]


def test_the_class_study_of_a_new_design(own):
    """geardyn new-design's drive (its tolerance block: class 6, allowances) gets the class study's file, figure and
    table; its TE bound is that of ISO 1328-1:2013's profile tolerances at the two classes."""
    out = own / "results/mydrive"
    with xr.open_dataset(out / "probabilities/classes_w.nc") as ds:
        assert ds.sizes["tolerance_class"] == 2
        # classes 5 and 9 of the drive (m = 2, d = 80 and 86 mm): (7) 0.8 + 0.08 + 4 = 4.88 (4.886), (8) 1.1 + 5 = 6.1,
        # (9) sqrt(4.88^2 + 6.1^2) = 7.81 -> 8.0 at class 5 and x 4 = 31.25 -> 31 at class 9, on both gears;
        # e_max half the rss: 8 / sqrt 2 = 5.657 and 31 / sqrt 2 = 21.92 um
        assert ds.e_max.values == pytest.approx([8.0 / math.sqrt(2), 31.0 / math.sqrt(2)], abs=1e-9)
        assert set(ds.coarsest_class.values) <= {0, 5, 9}
    table = (out / "tables/classes_w.md").read_text()
    assert "coarsest class" in table and (out / "figures/classes_w.png").stat().st_size > 10_000
