# Mesh stiffness along the admissible segment, k(t) and the backlash function (paper 1 Figs. 4-6).


rule stiffness_table:
    input:
        design=design_file,
    output:
        "results/{design}/data/stiffness_table.nc",
    log:
        "results/{design}/logs/stiffness_table.log",
    threads: 1
    params:
        spec=config_slice("stiffness_table"),
    script:
        "../scripts/stiffness_table.py"


rule stiffness_figures:
    input:
        design=design_file,
    output:
        fig04=report(
            "results/{design}/figures/fig04_single_tooth_stiffness.png",
            caption="../report/fig04_single_tooth_stiffness.rst",
            category=category,
            subcategory="Fig. 04: single tooth stiffness",
            labels={"design": "{design}"},
        ),
        fig05=report(
            "results/{design}/figures/fig05_mesh_stiffness.png",
            caption="../report/fig05_mesh_stiffness.rst",
            category=category,
            subcategory="Fig. 05: mesh stiffness",
            labels={"design": "{design}"},
        ),
        fig06=report(
            "results/{design}/figures/fig06_backlash.png",
            caption="../report/fig06_backlash.rst",
            category=category,
            subcategory="Fig. 06: backlash",
            labels={"design": "{design}"},
        ),
    log:
        "results/{design}/logs/stiffness_figures.log",
    threads: 1
    params:
        spec=config_slice("stiffness_table"),
    script:
        "../scripts/stiffness_figures.py"


STIFFNESS_TARGETS = per_design(
    [
        "results/{design}/data/stiffness_table.nc",
        "results/{design}/figures/fig04_single_tooth_stiffness.png",
        "results/{design}/figures/fig05_mesh_stiffness.png",
        "results/{design}/figures/fig06_backlash.png",
    ],
    KHV_DESIGNS,
)
