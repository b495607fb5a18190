"""Paper 1 as data: Li, Niu, Zhang, Tian, Fu (2013), KHV drive with a small teeth-number difference.

Every number the paper prints that the code compares with, every statement it makes about its
figures, and the values it gives for the dynamic model, each stated once.  Nothing here computes;
generic code receives these values as arguments, and only designs that name ``paper: li2013`` meet
them.
"""

from __future__ import annotations

KEY = "li2013"
SHORT = "Li et al. (2013)"
REFERENCE = (
    "Li H., Niu W., Zhang D., Tian Y., Fu S. (2013) Effect of modification coefficient on "
    "nonlinear dynamic characteristics of planetary drive with small teeth number difference. "
    "Journal of Vibroengineering 15(4), paper 1131."
)
#: Report category of the paper's figures.
CATEGORY = "Paper 1: Li et al. (2013), KHV drive"

#: Sec. 3.2: the limit points of the admissible segment on line 4, (x1, x2).
POINTS: dict[str, tuple[float, float]] = {"M": (0.416, 0.601), "N": (0.835, 0.995)}
#: The paper prints M and N to three decimals: a computed x2 agrees within this.
POINT_TOLERANCE = 0.0011

#: Sec. 4.1 (b = 2, e = 5): the regime sequence along x1 as (from, to, label); label n >= 1 is
#: period-n, "QP" quasi-periodic, "chaos" chaotic.  The P6 window "near 0.761" is taken as
#: [0.755, 0.768] (the paper names 0.768 as the start of the second chaotic range).
SEQUENCE: tuple[tuple[float, float, int | str], ...] = (
    (0.416, 0.565, 1),
    (0.565, 0.568, "QP"),
    (0.568, 0.593, 5),
    (0.593, 0.755, "chaos"),
    (0.755, 0.768, 6),
    (0.768, 0.835, "chaos"),
)
#: How the paper words each entry of :data:`SEQUENCE` (Sec. 4.1), for the claims table.
SEQUENCE_TEXT: tuple[str, ...] = (
    "synchronous (period-1) motion for x1 in [0.416, 0.565]",
    "quasi-periodic motion for x1 in [0.565, 0.568]",
    "period-5 motion for x1 in [0.568, 0.593]",
    "chaos for x1 above 0.593 (until the period-6 window)",
    "period-6 motion near x1 = 0.761 (window taken as [0.755, 0.768])",
    "chaos again for x1 above 0.768",
)
#: The transition points along x1 the paper names (Sec. 4.1).
TRANSITIONS: tuple[float, ...] = (0.565, 0.568, 0.593, 0.761, 0.768)
#: Fixed values of the x1 sweep of Fig. 7 (um).
FIG07_FIXED = {"b": 2.0, "e": 5.0}
#: The three x1 values of Figs. 9-12.
CASE_X1: tuple[float, ...] = (0.5, 0.761, 0.83)
#: Fig. 8: the label the paper gives at each x1 (b = 2, e = 5).
FIG08_POINTS: tuple[tuple[str, float, int | str], ...] = (
    ("8a", 0.5, 1),
    ("8b", 0.565, "QP"),
    ("8c", 0.585, 5),
    ("8d", 0.63, "chaos"),
    ("8e", 0.761, 6),
    ("8f", 0.8, "chaos"),
)
#: Figs. 9/10 at b = 0.5 (e = 5): the label at each of the three x1.
FIG10_B = 0.5
FIG10_LABELS: tuple[tuple[str, float, int | str], ...] = (
    ("9a/10a", 0.5, 1),
    ("9b/10b", 0.761, "QP"),
    ("9c/10c", 0.83, "chaos"),
)
#: Figs. 11/12 at e = 4.55 (b = 2): the label at each of the three x1 ("QP|chaos": either).
FIG12_E = 4.55
FIG12_LABELS: tuple[tuple[str, float, int | str], ...] = (
    ("11a/12a", 0.5, 1),
    ("12b", 0.761, "QP|chaos"),
    ("12c", 0.83, "QP|chaos"),
)
#: The runs of the workflow's config the claims read, by their argument of geardyn.claims.claims:
#: (config section, entry name) of the Fig. 7, 9 and 11 sweeps and of the Fig. 8 dense runs.
CLAIM_RUNS: dict[str, tuple[str, str]] = {
    "fig07": ("sweeps", "fig07_bifurcation_x1"),
    "fig09": ("sweeps", "fig09_bifurcation_b"),
    "fig11": ("sweeps", "fig11_bifurcation_e"),
    "fig08_points": ("points", "fig08_points_x1"),
}
#: Fig. 5: the three x1 values of the k(t) curves.
FIG05_X1: tuple[float, ...] = (0.416, 0.626, 0.835)
#: Fig. 8c: the spectral peaks at x1 = 0.585, in multiples of the mesh frequency.
PEAKS_0585: tuple[float, ...] = (0.48, 0.57, 0.8099, 1.0, 1.2)
#: Upper end of the P1 range in which the paper says the amplitude falls as x1 grows.
P1_AMPLITUDE_RANGE = (0.416, 0.56)

#: What the paper states about each dynamic figure (Sec. 4), quoted as closely as the text allows.
FIGURE_CLAIMS: dict[str, str] = {
    "fig07": "P1 for x1 in [0.416, 0.565] with amplitude falling; quasi-periodic on [0.565, 0.568]; period-5 on "
    "[0.568, 0.593]; chaos above 0.593; period-6 near 0.761; chaos again above 0.768.",
    "fig08": "(a) x1 = 0.5 P1; (b) 0.565 quasi-periodic; (c) 0.585 P5 with peaks 0.48, 0.57, 0.81, 1, 1.2 x f_mesh; "
    "(d) 0.63 chaos; (e) 0.761 P6; (f) 0.8 chaos.",
    "fig09": "At b = 0.5: P1 for x1 = 0.5, quasi-periodic for 0.761, chaotic for 0.83; the response goes from P1 "
    "to chaos as b grows.",
    "fig10": "b = 0.5: (a) x1 = 0.5 P1; (b) 0.761 quasi-periodic; (c) 0.83 chaotic.",
    "fig11": "P1 at e = 4.55 for x1 = 0.5; synchronous, then quasi-periodic, then chaotic as e grows; the "
    "synchronous range narrows as x1 grows.",
    "fig12": "e = 4.55: P1 for x1 = 0.5, quasi-periodic and chaotic as x1 grows (0.761, 0.83).",
}

#: Table 1 and Table 2 values of the dynamic model (SI), with Table 2's "I_K" read as the carrier
#: inertia I_H (the annulus is fixed).  For tests and benchmarks that need the paper's magnitudes.
TABLE2 = {"I_D": 0.03, "I_H": 0.15, "I_V": 0.2175, "I_L": 0.03, "zeta": 0.1, "eta": 0.005, "T_D": 50.0, "T_L": 50.0}
#: The values the paper does not give, as the ``li2013`` design file assumes them (its comments give
#: the reasons): radii from the pair, a steel-disc planet, shaft stiffnesses, TE phase, mesh frequency.
ASSUMED = {
    "r_bV": 0.04933386259126019,
    "r_bH": 0.00493338625912602,
    "m_V": 1.359465315978728,
    "K_DH": 3.0e4,
    "K_VL": 3.0e4,
    "te_phase": 0.0,
    "omega_bar": 0.9,
    "input_speed_rpm": 525.0,
    "z_annulus": 33,
    "backlash": 2.0e-6,
    "te_amplitude": 5.0e-6,
    "pressure_angle_deg": 20.0,
}
