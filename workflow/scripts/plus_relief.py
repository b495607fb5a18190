"""Adapter: paper 2 TE of the p-d pair, relief optima (DE), mesh stiffness vs ISO -> tables and te.nc."""


from geardyn.plus import files, ishikawa, relief, tables


def main(design_path, te_nc, optima_csv, optima_md, stiffness_csv, stiffness_md, load_csv=None, load_md=None, log_path=None,
         torques=(43.0, 100.0, 200.0, 500.0, 750.0, 1000.0, 1500.0, 2000.0)):
    with files.logger(log_path, "yue2014_relief") as log:
        design = files.read_design(design_path)
        grid = ishikawa.design_grid(design)
        optima = [relief.optimise(design, sh, b, grid=grid) for sh in relief.SHAPES for b in relief.BOUND_SETS]
        for o in optima:
            log.info("%s/%s: amount %.3f um, length %.4f mm, ptp %.3f um (%.1f %%), %d evaluations",
                     o.shape, o.bounds, o.amount * 1e6, o.length * 1e3, o.ptp * 1e6, 100 * o.reduction, o.nfev)
        rt = tables.relief_table(optima)
        paper_at_ours = ishikawa.design_te(design, relief_amount=tables.PAPER_RELIEF["amount_mm"] * 1e-3,
                                           relief_length=tables.PAPER_RELIEF["length_mm"] * 1e-3, relief_shape="linear").ptp
        rt["ours_at_this_relief_um"] = [o.ptp * 1e6 for o in optima] + [paper_at_ours * 1e6]
        files.write_table(rt, optima_csv, optima_md, header=(
            "# Tip-relief optima of the p-d pair (paper 2, Sec. 4) with differential evolution\n\n"
            f"Load {ishikawa.pd_mesh_load(design):.1f} N per p-d mesh, ES = {design.te.es*1e6:g} um (base-pitch model), "
            f"relief on '{design.relief.apply_to}' tip(s). The last row is the paper's result; its "
            "'ours_at_this_relief_um' is our TE with the paper's optimum relief."))
        ds = tables.te_dataset(design, optima)
        files.write_netcdf(ds, te_nc, files.provenance(design, ds.attrs["title"], ds.attrs["model_variant"]))
        st = tables.stiffness_comparison(design)
        files.write_table(st, stiffness_csv, stiffness_md, header=(
            "# Mesh stiffness of the p-d pair: Ishikawa (Sec. 2.2) vs ISO 6336-1 method B vs Table 1\n\n"
            "ISO's C1..C9 are fitted for 20 deg racks; the 25 deg rack enters through C_B (1 - 0.02 (20 - 25)) = 1.10."))
        if load_csv is not None:
            lt = tables.relief_load_table(relief.load_study(design, tuple(torques)))
            files.write_table(lt, load_csv, load_md, header=(
                "# Optimal linear tip relief against the load (sensitivity study, not in the paper)\n\n"
                "Sun torque shared by three planets; ES = 10 um. 'paper' bounds: amount 20-80 um, length 0.0001-2.6 mm; "
                "'wide' bounds: amount 0-80 um, length 0-4.5 mm. Paper: 32.5 um, 2.498 mm, -27.78 % at T = 43 N m. "
                "DE on 200 mesh positions per period."))
            log.info("load study: %s", lt.round(2).to_dict("records"))


if "snakemake" in globals():
    sm = globals()["snakemake"]
    main(sm.input.design, sm.output.te, sm.output.optima_csv, sm.output.optima_md, sm.output.stiffness_csv,
         sm.output.stiffness_md, sm.output.load_csv, sm.output.load_md, sm.log[0])
