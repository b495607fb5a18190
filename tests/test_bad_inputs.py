"""Malformed designs and configs: each gives one geardyn line, before anything runs.

Every case goes through :func:`geardyn.config.validate.validate_workflow` in-process, the code the Snakefile
and `geardyn check-config` run; a handful (END_TO_END) also run the real workflow (a copy in tmp_path,
`snakemake --cores 1`, no dry run): if a case slipped through, jobs would start and results/ would appear.
"""

import pytest

import _workflow as wf
from geardyn.config import ConfigError
from geardyn.config.validate import read_config_file, selected_designs, validate_workflow

LI2013 = "config/designs/li2013.yaml"


def _design(change):
    def make(cfg, designs, work):
        change(designs["li2013"])

    return make


def _config(change):
    def make(cfg, designs, work):
        change(cfg)

    return make


def _sweep(change):
    return _config(lambda c: change(c["sweeps"]["fig07_small"]))


def _raw_file(rel, data):
    def make(cfg, designs, work):
        designs.pop("li2013", None) if rel == LI2013 else None
        return rel, data

    return make


def _pop(mapping, *keys):
    for key in keys[:-1]:
        mapping = mapping[key]
    mapping.pop(keys[-1])


#: (id, how to break the input, text the one-line error must contain)
CASES = [
    # design file: wrong types
    ("z1-not-integer", _design(lambda d: d["pair"].update(z1="thirty")), "pair.z1 = 'thirty' is not allowed: integer"),
    ("module-a-list", _design(lambda d: d["pair"].update(module=[3.5])), "pair.module = [3.5] is not allowed: number"),
    (
        "torque-a-string",
        _design(lambda d: d["dynamics"]["parameters"].update(T_D="50")),
        "dynamics.parameters.T_D = '50' is not allowed: number",
    ),
    # design file: out-of-range values
    (
        "pressure-angle-60",
        _design(lambda d: d["pair"].update(pressure_angle_deg=60)),
        "pair.pressure_angle_deg = 60 is not allowed: number > 0 and < 45",
    ),
    (
        "negative-damping",
        _design(lambda d: d["dynamics"]["parameters"].update(zeta=-0.1)),
        "dynamics.parameters.zeta = -0.1 is not allowed: number >= 0",
    ),
    ("few-teeth", _design(lambda d: d["pair"].update(z1=5)), "pair.z1 = 5 is not allowed: integer >= 8"),
    # design file: infeasible gear pairs
    ("same-teeth-number", _design(lambda d: d["pair"].update(z1=33, z2=33)), "pair.z2 - pair.z1 = 0 is not allowed"),
    (
        "design-point-infeasible",
        _design(lambda d: d["pair"].update(x1=0.2, x2=0.2)),
        "design point (x1, x2) = (0.2000, 0.2000) is outside the feasible region",
    ),
    (
        "segment-leaves-feasible-region",
        _design(lambda d: d["admissible"].update(x1_max=1.5)),
        "admissible segment x1 = [0.416, 1.5] leaves the feasible region",
    ),
    (
        "segment-below-line4",
        _design(lambda d: d["admissible"].update(x1_min=-0.9)),
        "admissible segment x1 = [-0.9, 0.835] leaves the region the model covers at x1 = -0.9000: no x2 on line 4",
    ),
    (
        "segment-reversed",
        _design(lambda d: d["admissible"].update(x1_min=0.9)),
        "admissible.x1_min = 0.9 must be below admissible.x1_max",
    ),
    # design file: missing keys, typos in keys, wrong kind or name
    (
        "closed-graph-percentage",
        _config(lambda c: c.setdefault("closed_graph", {}).update(x1={"start": "10%", "stop": 1.1, "num": 5})),
        "closed_graph.x1.start = '10%' is not allowed: number",
    ),
    ("missing-pair", _design(lambda d: d.pop("pair")), "missing required key 'pair'"),
    ("missing-module", _design(lambda d: _pop(d, "pair", "module")), "missing required key 'pair.module'"),
    (
        "typo-stifness",
        _design(lambda d: d.update(stifness=d.pop("stiffness"))),
        "unknown key 'stifness' (did you mean 'stiffness'?)",
    ),
    (
        "typo-modul",
        _design(lambda d: d["pair"].update(modul=d["pair"].pop("module"))),
        "unknown key 'pair.modul' (did you mean 'module'?)",
    ),
    ("kind-typo", _design(lambda d: d.update(kind="kvh")), "kind = 'kvh' is not allowed: one of 'khv'"),
    ("name-differs", _design(lambda d: d.update(name="li2014")), "name = 'li2014' differs from its key 'li2013'"),
    # design file: unreadable
    (
        "design-not-utf8",
        _raw_file(LI2013, "kind: khv\nname: li2013\ntitle: caf\xe9\n".encode("latin-1")),
        "li2013.yaml: not UTF-8 text",
    ),
    (
        "design-yaml-syntax",
        _raw_file(LI2013, b"kind: khv\npair: {z1: 30, z2: 33\nname: li2013\n"),
        "li2013.yaml: YAML syntax error at line",
    ),
    ("design-empty", _raw_file(LI2013, b""), "li2013.yaml: expected a mapping with a 'kind' key"),
    # config: empty sweeps
    ("sweep-no-points", _sweep(lambda s: s.update(num=0)), "sweeps.fig07_small.num = 0 is not allowed: integer >= 1"),
    ("sweep-no-cases", _sweep(lambda s: s.update(cases=[])), "sweeps.fig07_small.cases = [] is not allowed"),
    ("sweep-no-designs", _sweep(lambda s: s.update(designs=[])), "sweeps.fig07_small.designs = [] is not allowed"),
    (
        "sweep-empty-spec",
        _config(lambda c: c["sweeps"].update(fig07_small={})),
        "missing required key 'sweeps.fig07_small.parameter'",
    ),
    # config: sweep ranges outside the feasible region / allowed range
    (
        "sweep-leaves-segment",
        _sweep(lambda s: s.update(start=0.3, stop=0.9)),
        "sweeps.fig07_small.start: x1 = 0.3 is not allowed: number >= 0.416 and <= 0.835 (the admissible segment of",
    ),
    (
        "case-x1-outside",
        _sweep(lambda s: s.update(parameter="b", start=0.0, stop=2.0, cases=[{"x1": 0.9}])),
        "sweeps.fig07_small.cases[0]: x1 = 0.9 is not allowed",
    ),
    (
        "negative-backlash",
        _sweep(lambda s: s.update(parameter="b", start=-1.0, stop=2.0)),
        "sweeps.fig07_small.start: b = -1.0 is not allowed: number >= 0",
    ),
    ("sweep-reversed", _sweep(lambda s: s.update(start=0.8, stop=0.5)), "stop = 0.5 must be above start = 0.8"),
    (
        "steps-too-few",
        _sweep(lambda s: s["integration"].update(steps_per_period=2)),
        "sweeps.fig07_small.integration.steps_per_period = 2 is not allowed: integer >= 8",
    ),
    # config: unknown names, typos, wrong types
    (
        "unknown-parameter",
        _sweep(lambda s: s.update(parameter="x3")),
        "sweeps.fig07_small.parameter: unknown control parameter 'x3' (allowed: b, e, speed, w, x1, I_D",
    ),
    (
        "override-typo",
        _sweep(lambda s: s["fixed"].update(bb=1.0)),
        "unknown control parameter 'bb' (did you mean 'b'?)",
    ),
    (
        "sweep-key-typo",
        _sweep(lambda s: s.update(chunk=s.pop("chunks"))),
        "unknown key 'sweeps.fig07_small.chunk' (did you mean 'chunks'?)",
    ),
    (
        "top-key-typo",
        _config(lambda c: c.update(sweep=c.pop("sweeps"))),
        "unknown key 'sweep' (did you mean 'sweeps'?)",
    ),
    ("num-a-string", _sweep(lambda s: s.update(num="many")), "sweeps.fig07_small.num = 'many' is not allowed: integer"),
    (
        "unknown-design",
        _sweep(lambda s: s.update(designs=["li2031"])),
        "design 'li2031' is not allowed: one of 'li2013'",
    ),
    (
        "design-file-missing",
        _config(lambda c: c["designs"].update(li2013="config/designs/none.yaml")),
        "config/designs/none.yaml: file not found",
    ),
    (
        "calibration-without-search",
        _config(lambda c: c["calibration"].update(cal={"design": "li2013"})),
        "missing required key 'calibration.cal.search'",
    ),
    # config file: unreadable
    (
        "config-not-utf8",
        _raw_file("config/config.yaml", "designs:\n  li2013: caf\xe9.yaml\n".encode("latin-1")),
        "config/config.yaml: not UTF-8 text",
    ),
    (
        "config-yaml-syntax",
        _raw_file("config/config.yaml", b"designs: {li2013: config/designs/li2013.yaml\n"),
        "config/config.yaml: YAML syntax error at line",
    ),
    ("config-empty", _raw_file("config/config.yaml", b""), "config/config.yaml: the file is empty"),
    (
        "config-a-list",
        _raw_file("config/config.yaml", b"- li2013\n- yue2014\n"),
        "config/config.yaml: expected a mapping with a 'designs' key at the top level, got list",
    ),
    (
        "config-duplicate-key",
        _raw_file("config/config.yaml", b"designs: {li2013: config/designs/li2013.yaml}\nsweeps: {}\nsweeps: {}\n"),
        "config/config.yaml: duplicate key 'sweeps' at line 3 (first at line 2)",
    ),
    (
        "config-alias-bomb",
        _raw_file(
            "config/config.yaml",
            b"a0: &a0 [lol]\n"
            + b"".join(f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 9)}]\n".encode() for i in range(1, 10))
            + b"designs: *a9\n",
        ),
        "config/config.yaml: expanded size of designs = ",
    ),
    # config: names that are selector words, too long or unusable in paths; presets; degenerate maps
    (
        "design-named-all",
        _config(lambda c: c.update(designs={"all": LI2013})),
        "config: designs name 'all' is not allowed",
    ),
    (
        "design-name-300",
        _config(lambda c: c.update(designs={"d" * 300: LI2013})),
        "(300 characters) is not allowed: at most 64 characters",
    ),
    (
        "unknown-preset",
        _sweep(lambda s: s.update(preset="cheap")),
        "sweeps.fig07_small.preset = 'cheap' is not allowed: the name of an entry of presets, and the config has none",
    ),
    (
        "map-one-parameter",
        _config(
            lambda c: c.update(
                maps={
                    "m": {
                        "designs": ["li2013"],
                        "x": {"parameter": "b", "start": 0, "stop": 1, "num": 3},
                        "y": {"parameter": "b", "start": 0, "stop": 2, "num": 3},
                    }
                }
            )
        ),
        "maps.m.y.parameter = 'b' is not allowed: a parameter other than x.parameter ('b')",
    ),
    # NaN, infinity and numbers YAML 1.1 reads as strings
    (
        "module-nan",
        _design(lambda d: d["pair"].update(module=float("nan"))),
        "pair.module = nan is not allowed: a finite number",
    ),
    (
        "torque-nan",
        _design(lambda d: d["dynamics"]["parameters"].update(T_D=float("nan"))),
        "dynamics.parameters.T_D = nan is not allowed: a finite number",
    ),
    (
        "zeta-inf",
        _design(lambda d: d["dynamics"]["parameters"].update(zeta=float("inf"))),
        "dynamics.parameters.zeta = inf is not allowed: a finite number",
    ),
    (
        "sweep-b-nan",
        _sweep(lambda s: s["fixed"].update(b=float("nan"))),
        "sweeps.fig07_small.fixed.b = nan is not allowed: a finite number",
    ),
    (
        "claims-unknown-design",
        _config(lambda c: c.update(claims={"designs": ["li2031"]})),
        "claims.designs: design 'li2031' is not allowed: one of 'li2013'",
    ),
    (
        # the runs paper 1's claims read (papers.li2013.CLAIM_RUNS) are not in this config
        "claims-without-their-runs",
        _config(lambda c: c.update(claims={"designs": ["li2013"]})),
        "claims.designs: design 'li2013' needs sweeps.fig07_bifurcation_x1 to run for it",
    ),
    (
        "percent-for-b",
        _sweep(lambda s: s["fixed"].update(b="50%")),
        "sweeps.fig07_small.fixed.b = '50%' is not allowed: number (percentages of the admissible segment are for x1",
    ),
    ("unknown-selector-paper", _sweep(lambda s: s.update(designs="paper:li2031")), None),
]

#: Cases that also run the real workflow end to end (Snakemake's start-up costs seconds each).
END_TO_END = (
    "design-empty",
    "config-a-list",
    "sweep-b-nan",
    "segment-leaves-feasible-region",
    "module-nan",
    "config-alias-bomb",
    "design-name-300",
)


def _inputs(tmp_path, make):
    cfg, designs = wf.sweep_config(num=3, chunks=1), {"li2013": wf.shipped(LI2013)}
    raw = make(cfg, designs, tmp_path)
    work = wf.workflow_copy(tmp_path / "w", cfg, designs)
    if raw:
        rel, data = raw
        (work / rel).write_bytes(data)
    return work


@pytest.mark.parametrize(("make", "message"), [c[1:] for c in CASES if c[2]], ids=[c[0] for c in CASES if c[2]])
def test_bad_input_gives_one_line_from_the_validator(tmp_path, make, message):
    work = _inputs(tmp_path, make)
    with pytest.raises(ConfigError) as err:
        validate_workflow(read_config_file(work / "config/config.yaml"), work)
    text = str(err.value)
    assert "\n" not in text and message in text, text


def test_a_selector_that_selects_nothing_runs_nothing(tmp_path):
    make = dict((c[0], c[1]) for c in CASES)["unknown-selector-paper"]
    work = _inputs(tmp_path, make)
    filled, designs = validate_workflow(read_config_file(work / "config/config.yaml"), work)

    assert selected_designs(filled["sweeps"]["fig07_small"]["designs"], designs) == []


@pytest.mark.parametrize("case", END_TO_END)
def test_bad_input_stops_snakemake_before_any_job_with_one_line(tmp_path, case):
    make, message = dict((c[0], c[1:]) for c in CASES)[case]
    work = _inputs(tmp_path, make)
    run = wf.snakemake(work, "--cores", "1", "results/li2013/sweeps/fig07_small.nc", timeout=120, check=False)
    assert run.returncode != 0
    lines = [line for line in (run.stderr + run.stdout).splitlines() if line.strip()]
    assert len(lines) == 1, run.stderr + run.stdout
    assert lines[0].startswith("geardyn config error:") and message in lines[0], lines[0]
    assert not (work / "results").exists()


def test_yaml_numbers_as_yaml_1_2_reads_them(tmp_path):
    path = tmp_path / "c.yaml"
    path.write_text("a: 1.0e6\nb: 2e-6\nc: 1e-3\nd: '1e6'\n")
    assert read_config_file(path) == {"a": 1.0e6, "b": 2e-6, "c": 1e-3, "d": "1e6"}
