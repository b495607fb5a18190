# The closed graph of profile-shift coefficients (paper 1 Fig. 3 for a paper design), every KHV design.
# Its figure is fig03_closed_graph.png for a design that names a paper, closed_graph.png for one of your own.


rule closed_graph:
    input:
        design=design_file,
    output:
        results("data", "closed_graph.nc"),
    log:
        logs("closed_graph.log"),
    threads: 1
    params:
        spec=config_slice("closed_graph"),
    script:
        "../scripts/closed_graph.py"


GEOMETRY_TARGETS = per_design(rules.closed_graph.output, KHV_DESIGNS)

for _scheme, _designs in naming_schemes("khv"):
    _rule = name_of(_scheme, "fig03_closed_graph", "closed_graph_figure")
    _figure = scheme_path(
        _scheme, "figures", "fig03_closed_graph", "closed_graph", ".png"
    )

    rule:
        name:
            _rule
        input:
            design=design_file,
            data=rules.closed_graph.output[0],
        output:
            figure=report(
                _figure,
                caption="../report/fig03_closed_graph.rst",
                category=category,
                subcategory=name_of(_scheme, "Fig. 03: closed graph", "Closed graph"),
                labels={"design": "{design}"},
            ),
            caption=f"{_figure}.txt",
        log:
            logs(f"{_rule}.log"),
        wildcard_constraints:
            design=either(_designs, "no-design"),
        threads: 1
        script:
            "../scripts/fig03_closed_graph.py"

    GEOMETRY_TARGETS += per_design([_figure], _designs)
