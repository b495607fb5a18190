# Search a paper design's unknowns for the best agreement with the paper's regime sequence along x1.


rule calibration_chunk:
    input:
        design=design_file,
    output:
        "results/{design}/calibration/{calibration}/chunk_{chunk}.nc",
    log:
        "results/{design}/logs/calibration_{calibration}_{chunk}.log",
    threads: 1
    params:
        spec=config_slice("calibration"),
    script:
        "../scripts/calibration_chunk.py"


rule calibration_merge:
    input:
        design=design_file,
        chunks=chunk_files(
            "calibration",
            "results/{design}/calibration/{name}/chunk_{chunk}.nc",
            calibration_chunks,
        ),
    output:
        scores="results/{design}/calibration/{calibration}.nc",
        design="results/{design}/calibration/{calibration}_design.yaml",
        table="results/{design}/calibration/{calibration}.md",
    log:
        "results/{design}/logs/calibration_{calibration}_merge.log",
    threads: 1
    params:
        spec=config_slice("calibration"),
    script:
        "../scripts/calibration_merge.py"


CALIBRATION_TARGETS = [
    f"results/{spec['design']}/calibration/{name}.nc"
    for name, spec in config["calibration"].items()
]
