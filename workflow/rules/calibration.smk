# Calibration of a paper design's unknowns (docs/calibration.md).
#
# Each entry of `calibration:` is a search: one job runs a seeded differential evolution scored by the
# paper's claims on a worker pool (the job's threads); every evaluated candidate is appended to
# results/{design}/calibration/{calibration}_cache.jsonl (not an output: it survives a failed or
# interrupted job, and a rerun replays it and resumes).  A second job measures the robustness and
# sensitivity of the best candidate (tornado chart, 2-D map) from the same cache; a third compares the
# best candidate with the committed design the search once produced.


rule calibration_search:
    input:
        kernels=KERNELS,
        design=design_file,
    output:
        scores=results("calibration", "{calibration}.nc"),
        best=results("calibration", "{calibration}_best.json"),
        design=results("calibration", "{calibration}_design.yaml"),
        table=results("calibration", "{calibration}.md"),
    log:
        logs("calibration_{calibration}_search.log"),
    threads: search_workers
    params:
        spec=config_slice("calibration"),
    script:
        "../scripts/calibration_search.py"


rule calibration_sensitivity:
    input:
        design=design_file,
        best=rules.calibration_search.output.best,
    output:
        oat=results("calibration", "{calibration}_sensitivity.nc"),
        map=results("calibration", "{calibration}_map.nc"),
        tornado=results("calibration", "{calibration}_tornado.png"),
        map_figure=results("calibration", "{calibration}_map.png"),
        table=results("calibration", "{calibration}_sensitivity.md"),
    log:
        logs("calibration_{calibration}_sensitivity.log"),
    threads: search_workers
    params:
        spec=config_slice("calibration"),
    script:
        "../scripts/calibration_sensitivity.py"


rule calibration_compare:
    input:
        design=design_file,
        best=rules.calibration_search.output.best,
        committed=committed_design,
    output:
        results("calibration", "{calibration}_vs_committed.md"),
    log:
        logs("calibration_{calibration}_compare.log"),
    threads: 1
    params:
        spec=config_slice("calibration"),
    script:
        "../scripts/calibration_compare.py"


CALIBRATION_TARGETS = runs_for(
    "calibration",
    rules.calibration_search.output.scores,
    *rules.calibration_sensitivity.output,
    *rules.calibration_compare.output,
)
