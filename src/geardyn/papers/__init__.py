"""The papers as data: each module holds one paper's printed values, claims and caption texts.

A design file names its paper (``paper: li2013``) or none; only designs that name a paper are
compared with it.  :data:`PAPERS` maps the key to the module.
"""

from geardyn.papers import li2013, yue2014

PAPERS = {li2013.KEY: li2013, yue2014.KEY: yue2014}


def paper_of(key: str | None):
    """The paper module of ``key``, or ``None`` for a design that names no paper."""
    return PAPERS.get(key) if key else None


__all__ = ["PAPERS", "li2013", "paper_of", "yue2014"]
