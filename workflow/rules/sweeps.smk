# Paper 1 Figs. 7, 9, 11: bifurcation sweeps in chunks, merged into one cube per sweep.


rule sweep_chunk:
    input:
        design=sweep_design_file,
    output:
        "results/{design}/sweeps/{sweep}/chunk_{chunk}.nc",
    log:
        "results/{design}/logs/sweep_{sweep}_{chunk}.log",
    params:
        sweep=sweep_spec,
    threads: 1
    script:
        "../scripts/sweep_chunk.py"


rule sweep_merge:
    input:
        design=sweep_design_file,
        chunks=sweep_chunk_files,
    output:
        "results/{design}/sweeps/{sweep}.nc",
    log:
        "results/{design}/logs/sweep_{sweep}_merge.log",
    params:
        sweep=sweep_spec,
    threads: 1
    script:
        "../scripts/sweep_merge.py"


rule bifurcation_figure:
    input:
        cube="results/{design}/sweeps/{sweep}.nc",
    output:
        figure=report("results/{design}/figures/{sweep}.png", caption="../report/bifurcation.rst",
                      category=PAPER1, subcategory=sweep_figure, labels={"design": "{design}"}),
        caption="results/{design}/figures/{sweep}.png.txt",
    log:
        "results/{design}/logs/figure_{sweep}.log",
    params:
        sweep=sweep_spec,
    threads: 1
    script:
        "../scripts/bifurcation_figure.py"


rule point_runs:
    input:
        design=points_design_file,
    output:
        data="results/{design}/points/{points}.nc",
    log:
        "results/{design}/logs/points_{points}.log",
    params:
        points=points_spec,
    threads: 1
    script:
        "../scripts/point_runs.py"


rule point_figure:
    input:
        data="results/{design}/points/{points}.nc",
    output:
        figure=report("results/{design}/figures/{points}.png", caption="../report/points.rst",
                      category=PAPER1, subcategory=points_figure, labels={"design": "{design}"}),
        caption="results/{design}/figures/{points}.png.txt",
    log:
        "results/{design}/logs/figure_{points}.log",
    params:
        points=points_spec,
    threads: 1
    script:
        "../scripts/point_figure.py"


SWEEP_TARGETS = (
    runs_for("sweeps", "results/{design}/sweeps/{name}.nc")
    + runs_for("sweeps", "results/{design}/figures/{name}.png")
    + runs_for("points", "results/{design}/points/{name}.nc")
    + runs_for("points", "results/{design}/figures/{name}.png")
)
