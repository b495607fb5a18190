# The closed graph of profile-shift coefficients (paper 1 Fig. 3 for a paper design), every KHV design.


rule closed_graph:
    input:
        design=design_file,
    output:
        "results/{design}/data/closed_graph.nc",
    log:
        "results/{design}/logs/closed_graph.log",
    threads: 1
    params:
        spec=config_slice("closed_graph"),
    script:
        "../scripts/closed_graph.py"


rule fig03_closed_graph:
    input:
        design=design_file,
        data=rules.closed_graph.output[0],
    output:
        figure=report(
            "results/{design}/figures/fig03_closed_graph.png",
            caption="../report/fig03_closed_graph.rst",
            category=category,
            subcategory="Fig. 03: closed graph",
            labels={"design": "{design}"},
        ),
        caption="results/{design}/figures/fig03_closed_graph.png.txt",
    log:
        "results/{design}/logs/fig03_closed_graph.log",
    threads: 1
    script:
        "../scripts/fig03_closed_graph.py"


GEOMETRY_TARGETS = per_design(
    [
        "results/{design}/data/closed_graph.nc",
        "results/{design}/figures/fig03_closed_graph.png",
    ],
    KHV_DESIGNS,
)
