"""geardyn: every study of every design listed in config/config.yaml, under results/<design>/.

    snakemake --cores 2            # build everything under results/
    snakemake --cores 2 <design>   # build one design's studies under results/<design>/ and nothing else

The configuration and every design file are validated here, before any job runs, by the same code
as `geardyn check-config` (geardyn.validate): a bad value stops the run with one line naming the
key, the value and what is allowed.
"""

import sys

from geardyn.config import ConfigError
from geardyn.validate import read_config_file, validate_workflow

CONFIG_FILES = workflow.overwrite_configfiles or ["config/config.yaml"]
try:
    # geardyn's YAML reading (1e6 is a number, duplicate keys are refused, the top level must be a
    # mapping), before Snakemake reads the same files
    _read = [read_config_file(path) for path in CONFIG_FILES]
except ConfigError as err:
    sys.stderr.write(f"geardyn config error: {err}\n")
    sys.exit(1)


configfile: "config/config.yaml"


for _data in _read:
    config.update(_data)
try:
    _filled, DESIGNS = validate_workflow(config, workflow.basedir)
except ConfigError as err:
    sys.stderr.write(f"geardyn config error: {err}\n")
    sys.exit(1)
config.update(_filled)


include: "workflow/rules/common.smk"
include: "workflow/rules/report.smk"
include: "workflow/rules/geometry.smk"
include: "workflow/rules/stiffness.smk"
include: "workflow/rules/sweeps.smk"
include: "workflow/rules/orbits.smk"
include: "workflow/rules/calibration.smk"
include: "workflow/rules/plus.smk"
include: "workflow/rules/benchmarks.smk"
include: "workflow/rules/classify.smk"
include: "workflow/rules/maps.smk"
include: "workflow/rules/curves.smk"
include: "workflow/rules/response.smk"
include: "workflow/rules/probabilities.smk"
include: "workflow/rules/archive.smk"
include: "workflow/rules/cluster.smk"


rule all:
    default_target: True
    input:
        GEOMETRY_TARGETS,
        STIFFNESS_TARGETS,
        SWEEP_TARGETS,
        PLUS_TARGETS,
        BENCHMARK_TARGETS,
        CLASSIFY_TARGETS,
        MAP_TARGETS,
        RESPONSE_TARGETS,
        PROBABILITY_TARGETS,
        ORBIT_TARGETS,


# The calibration searches rerun from scratch and compared with the committed designs they produced
# (docs/calibration.md): `snakemake --cores 2 calibration`. The committed design files are the source of the
# calibrated designs; the default build takes them as they are.
rule calibration:
    input:
        CALIBRATION_TARGETS,
    localrule: True


# One target rule per design, named after it: `snakemake --cores 2 <design>` builds the studies of `rule all`
# under results/<design>/ and nothing else. A design may not take the name of a rule.
_RULE_NAMES = {r.name for r in workflow.rules}
for _design in DESIGNS:
    if _design in _RULE_NAMES:
        sys.stderr.write(
            f"geardyn config error: design name {_design!r} is the name of a rule of the workflow; "
            "rename the design (its key under designs: in the config)\n"
        )
        sys.exit(1)

    rule:
        name:
            _design
        input:
            design_targets(_design, rules.all.input),
        localrule: True
