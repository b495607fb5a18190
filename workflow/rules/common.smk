# Helpers shared by the rules: where files go (the one path helper), which designs exist, the one config
# accessor, the design file of a job.

#: The root of every file the workflow writes. A rule writes its paths through results() and logs(),
#: never as literals, so a rename touches one line.
RESULTS = "results"


def results(*parts, design="{design}"):
    """A path under the results root: ``results("sweeps", "{sweep}.nc")`` is
    ``results/{design}/sweeps/{sweep}.nc`` (``design``: the job's wildcard, a design's name, or ``None``
    for a file of no design such as the benchmarks or an archive)."""
    return "/".join([RESULTS, *([design] if design else []), *parts])


def logs(name, design="{design}"):
    """The log of a job: ``results/<design>/logs/<name>``."""
    return results("logs", name, design=design)


def benchmarks(*parts):
    """``results/benchmarks/<parts>``: the solver's own studies, which belong to no design."""
    return results("benchmarks", *parts, design=None)


def designs_of_kind(kind):
    return [name for name, raw in DESIGNS.items() if raw["kind"] == kind]


KHV_DESIGNS = designs_of_kind("khv")
PLUS_DESIGNS = designs_of_kind("plus_planetary")


def naming_schemes(kind):
    """(scheme, designs) pairs of one kind: "paper" for the designs that name a paper (their outputs keep
    the paper's figure and table numbers), "own" for the others (descriptive names only).
    """
    names = designs_of_kind(kind)
    return (
        ("paper", [d for d in names if DESIGNS[d].get("paper")]),
        ("own", [d for d in names if not DESIGNS[d].get("paper")]),
    )


def name_of(scheme, paper_name, own_name):
    """A file stem, a rule's name or a report label: the paper's (numbered) one under scheme "paper", the
    descriptive one otherwise."""
    return paper_name if scheme == "paper" else own_name


def scheme_path(scheme, folder, paper_name, own_name, suffix=""):
    """``results/{design}/<folder>/<stem><suffix>`` with the stem of the naming scheme."""
    return results(folder, f"{name_of(scheme, paper_name, own_name)}{suffix}")


#: The wildcard that names an entry of each config section.
SECTION_KEYS = {
    "sweeps": "sweep",
    "points": "points",
    "maps": "map",
    "calibration": "calibration",
    "orbits": "sweep",
    "responses": "response",
    "curves": "study",
    "probabilities": "prob",
}


def config_slice(section, omit=()):
    """The one accessor of config slices (for ``params:``): the entry of ``section`` named by the
    job's wildcard (``SECTION_KEYS``), or the whole section when it has no such wildcard; without the
    entry's keys ``omit`` (settings of other rules, so that changing them does not rerun this one).
    """

    def get(wildcards):
        key = SECTION_KEYS.get(section)
        entry = config[section][wildcards[key]] if key else config[section]
        return {k: v for k, v in entry.items() if k not in omit} if omit else entry

    return get


def design_file(wildcards):
    """The design file of the job's design (``{design}`` wildcard)."""
    return config["designs"][wildcards.design]


def search_workers(wildcards):
    """The threads of a calibration job: the worker pool of its search (``workers``, default 1)."""
    return config["calibration"][wildcards.calibration]["search"].get("workers", 1)


def committed_design(wildcards):
    """The committed design file a search reproduces (its ``design_name``, else ``<design>_calibrated``)."""
    search = config["calibration"][wildcards.calibration]["search"]
    name = search.get("design_name") or f"{wildcards.design}_calibrated"
    return config["designs"].get(name, f"config/designs/{name}.yaml")


def either(names, none):
    return "|".join(sorted(names, key=len, reverse=True)) or none


wildcard_constraints:
    design=either(DESIGNS, "no-design"),
    sweep=either(config["sweeps"], "no-sweep"),
    points=either(config["points"], "no-points"),
    map=either(config["maps"], "no-map"),
    calibration=either(config["calibration"], "no-calibration"),
    response=either(config["responses"], "no-response"),
    study=either(config["curves"], "no-study"),
    prob=either(config["probabilities"], "no-prob"),
    chunk=r"\d+",


def per_design(pattern, designs):
    return expand(pattern, design=designs)


def entry_path(pattern, section, name, design):
    """``pattern`` (a rule's output) for entry ``name`` of a config section and one design."""
    return str(pattern).format(design=design, **{SECTION_KEYS[section]: name})


def runs_for(section, *patterns):
    """Each of ``patterns`` (a rule's outputs) for every (design, entry) of a config section: the designs
    each entry selects (``designs:``, or a calibration's one ``design:``), the entry's name in the
    section's wildcard (``SECTION_KEYS``)."""
    from geardyn.config.run_checks import study_designs

    return [
        entry_path(pattern, section, name, design)
        for pattern in patterns
        for name, spec in config[section].items()
        for design in study_designs(spec, DESIGNS)
    ]


def chunk_files(section, pattern, n_chunks):
    """Input function: the chunk files of one run (``pattern``: the chunk rule's output);
    ``n_chunks(name, spec, design)`` counts them."""

    def get(wildcards):
        key = SECTION_KEYS[section]
        name = wildcards[key]
        count = n_chunks(name, config[section][name], wildcards.design)
        return expand(
            str(pattern), design=wildcards.design, chunk=range(count), **{key: name}
        )

    return get


def segment_of(design):
    """The admissible segment (x1_min, x1_max) of a KHV design (resolves percentages of x1)."""
    adm = DESIGNS[design]["admissible"]
    return (adm["x1_min"], adm["x1_max"])


def sweep_chunks(name, spec, design):
    from geardyn.runs.sweep import SweepSpec

    return SweepSpec.from_config(name, spec, design, segment_of(design)).n_chunks


def map_chunks(name, spec, design):
    from geardyn.runs.maps import MapSpec

    return MapSpec.from_config(name, spec, design, segment_of(design)).n_chunks


def probability_chunks(name, spec, design):
    from geardyn.runs.probabilities import ProbabilitySpec

    return ProbabilitySpec.from_config(name, spec, design, segment_of(design)).n_chunks


def probability_claims(pattern):
    """``pattern`` (the probabilities claims rule's output) for every design of every study that checks claims."""
    from geardyn.config.run_checks import study_designs

    return [
        entry_path(pattern, "probabilities", name, design)
        for name, spec in config["probabilities"].items()
        if spec.get("claims")
        for design in study_designs(spec, DESIGNS)
    ]


def skipped_designs(section):
    """For ``params:``: the lines saying which designs the job's study skips (caption and log)."""
    from geardyn.config.run_checks import skipped_runs

    def get(wildcards):
        name = wildcards[SECTION_KEYS[section]]
        return skipped_runs({section: {name: config[section][name]}}, DESIGNS)

    return get


def design_targets(design, targets):
    """The files of ``targets`` (e.g. ``rules.all.input``) under results/<design>/: one design's studies."""
    prefix = results(design=design) + "/"
    return sorted({str(f) for f in targets if str(f).startswith(prefix)})


def archive_cubes(wildcards):
    """The netCDF cubes of ``rule all`` under results/<design>/ (chunk files are not final cubes)."""
    return [
        f
        for f in design_targets(wildcards.design, rules.all.input)
        if f.endswith(".nc")
    ]


def claims_runs(wildcards):
    """Input function (``unpack``) of the claims of the job's design: the runs its paper's claims read
    (``CLAIM_RUNS`` of the paper's module in geardyn.papers), by role (``fig07``, ``fig08_points``, ...).
    """
    from geardyn.papers import paper_of

    paper = paper_of(DESIGNS[wildcards.design].get("paper"))
    produced = {
        "sweeps": rules.sweep_merge.output[0],
        "points": rules.point_runs.output.data,
    }
    return {
        role: entry_path(produced[section], section, name, wildcards.design)
        for role, (section, name) in paper.CLAIM_RUNS.items()
    }


def effective_config(wildcards):
    return config
