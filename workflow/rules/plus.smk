# Plus planetary sets (paper 2 kind): modal analysis (natural frequencies, modal energy, key elements),
# transmission error of the p-d pair and tip relief, and the forced response to that TE against speed, for every
# plus design in the config.


rule plus_modal:
    input:
        design=design_file,
    output:
        modal="results/{design}/data/modal.nc",
        table02_csv=report(
            "results/{design}/tables/table02_natural_frequencies.csv",
            caption="../report/plus_table.rst",
            category=category,
            subcategory="Table 02: natural frequencies",
            labels={"design": "{design}", "table": "natural frequencies"},
        ),
        table02_md="results/{design}/tables/table02_natural_frequencies.md",
        scaling_csv="results/{design}/tables/table02b_stiffness_scaling.csv",
        scaling_md="results/{design}/tables/table02b_stiffness_scaling.md",
        table05_csv=report(
            "results/{design}/tables/table05_key_elements.csv",
            caption="../report/plus_table.rst",
            category=category,
            subcategory="Table 05: key elements",
            labels={"design": "{design}", "table": "key elements"},
        ),
        table05_md="results/{design}/tables/table05_key_elements.md",
    log:
        "results/{design}/logs/modal.log",
    threads: 1
    script:
        "../scripts/plus_modal.py"


rule plus_modal_figures:
    input:
        design=design_file,
        modal=rules.plus_modal.output.modal,
    output:
        fig06=report(
            "results/{design}/figures/fig06_modal_strain_energy.png",
            caption="../report/plus_fig06_modal_strain_energy.rst",
            category=category,
            subcategory="Fig. 06: modal strain energy",
            labels={"design": "{design}"},
        ),
        fig06_caption="results/{design}/figures/fig06_modal_strain_energy.png.txt",
        fig07=report(
            "results/{design}/figures/fig07_modal_kinetic_energy.png",
            caption="../report/plus_fig07_modal_kinetic_energy.rst",
            category=category,
            subcategory="Fig. 07: modal kinetic energy",
            labels={"design": "{design}"},
        ),
        fig07_caption="results/{design}/figures/fig07_modal_kinetic_energy.png.txt",
        fig07b=report(
            "results/{design}/figures/fig07b_mode_shapes.png",
            caption="../report/plus_fig07b_mode_shapes.rst",
            category=category,
            subcategory="Fig. 07b: mode shapes",
            labels={"design": "{design}"},
        ),
        fig07b_caption="results/{design}/figures/fig07b_mode_shapes.png.txt",
    log:
        "results/{design}/logs/modal_figures.log",
    threads: 1
    script:
        "../scripts/plus_modal_figures.py"


rule plus_relief:
    input:
        design=design_file,
    output:
        te="results/{design}/data/te.nc",
        optima_csv=report(
            "results/{design}/tables/sec4_relief_optima.csv",
            caption="../report/plus_table.rst",
            category=category,
            subcategory="Tip-relief optima",
            labels={"design": "{design}", "table": "relief optima"},
        ),
        optima_md="results/{design}/tables/sec4_relief_optima.md",
        stiffness_csv="results/{design}/tables/sec22_mesh_stiffness.csv",
        stiffness_md="results/{design}/tables/sec22_mesh_stiffness.md",
        load_csv="results/{design}/tables/sec4_relief_vs_load.csv",
        load_md="results/{design}/tables/sec4_relief_vs_load.md",
    log:
        "results/{design}/logs/relief.log",
    threads: 1
    script:
        "../scripts/plus_relief.py"


rule plus_landscape:
    input:
        design=design_file,
    output:
        landscape="results/{design}/data/relief_landscape.nc",
    log:
        "results/{design}/logs/landscape.log",
    threads: 1
    script:
        "../scripts/plus_landscape.py"


rule plus_te_figures:
    input:
        design=design_file,
        te=rules.plus_relief.output.te,
        landscape=rules.plus_landscape.output.landscape,
        optima_csv=rules.plus_relief.output.optima_csv,
    output:
        fig04=report(
            "results/{design}/figures/fig04_te_unmodified.png",
            caption="../report/plus_fig04_te_unmodified.rst",
            category=category,
            subcategory="Fig. 04: transmission error",
            labels={"design": "{design}"},
        ),
        fig04_caption="results/{design}/figures/fig04_te_unmodified.png.txt",
        fig09=report(
            "results/{design}/figures/fig09_te_relief.png",
            caption="../report/plus_fig09_te_relief.rst",
            category=category,
            subcategory="Fig. 09: tip relief",
            labels={"design": "{design}"},
        ),
        fig09_caption="results/{design}/figures/fig09_te_relief.png.txt",
        fig09b=report(
            "results/{design}/figures/fig09b_relief_landscape.png",
            caption="../report/plus_fig09b_relief_landscape.rst",
            category=category,
            subcategory="Fig. 09b: relief landscape",
            labels={"design": "{design}"},
        ),
        fig09b_caption="results/{design}/figures/fig09b_relief_landscape.png.txt",
    log:
        "results/{design}/logs/te_figures.log",
    threads: 1
    script:
        "../scripts/plus_te_figures.py"


rule plus_forced_response:
    input:
        design=design_file,
        te=rules.plus_relief.output.te,
    output:
        data="results/{design}/data/forced_response.nc",
        figure=report(
            "results/{design}/figures/forced_response.png",
            caption="../report/plus_forced_response.rst",
            category=category,
            subcategory="Forced response across speed",
            labels={"design": "{design}"},
        ),
        caption="results/{design}/figures/forced_response.png.txt",
    log:
        "results/{design}/logs/forced_response.log",
    threads: 1
    script:
        "../scripts/plus_forced_response.py"


PLUS_TARGETS = per_design(
    [
        *rules.plus_modal.output,
        *rules.plus_modal_figures.output,
        *rules.plus_relief.output,
        *rules.plus_landscape.output,
        *rules.plus_te_figures.output,
        *rules.plus_forced_response.output,
    ],
    PLUS_DESIGNS,
)
