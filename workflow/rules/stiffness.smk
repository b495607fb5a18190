# Mesh stiffness along the admissible segment, k(t) and the backlash function (paper 1 Figs. 4-6).
# Figures: fig04_/fig05_/fig06_ names for a design that names a paper, descriptive names for one of your own.


rule stiffness_table:
    input:
        design=design_file,
    output:
        results("data", "stiffness_table.nc"),
    log:
        logs("stiffness_table.log"),
    threads: 1
    params:
        spec=config_slice("stiffness_table"),
    script:
        "../scripts/stiffness_table.py"


STIFFNESS_TARGETS = per_design(rules.stiffness_table.output, KHV_DESIGNS)

for _scheme, _designs in naming_schemes("khv"):
    _rule = name_of(_scheme, "stiffness_figures", "stiffness_figures_own")
    _fig = {
        key: scheme_path(_scheme, "figures", paper, own, ".png")
        for key, paper, own in (
            ("fig04", "fig04_single_tooth_stiffness", "single_tooth_stiffness"),
            ("fig05", "fig05_mesh_stiffness", "mesh_stiffness"),
            ("fig06", "fig06_backlash", "backlash"),
        )
    }

    rule:
        name:
            _rule
        input:
            design=design_file,
        output:
            fig04=report(
                _fig["fig04"],
                caption="../report/fig04_single_tooth_stiffness.rst",
                category=category,
                subcategory=name_of(
                    _scheme,
                    "Fig. 04: single tooth stiffness",
                    "Single tooth stiffness",
                ),
                labels={"design": "{design}"},
            ),
            fig04_caption=f"{_fig['fig04']}.txt",
            fig05=report(
                _fig["fig05"],
                caption="../report/fig05_mesh_stiffness.rst",
                category=category,
                subcategory=name_of(
                    _scheme, "Fig. 05: mesh stiffness", "Mesh stiffness"
                ),
                labels={"design": "{design}"},
            ),
            fig05_caption=f"{_fig['fig05']}.txt",
            fig06=report(
                _fig["fig06"],
                caption="../report/fig06_backlash.rst",
                category=category,
                subcategory=name_of(_scheme, "Fig. 06: backlash", "Backlash"),
                labels={"design": "{design}"},
            ),
            fig06_caption=f"{_fig['fig06']}.txt",
        log:
            logs("stiffness_figures.log"),
        wildcard_constraints:
            design=either(_designs, "no-design"),
        threads: 1
        params:
            spec=config_slice("stiffness_table"),
        script:
            "../scripts/stiffness_figures.py"

    STIFFNESS_TARGETS += per_design(list(_fig.values()), _designs)
