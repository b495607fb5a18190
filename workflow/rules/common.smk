# Helpers shared by the rules: which designs exist and the config slice each rule needs.


def designs_of_kind(kind):
    return [name for name, raw in DESIGNS.items() if raw["kind"] == kind]


KHV_DESIGNS = designs_of_kind("khv")


wildcard_constraints:
    design="|".join(KHV_DESIGNS) or "no-khv-design",


def design_file(wildcards):
    return config["designs"][wildcards.design]


def closed_graph_spec(wildcards):
    return config["closed_graph"]


def stiffness_spec(wildcards):
    return config["stiffness_table"]


def per_khv_design(pattern):
    return expand(pattern, design=KHV_DESIGNS)
