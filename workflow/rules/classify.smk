# The regime bands of every sweep (labels from geardyn.label.vocabulary; written with the sweep's cube by rule
# sweep_merge) and, for designs that name paper 1, its claims checked one by one.


rule claims:
    input:
        unpack(claims_runs),
        design=design_file,
        closed_graph=rules.closed_graph.output[0],
        stiffness=rules.stiffness_table.output[0],
    output:
        md=results("claims.md"),
        csv=report(
            results("claims.csv"),
            caption="../report/claims.rst",
            category=category,
            subcategory="Claims of the paper",
            labels={"design": "{design}", "table": "claims"},
        ),
    log:
        logs("claims.log"),
    wildcard_constraints:
        design=either(KHV_DESIGNS, "no-design"),
    threads: 1
    params:
        spec=config_slice("claims"),
    script:
        "../scripts/claims.py"


CLASSIFY_TARGETS = runs_for("sweeps", rules.sweep_merge.output.md) + per_design(
    rules.claims.output.md, config["claims"]["designs"]
)
