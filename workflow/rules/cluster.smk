# Rules that take seconds (figures, merges, tables, archives) run on the submitting host
# under a cluster executor (workflow/profiles/slurm): a batch job would cost more in queueing and
# start-up than the work itself. Without a cluster executor every job is local anyway.


localrules:
    fig03_closed_graph,
    closed_graph_figure,
    stiffness_figures,
    stiffness_figures_own,
    sweep_merge,
    point_figure,
    calibration_compare,
    plus_modal_figures,
    plus_modal_figures_own,
    plus_te_figures,
    plus_te_figures_own,
    plus_forced_response,
    claims,
    map_merge,
    map_figure,
    probabilities_merge,
    probabilities_claims,
