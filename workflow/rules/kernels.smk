# The solver's compiled loops, compiled once before the jobs that use them. numba caches them on disk,
# keyed on all their sources (geardyn.solve._cache); without this step the first two jobs of a fresh build
# would each compile them (about 30 s), side by side. The jobs take the record as ancient(): a
# recompile does not make their results out of date.


rule compile_kernels:
    input:
        sources=kernel_sources(),
        design=lambda wildcards: config["designs"][KHV_DESIGNS[0]],
    output:
        results("kernels.txt", design=None),
    log:
        results("logs", "kernels.log", design=None),
    # first, so the other core takes the jobs that need no kernels meanwhile
    priority: 3
    threads: 1
    script:
        "../scripts/compile_kernels.py"


#: The input that orders a job after the compile (its time stamp does not make the job's outputs stale).
KERNELS = ancient(rules.compile_kernels.output[0])
