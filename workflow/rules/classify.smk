# Regime bands of every sweep (labels from geardyn.classify) and paper 1's claims checked.


rule regime_bands:
    input:
        cube="results/{design}/sweeps/{sweep}.nc",
    output:
        csv="results/{design}/tables/{sweep}_bands.csv",
        md="results/{design}/tables/{sweep}_bands.md",
    log:
        "results/{design}/logs/bands_{sweep}.log",
    params:
        sweep=sweep_spec,
    threads: 1
    script:
        "../scripts/regime_bands.py"


rule claims:
    input:
        design=design_file,
        closed_graph="results/{design}/data/closed_graph.nc",
        stiffness="results/{design}/data/stiffness_table.nc",
        fig07="results/{design}/sweeps/fig07_bifurcation_x1.nc",
        fig09="results/{design}/sweeps/fig09_bifurcation_b.nc",
        fig11="results/{design}/sweeps/fig11_bifurcation_e.nc",
        fig08_points="results/{design}/points/fig08_points_x1.nc",
    output:
        md="results/{design}/claims.md",
        csv="results/{design}/claims.csv",
    log:
        "results/{design}/logs/claims.log",
    params:
        spec=claims_spec,
    threads: 1
    script:
        "../scripts/claims.py"


CLASSIFY_TARGETS = runs_for("sweeps", "results/{design}/tables/{name}_bands.md") + expand(
    "results/{design}/claims.md", design=config["claims"]["designs"]
)
