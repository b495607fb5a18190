# Periodic orbits of a sweep: Newton shooting seeded by the sweep's periodic points, pseudo-arclength
# continuation with Floquet multipliers and typed bifurcation points, the branches drawn over the
# sweep's bifurcation diagram, and coexisting attractors at a subset of the sweep's points.
# Configuration: the `orbits:` section, one entry per sweep name (docs/orbits.md).


rule orbit_branches:
    input:
        kernels=KERNELS,
        design=design_file,
        cube=rules.sweep_merge.output[0],
    output:
        data=results("orbits", "{sweep}_branches.nc"),
        table=results("orbits", "{sweep}_bifurcations.csv"),
    log:
        logs("orbits_{sweep}.log"),
    threads: 1
    params:
        spec=config_slice("orbits"),
        sweep=config_slice("sweeps"),
    script:
        "../scripts/orbits_branches.py"


rule orbit_figure:
    input:
        design=design_file,
        cube=rules.sweep_merge.output[0],
        branches=rules.orbit_branches.output.data,
    output:
        figure=report(
            results("figures", "{sweep}_orbits.png"),
            caption="../report/orbits.rst",
            category=category,
            subcategory=subcategory("sweep"),
            labels={"design": "{design}"},
        ),
        caption=results("figures", "{sweep}_orbits.png.txt"),
    log:
        logs("figure_{sweep}_orbits.log"),
    threads: 1
    params:
        sweep=config_slice("sweeps"),
    script:
        "../scripts/orbits_figure.py"


rule orbit_attractors:
    input:
        kernels=KERNELS,
        design=design_file,
        cube=rules.sweep_merge.output[0],
        branches=rules.orbit_branches.output.data,
    output:
        data=results("orbits", "{sweep}_attractors.nc"),
    log:
        logs("attractors_{sweep}.log"),
    threads: 1
    params:
        spec=config_slice("orbits"),
        sweep=config_slice("sweeps"),
    script:
        "../scripts/orbits_attractors.py"


ORBIT_TARGETS = (
    runs_for(
        "orbits",
        *rules.orbit_branches.output,
        rules.orbit_figure.output.figure,
        *rules.orbit_attractors.output,
    )
    if config.get("orbits")
    else []
)
