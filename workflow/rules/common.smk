# Helpers shared by the rules: which designs exist, the one config accessor, the design file of a job.


def designs_of_kind(kind):
    return [name for name, raw in DESIGNS.items() if raw["kind"] == kind]


def designs_of_paper(paper):
    return [name for name, raw in DESIGNS.items() if raw.get("paper") == paper]


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
    return (
        f"results/{{design}}/{folder}/{name_of(scheme, paper_name, own_name)}{suffix}"
    )


#: The wildcard that names an entry of each config section.
SECTION_KEYS = {
    "sweeps": "sweep",
    "points": "points",
    "maps": "map",
    "calibration": "calibration",
    "orbits": "sweep",
    "responses": "response",
}


def config_slice(section):
    """The one accessor of config slices (for ``params:``): the entry of ``section`` named by the
    job's wildcard (``SECTION_KEYS``), or the whole section when it has no such wildcard.
    """

    def get(wildcards):
        key = SECTION_KEYS.get(section)
        return config[section][wildcards[key]] if key else config[section]

    return get


def design_file(wildcards):
    """The design file of the job's design (``{design}`` wildcard)."""
    return config["designs"][wildcards.design]


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
    chunk=r"\d+",


def per_design(pattern, designs):
    return expand(pattern, design=designs)


def runs_for(section, pattern):
    """``pattern`` for every (design, name) of a config section: the designs each entry selects."""
    from geardyn.validate import selected_designs

    return [
        pattern.format(design=design, name=name)
        for name, spec in config[section].items()
        for design in selected_designs(spec["designs"], DESIGNS)
    ]


def chunk_files(section, pattern, n_chunks):
    """Input function: the chunk files of one run; ``n_chunks(name, spec, design)`` counts them."""

    def get(wildcards):
        key = SECTION_KEYS[section]
        name = wildcards[key]
        count = n_chunks(name, config[section][name], wildcards.design)
        return expand(pattern, design=wildcards.design, name=name, chunk=range(count))

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


def design_targets(design, targets):
    """The files of ``targets`` (e.g. ``rules.all.input``) under results/<design>/: one design's studies."""
    prefix = f"results/{design}/"
    return sorted({str(f) for f in targets if str(f).startswith(prefix)})


def archive_cubes(wildcards):
    """The netCDF cubes of ``rule all`` under results/<design>/ (chunk files are not final cubes)."""
    prefix = f"results/{wildcards.design}/"
    return sorted(
        {
            str(f)
            for f in rules.all.input
            if str(f).startswith(prefix) and str(f).endswith(".nc")
        }
    )


def effective_config(wildcards):
    return config
