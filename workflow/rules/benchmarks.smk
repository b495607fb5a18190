# Speed against error of the integrators (issue 3); the default steps per period comes from it.


rule work_precision:
    output:
        data="results/li2013/benchmarks/work_precision.nc",
        table="results/li2013/benchmarks/work_precision.md",
        figure="results/li2013/benchmarks/work_precision.png",
    log:
        "results/li2013/logs/work_precision.log",
    threads: 1
    script:
        "../scripts/work_precision.py"


BENCHMARK_TARGETS = rules.work_precision.output
