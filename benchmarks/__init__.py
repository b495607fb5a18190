"""Benchmarks of geardyn, kept beside the package as scipy keeps its own: speed against error of the
integrators (:mod:`benchmarks.work_precision`, also a pipeline target), the labeller's throughput
(:mod:`benchmarks.throughput`), two builds' labels compared (:mod:`benchmarks.labels`), an independent
long-run check (:mod:`benchmarks.long_run`) and the cost of the kernels against C (:mod:`benchmarks.kernels`).

Run from the repository root: ``python -m benchmarks.bench [mode] [--out DIR]`` (:mod:`benchmarks.bench`).
Importing any of these modules sets no environment variable and compiles nothing.
"""
