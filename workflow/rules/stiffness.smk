# Paper 1 Figs. 4-6: mesh stiffness along M-N and the backlash function.


rule stiffness_table:
    input:
        design=design_file,
    output:
        "results/{design}/data/stiffness_table.nc",
    log:
        "results/{design}/logs/stiffness_table.log",
    params:
        spec=stiffness_spec,
    threads: 1
    script:
        "../scripts/stiffness_table.py"


rule stiffness_figures:
    input:
        design=design_file,
        table="results/{design}/data/stiffness_table.nc",
    output:
        fig04="results/{design}/figures/fig04_single_tooth_stiffness.png",
        fig05="results/{design}/figures/fig05_mesh_stiffness.png",
        fig06="results/{design}/figures/fig06_backlash.png",
    log:
        "results/{design}/logs/stiffness_figures.log",
    params:
        spec=stiffness_spec,
    threads: 1
    script:
        "../scripts/stiffness_figures.py"


STIFFNESS_TARGETS = per_khv_design(
    [
        "results/{design}/data/stiffness_table.nc",
        "results/{design}/figures/fig04_single_tooth_stiffness.png",
        "results/{design}/figures/fig05_mesh_stiffness.png",
        "results/{design}/figures/fig06_backlash.png",
    ]
)
