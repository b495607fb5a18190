# How figures are grouped in `snakemake --report results/report.html`: one category per paper for the
# designs that reproduce a paper, one per design for the others; one subcategory per figure. Captions:
# workflow/report/*.rst, each of which includes the caption text the figure's job wrote beside it.
import re

BENCHMARKS = "Benchmarks"


def category(wildcards):
    """The report category of a design's figures: its paper's, or the design's own."""
    from geardyn.papers import paper_of

    paper = paper_of(DESIGNS[wildcards.design].get("paper"))
    return paper.CATEGORY if paper is not None else f"Design {wildcards.design}"


def figure_label(name):
    """'fig07_bifurcation_x1' -> 'Fig. 07: fig07_bifurcation_x1' (zero-padded so the report sorts)."""
    match = re.match(r"fig(\d+)", name)
    return f"Fig. {int(match.group(1)):02d}: {name}" if match else name


def subcategory(key):
    """Report subcategory from the wildcard ``key`` (sweep, points, map) of a figure."""

    def get(wildcards):
        return figure_label(wildcards[key])

    return get
