"""Paper 1's model parameters for tests that need realistic magnitudes (Table 2 and the li2013 design's
assumptions, from :mod:`geardyn.papers.li2013`)."""

from geardyn.khv.model import KHVParameters
from geardyn.papers import li2013


def li2013_parameters(**changes) -> KHVParameters:
    """:class:`KHVParameters` of paper 1's drive with ``changes`` (eps and k_c are required)."""
    return KHVParameters(**{**li2013.TABLE2, **li2013.ASSUMED, **changes})
