"""Adapter: pack every netCDF cube of one design, its configs and a sha256 manifest into a .tar.gz."""

from pathlib import Path

from geardyn.io import archive, logs

log = logs.to_file(snakemake.log[0])
design = snakemake.wildcards.design
cubes = {str(p): p for p in snakemake.input.cubes}  # inside the archive at the pipeline's own paths
configs = {
    "config.yaml": snakemake.input.config,
    f"designs/{Path(snakemake.input.design).name}": snakemake.input.design,
}
manifest = archive.build(snakemake.output[0], design, cubes, configs, effective_config=snakemake.params.config)
log.info(
    "archived %d files (%d cubes) of design %s into %s", len(manifest["files"]), len(cubes), design, snakemake.output[0]
)
