# Bifurcation sweeps in chunks, merged into one cube per sweep and drawn (paper 1 Figs. 7, 9, 11 for a paper
# design), and dense runs at single points (Figs. 8, 10, 12).


rule sweep_chunk:
    input:
        kernels=KERNELS,
        design=design_file,
    output:
        temp(results("sweeps", "{sweep}", "chunk_{chunk}.nc")),
    log:
        logs("sweep_{sweep}_{chunk}.log"),
    priority: 1
    threads: 1
    params:
        spec=config_slice("sweeps"),
    script:
        "../scripts/sweep_chunk.py"


rule sweep_merge:
    input:
        design=design_file,
        chunks=chunk_files("sweeps", rules.sweep_chunk.output[0], sweep_chunks),
    output:
        cube=results("sweeps", "{sweep}.nc"),
        # the regime bands of the cube, written by the same job (a job of their own paid an interpreter and
        # the cube's reading for 0.1 s of work)
        csv=report(
            results("tables", "{sweep}_bands.csv"),
            caption="../report/bands.rst",
            category=category,
            subcategory=subcategory("sweep"),
            labels={"design": "{design}", "table": "regime bands"},
        ),
        md=results("tables", "{sweep}_bands.md"),
        # and its bifurcation diagram (paper 1 Figs. 7, 9, 11 for a paper design), still a target of its own: a
        # job of its own paid an interpreter, xarray's import and the cube's reading again (0.9 of its 1.3 CPU-s)
        figure=report(
            results("figures", "{sweep}.png"),
            caption="../report/bifurcation.rst",
            category=category,
            subcategory=subcategory("sweep"),
            labels={"design": "{design}"},
        ),
        caption=results("figures", "{sweep}.png.txt"),
    log:
        logs("sweep_{sweep}_merge.log"),
    threads: 1
    params:
        spec=config_slice("sweeps"),
    script:
        "../scripts/sweep_merge.py"


rule point_runs:
    input:
        kernels=KERNELS,
        design=design_file,
    output:
        data=results("points", "{points}.nc"),
    log:
        logs("points_{points}.log"),
    threads: 1
    params:
        spec=config_slice("points"),
    script:
        "../scripts/point_runs.py"


rule point_figure:
    input:
        design=design_file,
        data=rules.point_runs.output.data,
    output:
        figure=report(
            results("figures", "{points}.png"),
            caption="../report/points.rst",
            category=category,
            subcategory=subcategory("points"),
            labels={"design": "{design}"},
        ),
        caption=results("figures", "{points}.png.txt"),
    log:
        logs("figure_{points}.log"),
    threads: 1
    params:
        spec=config_slice("points"),
    script:
        "../scripts/point_figure.py"


SWEEP_TARGETS = runs_for(
    "sweeps", rules.sweep_merge.output[0], rules.sweep_merge.output.figure
) + runs_for("points", rules.point_runs.output.data, rules.point_figure.output.figure)
