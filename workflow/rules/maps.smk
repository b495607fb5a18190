# Two-parameter regime maps (beyond paper 1): label over (x, y) grids, in chunks.


rule map_chunk:
    input:
        design=sweep_design_file,
    output:
        "results/{design}/maps/{map}/chunk_{chunk}.nc",
    log:
        "results/{design}/logs/map_{map}_{chunk}.log",
    params:
        spec=map_spec,
    threads: 1
    script:
        "../scripts/map_chunk.py"


rule map_merge:
    input:
        design=sweep_design_file,
        chunks=map_chunk_files,
    output:
        "results/{design}/maps/{map}.nc",
    log:
        "results/{design}/logs/map_{map}_merge.log",
    params:
        spec=map_spec,
    threads: 1
    script:
        "../scripts/map_merge.py"


rule map_figure:
    input:
        cube="results/{design}/maps/{map}.nc",
    output:
        figure="results/{design}/figures/{map}.png",
        caption="results/{design}/figures/{map}.png.txt",
    log:
        "results/{design}/logs/figure_{map}.log",
    params:
        spec=map_spec,
    threads: 1
    script:
        "../scripts/map_figure.py"


MAP_TARGETS = runs_for("maps", "results/{design}/maps/{name}.nc") + runs_for(
    "maps", "results/{design}/figures/{name}.png"
)
