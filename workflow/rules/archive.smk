# One archive per design with every netCDF cube, the configs and a sha256 manifest.
#   snakemake --cores 2 archive                         # all designs
#   geardyn verify-archive results/li2013_archive.tar.gz


def archive_cubes(wildcards):
    """The netCDF cubes of ``rule all`` under results/<design>/ (chunk files are not final cubes)."""
    prefix = f"results/{wildcards.design}/"
    return sorted({str(f) for f in rules.all.input if str(f).startswith(prefix) and str(f).endswith(".nc")})


def effective_config(wildcards):
    return config


rule design_archive:
    input:
        cubes=archive_cubes,
        design=design_file,
        config="config/config.yaml",
    output:
        "results/{design}_archive.tar.gz",
    log:
        "results/{design}/logs/archive.log",
    params:
        config=effective_config,
    localrule: True
    threads: 1
    script:
        "../scripts/archive.py"


rule archive:
    input:
        expand("results/{design}_archive.tar.gz", design=DESIGNS),
    localrule: True
