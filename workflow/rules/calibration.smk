# Search the unknowns of paper 1 for the best agreement with its regime sequence along x1.


rule calibration_chunk:
    input:
        design=calibration_design_file,
    output:
        "results/{design}/calibration/{calibration}/chunk_{chunk}.nc",
    log:
        "results/{design}/logs/calibration_{calibration}_{chunk}.log",
    params:
        spec=calibration_spec,
    threads: 1
    script:
        "../scripts/calibration_chunk.py"


rule calibration_merge:
    input:
        design=calibration_design_file,
        chunks=calibration_chunk_files,
    output:
        scores="results/{design}/calibration/{calibration}.nc",
        design="results/{design}/calibration/{calibration}_design.yaml",
        table="results/{design}/calibration/{calibration}.md",
    log:
        "results/{design}/logs/calibration_{calibration}_merge.log",
    params:
        spec=calibration_spec,
    threads: 1
    script:
        "../scripts/calibration_merge.py"


CALIBRATION_TARGETS = [
    f"results/{spec['design']}/calibration/{name}.nc" for name, spec in config["calibration"].items()
]
