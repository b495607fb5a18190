# Calibration of a paper design's unknowns (docs/calibration.md).
#
# A ``search`` entry: one job runs a seeded differential evolution scored by the paper's claims on a
# worker pool (the job's threads); every evaluated candidate is appended to
# results/{design}/calibration/{calibration}_cache.jsonl (not an output: it survives a failed or
# interrupted job, and a rerun replays it and resumes).  A second job measures the robustness and
# sensitivity of the best candidate (tornado chart, 2-D map) from the same cache.

SEARCH_CALIBRATIONS = list(config["calibration"])


rule calibration_search:
    input:
        design=design_file,
    output:
        scores="results/{design}/calibration/{calibration}.nc",
        best="results/{design}/calibration/{calibration}_best.json",
        design="results/{design}/calibration/{calibration}_design.yaml",
        table="results/{design}/calibration/{calibration}.md",
    log:
        "results/{design}/logs/calibration_{calibration}_search.log",
    wildcard_constraints:
        calibration=either(SEARCH_CALIBRATIONS, "no-search"),
    threads:
        lambda wildcards: config["calibration"][wildcards.calibration]["search"].get(
            "workers", 1
        )
    params:
        spec=config_slice("calibration"),
    script:
        "../scripts/calibration_search.py"


rule calibration_sensitivity:
    input:
        design=design_file,
        best="results/{design}/calibration/{calibration}_best.json",
    output:
        oat="results/{design}/calibration/{calibration}_sensitivity.nc",
        map="results/{design}/calibration/{calibration}_map.nc",
        tornado="results/{design}/calibration/{calibration}_tornado.png",
        map_figure="results/{design}/calibration/{calibration}_map.png",
        table="results/{design}/calibration/{calibration}_sensitivity.md",
    log:
        "results/{design}/logs/calibration_{calibration}_sensitivity.log",
    wildcard_constraints:
        calibration=either(SEARCH_CALIBRATIONS, "no-search"),
    threads:
        lambda wildcards: config["calibration"][wildcards.calibration]["search"].get(
            "workers", 1
        )
    params:
        spec=config_slice("calibration"),
    script:
        "../scripts/calibration_sensitivity.py"


rule calibration_compare:
    input:
        design=design_file,
        best="results/{design}/calibration/{calibration}_best.json",
        committed=committed_design,
    output:
        "results/{design}/calibration/{calibration}_vs_committed.md",
    log:
        "results/{design}/logs/calibration_{calibration}_compare.log",
    wildcard_constraints:
        calibration=either(SEARCH_CALIBRATIONS, "no-search"),
    threads: 1
    params:
        spec=config_slice("calibration"),
    script:
        "../scripts/calibration_compare.py"


CALIBRATION_TARGETS = [
    f"results/{spec['design']}/calibration/{name}.nc"
    for name, spec in config["calibration"].items()
] + [
    f"results/{config['calibration'][name]['design']}/calibration/{name}_{kind}"
    for name in SEARCH_CALIBRATIONS
    for kind in (
        "sensitivity.md",
        "sensitivity.nc",
        "map.nc",
        "tornado.png",
        "map.png",
        "vs_committed.md",
    )
]
