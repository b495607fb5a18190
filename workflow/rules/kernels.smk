# The compiled loops: numba compiles them into its on-disk cache once, in one job at a time (the resource
# "kernels"), before the jobs that integrate (their input KERNELS), while the other core runs jobs that
# need none (docs/performance.md).
workflow.register_resource("kernels", 1)


rule kernels:
    input:
        design=design_file,
    output:
        results("kernels.txt"),
    log:
        logs("kernels.log"),
    priority: 3
    threads: 1
    resources:
        kernels=1,
    script:
        "../scripts/kernels.py"


KERNELS = ancient(rules.kernels.output[0])
