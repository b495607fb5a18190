"""The growth test a record passes before a torus or chaos verdict: a trend in the amplitude of its Poincare
points (``docs/classify.md``, "Growing records").

The amplitude of a point is its distance (max norm) from the record's median point, over the attractor's size
(the largest standard deviation of a component). The record is cut into ``blocks`` blocks of whole periods and
each block's largest amplitude is its envelope. The record grows when the envelope rises by the Mann-Kendall test
(Kendall's tau of the envelope against the block index, one-sided p below ``alpha``) and the Theil-Sen slope of
the log-envelope rises by more than ``min_rise`` over the record, and its newest half grows so too at the same rate: a
bounded record's envelope only fluctuates, a record approaching its bound levels off in its newest half, a spiral off
an unstable orbit or toward divergence rises block after block to its end."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from geardyn.label.indicators import LOG_FLOOR
from geardyn.label.policy import GrowthSettings


@dataclass(frozen=True)
class Growth:
    """The growth test on one record: Kendall's tau of the block envelope against the block index, its one-sided
    p-value, the envelope's rise over the record (Theil-Sen, exp(slope (blocks - 1)) - 1), the same rise over the
    record's newest half, and the verdict."""

    tau: float
    p_value: float
    rise: float
    growing: bool
    newest_rise: float = math.nan

    def describe(self) -> str:
        """The statistic in words, for a verdict's reason."""
        rise = f"envelope rises {100 * self.rise:.0f} % over the record ({100 * self.newest_rise:.0f} % over its newest"
        return f"{rise} half), Kendall tau {self.tau:.2f}, p = {self.p_value:.1g}"


def envelope(poincare: np.ndarray, blocks: int) -> np.ndarray:
    """The largest amplitude of each of ``blocks`` equal blocks of the record (the oldest periods left out where
    its length is not a multiple), amplitudes relative to the attractor's size (module docstring)."""
    p = np.asarray(poincare, dtype=float)
    p = p[np.all(np.isfinite(p), axis=1)]
    size = float(np.max(p.std(axis=0))) if p.shape[0] else 0.0
    amp = np.max(np.abs(p - np.median(p, axis=0)), axis=1) / (size or 1.0)
    length = amp.shape[0] // blocks
    return amp[amp.shape[0] - blocks * length :].reshape(blocks, length).max(axis=1)


def _trend(poincare: np.ndarray, s: GrowthSettings) -> tuple[float, float, float]:
    """Kendall's tau and one-sided p of the record's block envelope against the block index, and its Theil-Sen
    rise over the record ((0, 1, 0) for a constant envelope)."""
    from scipy import stats  # noqa: PLC0415 - 0.3 s to import: only the labelling jobs

    env = envelope(poincare, s.blocks)
    if np.ptp(env) == 0.0:  # a constant envelope (a fixed point, a cycle sampled alike in every block)
        return 0.0, 1.0, 0.0
    tau, p_value = stats.kendalltau(np.arange(s.blocks, dtype=float), env, alternative="greater")
    return float(tau), float(p_value), _rise(env)


def _rise(env: np.ndarray) -> float:
    """The envelope's rise over the record: exp(slope (blocks - 1)) - 1 with the Theil-Sen slope of its log
    against the block index, the median of the pairwise slopes as ``scipy.stats.theilslopes`` takes it (the
    same number, without its intercept and confidence interval)."""
    y = np.log(np.maximum(env, LOG_FLOOR))
    x = np.arange(env.shape[0], dtype=float)
    dx, dy = x[:, np.newaxis] - x, y[:, np.newaxis] - y
    slopes = dy[dx > 0] / dx[dx > 0]
    slopes.sort()
    return math.expm1(float(np.median(slopes)) * (env.shape[0] - 1))


def _rises(poincare: np.ndarray, s: GrowthSettings, min_rise: float) -> tuple[float, float, float] | None:
    """:func:`_trend`'s numbers where the record's envelope rises by more than ``min_rise`` and by the
    Mann-Kendall test (one-sided p below ``alpha``), None where it does not: the rise first, Kendall's tau only
    where the rise passes."""
    from scipy import stats  # noqa: PLC0415

    env = envelope(poincare, s.blocks)
    if np.ptp(env) == 0.0:
        return None
    rise = _rise(env)
    if not rise > min_rise:
        return None
    tau, p_value = stats.kendalltau(np.arange(s.blocks, dtype=float), env, alternative="greater")
    return (float(tau), float(p_value), rise) if float(p_value) < s.alpha else None


def growing(poincare: np.ndarray, settings: GrowthSettings | None = None) -> Growth | None:
    """:func:`growth_test`'s result where the record grows, None where it does not: the same numbers for less
    work (each rule in turn, the newest half only where the whole record grows, the Mann-Kendall test only where
    the rise passes)."""
    s = GrowthSettings() if settings is None else settings
    p = np.asarray(poincare, dtype=float)
    p = p[np.all(np.isfinite(p), axis=1)]
    if s.blocks == 0 or p.shape[0] < s.blocks * s.min_block:
        return None
    whole = _rises(p, s, s.min_rise)
    if whole is None:
        return None
    half = p[p.shape[0] // 2 :]
    if half.shape[0] < s.blocks * s.min_block:
        return Growth(*whole, True)
    newest = _rises(half, s, math.sqrt(1.0 + s.min_rise) - 1.0)
    return None if newest is None else Growth(*whole, True, newest[2])


def growth_test(poincare: np.ndarray, settings: GrowthSettings | None = None) -> Growth:
    """Whether the record ``poincare`` (n_periods, n_states) grows (module docstring; ``settings``: the default
    :class:`GrowthSettings` unless given): the whole record, and its newest half at the same rate (a rise of
    sqrt(1 + ``min_rise``) - 1) where that half holds ``blocks`` x ``min_block`` periods; a record shorter than
    that, or the test off, does not grow."""
    s = GrowthSettings() if settings is None else settings
    p = np.asarray(poincare, dtype=float)
    p = p[np.all(np.isfinite(p), axis=1)]
    if s.blocks == 0 or p.shape[0] < s.blocks * s.min_block:
        return Growth(math.nan, 1.0, 0.0, False)
    tau, p_value, rise = _trend(p, s)
    growing = p_value < s.alpha and rise > s.min_rise
    half = p[p.shape[0] // 2 :]
    newest = math.nan
    if half.shape[0] >= s.blocks * s.min_block:
        _, p_half, newest = _trend(half, s)
        growing = growing and p_half < s.alpha and newest > math.sqrt(1.0 + s.min_rise) - 1.0
    return Growth(tau, p_value, rise, bool(growing), newest)
