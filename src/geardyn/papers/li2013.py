"""Paper 1 as data: Li, Niu, Zhang, Tian, Fu (2013), KHV drive with a small teeth-number difference: every
number it prints that the code compares with, every statement about its figures and its dynamic model's values,
each stated once; nothing here computes, and only designs that name ``paper: li2013`` meet them."""

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

#: The transition points along x1 the paper names (Sec. 4.1).
TRANSITIONS: tuple[float, ...] = (0.565, 0.568, 0.593, 0.761, 0.768)
#: Fixed values of the x1 sweep of Fig. 7 (um).
FIG07_FIXED = {"b": 2.0, "e": 5.0}
#: The three x1 values of Figs. 9-12.
CASE_X1: tuple[float, ...] = (0.5, 0.761, 0.83)
#: The runs of the workflow's config the claims read, by role: (config section, entry name) of the
#: Fig. 7, 9 and 11 sweeps and of the Fig. 8 dense runs.  A claim names the role it reads.
CLAIM_RUNS: dict[str, tuple[str, str]] = {
    "fig07": ("sweeps", "fig07_bifurcation_x1"),
    "fig09": ("sweeps", "fig09_bifurcation_b"),
    "fig11": ("sweeps", "fig11_bifurcation_e"),
    "fig08_points": ("points", "fig08_points_x1"),
}
#: The labelled lines among those runs, by role: the parameter swept, the values held fixed and, for a
#: family of lines (one per case of the sweep, ``x1=0.5``, ...), the parameter that tells them apart and
#: its values.  The claims read the sweeps' labels along them; the calibration labels a candidate along
#: the same lines (its grids come from the config, by parameter).
CLAIM_LINES: dict[str, dict] = {
    "fig07": {"parameter": "x1", "fixed": FIG07_FIXED, "text": "Fig. 7 (x1 sweep, b = 2, e = 5)"},
    "fig09": {"parameter": "b", "fixed": {"e": FIG07_FIXED["e"]}, "case_parameter": "x1", "cases": CASE_X1},
    "fig11": {"parameter": "e", "fixed": {"b": FIG07_FIXED["b"]}, "case_parameter": "x1", "cases": CASE_X1},
}
#: Fig. 5: the three x1 values of the k(t) curves.
FIG05_X1: tuple[float, ...] = (0.416, 0.626, 0.835)
#: Fig. 8c: the spectral peaks at x1 = 0.585, in multiples of the mesh frequency.
PEAKS_0585: tuple[float, ...] = (0.48, 0.57, 0.8099, 1.0, 1.2)
#: Upper end of the P1 range in which the paper says the amplitude falls as x1 grows (the claims'
#: ``amplitude`` input: dense runs at the Fig. 7 values of b and e along this range).
P1_AMPLITUDE_RANGE = (0.416, 0.56)

#: Sec. 4.1 / Fig. 7 (b = 2, e = 5): the regime sequence along x1 as claims of rule "range", by name (in
#: :data:`CLAIMS` among the P1 amplitude and the Fig. 8c spectrum).  The P6 window "near 0.761" is taken as
#: [0.755, 0.768] (the paper names 0.768 as the start of the second chaotic range); a chaotic range after
#: the first entry is open at its lower end.
_FIG07_RANGES: dict[str, dict] = {
    key: {
        "id": f"fig07_{key}",
        "figure": "Fig. 7",
        "statement": statement,
        "rule": "range",
        "line": "fig07",
        "interval": interval,
        "label": label,
        **({"open_below": True} if label == "chaos" else {}),
    }
    for key, interval, label, statement in (
        ("p1", (0.416, 0.565), 1, "synchronous (period-1) motion for x1 in [0.416, 0.565]"),
        ("qp", (0.565, 0.568), "QP", "quasi-periodic motion for x1 in [0.565, 0.568]"),
        ("p5", (0.568, 0.593), 5, "period-5 motion for x1 in [0.568, 0.593]"),
        ("chaos1", (0.593, 0.755), "chaos", "chaos for x1 above 0.593 (until the period-6 window)"),
        ("p6", (0.755, 0.768), 6, "period-6 motion near x1 = 0.761 (window taken as [0.755, 0.768])"),
        ("chaos2", (0.768, 0.835), "chaos", "chaos again for x1 above 0.768"),
    )
}

#: The paper's names of the labels its claims give ("QP|chaos": either).
_NAMES = {1: "P1", 5: "P5", 6: "P6", "QP": "QP", "chaos": "chaos", "QP|chaos": "quasi-periodic or chaotic"}
#: Figs. 9-12: the label the paper gives on each line of a family (x1 = 0.5, 0.761, 0.83) at one value of its
#: parameter, b = 0.5 (Figs. 9/10, e = 5) and e = 4.55 (Figs. 11/12, b = 2), as claims of rule "label_at".
_FAMILY_LABELS: dict[str, tuple[dict, ...]] = {
    line: tuple(
        {
            "id": f"{line}_{par}{at}_x1_{x1}",
            "figure": f"Fig. {fig}",
            "statement": f"{par} = {at}, x1 = {x1}: {_NAMES[label]}",
            "rule": "label_at",
            "line": line,
            "case": x1,
            "at": at,
            "label": label,
        }
        for fig, x1, label in rows
    )
    for line, par, at, rows in (
        ("fig09", "b", 0.5, (("9a/10a", 0.5, 1), ("9b/10b", 0.761, "QP"), ("9c/10c", 0.83, "chaos"))),
        ("fig11", "e", 4.55, (("11a/12a", 0.5, 1), ("12b", 0.761, "QP|chaos"), ("12c", 0.83, "QP|chaos"))),
    )
}

#: Every checkable statement of the paper, in the order of the claims table, as data for
#: geardyn.claims.evaluate (the rules and their keys: geardyn.claims.SWEEP_RULES).  Each names its
#: rule and what it reads: ``input`` (a product: closed_graph, stiffness, amplitude, or a role of
#: CLAIM_RUNS) or ``line`` (a role of CLAIM_LINES, with ``case`` the x1 of one line of a family).
#: Labels: n >= 1 period-n, "QP" quasi-periodic, "chaos" chaotic, "QP|chaos" either.
CLAIMS: tuple[dict, ...] = (
    # Sec. 3.2 / Fig. 3: the limit points of the admissible segment on line 4 of the closed graph
    *(
        {
            "id": f"fig03_{pt}",
            "figure": "Fig. 3",
            "statement": f"limit point {pt} = ({x1}, {x2}) lies on line 4",
            "paper": f"x2 = {x2:.3f}",
            "rule": "on_line",
            "input": "closed_graph",
            "point": pt,
            "at": (x1, x2),
            "tolerance": POINT_TOLERANCE,
            "precision": "paper prints 3 decimals",
        }
        for pt, (x1, x2) in POINTS.items()
    ),
    {
        "id": "stiffness_falls",
        "figure": "Sec. 4.1",
        "statement": "meshing stiffness becomes small as x1 increases",
        "paper": "falls",
        "rule": "stiffness_falls",
        "input": "stiffness",
        "along": "M-N",
    },
    # Sec. 4.1 / Fig. 7 (b = 2, e = 5): the regime sequence along x1 (_FIG07_RANGES), with the P1 amplitude
    # and the Fig. 8c spectrum
    _FIG07_RANGES["p1"],
    {
        "id": "fig07_amplitude",
        "figure": "Fig. 7",
        "statement": "in the P1 range the amplitude decreases as x1 increases",
        "paper": "decreasing",
        "rule": "amplitude_falls",
        "input": "amplitude",
    },
    _FIG07_RANGES["qp"],
    _FIG07_RANGES["p5"],
    {
        "id": "fig08_peaks",
        "figure": "Fig. 8c",
        "statement": "Fig. 8c: five spectral peaks at "
        + ", ".join(f"{v:g}" for v in PEAKS_0585)
        + " x f_mesh for x1 = 0.585",
        "rule": "peaks",
        "input": "fig08_points",
        "case": {"x1": 0.585},
        "peaks": PEAKS_0585,
        "tolerance": 0.02,
        "highest": 8,
        "note": "(frequency resolution 0.01). Note: a period-5 motion has lines only at k/5 = 0.2, 0.4, 0.6, 0.8, "
        "1.0, 1.2; the paper's 0.48 and 0.57 are not of that form, so its own spectrum does not fit its P5 label",
    },
    _FIG07_RANGES["chaos1"],
    _FIG07_RANGES["p6"],
    _FIG07_RANGES["chaos2"],
    # Fig. 8 (b = 2, e = 5): the label the paper gives at each x1, read on the Fig. 7 line
    *(
        {
            "id": f"fig{fig}",
            "figure": f"Fig. {fig}",
            "statement": f"x1 = {x1}: {_NAMES[label]}",
            "rule": "label_at",
            "line": "fig07",
            "at": x1,
            "label": label,
        }
        for fig, x1, label in (
            ("8a", 0.5, 1),
            ("8b", 0.565, "QP"),
            ("8c", 0.585, 5),
            ("8d", 0.63, "chaos"),
            ("8e", 0.761, 6),
            ("8f", 0.8, "chaos"),
        )
    ),
    # Figs. 9/10 at b = 0.5 (e = 5): the label at each of the three x1, then the route along b
    *_FAMILY_LABELS["fig09"],
    {
        "id": "fig09_route",
        "figure": "Fig. 9",
        "statement": "the response turns from P1 into chaos as b increases (each x1)",
        "paper": "P1 at small b, chaos at larger b",
        "rule": "route",
        "line": "fig09",
        "start": 1,
        "end": "chaos",
    },
    # Figs. 11/12 at e = 4.55 (b = 2): the label at each of the three x1 ("QP|chaos": either), the route
    # along e and the synchronous range
    *_FAMILY_LABELS["fig11"],
    {
        "id": "fig11_route",
        "figure": "Fig. 11",
        "statement": "as e grows the response goes P1 -> quasi-periodic -> chaos",
        "paper": "P1, then QP, then chaos",
        "rule": "route",
        "line": "fig11",
        "start": 1,
        "via": "QP",
        "end": "chaos",
    },
    {
        "id": "fig11_sync_range",
        "figure": "Fig. 11",
        "statement": "the range of synchronous motion narrows as x1 increases",
        "paper": "narrower for larger x1",
        "rule": "narrows",
        "line": "fig11",
        "label": 1,
    },
)
#: The paper's names of the motions its claims compare, as the claims table's note lists them.
CLAIM_LABELS = "P1 = synchronous, QP, P5, P6, chaos"
#: Sec. 4.1 (b = 2, e = 5): the regime sequence along x1 as (from, to, label), the ranges of :data:`CLAIMS`.
SEQUENCE: tuple[tuple[float, float, int | str], ...] = tuple(
    (*c["interval"], c["label"]) for c in CLAIMS if c["rule"] == "range"
)
#: The calibration of the paper's unknowns (geardyn.khv.calibrate) scores a candidate by :data:`CLAIMS` on
#: its own labels along :data:`CLAIM_LINES`; ``line``: the line along which the transitions (where P1 is
#: left and where chaos starts, as :data:`SEQUENCE` places them) and the regime order earn partial credit
#: and a requirement is tested; ``claims`` and ``fitted_to``: what a calibrated design file and the search
#: table say the candidates were scored by.
CALIBRATION: dict = {
    "line": "fig07",
    "claims": "paper 1's claims",
    "fitted_to": (
        "Fitted to paper 1's claims (geardyn.claims.evaluate on the labels along x1 at b = 2, e = 5 and",
        "along b and e at x1 = 0.5, 0.761, 0.83; reduced integration settings, docs/calibration.md).",
    ),
}

#: The assumptions where the paper is silent, as the captions of the dynamic figures state them.
FIGURE_ASSUMPTIONS = (
    "Assumptions where the paper is silent (see the design file and docs/model.md): shaft stiffnesses, planet "
    "mass, carrier radius a cos(alpha), dimensionless mesh frequency, TE phase; corrected Eq. (4) damping and "
    "Eq. (9) stiffness."
)
#: The paper's text in our captions, by caption (geardyn.plots.paper_says): what it states about each dynamic
#: figure (Sec. 4), quoted as closely as the text allows, and its geometry and stiffness figures around ours
#: (``{text}``) with what it shows or says that we read otherwise.
CAPTIONS: dict[str, str] = {
    "fig07": "Paper ({SHORT}): P1 for x1 in [0.416, 0.565] with amplitude falling; quasi-periodic on [0.565, 0.568]; "
    "period-5 on [0.568, 0.593]; chaos above 0.593; period-6 near 0.761; chaos again above 0.768.",
    "fig08": "Paper ({SHORT}): (a) x1 = 0.5 P1; (b) 0.565 quasi-periodic; (c) 0.585 P5 with peaks 0.48, 0.57, 0.81, "
    "1, 1.2 x f_mesh; (d) 0.63 chaos; (e) 0.761 P6; (f) 0.8 chaos.",
    "fig09": "Paper ({SHORT}): At b = 0.5: P1 for x1 = 0.5, quasi-periodic for 0.761, chaotic for 0.83; the response "
    "goes from P1 to chaos as b grows.",
    "fig10": "Paper ({SHORT}): b = 0.5: (a) x1 = 0.5 P1; (b) 0.761 quasi-periodic; (c) 0.83 chaotic.",
    "fig11": "Paper ({SHORT}): P1 at e = 4.55 for x1 = 0.5; synchronous, then quasi-periodic, then chaotic as e "
    "grows; the synchronous range narrows as x1 grows.",
    "fig12": "Paper ({SHORT}): e = 4.55: P1 for x1 = 0.5, quasi-periodic and chaotic as x1 grows (0.761, 0.83).",
    "closed_graph": "Fig. 3 of {SHORT}. {text} The paper calls line 4 'equal meshing angle', but its limit points "
    "lie on G_s = 0 where a' varies.",
    "single_tooth": "Fig. 4 of {SHORT}. {text} The paper's sentence that the meshing point is '1.67 times' the "
    "engaging-in point does not match its own k_C = 1.5 k'; we follow k_C = 1.5 k'.",
    "mesh_stiffness": "Fig. 5 of {SHORT} (the paper's three x1 values). {text} Differences from the paper: Eq. (9) "
    "prints its two intervals swapped; here the double-pair zone is on [0, eps - 1] (sum of the single-pair "
    "parabolas), so k(t) jumps by k' where a pair enters or leaves. The exact mean is (8/9) eps k_C, not the "
    "printed 0.866268 eps k_C (that constant equals cos a' at N). Stiffness still falls with x1 because eps falls.",
    "backlash": "Fig. 6 of {SHORT} (Eq. (11)). {text} Identical to the paper's figure; Eq. (14)'s last case is "
    "misprinted ('-b' should read 'X < -b').",
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
