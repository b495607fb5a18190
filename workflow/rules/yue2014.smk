# Paper 2 (Yue et al. 2014): plus planetary set, modal analysis (Tables 2, 5; Figs. 6-7),
# transmission error and tip relief (Eq. 9; Figs. 4, 9).

YUE2014_TARGETS = [
    "results/yue2014/data/modal.nc",
    "results/yue2014/tables/table02_natural_frequencies.csv",
    "results/yue2014/tables/table02_natural_frequencies.md",
    "results/yue2014/tables/table02b_stiffness_scaling.csv",
    "results/yue2014/tables/table02b_stiffness_scaling.md",
    "results/yue2014/tables/table05_key_elements.csv",
    "results/yue2014/tables/table05_key_elements.md",
    "results/yue2014/figures/fig06_modal_strain_energy.png",
    "results/yue2014/figures/fig07_modal_kinetic_energy.png",
    "results/yue2014/figures/fig07b_mode_shapes.png",
    "results/yue2014/data/te.nc",
    "results/yue2014/data/relief_landscape.nc",
    "results/yue2014/tables/sec4_relief_optima.csv",
    "results/yue2014/tables/sec4_relief_optima.md",
    "results/yue2014/tables/sec22_mesh_stiffness.csv",
    "results/yue2014/tables/sec22_mesh_stiffness.md",
    "results/yue2014/tables/sec4_relief_vs_load.csv",
    "results/yue2014/tables/sec4_relief_vs_load.md",
    "results/yue2014/figures/fig04_te_unmodified.png",
    "results/yue2014/figures/fig09_te_relief.png",
    "results/yue2014/figures/fig09b_relief_landscape.png",
]


rule yue2014_modal:
    input:
        design="config/designs/yue2014.yaml",
    output:
        modal="results/yue2014/data/modal.nc",
        table02_csv="results/yue2014/tables/table02_natural_frequencies.csv",
        table02_md="results/yue2014/tables/table02_natural_frequencies.md",
        scaling_csv="results/yue2014/tables/table02b_stiffness_scaling.csv",
        scaling_md="results/yue2014/tables/table02b_stiffness_scaling.md",
        table05_csv="results/yue2014/tables/table05_key_elements.csv",
        table05_md="results/yue2014/tables/table05_key_elements.md",
    log:
        "results/yue2014/logs/modal.log",
    threads: 1
    script:
        "../scripts/yue2014_modal.py"


rule yue2014_modal_figures:
    input:
        modal="results/yue2014/data/modal.nc",
    output:
        fig06=report("results/yue2014/figures/fig06_modal_strain_energy.png", caption="../report/yue2014_fig06_modal_strain_energy.rst",
                     category=PAPER2, subcategory="Fig. 06: modal strain energy", labels={"design": "yue2014"}),
        fig06_caption="results/yue2014/figures/fig06_modal_strain_energy.png.txt",
        fig07=report("results/yue2014/figures/fig07_modal_kinetic_energy.png", caption="../report/yue2014_fig07_modal_kinetic_energy.rst",
                     category=PAPER2, subcategory="Fig. 07: modal kinetic energy", labels={"design": "yue2014"}),
        fig07_caption="results/yue2014/figures/fig07_modal_kinetic_energy.png.txt",
        fig07b=report("results/yue2014/figures/fig07b_mode_shapes.png", caption="../report/yue2014_fig07b_mode_shapes.rst",
                     category=PAPER2, subcategory="Fig. 07b: mode shapes", labels={"design": "yue2014"}),
        fig07b_caption="results/yue2014/figures/fig07b_mode_shapes.png.txt",
    log:
        "results/yue2014/logs/modal_figures.log",
    threads: 1
    script:
        "../scripts/yue2014_modal_figures.py"


rule yue2014_relief:
    input:
        design="config/designs/yue2014.yaml",
    output:
        te="results/yue2014/data/te.nc",
        optima_csv="results/yue2014/tables/sec4_relief_optima.csv",
        optima_md="results/yue2014/tables/sec4_relief_optima.md",
        stiffness_csv="results/yue2014/tables/sec22_mesh_stiffness.csv",
        stiffness_md="results/yue2014/tables/sec22_mesh_stiffness.md",
        load_csv="results/yue2014/tables/sec4_relief_vs_load.csv",
        load_md="results/yue2014/tables/sec4_relief_vs_load.md",
    log:
        "results/yue2014/logs/relief.log",
    threads: 1
    script:
        "../scripts/yue2014_relief.py"


rule yue2014_landscape:
    input:
        design="config/designs/yue2014.yaml",
    output:
        landscape="results/yue2014/data/relief_landscape.nc",
    log:
        "results/yue2014/logs/landscape.log",
    threads: 1
    script:
        "../scripts/yue2014_landscape.py"


rule yue2014_te_figures:
    input:
        design="config/designs/yue2014.yaml",
        te="results/yue2014/data/te.nc",
        landscape="results/yue2014/data/relief_landscape.nc",
        optima_csv="results/yue2014/tables/sec4_relief_optima.csv",
    output:
        fig04=report("results/yue2014/figures/fig04_te_unmodified.png", caption="../report/yue2014_fig04_te_unmodified.rst",
                     category=PAPER2, subcategory="Fig. 04: transmission error", labels={"design": "yue2014"}),
        fig04_caption="results/yue2014/figures/fig04_te_unmodified.png.txt",
        fig09=report("results/yue2014/figures/fig09_te_relief.png", caption="../report/yue2014_fig09_te_relief.rst",
                     category=PAPER2, subcategory="Fig. 09: tip relief", labels={"design": "yue2014"}),
        fig09_caption="results/yue2014/figures/fig09_te_relief.png.txt",
        fig09b=report("results/yue2014/figures/fig09b_relief_landscape.png", caption="../report/yue2014_fig09b_relief_landscape.rst",
                     category=PAPER2, subcategory="Fig. 09b: relief landscape", labels={"design": "yue2014"}),
        fig09b_caption="results/yue2014/figures/fig09b_relief_landscape.png.txt",
    log:
        "results/yue2014/logs/te_figures.log",
    threads: 1
    script:
        "../scripts/yue2014_te_figures.py"
