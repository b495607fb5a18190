# Speed against error of the integrators; the default steps per period comes from it. Not a design's
# result: it runs the solver on fixed benchmark cases (benchmarks/), under results/benchmarks/.


rule work_precision:
    input:
        # the kernels compiled for the first KHV design (numba's cache serves every design)
        kernels=(
            ancient(results("kernels.txt", design=KHV_DESIGNS[0]))
            if KHV_DESIGNS
            else []
        ),
    output:
        data=benchmarks("work_precision.nc"),
        table=benchmarks("work_precision.md"),
        figure=report(
            benchmarks("work_precision.png"),
            caption="../report/work_precision.rst",
            category=BENCHMARKS,
            subcategory="Work-precision of the integrators",
        ),
    log:
        benchmarks("logs", "work_precision.log"),
    threads: 1
    params:
        spec=config_slice("benchmarks"),
    script:
        "../scripts/work_precision.py"


BENCHMARK_TARGETS = (
    rules.work_precision.output if config["benchmarks"]["work_precision"] else []
)
