# Two-parameter regime maps (beyond paper 1): label over (x, y) grids, in chunks.


rule map_chunk:
    input:
        kernels=KERNELS,
        design=design_file,
    output:
        temp(results("maps", "{map}", "chunk_{chunk}.nc")),
    log:
        logs("map_{map}_{chunk}.log"),
    # the longest jobs of a build first (map chunks, then sweep chunks), so that no long job runs alone
    # at the end while the other core idles
    priority: 2
    threads: 1
    params:
        spec=config_slice("maps", omit=("curves",)),
    script:
        "../scripts/map_chunk.py"


rule map_merge:
    input:
        design=design_file,
        chunks=chunk_files("maps", rules.map_chunk.output[0], map_chunks),
    output:
        results("maps", "{map}.nc"),
    log:
        logs("map_{map}_merge.log"),
    threads: 1
    params:
        spec=config_slice("maps", omit=("curves",)),
    script:
        "../scripts/map_merge.py"


rule map_figure:
    input:
        cube=rules.map_merge.output[0],
        # the map's curves (rule map_curves, workflow/rules/curves.smk) when its curves.enabled
        curves=lambda wc: (
            entry_path(rules.map_curves.output[0], "maps", wc.map, wc.design)
            if config["maps"][wc.map]["curves"]["enabled"]
            else []
        ),
    output:
        figure=report(
            results("figures", "{map}.png"),
            caption="../report/map.rst",
            category=category,
            subcategory=subcategory("map"),
            labels={"design": "{design}"},
        ),
        caption=results("figures", "{map}.png.txt"),
    log:
        logs("figure_{map}.log"),
    threads: 1
    params:
        spec=config_slice("maps"),
    script:
        "../scripts/map_figure.py"


MAP_TARGETS = runs_for(
    "maps", rules.map_merge.output[0], rules.map_figure.output.figure
)
