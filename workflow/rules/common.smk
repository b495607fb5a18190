# Helpers shared by the rules: which designs exist and the config slice each rule needs.


def designs_of_kind(kind):
    return [name for name, raw in DESIGNS.items() if raw["kind"] == kind]


KHV_DESIGNS = designs_of_kind("khv")


wildcard_constraints:
    design="|".join(sorted(KHV_DESIGNS, key=len, reverse=True)) or "no-khv-design",


def design_file(wildcards):
    return config["designs"][wildcards.design]


def closed_graph_spec(wildcards):
    return config["closed_graph"]


def stiffness_spec(wildcards):
    return config["stiffness_table"]


def per_khv_design(pattern):
    return expand(pattern, design=KHV_DESIGNS)


wildcard_constraints:
    sweep="|".join(config["sweeps"]) or "no-sweep",
    points="|".join(config["points"]) or "no-points",
    chunk=r"\d+",


def sweep_spec(wildcards):
    return config["sweeps"][wildcards.sweep]


def points_spec(wildcards):
    return config["points"][wildcards.points]


def sweep_design_file(wildcards):
    return config["designs"][wildcards.design]


def points_design_file(wildcards):
    return config["designs"][wildcards.design]


def runs_for(section, pattern):
    """``pattern`` for every (design, name) of a config section whose entries list their designs."""
    return [
        pattern.format(design=design, name=name)
        for name, spec in config[section].items()
        for design in spec["designs"]
    ]


def checked_chunks(paths):
    """``paths``, after setting aside (``.damaged``) any chunk file that does not read back whole, so
    that it is recomputed rather than merged (issue 7; see geardyn.io.set_aside_damaged)."""
    from snakemake.logging import logger

    from geardyn.io import set_aside_damaged

    set_aside_damaged(paths, log=logger.warning)
    return paths


def sweep_chunk_files(wildcards):
    from geardyn.sweep import SweepSpec

    spec = SweepSpec.from_config(wildcards.sweep, config["sweeps"][wildcards.sweep], wildcards.design)
    return checked_chunks(expand(
        "results/{design}/sweeps/{sweep}/chunk_{chunk}.nc",
        design=wildcards.design,
        sweep=wildcards.sweep,
        chunk=range(spec.n_chunks),
    ))


wildcard_constraints:
    calibration="|".join(config["calibration"]) or "no-calibration",


def calibration_spec(wildcards):
    return config["calibration"][wildcards.calibration]


def calibration_design_file(wildcards):
    return config["designs"][config["calibration"][wildcards.calibration]["design"]]


def calibration_chunk_files(wildcards):
    from geardyn.calibrate import candidate_grid, n_chunks

    spec = config["calibration"][wildcards.calibration]
    count = n_chunks(len(candidate_grid(spec["grid"])), spec["chunks"])
    return checked_chunks(expand(
        "results/{design}/calibration/{calibration}/chunk_{chunk}.nc",
        design=wildcards.design,
        calibration=wildcards.calibration,
        chunk=range(count),
    ))


def claims_spec(wildcards):
    return config["claims"]


wildcard_constraints:
    map="|".join(config["maps"]) or "no-map",


def map_spec(wildcards):
    return config["maps"][wildcards.map]


def map_chunk_files(wildcards):
    from geardyn.maps import MapSpec

    spec = MapSpec.from_config(wildcards.map, config["maps"][wildcards.map], wildcards.design)
    return checked_chunks(expand(
        "results/{design}/maps/{map}/chunk_{chunk}.nc",
        design=wildcards.design,
        map=wildcards.map,
        chunk=range(spec.n_chunks),
    ))
