"""The one vocabulary of bifurcations: every kind of event that the labeller and the continuation name, with its
integer code and its legend text.  Every output's ``flag_values``/``flag_meanings`` (:func:`flags`) and every
figure legend are made from :data:`KINDS`, so a kind has the same code in every file."""

from __future__ import annotations

from collections.abc import Iterable, Mapping

import numpy as np

from geardyn.jsontypes import Json

#: kind -> (code, legend text).  Codimension 1: the way an orbit loses stability or contact; codimension 2: the
#: points of a curve where two conditions hold at once (docs/orbits.md).
KINDS: dict[str, tuple[int, str]] = {
    "none": (0, "no bifurcation"),
    "fold": (1, "fold (mu = +1)"),
    "period_doubling": (2, "period doubling (mu = -1)"),
    "neimark_sacker": (3, "Neimark-Sacker (complex pair, |mu| = 1)"),
    "orbit_lost": (4, "orbit lost (no orbit near the previous one)"),
    "branch_point": (5, "branch point (mu = +1, no turn)"),
    "grazing": (6, "grazing (contact loss, min |X_VH| = b)"),
    "back_grazing": (7, "back-flank grazing (double-sided impact)"),
    "cusp": (8, "cusp"),
    "resonance_1_1": (9, "1:1 resonance"),
    "resonance_1_2": (10, "1:2 resonance"),
    "fold_flip": (11, "fold-flip"),
    "fold_neimark_sacker": (12, "fold-Neimark-Sacker"),
    "flip_neimark_sacker": (13, "flip-Neimark-Sacker"),
    "double_neimark_sacker": (14, "double Neimark-Sacker"),
    "grazing_fold": (15, "grazing-fold"),
    "grazing_flip": (16, "grazing-flip"),
    "grazing_neimark_sacker": (17, "grazing-Neimark-Sacker"),
}
CODES = {kind: code for kind, (code, _) in KINDS.items()}

#: The kinds of a continued branch's typed points, of a two-parameter curve, and the codimension-2 types.
BRANCH_KINDS = ("fold", "period_doubling", "neimark_sacker", "branch_point", "grazing")
CURVE_KINDS = ("fold", "period_doubling", "neimark_sacker", "grazing")
CODIM2 = tuple(kind for kind, (code, _) in KINDS.items() if code >= CODES["cusp"])


def legend(kind: str) -> str:
    """The legend text of ``kind``."""
    return KINDS[kind][1] if kind in KINDS else kind


def flags(kinds: Iterable[str]) -> dict[str, int]:
    """meaning -> code of ``kinds``: the ``flags`` of a :class:`geardyn.io.Var` holding their codes."""
    return {k: CODES[k] for k in kinds}


def decode(attrs: Mapping[str, Json]) -> dict[int, str]:
    """code -> meaning of a flag variable's attributes (``flag_values``, ``flag_meanings``)."""
    values = np.atleast_1d(np.asarray(attrs.get("flag_values", []))).tolist()
    return dict(zip(values, str(attrs.get("flag_meanings", "")).split(), strict=True))
