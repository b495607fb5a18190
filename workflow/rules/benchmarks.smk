# Speed against error of the integrators (issue 3); the default steps per period comes from it.


rule work_precision:
    output:
        data="results/li2013/benchmarks/work_precision.nc",
        table="results/li2013/benchmarks/work_precision.md",
        figure=report("results/li2013/benchmarks/work_precision.png", caption="../report/work_precision.rst",
                      category=BENCHMARKS, subcategory="Work-precision of the integrators", labels={"design": "li2013"}),
    log:
        "results/li2013/logs/work_precision.log",
    threads: 1
    script:
        "../scripts/work_precision.py"


BENCHMARK_TARGETS = rules.work_precision.output
