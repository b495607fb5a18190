"""The labels' vocabulary: the code of each motion label stored in cubes (period-n, quasi-periodic, chaotic,
diverged, undetermined, ...) and its names in words (``docs/classify.md``)."""

from __future__ import annotations

#: Label codes stored in cubes (``flag_values``/``flag_meanings``); n >= 1 is period-n.
#: ``not_periodic`` is what the Poincaré test alone says (QP or chaos, unresolved).
#: ``transient``: a record that still grows at the policy's cap (``docs/classify.md``, "Growing records"): no
#: attractor found, counted as undetermined where a family table needs one.
LABELS = {
    "transient": -6,
    "long_period": -5,
    "chaotic": -4,
    "quasi_periodic": -3,
    "diverged": -2,
    "undetermined": -1,
    "not_periodic": 0,
}

#: The code of "not computed" in every flag variable of the outputs (a point a chunk did not compute, a diverged
#: run's impact class): the same -1 as the label where no label was found.
NOT_COMPUTED = -1

#: The long and the short name of each code that is not period-n (period n: ``P{n}``).
NAMES = {
    LABELS["transient"]: ("transient (the record still grows)", "grow"),
    LABELS["long_period"]: ("long period (a phase-locked torus)", "Plong"),
    LABELS["chaotic"]: ("chaotic", "chaos"),
    LABELS["quasi_periodic"]: ("quasi-periodic", "QP"),
    LABELS["diverged"]: ("diverged", "div"),
    LABELS["undetermined"]: ("undetermined", "undet"),
    LABELS["not_periodic"]: ("not periodic (QP or chaos)", "NP"),
}


def label_name(n: int) -> str:
    """The label's name in words: ``quasi-periodic``, ``P3``, ..."""
    return NAMES[n][0] if n in NAMES else f"P{n}"


def short_name(n: int) -> str:
    """Compact label: P1, P5, QP, chaos, div, undet."""
    return NAMES[int(n)][1] if int(n) in NAMES else f"P{int(n)}"
