"""The growth test a record passes before a torus or chaos verdict: a trend in the amplitude of its Poincare
points (``docs/classify.md``, "Growing records").

The amplitude of a point is its distance (max norm) from the record's median point, over the attractor's size
(the largest standard deviation of a component). The record is cut into ``blocks`` blocks of whole periods and
each block's largest amplitude is its envelope. The record grows when the envelope rises by the Mann-Kendall test
(Kendall's tau of the envelope against the block index, one-sided p below ``alpha``) and the Theil-Sen slope of
the log-envelope rises by more than ``min_rise`` over the record: a bounded record's envelope only fluctuates,
a spiral off an unstable orbit or toward divergence rises block after block."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from geardyn.label.policy import GrowthSettings


@dataclass(frozen=True)
class Growth:
    """The growth test on one record: Kendall's tau of the block envelope against the block index, its one-sided
    p-value, the envelope's rise over the record (Theil-Sen, exp(slope (blocks - 1)) - 1), the verdict, and for the
    reader the pace: the newer half's Theil-Sen slope over the older half's (about 1 for one exponential, near 0
    where the growth levels off; not part of the verdict: a record that levels off may still leave later)."""

    tau: float
    p_value: float
    rise: float
    growing: bool
    pace: float = math.nan

    def describe(self) -> str:
        """The statistic in words, for a verdict's reason."""
        rise = f"envelope rises {100 * self.rise:.0f} % over the record"
        return f"{rise}, Kendall tau {self.tau:.2f}, p = {self.p_value:.1g}, newer half's pace {self.pace:.2f}"


def envelope(poincare: np.ndarray, blocks: int) -> np.ndarray:
    """The largest amplitude of each of ``blocks`` equal blocks of the record (the oldest periods left out where
    its length is not a multiple), amplitudes relative to the attractor's size (module docstring)."""
    p = np.asarray(poincare, dtype=float)
    p = p[np.all(np.isfinite(p), axis=1)]
    size = float(np.max(p.std(axis=0))) if p.shape[0] else 0.0
    amp = np.max(np.abs(p - np.median(p, axis=0)), axis=1) / (size or 1.0)
    length = amp.shape[0] // blocks
    return amp[amp.shape[0] - blocks * length :].reshape(blocks, length).max(axis=1)


def growth_test(poincare: np.ndarray, settings: GrowthSettings | None = None) -> Growth:
    """Whether the record ``poincare`` (n_periods, n_states) grows (module docstring; ``settings``: the default
    :class:`GrowthSettings` unless given); a record shorter than ``blocks`` x ``min_block`` periods, or the test
    off, does not."""
    from scipy import stats  # noqa: PLC0415 - 0.3 s to import: only the labelling jobs

    s = GrowthSettings() if settings is None else settings
    n = int(np.sum(np.all(np.isfinite(poincare), axis=1)))
    if s.blocks == 0 or n < s.blocks * s.min_block:
        return Growth(math.nan, 1.0, 0.0, False)
    env = envelope(poincare, s.blocks)
    index = np.arange(s.blocks, dtype=float)
    if np.ptp(env) == 0.0:  # a constant envelope (a fixed point, a cycle sampled alike in every block)
        return Growth(0.0, 1.0, 0.0, False)
    tau, p_value = stats.kendalltau(index, env, alternative="greater")
    log_env = np.log(np.maximum(env, 1e-300))
    slope = float(stats.theilslopes(log_env, index).slope)
    rise = math.expm1(slope * (s.blocks - 1))
    half = s.blocks // 2
    older, newer = (float(stats.theilslopes(log_env[k], index[k]).slope) for k in (slice(0, half), slice(half, None)))
    pace = newer / older if older > 0.0 else math.inf
    return Growth(float(tau), float(p_value), rise, bool(p_value < s.alpha and rise > s.min_rise), pace)
