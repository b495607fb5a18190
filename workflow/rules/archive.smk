# One archive per design with every netCDF cube, the configs and a sha256 manifest; its own sha256 beside it.
#   snakemake --cores 2 archive                         # all designs
#   geardyn verify-archive results/li2013_archive.tar.gz


rule design_archive:
    input:
        cubes=archive_cubes,
        design=design_file,
        config="config/config.yaml",
    output:
        results("{design}_archive.tar.gz", design=None),
        results("{design}_archive.tar.gz.sha256", design=None),
    log:
        logs("archive.log"),
    localrule: True
    threads: 1
    params:
        config=effective_config,
    script:
        "../scripts/archive.py"


rule archive:
    input:
        per_design(rules.design_archive.output, DESIGNS),
    localrule: True
