# Paper 1 Fig. 3: the closed graph of profile-shift coefficients.


rule closed_graph:
    input:
        design=design_file,
    output:
        "results/{design}/data/closed_graph.nc",
    log:
        "results/{design}/logs/closed_graph.log",
    params:
        grid=closed_graph_spec,
    threads: 1
    script:
        "../scripts/closed_graph.py"


rule fig03_closed_graph:
    input:
        data="results/{design}/data/closed_graph.nc",
    output:
        figure=report("results/{design}/figures/fig03_closed_graph.png", caption="../report/fig03_closed_graph.rst",
                      category=PAPER1, subcategory="Fig. 03: closed graph", labels={"design": "{design}"}),
        caption="results/{design}/figures/fig03_closed_graph.png.txt",
    log:
        "results/{design}/logs/fig03_closed_graph.log",
    threads: 1
    script:
        "../scripts/fig03_closed_graph.py"


GEOMETRY_TARGETS = per_khv_design(
    ["results/{design}/data/closed_graph.nc", "results/{design}/figures/fig03_closed_graph.png"]
)
