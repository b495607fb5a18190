"""The papers as data, a module each (printed values, claims, caption texts); :data:`PAPERS` maps a design file's
``paper:`` key to its module, and only designs that name a paper are compared with it."""

from geardyn.papers import li2013, yue2014

PAPERS = {li2013.KEY: li2013, yue2014.KEY: yue2014}


def paper_of(key: str | None):
    """The paper module of ``key``, or ``None`` for a design that names no paper."""
    return PAPERS.get(key) if key else None


__all__ = ["PAPERS", "li2013", "paper_of", "yue2014"]
