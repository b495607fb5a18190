# Regime probabilities under uncertain inputs (docs/probabilities.md): the samples of the inputs, each a line
# along the study's axis, in chunks of whole samples; merged with their statistics (probabilities, quantiles,
# sensitivities), drawn and tabulated; for a study with claims, the paper's claims along its line checked per sample.


rule probabilities_chunk:
    input:
        kernels=KERNELS,
        design=design_file,
    output:
        temp(results("probabilities", "{prob}", "chunk_{chunk}.nc")),
    log:
        logs("probabilities_{prob}_{chunk}.log"),
    priority: 2
    threads: 1
    params:
        spec=config_slice("probabilities"),
    script:
        "../scripts/probabilities_chunk.py"


rule probabilities_merge:
    input:
        design=design_file,
        chunks=chunk_files(
            "probabilities", rules.probabilities_chunk.output[0], probability_chunks
        ),
    output:
        cube=results("probabilities", "{prob}.nc"),
        # and the study's figure (with its caption) and table, each still a target of its own: a job of its own
        # paid an interpreter, xarray's and matplotlib's imports and the cube's reading again
        figure=report(
            results("figures", "{prob}.png"),
            caption="../report/probabilities.rst",
            category=category,
            subcategory="Regime probabilities",
            labels={"design": "{design}", "study": "{prob}"},
        ),
        caption=results("figures", "{prob}.png.txt"),
        table=results("tables", "{prob}.md"),
    log:
        logs("probabilities_{prob}_merge.log"),
    threads: 1
    params:
        spec=config_slice("probabilities"),
        skipped=skipped_designs("probabilities"),
    script:
        "../scripts/probabilities_merge.py"


rule probabilities_claims:
    input:
        design=design_file,
        cube=rules.probabilities_merge.output[0],
    output:
        md=results("claims_{prob}.md"),
        csv=report(
            results("claims_{prob}.csv"),
            caption="../report/claims_probabilities.rst",
            category=category,
            subcategory="Claims of the paper",
            labels={
                "design": "{design}",
                "table": "claims under the unknowns ({prob})",
            },
        ),
    log:
        logs("claims_{prob}.log"),
    threads: 1
    params:
        spec=config_slice("probabilities"),
    script:
        "../scripts/probabilities_claims.py"


PROBABILITY_TARGETS = runs_for(
    "probabilities",
    rules.probabilities_merge.output[0],
    rules.probabilities_merge.output.figure,
    rules.probabilities_merge.output.table,
) + probability_claims(rules.probabilities_claims.output.csv)
