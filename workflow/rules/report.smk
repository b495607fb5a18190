# Issue 7: how figures are grouped in `snakemake --report results/report.html`: one category per
# paper, one subcategory per figure number, the design as a label. Captions: workflow/report/*.rst,
# each of which includes the caption text the figure's job wrote beside it (<figure>.png.txt).
import re

PAPER1 = "Paper 1: Li et al. (2013), KHV drive"
PAPER2 = "Paper 2: Yue et al. (2014), plus planetary set"
BENCHMARKS = "Benchmarks"


def figure_label(name):
    """'fig07_bifurcation_x1' -> 'Fig. 07: fig07_bifurcation_x1' (zero-padded so the report sorts)."""
    match = re.match(r"fig(\d+)", name)
    return f"Fig. {int(match.group(1)):02d}: {name}" if match else f"Other: {name}"


def sweep_figure(wildcards):
    return figure_label(wildcards.sweep)


def points_figure(wildcards):
    return figure_label(wildcards.points)
