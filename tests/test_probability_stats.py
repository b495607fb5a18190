"""The statistics of a probabilities study (geardyn.runs.probability_stats, the sampling of runs.probabilities) on
synthetic outputs, against numbers from outside the code: pure statistics, no simulation.

* Dummy inputs never lead: 8 inputs, 128 lines of the index design, an output of one input alone, 20 seeds: no
  dummy clears its permutation null by its interval in more than 5 % of the seeds, the true input in every seed;
  RBD-FAST and PAWN alike.  On the scrambled Sobol' points themselves RBD-FAST gives the dummies indices far from
  0 (the artefact the index design removes).
* SALib's estimators: the vectorised RBD-FAST and PAWN indices (the nulls' hundreds of permutations in one call)
  equal SALib's to 1e-12.
* Every sample counted: the families (not_periodic among them) and the impact classes (diverged among them) sum
  to 1; a diverged sample is +inf in the K_v quantiles; the intervals are scipy's and equal the hand-written
  formulas (Wilson's score interval, the binomial order statistics) and the inputs' frozen distributions equal
  the inverse distribution functions written out.
* The QMC standard error across R scramblings covers the error of a known probability.
"""

import math
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from SALib.analyze import pawn, rbd_fast
from scipy.stats import binom, norm

from geardyn.io import tables
from geardyn.khv import design
from geardyn.plots import probabilities as plots
from geardyn.plots import save_figure
from geardyn.runs import probabilities, probability_stats

ROOT = Path(__file__).resolve().parents[1]
D, N, SEEDS = 8, 128, 20


def _lead(method, unit, y, seed):
    """The leading input of one indicator at one point (probability_stats.leading), and which inputs clear."""
    r = probability_stats.indices(method, unit, y, 30, seed, 200)
    dims = ("indicator", "input", "sensitivity_at")
    ds = xr.Dataset(
        {
            "sensitivity_index": (dims, r[0][None, :, None]),
            "sensitivity_index_conf": (dims, r[1][None, :, None]),
            "sensitivity_null": (dims, r[4][None, :, None]),
        },
        coords={"indicator": ["y"], "input": [f"u{k}" for k in range(D)]},
        attrs={"sensitivity_method": method},
    )
    return probability_stats.leading(ds)["y"], r[0] - r[1] > r[4]


@pytest.mark.parametrize(
    ("method", "output"),
    [
        ("rbd_fast", lambda u: (u > 0.35).astype(float)),  # a regime indicator (0/1)
        ("rbd_fast", lambda u: np.sin(2 * np.pi * u) + 0.3 * u),  # a response measure, not monotone
        ("pawn", lambda u: (u > 0.35).astype(float)),
    ],
)
def test_dummy_inputs_never_lead(method, output):
    clears = np.zeros(D)
    for seed in range(SEEDS):
        unit = probabilities.index_design(D, N, seed)
        lead, clear = _lead(method, unit, output(unit[:, 0]), seed)
        assert lead == "u0", (seed, lead)  # the true input leads in every seed
        clears += clear
    assert clears[0] == SEEDS and np.all(clears[1:] <= 0.05 * SEEDS), clears  # measured: no dummy in any seed


def test_on_the_sobol_points_themselves_rbd_fast_gives_dummies_an_index():
    """The artefact the index design removes: the same output on the scrambled Sobol' net of 128 points."""
    unit, _ = probabilities.unit_cube(D, N, 0)
    s = rbd_fast.analyze(probability_stats._problem(D), unit, (unit[:, 0] > 0.35).astype(float), seed=0)["S1"]
    assert np.max(np.abs(s[1:])) > 0.05  # measured: dummies at -0.16 to -0.08
    lh = probabilities.index_design(D, N, 0)
    lead, clear = _lead("rbd_fast", lh, (lh[:, 0] > 0.35).astype(float), 0)
    assert lead == "u0" and clear.sum() == 1


def test_vectorised_indices_are_salibs():
    unit = probabilities.index_design(D, N, 3)
    y = np.sin(3 * unit[:, 1]) + unit[:, 0] ** 2 + (unit[:, 2] > 0.5)
    problem = probability_stats._problem(D)
    ys = np.array([y, y[::-1]])
    for k, yk in enumerate(ys):
        want = pawn.analyze(problem, unit, yk)["median"]
        assert probability_stats.pawn_index(unit, ys)[k] == pytest.approx(want, abs=1e-12)
        want = rbd_fast.analyze(problem, unit, yk, num_resamples=2)["S1"]
        assert probability_stats.rbd_fast_index(unit, ys)[k] == pytest.approx(want, abs=1e-12)


def _spec(**entry):
    d = design.load(ROOT / "tests" / "data" / "li2013_w07.yaml")
    base = {
        "axis": {"parameter": "x1", "start": 0.5, "stop": 0.8, "num": 5},
        "fixed": {"b": 2.0},
        "inputs": {"e": {"low": 0.5, "high": 5.0}, "zeta": {"low": 0.03, "high": 0.15}},
        "sensitivity": {"samples": 64, "indicators": ["P1", "double_sided", "dynamic_factor"], "points": 2},
    }
    spec = probabilities.ProbabilitySpec.from_config("s", {**base, **entry}, d.name, d.segment)
    table = probabilities.samples(d, spec)
    return spec, table, probabilities.attributes(spec, table, spec.policy(d))


def _cube(table, attrs, seed=0):
    """A merged cube of random verdicts: labels among P1, P3, QP, chaos, not_periodic, undetermined and
    diverged; a diverged point has impact class -1 and K_v NaN, as the study runner writes them."""
    rng = np.random.default_rng(seed)
    shape = (table.values.shape[0], 5)
    lab = rng.choice([1, 3, -3, -4, 0, -1, -2], size=shape, p=[0.5, 0.1, 0.1, 0.05, 0.1, 0.05, 0.1])
    imp = np.where(lab == -2, -1, rng.integers(0, 3, shape))
    kv = np.where(lab == -2, np.nan, 1.0 + rng.random(shape) + 2.0 * table.unit[:, :1])
    dims = ("sample", "x1")
    return xr.Dataset(
        {"label": (dims, lab), "impact_class": (dims, imp), "dynamic_factor": (dims, kv), "dte_rms": (dims, kv)},
        coords={"sample": np.arange(shape[0]), "x1": ("x1", np.linspace(0.5, 0.8, 5), {"units": "1"})},
        attrs=attrs,
    )


def test_every_sample_counted(tmp_path):
    spec, table, attrs = _spec(samples=128, scramblings=4)
    ds = probability_stats.summarize(_cube(table, attrs), spec, table)
    rows = table.block >= 0
    assert rows.sum() == 128 and (table.block == -1).sum() == 64 and set(table.block[rows]) == {0, 1, 2, 3}
    assert np.allclose(ds.family_probability.sum("family"), 1.0)  # not_periodic its own family
    assert np.allclose(ds.impact_probability.sum("impact"), 1.0)  # diverged its own impact class
    lab = ds.label.values[rows]
    assert ds.family_probability.sel(family="not_periodic").values == pytest.approx((lab == 0).mean(axis=0))
    assert ds.impact_probability.sel(impact="diverged").values == pytest.approx((lab == -2).mean(axis=0))
    # diverged (about 10 %) counts as +inf: the 95 % quantile of K_v is +inf where more than 5 % diverged
    share = (lab == -2).mean(axis=0)
    kv95 = ds.dynamic_factor_quantile.sel(quantile=0.95).values
    assert np.all(np.isinf(kv95) == (share > 0.05 + 1 / 128)), (share, kv95)
    # the convergence: nested prefixes 32, 64, 128; the whole sample's is the probability along the axis
    assert list(ds.prefix.values) == [32, 64, 128]
    whole = ds.family_probability.sel(family="P1").mean("x1")
    assert ds.convergence_probability.sel(headline="P1", prefix=128) == pytest.approx(float(whole))
    assert set(ds.headline.values) == {"P1", "double_sided"}
    # the labels are random, K_v rises with e: the table and the caption say so
    assert ds.attrs["leading_input_P1"] == ds.attrs["leading_input_double_sided"] == "none"
    assert ds.attrs["leading_input_dynamic_factor"] == "e"
    text = tables.table_markdown(ds, "t") + plots.caption("s", ds)
    assert "P1: none; double_sided: none; dynamic_factor: e " in text and "+-" in text
    save_figure(plots.probabilities_figure(ds, "s"), tmp_path / "s.png", plots.caption("s", ds))
    assert (tmp_path / "s.png").stat().st_size > 10_000


def test_sobol_probabilities_are_of_the_base_sample():
    spec, table, attrs = _spec(samples=16, sensitivity={"method": "sobol", "indicators": ["P1"], "points": 1})
    ds = probability_stats.summarize(_cube(table, attrs), spec, table)
    base = ds.label.values[:: len(table.names) + 2]
    assert table.values.shape[0] == 16 * (2 + 2) and base.shape[0] == 16  # N (D + 2) lines, no second order
    # Saltelli's layout per base point: A, AB_1 .. AB_D (A with column i from B), B; block 0 marks A
    u = table.unit.reshape(16, 4, 2)
    assert np.all(u[:, 1, 1] == u[:, 0, 1]) and np.all(u[:, 1, 0] == u[:, 3, 0]) and np.all(u[:, 2, 0] == u[:, 0, 0])
    assert np.all(table.block.reshape(16, 4) == [0, -1, -1, -1])
    assert ds.family_probability.sel(family="P1").values == pytest.approx((base == 1).mean(axis=0))
    assert "total_index" in ds and "sensitivity_null" not in ds


def test_intervals_are_the_formulas():
    z = norm.ppf(0.975)
    for k, n in ((0, 20), (3, 20), (20, 20), (57, 128)):
        p = k / n
        centre, half = p + z * z / (2 * n), z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
        want = ((centre - half) / (1 + z * z / n), (centre + half) / (1 + z * z / n))
        assert probability_stats.wilson(k, n) == pytest.approx(want, abs=1e-12)
    x = np.random.default_rng(0).random(256)
    s = np.sort(x)
    for q in (0.05, 0.5, 0.95):
        r, t = binom.ppf([0.025, 0.975], x.size, q)  # the order statistics X_(r), X_(t + 1)
        want = (np.quantile(x, q), s[int(r) - 1], s[int(t)])
        assert probability_stats.quantile_interval(x, q) == pytest.approx(want, abs=0)
    y = np.concatenate([x[:240], np.full(16, np.inf)])  # 6 % diverged
    assert probability_stats.quantile_interval(y, 0.95)[0] == math.inf
    sx = np.sort(x[:240])  # the median lies among the finite values: theirs, interpolated as numpy does
    assert probability_stats.quantile_interval(y, 0.5)[0] == pytest.approx(0.5 * (sx[127] + sx[128]), abs=1e-15)


def test_input_distributions_are_the_inverse_distribution_functions():
    u = np.linspace(0.0, 1.0, 101)[1:-1]
    uni = probabilities.Input("e", 0.5, 5.0).values(u)
    assert uni == pytest.approx(0.5 + u * 4.5, rel=1e-14)
    log = probabilities.Input("K_DH", 1e4, 1e6, log=True).values(u)
    assert log == pytest.approx(np.exp(math.log(1e4) + u * (math.log(1e6) - math.log(1e4))), rel=1e-12)
    mean, std, low, high = 0.1, 0.02, 0.07, 0.16
    a, b = norm.cdf((low - mean) / std), norm.cdf((high - mean) / std)
    tn = probabilities.Input("zeta", low, high, mean=mean, std=std).values(u)
    assert tn == pytest.approx(mean + std * norm.ppf(a + u * (b - a)), rel=1e-9)


def test_scramblings_are_nets_and_their_spread_covers_the_error():
    unit, block = probabilities.unit_cube(3, 256, 5, scramblings=8)
    assert unit.shape == (256, 3) and np.bincount(block).tolist() == [32] * 8
    for b in range(8):  # each scrambling a net: one point in each of 32 intervals of every coordinate
        cells = np.floor(unit[block == b] * 32).astype(int)
        assert all(sorted(c) == list(range(32)) for c in cells.T)
    assert not np.allclose(unit[block == 0], unit[block == 1])
    # P(u0 + u1 < 0.7) = 0.245: the error within 3 standard errors of the scramblings in >= 95 % of 200 seeds
    hits = []
    for seed in range(200):
        unit, block = probabilities.unit_cube(2, 512, seed, scramblings=8)
        flag = (unit.sum(axis=1) < 0.7)[:, None]
        r = probability_stats._probabilities({"f": flag}, block, "x", "t")
        p, se = float(r["t_probability"][1][0, 0]), float(r["t_probability_qmc_se"][1][0, 0])
        hits.append(abs(p - 0.245) <= 3 * se)
    assert np.mean(hits) >= 0.95, np.mean(hits)
