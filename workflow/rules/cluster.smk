# Rules that take seconds (figures, merges, tables, archives) run on the submitting host
# under a cluster executor (workflow/profiles/slurm): a batch job would cost more in queueing and
# start-up than the work itself. Without a cluster executor every job is local anyway.


localrules:
    fig03_closed_graph,
    stiffness_figures,
    sweep_merge,
    bifurcation_figure,
    point_figure,
    calibration_merge,
    calibration_compare,
    plus_modal_figures,
    plus_te_figures,
    regime_bands,
    claims,
    map_merge,
    map_figure,
