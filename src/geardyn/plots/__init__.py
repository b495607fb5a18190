"""Figure functions: each takes datasets and returns a matplotlib Figure (no file I/O); :func:`save_figure`
writes one, with its caption beside it."""

from __future__ import annotations

import os
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING, Literal

from geardyn.io import atomic, write_text

if TYPE_CHECKING:  # for the annotations only
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure


def paper_says(paper: ModuleType | None, key: str, **fields: object) -> str:
    """The paper's text for caption or table header ``key`` (its ``CAPTIONS``, formatted with the paper's own
    values and ``fields``, ``text`` ours where it surrounds it); "" for a design that names no paper."""
    if paper is None or key not in getattr(paper, "CAPTIONS", {}):
        return ""
    return paper.CAPTIONS[key].format_map({**vars(paper), **fields})


def single_axes(
    figsize: tuple[float, float],
    title: str,
    xlabel: str,
    ylabel: str,
    layout: Literal["constrained", "compressed", "tight"] | None = None,
) -> tuple[Figure, Axes]:
    """A pyplot-free figure of one axes with its title and axis labels; ``layout`` "constrained" lays it out,
    else the caller does."""
    from matplotlib.figure import Figure  # noqa: PLC0415 - the captions import this package without matplotlib

    fig = Figure(figsize=figsize, layout=layout)
    ax = fig.subplots()
    ax.set(title=title, xlabel=xlabel, ylabel=ylabel)
    return fig, ax


def save_figure(fig: Figure, path: str | os.PathLike[str], caption: str | None = None, dpi: int = 150) -> Path:
    """Save a matplotlib figure atomically, and its caption beside it as ``<name>.txt``.  The plots build
    :class:`matplotlib.figure.Figure` objects without pyplot (0.2-0.3 s of a figure job's start-up)."""
    path = Path(path)
    with atomic(path) as tmp:  # the temporary name ends in .tmp: the format is the target's suffix
        fig.savefig(tmp, format=path.suffix.lstrip(".").lower(), dpi=dpi, bbox_inches="tight")
    if caption is not None:
        write_text(caption.strip() + "\n", path.with_name(path.name + ".txt"))
    return path
