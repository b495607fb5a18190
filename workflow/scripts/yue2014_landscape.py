"""Adapter: objective landscape of the tip-relief optimisation -> relief_landscape.nc."""


from geardyn.plus import files, tables


def main(design_path, landscape_nc, log_path=None):
    with files.logger(log_path, "yue2014_landscape") as log:
        design = files.read_design(design_path)
        ds = tables.landscape_dataset(design)
        files.write_netcdf(ds, landscape_nc, files.provenance(design, ds.attrs["title"], "Ishikawa static TE"))
        log.info("landscape %s, ptp range %.2f-%.2f um", dict(ds.sizes), float(ds.te_ptp.min()), float(ds.te_ptp.max()))


if "snakemake" in globals():
    sm = globals()["snakemake"]
    main(sm.input.design, sm.output.landscape, sm.log[0])
