# Regime bands of every sweep (labels from geardyn.classify) and, for designs that name paper 1, its
# claims checked one by one.


rule regime_bands:
    input:
        cube=rules.sweep_merge.output[0],
    output:
        csv=report(
            "results/{design}/tables/{sweep}_bands.csv",
            caption="../report/bands.rst",
            category=category,
            subcategory=subcategory("sweep"),
            labels={"design": "{design}", "table": "regime bands"},
        ),
        md="results/{design}/tables/{sweep}_bands.md",
    log:
        "results/{design}/logs/bands_{sweep}.log",
    threads: 1
    params:
        spec=config_slice("sweeps"),
    script:
        "../scripts/regime_bands.py"


rule claims:
    input:
        design=design_file,
        closed_graph=rules.closed_graph.output[0],
        stiffness=rules.stiffness_table.output[0],
        fig07="results/{design}/sweeps/fig07_bifurcation_x1.nc",
        fig09="results/{design}/sweeps/fig09_bifurcation_b.nc",
        fig11="results/{design}/sweeps/fig11_bifurcation_e.nc",
        fig08_points="results/{design}/points/fig08_points_x1.nc",
    output:
        md="results/{design}/claims.md",
        csv=report(
            "results/{design}/claims.csv",
            caption="../report/claims.rst",
            category=category,
            subcategory="Claims of the paper",
            labels={"design": "{design}", "table": "claims"},
        ),
    log:
        "results/{design}/logs/claims.log",
    threads: 1
    params:
        spec=config_slice("claims"),
    script:
        "../scripts/claims.py"


CLASSIFY_TARGETS = runs_for(
    "sweeps", "results/{design}/tables/{name}_bands.md"
) + expand("results/{design}/claims.md", design=config["claims"]["designs"])
