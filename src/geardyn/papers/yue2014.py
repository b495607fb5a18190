"""Paper 2 as data: Yue, Liu, Xu, Lai (2014), vibration and tip relief of a plus planetary set.

The numbers the paper prints that the code compares with, each stated once.  Only designs that
name ``paper: yue2014`` are compared with them.
"""

from __future__ import annotations

KEY = "yue2014"
SHORT = "Yue et al. (2014)"
REFERENCE = (
    "Yue H., Liu Y., Xu X., Lai J. (2014) Study on vibration characteristics and tooth profile "
    "modification of a plus planetary gear set. Journal of Vibroengineering 16(2)."
)
#: Report category of the paper's figures.
CATEGORY = "Paper 2: Yue et al. (2014), plus planetary set"

#: Table 2 of paper 2: (theoretical, simulated, experimental) natural frequencies in Hz, orders 1-6.
PAPER_TABLE2: dict[str, dict[str, tuple[float, ...]]] = {
    "I": {
        "theoretical": (1295, 4519, 6456, 6559, 8293, 9316),
        "simulated": (1204, 4850, 6395, 6637, 8288, 9413),
        "experimental": (1217, 4622, 6272, 6510, 8515, 9278),
    },
    "II": {
        "theoretical": (1295, 4211, 6456, 6559, 6718, 8471),
        "simulated": (1204, 4187, 6395, 6600, 6637, 8516),
        "experimental": (1155, 4039, 6293, 6685, 6790, 8527),
    },
    "III": {
        "theoretical": (1295, 2298, 6456, 6559, 6682, 9123),
        "simulated": (1204, 2155, 6395, 6544, 6636, 9280),
        "experimental": (1178, 2092, 6421, 6714, 6754, 9216),
    },
}
#: Table 5 of paper 2: key element (mesh type) per condition and order.
PAPER_TABLE5_ELEMENT: dict[str, tuple[str, ...]] = {
    "I": ("sp", "pd", "dr", "pd", "sp", "dr"),
    "II": ("sp", "pd", "dr", "dr", "pd", "sp"),
    "III": ("sp", "sp", "dr", "pd", "pd", "dr"),
}
PAPER_TABLE5_COMPONENTS: dict[str, tuple[str, ...]] = {
    "I": (
        "planet gear p",
        "planet gear d, sun gear",
        "planet gear p",
        "planet gear d",
        "sun gear, gear ring",
        "planet gear d, sun gear",
    ),
    "II": (
        "planet gear p, planet gear d",
        "sun gear, planet gear p, planet carrier",
        "planet gear p, planet carrier",
        "planet gear d, sun gear",
        "planet gear d",
        "planet gear p, sun gear",
    ),
    "III": (
        "planet gear p, planet gear d, planet carrier",
        "planet gear p, planet gear d, gear ring",
        "planet gear p, planet gear d, planet carrier",
        "planet gear p, planet gear d, planet carrier",
        "planet gear p, planet gear d",
        "planet gear d, planet carrier, gear ring",
    ),
}
#: Relief result of paper 2, Sec. 4.
PAPER_RELIEF = {
    "amount_mm": 0.032534,
    "length_mm": 2.4983,
    "te_before_um": 9.0,
    "te_after_um": 6.5,
    "reduction_pct": -27.78,
}
#: The three frequencies of Table 2 shared by conditions I-III (doubled planet modes), Hz.
PAPER_SHARED = (1295.0, 6456.0, 6559.0)
#: Fig. 4 / Fig. 9: static TE peak-to-peak before and after relief, um.
TE_BEFORE_UM = PAPER_RELIEF["te_before_um"]
TE_AFTER_UM = PAPER_RELIEF["te_after_um"]
