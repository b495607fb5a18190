# Regime boundaries as curves (docs/orbits.md, "Regime boundaries as curves"): the folds, period doublings,
# Neimark-Sacker points and grazings of the periodic orbits found along a map's cut lines and in its rows,
# continued in the map's two parameters (every map whose `curves.enabled` is true, the default), and the
# `curves:` studies, which do the same in a plane without a map.
from geardyn.config.validate import selected_designs


rule map_curves:
    input:
        design=design_file,
        cube=rules.map_merge.output[0],
    output:
        results("maps", "{map}_curves.nc"),
    log:
        logs("map_{map}_curves.log"),
    threads: 1
    params:
        spec=config_slice("maps"),
    script:
        "../scripts/map_curves.py"


rule map_curves_figure:
    input:
        curves=rules.map_curves.output[0],
        cube=rules.map_merge.output[0],
    output:
        figure=report(
            results("figures", "{map}_curves.png"),
            caption="../report/map.rst",
            category=category,
            subcategory=subcategory("map"),
            labels={"design": "{design}"},
        ),
        caption=results("figures", "{map}_curves.png.txt"),
        table=results("tables", "{map}_codim2.md"),
    log:
        logs("figure_{map}_curves.log"),
    localrule: True
    threads: 1
    params:
        spec=config_slice("maps"),
    script:
        "../scripts/curves_figure.py"


rule curves_study:
    input:
        kernels=KERNELS,
        design=design_file,
    output:
        results("curves", "{study}.nc"),
    log:
        logs("curves_{study}.log"),
    threads: 1
    params:
        spec=config_slice("curves"),
    script:
        "../scripts/curves_study.py"


rule curves_study_figure:
    input:
        curves=rules.curves_study.output[0],
    output:
        figure=report(
            results("figures", "{study}_curves.png"),
            category=category,
            subcategory=subcategory("study"),
            labels={"design": "{design}"},
        ),
        caption=results("figures", "{study}_curves.png.txt"),
        table=results("tables", "{study}_codim2.md"),
    log:
        logs("figure_{study}_curves.log"),
    localrule: True
    threads: 1
    params:
        spec=config_slice("curves"),
    script:
        "../scripts/curves_figure.py"


# `rule all` lists MAP_TARGETS: the curves of every map whose curves.enabled (for each design it selects) and
# the curves studies (regime boundaries without a map) join them there.
MAP_TARGETS += [
    entry_path(pattern, "maps", name, design)
    for pattern in (rules.map_curves.output[0], rules.map_curves_figure.output.figure)
    for name, spec in config["maps"].items()
    if spec["curves"]["enabled"]
    for design in selected_designs(spec["designs"], DESIGNS)
] + runs_for(
    "curves", rules.curves_study.output[0], rules.curves_study_figure.output.figure
)
