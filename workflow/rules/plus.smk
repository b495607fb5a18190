# Plus planetary sets (paper 2 kind): modal analysis (natural frequencies, modal energy, key elements),
# transmission error of the p-d pair and tip relief, and the forced response to that TE against speed, for every
# plus design in the config. Tables and figures carry the paper's numbers (table02_, fig04_, sec4_ ...) for a
# design that names a paper and descriptive names for one of your own; each rule of a pair serves one of them.
# A pair is one rule statement, written once in the loop below for disjoint sets of designs, so for every
# design exactly one rule writes each file. The loop's rules read their own pair's outputs; the forced
# response, shared by both schemes, reads the TE of either relief rule (TE_DATA, the path both write).

TE_DATA = results("data", "te.nc")


rule plus_landscape:
    input:
        design=design_file,
    output:
        landscape=results("data", "relief_landscape.nc"),
    log:
        logs("landscape.log"),
    threads: 1
    script:
        "../scripts/plus_landscape.py"


rule plus_forced_response:
    input:
        design=design_file,
        te=TE_DATA,
    output:
        data=results("data", "forced_response.nc"),
        figure=report(
            results("figures", "forced_response.png"),
            caption="../report/plus_forced_response.rst",
            category=category,
            subcategory="Forced response across speed",
            labels={"design": "{design}"},
        ),
        caption=results("figures", "forced_response.png.txt"),
    log:
        logs("forced_response.log"),
    threads: 1
    script:
        "../scripts/plus_forced_response.py"


PLUS_TARGETS = per_design(
    [*rules.plus_landscape.output, *rules.plus_forced_response.output], PLUS_DESIGNS
)

for _scheme, _designs in naming_schemes("plus_planetary"):
    _t02 = scheme_path(
        _scheme, "tables", "table02_natural_frequencies", "natural_frequencies"
    )
    _t02b = scheme_path(
        _scheme, "tables", "table02b_stiffness_scaling", "stiffness_scaling"
    )
    _t05 = scheme_path(_scheme, "tables", "table05_key_elements", "key_elements")
    _optima = scheme_path(_scheme, "tables", "sec4_relief_optima", "relief_optima")
    _stiff = scheme_path(_scheme, "tables", "sec22_mesh_stiffness", "mesh_stiffness")
    _load = scheme_path(_scheme, "tables", "sec4_relief_vs_load", "relief_vs_load")
    _f04 = scheme_path(
        _scheme, "figures", "fig04_te_unmodified", "te_unmodified", ".png"
    )
    _f06 = scheme_path(
        _scheme, "figures", "fig06_modal_strain_energy", "modal_strain_energy", ".png"
    )
    _f07 = scheme_path(
        _scheme, "figures", "fig07_modal_kinetic_energy", "modal_kinetic_energy", ".png"
    )
    _f07b = scheme_path(_scheme, "figures", "fig07b_mode_shapes", "mode_shapes", ".png")
    _f09 = scheme_path(_scheme, "figures", "fig09_te_relief", "te_relief", ".png")
    _f09b = scheme_path(
        _scheme, "figures", "fig09b_relief_landscape", "relief_landscape", ".png"
    )
    _suffix = name_of(_scheme, "", "_own")

    rule:
        name:
            f"plus_modal{_suffix}"
        input:
            design=design_file,
        output:
            modal=results("data", "modal.nc"),
            table02_csv=report(
                f"{_t02}.csv",
                caption="../report/plus_table.rst",
                category=category,
                subcategory=name_of(
                    _scheme, "Table 02: natural frequencies", "Natural frequencies"
                ),
                labels={"design": "{design}", "table": "natural frequencies"},
            ),
            table02_md=f"{_t02}.md",
            scaling_csv=f"{_t02b}.csv",
            scaling_md=f"{_t02b}.md",
            table05_csv=report(
                f"{_t05}.csv",
                caption="../report/plus_table.rst",
                category=category,
                subcategory=name_of(_scheme, "Table 05: key elements", "Key elements"),
                labels={"design": "{design}", "table": "key elements"},
            ),
            table05_md=f"{_t05}.md",
        log:
            logs("modal.log"),
        wildcard_constraints:
            design=either(_designs, "no-design"),
        threads: 1
        script:
            "../scripts/plus_modal.py"

    rule:
        name:
            f"plus_modal_figures{_suffix}"
        input:
            design=design_file,
            modal=getattr(rules, f"plus_modal{_suffix}").output.modal,
        output:
            fig06=report(
                _f06,
                caption="../report/plus_fig06_modal_strain_energy.rst",
                category=category,
                subcategory=name_of(
                    _scheme, "Fig. 06: modal strain energy", "Modal strain energy"
                ),
                labels={"design": "{design}"},
            ),
            fig06_caption=f"{_f06}.txt",
            fig07=report(
                _f07,
                caption="../report/plus_fig07_modal_kinetic_energy.rst",
                category=category,
                subcategory=name_of(
                    _scheme, "Fig. 07: modal kinetic energy", "Modal kinetic energy"
                ),
                labels={"design": "{design}"},
            ),
            fig07_caption=f"{_f07}.txt",
            fig07b=report(
                _f07b,
                caption="../report/plus_fig07b_mode_shapes.rst",
                category=category,
                subcategory=name_of(_scheme, "Fig. 07b: mode shapes", "Mode shapes"),
                labels={"design": "{design}"},
            ),
            fig07b_caption=f"{_f07b}.txt",
        log:
            logs("modal_figures.log"),
        wildcard_constraints:
            design=either(_designs, "no-design"),
        threads: 1
        script:
            "../scripts/plus_modal_figures.py"

    rule:
        name:
            f"plus_relief{_suffix}"
        input:
            design=design_file,
        output:
            te=TE_DATA,
            optima_csv=report(
                f"{_optima}.csv",
                caption="../report/plus_table.rst",
                category=category,
                subcategory="Tip-relief optima",
                labels={"design": "{design}", "table": "relief optima"},
            ),
            optima_md=f"{_optima}.md",
            stiffness_csv=f"{_stiff}.csv",
            stiffness_md=f"{_stiff}.md",
            load_csv=f"{_load}.csv",
            load_md=f"{_load}.md",
        log:
            logs("relief.log"),
        wildcard_constraints:
            design=either(_designs, "no-design"),
        threads: 1
        script:
            "../scripts/plus_relief.py"

    rule:
        name:
            f"plus_te_figures{_suffix}"
        input:
            design=design_file,
            te=getattr(rules, f"plus_relief{_suffix}").output.te,
            landscape=rules.plus_landscape.output.landscape,
            optima_csv=getattr(rules, f"plus_relief{_suffix}").output.optima_csv,
        output:
            fig04=report(
                _f04,
                caption="../report/plus_fig04_te_unmodified.rst",
                category=category,
                subcategory=name_of(
                    _scheme, "Fig. 04: transmission error", "Transmission error"
                ),
                labels={"design": "{design}"},
            ),
            fig04_caption=f"{_f04}.txt",
            fig09=report(
                _f09,
                caption="../report/plus_fig09_te_relief.rst",
                category=category,
                subcategory=name_of(_scheme, "Fig. 09: tip relief", "Tip relief"),
                labels={"design": "{design}"},
            ),
            fig09_caption=f"{_f09}.txt",
            fig09b=report(
                _f09b,
                caption="../report/plus_fig09b_relief_landscape.rst",
                category=category,
                subcategory=name_of(
                    _scheme, "Fig. 09b: relief landscape", "Relief landscape"
                ),
                labels={"design": "{design}"},
            ),
            fig09b_caption=f"{_f09b}.txt",
        log:
            logs("te_figures.log"),
        wildcard_constraints:
            design=either(_designs, "no-design"),
        threads: 1
        script:
            "../scripts/plus_te_figures.py"

    PLUS_TARGETS += per_design(
        [
            *getattr(rules, f"plus_modal{_suffix}").output,
            *getattr(rules, f"plus_modal_figures{_suffix}").output,
            *getattr(rules, f"plus_relief{_suffix}").output,
            *getattr(rules, f"plus_te_figures{_suffix}").output,
        ],
        _designs,
    )


# The paper's claims checked (its CLAIMS in geardyn.papers, read by geardyn.claims) for every plus design that
# names a paper stating them; a design of your own gets none. In the report beside the paper's tables, as
# paper 1's claims are.
from geardyn.papers import paper_of

PLUS_CLAIM_DESIGNS = [
    d
    for d in PLUS_DESIGNS
    if getattr(paper_of(DESIGNS[d].get("paper")), "CLAIMS", None)
]


rule plus_claims:
    input:
        design=design_file,
        frequencies=rules.plus_modal.output.table02_csv,
        scaling=rules.plus_modal.output.scaling_csv,
        key_elements=rules.plus_modal.output.table05_csv,
        modal=rules.plus_modal.output.modal,
        te=rules.plus_relief.output.te,
        optima=rules.plus_relief.output.optima_csv,
        forced=rules.plus_forced_response.output.data,
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
        design=either(PLUS_CLAIM_DESIGNS, "no-design"),
    localrule: True
    threads: 1
    script:
        "../scripts/plus_claims.py"


PLUS_TARGETS += per_design(rules.plus_claims.output, PLUS_CLAIM_DESIGNS)
