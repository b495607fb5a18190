# Two-parameter regime maps (beyond paper 1): label over (x, y) grids, in chunks.


rule map_chunk:
    input:
        design=design_file,
    output:
        temp("results/{design}/maps/{map}/chunk_{chunk}.nc"),
    log:
        "results/{design}/logs/map_{map}_{chunk}.log",
    threads: 1
    params:
        spec=config_slice("maps"),
    script:
        "../scripts/map_chunk.py"


rule map_merge:
    input:
        design=design_file,
        chunks=chunk_files(
            "maps", "results/{design}/maps/{name}/chunk_{chunk}.nc", map_chunks
        ),
    output:
        "results/{design}/maps/{map}.nc",
    log:
        "results/{design}/logs/map_{map}_merge.log",
    threads: 1
    params:
        spec=config_slice("maps"),
    script:
        "../scripts/map_merge.py"


rule map_figure:
    input:
        cube=rules.map_merge.output[0],
    output:
        figure=report(
            "results/{design}/figures/{map}.png",
            caption="../report/map.rst",
            category=category,
            subcategory=subcategory("map"),
            labels={"design": "{design}"},
        ),
        caption="results/{design}/figures/{map}.png.txt",
    log:
        "results/{design}/logs/figure_{map}.log",
    threads: 1
    params:
        spec=config_slice("maps"),
    script:
        "../scripts/map_figure.py"


MAP_TARGETS = runs_for("maps", "results/{design}/maps/{name}.nc") + runs_for(
    "maps", "results/{design}/figures/{name}.png"
)
